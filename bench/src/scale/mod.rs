//! `attsync-bench scale`: the in-process engine's agent-steps per second
//! against the number of agents N and of threads, per scheme, on networks
//! built in memory ([`tree`]), without any output (the engine alone).
//!
//! Each measurement runs about [`BUDGET`] agent-steps (or `--budget`) (at least
//! [`MIN_STEPS`] steps) after one untimed warm-up step, and reports
//! agent-steps/s = N × steps ÷ wall s, with `threads` the count the engine
//! used ([`attitude::engine::InProcess::with_threads`] gives each thread at
//! least 64 agents, `--exact` lifts that), agent-steps per CPU second (the
//! process's CPU time: on one thread the per-core figure, which a busy
//! machine disturbs less than the wall clock; on several it counts the
//! barriers' spinning too) and each thread count's speed-up over the first.
//!
//! A second table ([`conditions`]) says what the machine let each figure
//! have: wall and CPU time, CPU ÷ wall (the cores it kept busy: 2 threads
//! running in parallel show ≈ 2), and the time its threads were runnable
//! but waited for a core ([`sched`]), so figures of a shared machine can be
//! told from an idle one's.
//!
//! # Layout
//! - [`tree`]: the binary tree of any size.
//! - [`sched`]: the threads' time on a CPU and waiting for one (`schedstat`).

pub mod sched;
pub mod tree;

use attitude::engine::InProcess;
use std::fmt::Write as _;
use std::time::Instant;
use tree::SchemeArg;

/// Agent-steps per measurement.
pub const BUDGET: u64 = 2_000_000;

/// Fewest steps per measurement.
pub const MIN_STEPS: u64 = 10;

/// One measurement.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Scheme.
    pub scheme: SchemeArg,
    /// Agents.
    pub agents: u32,
    /// Threads asked for.
    pub asked: usize,
    /// Threads the engine used.
    pub threads: usize,
    /// Steps timed.
    pub steps: u64,
    /// Wall time of the timed steps, s.
    pub seconds: f64,
    /// CPU time of the timed steps (every thread), s, if `/proc` tells.
    pub cpu_seconds: Option<f64>,
    /// Whether every agent's final state is finite (the run did not diverge).
    pub finite: bool,
    /// The scheduler's books of the timed steps.
    pub books: sched::Books,
}

impl Figure {
    /// Agent-steps per second.
    pub fn agent_steps_per_s(&self) -> f64 {
        self.agent_steps() / self.seconds
    }

    /// Agent-steps per CPU second (`None` if unknown or under `/proc`'s resolution).
    pub fn agent_steps_per_cpu_s(&self) -> Option<f64> {
        (self.cpu_seconds).and_then(|c| (c > 0.0).then(|| self.agent_steps() / c))
    }

    fn agent_steps(&self) -> f64 {
        f64::from(self.agents) * self.steps as f64
    }
}

/// Runs `agents` agents under `scheme` on `threads` threads (`exact`: as
/// many as asked, however few agents each gets).
/// About `budget` agent-steps are timed.
pub fn measure(scheme: SchemeArg, agents: u32, threads: usize, exact: bool, budget: u64) -> Figure {
    let steps = (budget / u64::from(agents)).max(MIN_STEPS);
    let net = tree::network(agents, scheme, steps + 1);
    let engine = InProcess::new(&net);
    let mut engine = if exact {
        engine.with_exact_threads(threads)
    } else {
        engine.with_threads(threads)
    };
    engine.step();
    let watch = sched::Watch::start();
    let cpu = crate::stats::cpu_seconds();
    let started = Instant::now();
    let mut finite = true;
    engine.run(|snap| {
        if snap.step == net.steps {
            finite = snap
                .agents
                .iter()
                .all(|a| a.r.iter().chain(&a.w).all(|v| v.is_finite()));
        }
        true
    });
    let seconds = started.elapsed().as_secs_f64();
    let cpu_seconds = cpu.zip(crate::stats::cpu_seconds()).map(|(a, b)| b - a);
    Figure {
        scheme,
        agents,
        asked: threads,
        threads: engine.threads(),
        steps,
        seconds,
        cpu_seconds,
        finite,
        books: watch.stop(),
    }
}

/// The Markdown table of `figures`: one row per (scheme, N); per thread
/// count asked, agent-steps/s (threads used) and agent-steps per CPU s;
/// then the speed-up of each further thread count over the first.
pub fn table(figures: &[Figure], threads: &[usize]) -> String {
    let mut s = String::from("| scheme | N | steps |");
    for t in threads {
        let _ = write!(s, " threads {t}: agent-steps/s (used) | per CPU s |");
    }
    for t in &threads[1..] {
        let _ = write!(s, " speed-up {t}/{} |", threads[0]);
    }
    s.push_str("\n|---|---:|---:|");
    for _ in threads.iter().chain(threads).chain(&threads[1..]) {
        s.push_str("---:|");
    }
    let mut rows: Vec<(SchemeArg, u32)> = figures.iter().map(|f| (f.scheme, f.agents)).collect();
    rows.dedup();
    for (scheme, n) in rows {
        let of = |t: usize| {
            figures
                .iter()
                .find(|f| (f.scheme, f.agents, f.asked) == (scheme, n, t))
        };
        let steps = of(threads[0]).map_or(0, |f| f.steps);
        let _ = write!(s, "\n| {} | {n} | {steps} |", scheme.name());
        for &t in threads {
            s.push_str(&cells(of(t)));
        }
        let base = of(threads[0]).map(Figure::agent_steps_per_s);
        for &t in &threads[1..] {
            match (base, of(t)) {
                (Some(b), Some(f)) => {
                    let _ = write!(s, " {:.2} |", f.agent_steps_per_s() / b);
                }
                _ => s.push_str(" – |"),
            }
        }
    }
    s.push('\n');
    s
}

/// The Markdown table of what the machine gave each figure: wall s, CPU s
/// (`/proc`, every thread), CPU ÷ wall, and the threads' time on a CPU
/// and runnable but waiting for one (`schedstat`, summed over threads).
pub fn conditions(figures: &[Figure]) -> String {
    let mut s = String::from(
        "| scheme | N | threads (used) | wall s | CPU s | CPU ÷ wall | on a CPU s | waiting for a CPU s |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|",
    );
    for f in figures {
        let cpu = f.cpu_seconds.map_or("–".into(), |c| format!("{c:.2}"));
        let busy = (f.cpu_seconds).map_or("–".into(), |c| format!("{:.2}", c / f.seconds));
        let _ = write!(
            s,
            "\n| {} | {} | {} ({}) | {:.2} | {cpu} | {busy} | {:.2} | {:.2} |",
            f.scheme.name(),
            f.agents,
            f.asked,
            f.threads,
            f.seconds,
            f.books.on_cpu,
            f.books.waiting
        );
    }
    s.push('\n');
    s
}

/// The two cells of one figure: agent-steps/s (threads used) and per CPU s.
fn cells(f: Option<&Figure>) -> String {
    let Some(f) = f else {
        return " – | – |".into();
    };
    let mark = if f.finite { "" } else { " (diverged)" };
    let cpu = f
        .agent_steps_per_cpu_s()
        .map_or("–".into(), |r| format!("{r:.3e}"));
    format!(
        " {:.3e} ({}){mark} | {cpu} |",
        f.agent_steps_per_s(),
        f.threads
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every sample of a run: step and the bits of every agent's state.
    fn trajectory(net: &attitude::network::Network, threads: usize) -> Vec<(u64, Vec<u64>)> {
        let mut out = Vec::new();
        InProcess::new(net).with_exact_threads(threads).run(|snap| {
            let bits = (snap.agents.iter())
                .flat_map(|a| {
                    a.r.iter()
                        .chain(&a.w)
                        .chain(&a.r_hat)
                        .chain(&a.w_hat)
                        .chain(&a.s_hat)
                })
                .map(|v| v.to_bits())
                .collect();
            out.push((snap.step, bits));
            true
        });
        out
    }

    #[test]
    fn a_10_000_agent_tree_runs_bit_identically_on_1_2_and_3_threads() {
        let net = tree::network(10_000, SchemeArg::ObserverTimeVarying, 20);
        let one = trajectory(&net, 1);
        assert_eq!(one.len(), 3, "samples at t = 0, 10 and 20 steps");
        let last = &one[2].1;
        assert!(last.iter().all(|&b| f64::from_bits(b).is_finite()));
        assert_ne!(one[0].1, *last, "the network moved");
        assert_eq!(trajectory(&net, 2), one);
        assert_eq!(trajectory(&net, 3), one);
    }

    #[test]
    fn the_table_has_a_row_per_scheme_and_size() {
        let f = measure(SchemeArg::Observerless, 10, 2, true, BUDGET);
        assert_eq!(f.threads, 2);
        assert!(f.finite && f.steps == BUDGET / 10 && f.seconds > 0.0);
        let t = table(&[f], &[2, 1]);
        assert!(t.contains("| observerless | 10 | 200000 |"), "{t}");
        assert!(t.contains("(2) |") && t.contains(" – | – | – |"), "{t}");
        assert!(t.contains("| speed-up 1/2 |"), "{t}");
        assert_eq!(
            t.lines().nth(1).map(|l| l.matches(":|").count()),
            Some(7),
            "{t}"
        );
    }

    #[test]
    fn the_conditions_have_a_row_per_figure() {
        let f = measure(SchemeArg::ObserverConstant, 200, 2, false, 20_000);
        assert_eq!((f.threads, f.steps), (2, 100));
        let c = conditions(&[f.clone(), f]);
        assert_eq!(c.lines().count(), 4, "{c}");
        assert!(c.contains("| observer-constant | 200 | 2 (2) |"), "{c}");
        assert_eq!(c.lines().nth(1).map(|l| l.matches(":|").count()), Some(7));
    }
}

//! The Markdown report of `attsync-bench run`: a header saying how things
//! are counted, then one table per kind of measurement, then the notes
//! (failures, shortened and skipped runs). "—" marks a figure that could
//! not be measured.

use super::Options;
use super::plan::{Plan, ring_spec};
use super::run::{Results, max_opt};
use crate::measure::wait_name;
use msgs::config::WaitStrategy;
use std::fmt::Write as _;

/// When and where the benchmark ran.
#[derive(Debug, Clone)]
pub(super) struct Context {
    pub cores: u32,
    pub started_at: String,
    pub load_before: String,
    /// Seconds the whole benchmark took.
    pub total: f64,
    /// How many measurements started on an idle machine.
    pub idle: String,
}

fn f(x: Option<f64>, digits: usize) -> String {
    x.map_or_else(|| "—".into(), |v| format!("{v:.digits$}"))
}

fn rate(steps: u64, secs: Option<f64>) -> Option<f64> {
    secs.filter(|s| *s > 0.0).map(|s| steps as f64 / s)
}

fn us_per_exchange(steps: u64, secs: Option<f64>) -> Option<f64> {
    secs.map(|s| s / (steps as f64 * 4.0) * 1e6)
}

fn kb(x: Option<u64>) -> String {
    x.map_or_else(|| "—".into(), |v| v.to_string())
}

fn failures(label: &str, errors: &[String], ok: usize, out: &mut Vec<String>) {
    if !errors.is_empty() {
        out.push(format!(
            "{label}: {} of {} repetitions failed: {}",
            errors.len(),
            errors.len() + ok,
            errors[0]
        ));
    }
}

/// The whole report.
pub(super) fn report(o: &Options, plan: &Plan, res: &Results, cx: &Context) -> String {
    let mut s = String::new();
    let mut notes = Vec::new();
    header(&mut s, o, plan, cx);
    inproc(&mut s, res, &mut notes);
    procs(&mut s, res, &mut notes);
    ring(&mut s, res, &mut notes);
    diagnostics(&mut s, res, &mut notes);
    contended(&mut s, res, cx, &mut notes);
    notes.extend(res.skipped.iter().cloned());
    if !notes.is_empty() {
        let _ = writeln!(s, "\nNotes:");
        for n in notes {
            let _ = writeln!(s, "- {n}");
        }
    }
    s
}

fn header(w: &mut String, o: &Options, plan: &Plan, cx: &Context) {
    let _ = writeln!(
        w,
        "## attsync benchmark{}\n",
        if o.quick { " (quick)" } else { "" }
    );
    let _ = writeln!(
        w,
        "- machine: {}; started {}; took {:.0} s; load average before: {}, after: {}",
        crate::stats::machine(),
        cx.started_at,
        cx.total,
        cx.load_before,
        crate::stats::loadavg()
    );
    let _ = writeln!(
        w,
        "- **nodes** = agents + the leader; in the process engine each node is one OS process \
         (the orchestrator is one more, mostly asleep); the bare ring of N nodes is N processes."
    );
    let _ = writeln!(
        w,
        "- durations: paper scenarios {} s simulated, tree-32 {} s, tree-100 {} s (dt = 1 ms, so 1000 steps per simulated second; \
         4 exchanges per step); every figure is the median of {} repetition(s), each column's median taken separately; \
         peak RSS: max and median over every agent process of every repetition (leader excluded, listed below).",
        plan.paper, plan.tree32, plan.tree100, plan.reps
    );
    let _ = writeln!(
        w,
        "- `spin` with more processes than cores ({}): shortened to {} steps up to {} processes, skipped above.",
        cx.cores, plan.spin_steps, plan.spin_max_nodes
    );
    let _ = writeln!(
        w,
        "- times: **wall** = around the whole `attsync run` command, measured by the benchmark (process start, validation, \
         spawning and connecting the nodes, the run, writing results); **run** = `summary.json` `wall_seconds` \
         (for the process engine: from opening the run's ports to the nodes' shutdown, so it includes start-up); \
         **run − lockstep, ms per node** = the process engine's start-up (ports, spawning, connecting) and shutdown, per node; \
         **lockstep** = first node's `started_unix_ns` to last node's `done_unix_ns` in `summary.json` `nodes` \
         (the steady state, no start-up; peak RSS from the same entries); \
         the bare ring's time is measured the same way (first loop start to last loop end). \
         **bg load** = CPU used by other processes on the machine during the runs (cores, max over repetitions)."
    );
    let _ = writeln!(w, "- {}.", cx.idle);
    let _ = writeln!(w);
}

fn inproc(w: &mut String, res: &Results, notes: &mut Vec<String>) {
    let _ = writeln!(w, "### In-process engine\n");
    let _ = writeln!(
        w,
        "| case | nodes | simulated s | steps | wall s | run s | steps/s (run) | real-time factor (run) | real-time factor (wall) |"
    );
    let _ = writeln!(w, "|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (c, a) in res.cases.iter().zip(&res.inproc) {
        let sim = c.sim_seconds();
        let _ = writeln!(
            w,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            c.label,
            c.nodes,
            sim,
            c.steps,
            f(a.wall, 3),
            f(a.run_seconds, 3),
            f(rate(c.steps, a.run_seconds), 0),
            f(a.run_seconds.map(|r| sim / r), 1),
            f(a.wall.map(|r| sim / r), 1)
        );
        failures(&format!("{} in-process", c.label), &a.errors, a.ok, notes);
    }
    let _ = writeln!(w);
}

/// The process engine's own time outside the lockstep (spawning and
/// connecting the nodes, shutting them down), per node, ms.
fn per_node_ms(run: Option<f64>, lockstep: Option<f64>, nodes: u32) -> Option<f64> {
    run.zip(lockstep)
        .map(|(r, l)| (r - l) * 1e3 / f64::from(nodes.max(1)))
}

fn procs(w: &mut String, res: &Results, notes: &mut Vec<String>) {
    let _ = writeln!(
        w,
        "### Process engine vs bare iceoryx2 ring (same N, wait strategy and steps)\n"
    );
    let _ = writeln!(
        w,
        "| case | nodes | wait | steps | wall s | real-time factor (wall) | run s | lockstep s | wall − lockstep s | run − lockstep, ms per node | steps/s (lockstep) | ring steps/s | attsync ÷ ring (lockstep) | attsync ÷ ring (wall) | agent peak RSS max / median kB | bg load |"
    );
    let _ = writeln!(
        w,
        "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for p in &res.procs {
        let c = &res.cases[p.case];
        let a = &p.attsync;
        let ring = res.bare.get(&p.ring).cloned().unwrap_or_default();
        let ring_rate = rate(p.steps, ring.span);
        let lock_rate = rate(p.steps, a.lockstep);
        let wall_rate = rate(p.steps, a.wall);
        let ratio = |x: Option<f64>| x.zip(ring_rate).map(|(a, b)| a / b);
        let _ = writeln!(
            w,
            "| {} | {} | {}{} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} / {} | {} |",
            c.label,
            c.nodes,
            wait_name(p.wait),
            if p.note.is_empty() { "" } else { " ¹" },
            p.steps,
            f(a.wall, 2),
            f(a.wall.map(|x| p.steps as f64 * c.dt / x), 2),
            f(a.run_seconds, 2),
            f(a.lockstep, 2),
            f(a.wall.zip(a.lockstep).map(|(w, l)| w - l), 2),
            f(per_node_ms(a.run_seconds, a.lockstep, c.nodes), 1),
            f(lock_rate, 0),
            f(ring_rate, 0),
            f(ratio(lock_rate), 2),
            f(ratio(wall_rate), 2),
            kb(a.rss_max),
            kb(a.rss_median),
            f(max_opt(a.bg, ring.bg), 2)
        );
        let label = format!("{} processes {}", c.label, wait_name(p.wait));
        failures(&label, &a.errors, a.ok, notes);
        if !p.note.is_empty() {
            notes.push(format!("¹ {} {}: {}", c.label, wait_name(p.wait), p.note));
        }
    }
    let _ = writeln!(w);
    let leader: Vec<String> = res
        .procs
        .iter()
        .filter(|p| p.wait == WaitStrategy::Adaptive)
        .map(|p| {
            let label = &res.cases[p.case].label;
            format!("{label} {} kB", kb(p.attsync.leader_rss))
        })
        .collect();
    let _ = writeln!(
        w,
        "Leader process peak RSS (adaptive): {}.\n",
        leader.join(", ")
    );
}

fn ring(w: &mut String, res: &Results, notes: &mut Vec<String>) {
    let _ = writeln!(
        w,
        "### Bare iceoryx2 lockstep ring (`attsync-bench ring-node`)\n"
    );
    let _ = writeln!(
        w,
        "| N | wait | steps | loop s | steps/s | µs per exchange | ring-node peak RSS max kB | bg load |"
    );
    let _ = writeln!(w, "|---:|---|---:|---:|---:|---:|---:|---:|");
    for k in res.bare_order.iter().filter(|k| k.graph.is_none()) {
        let b = &res.bare[k];
        let _ = writeln!(
            w,
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            k.n,
            wait_name(k.wait),
            k.steps,
            f(b.span, 3),
            f(rate(k.steps, b.span), 0),
            f(us_per_exchange(k.steps, b.span), 1),
            kb(b.rss_max),
            f(b.bg, 2)
        );
        let label = format!("ring N={} {}", k.n, wait_name(k.wait));
        failures(&label, &b.errors, b.ok, notes);
    }
    let _ = writeln!(w);
}

fn diagnostics(w: &mut String, res: &Results, notes: &mut Vec<String>) {
    let _ = writeln!(
        w,
        "### Where an exchange's time goes (adaptive, µs per exchange = lockstep s ÷ (4 × steps))\n"
    );
    let _ = writeln!(
        w,
        "| case | nodes | steps | bare ring | bare, scenario's graph | bare, scenario's graph, pinned | attsync, telemetry off | attsync | in-process engine, all nodes in one thread |"
    );
    let _ = writeln!(w, "|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for d in &res.diag {
        let c = &res.cases[d.case];
        let ring = res
            .bare
            .get(&ring_spec(c.nodes, c.steps, WaitStrategy::Adaptive))
            .and_then(|b| b.span);
        let graph = res.bare.get(&d.graph).cloned().unwrap_or_default();
        let pinned = res.bare.get(&d.pinned).cloned().unwrap_or_default();
        let att = res
            .procs
            .iter()
            .find(|p| p.case == d.case && p.wait == WaitStrategy::Adaptive)
            .and_then(|p| p.attsync.lockstep);
        let inproc = res.inproc[d.case].run_seconds;
        let _ = writeln!(
            w,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            c.label,
            c.nodes,
            c.steps,
            f(us_per_exchange(c.steps, ring), 1),
            f(us_per_exchange(c.steps, graph.span), 1),
            f(us_per_exchange(c.steps, pinned.span), 1),
            f(us_per_exchange(c.steps, d.quiet.lockstep), 1),
            f(us_per_exchange(c.steps, att), 1),
            f(us_per_exchange(c.steps, inproc), 2)
        );
        let same_graph = format!("{} same-graph bare", c.label);
        failures(&same_graph, &graph.errors, graph.ok, notes);
        let pinned_graph = format!("{} same-graph bare, pinned", c.label);
        failures(&pinned_graph, &pinned.errors, pinned.ok, notes);
        let quiet = format!("{} telemetry off", c.label);
        failures(&quiet, &d.quiet.errors, d.quiet.ok, notes);
    }
    let _ = writeln!(
        w,
        "\n\"bare, scenario's graph\": `ring-node` processes wired like the scenario (each node's inputs and receivers as \
         the process engine wires them, the leader with no inputs), no model; \"pinned\": each of them pinned to one \
         core as `attsync run` pins a run with more nodes than cores (`--placement pin`). \"telemetry off\": \
         `--set output.sample_period=<duration>` (telemetry only at the first and last step)."
    );
}

fn contended(w: &mut String, res: &Results, cx: &Context, notes: &mut Vec<String>) {
    if res.contended.is_empty() {
        return;
    }
    let _ = writeln!(
        w,
        "\n### Under contention: {} CPU-bound competitors (`attsync-bench burn`) beside the run\n",
        cx.cores
    );
    let _ = writeln!(
        w,
        "| case | nodes | wait | steps | idle wall s | loaded wall s | loaded ÷ idle (wall) | idle lockstep s | loaded lockstep s | loaded ÷ idle (lockstep) | ring idle s | ring loaded s | ring loaded ÷ idle | attsync ÷ ring, loaded (steps/s, lockstep) |"
    );
    let _ = writeln!(
        w,
        "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for r in &res.contended {
        let c = &res.cases[r.case];
        let div = |a: Option<f64>, b: Option<f64>| a.zip(b).map(|(a, b)| a / b);
        let _ = writeln!(
            w,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            c.label,
            c.nodes,
            wait_name(r.wait),
            r.steps,
            f(r.idle.wall, 2),
            f(r.loaded.wall, 2),
            f(div(r.loaded.wall, r.idle.wall), 2),
            f(r.idle.lockstep, 2),
            f(r.loaded.lockstep, 2),
            f(div(r.loaded.lockstep, r.idle.lockstep), 2),
            f(r.ring_idle.span, 2),
            f(r.ring_loaded.span, 2),
            f(div(r.ring_loaded.span, r.ring_idle.span), 2),
            f(div(r.ring_loaded.span, r.loaded.lockstep), 2)
        );
        let label = format!("{} contended {}", c.label, wait_name(r.wait));
        failures(&format!("{label} idle"), &r.idle.errors, r.idle.ok, notes);
        failures(
            &format!("{label} loaded"),
            &r.loaded.errors,
            r.loaded.ok,
            notes,
        );
        failures(
            &format!("{label} ring idle"),
            &r.ring_idle.errors,
            r.ring_idle.ok,
            notes,
        );
        failures(
            &format!("{label} ring loaded"),
            &r.ring_loaded.errors,
            r.ring_loaded.ok,
            notes,
        );
    }
    let _ = writeln!(
        w,
        "\nEach strategy is measured idle and loaded at the same number of steps (yield at a tenth, spin at a hundredth: \
         each of their polls can hand a whole time slice to a competitor); \"loaded ÷ idle\" is the slow-down the \
         competitors cause (the fair share of 2 cores shared with {} CPU-bound programs is about 2×).",
        cx.cores
    );
}

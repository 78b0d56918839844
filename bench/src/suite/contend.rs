//! The contention case: the 8-node paper run (scheme 1) with K CPU-bound
//! competitors beside it (K = cores, `attsync-bench burn`), for each wait
//! strategy, next to the same run on an idle machine and the bare ring of the
//! same size under the same load. Idle and loaded repetitions are
//! interleaved, so a slow drift of the machine hits both alike.

use super::Options;
use super::plan::{Case, Plan, ring_spec};
use super::run::{Agg, BareAgg, Runner};
use crate::measure::{Bins, Engine};
use msgs::config::WaitStrategy;
use std::process::{Child, Command, Stdio};

/// One wait strategy measured idle and loaded.
#[derive(Debug, Clone)]
pub(super) struct ContendRow {
    pub case: usize,
    pub wait: WaitStrategy,
    pub steps: u64,
    pub idle: Agg,
    pub loaded: Agg,
    pub ring_idle: BareAgg,
    pub ring_loaded: BareAgg,
}

/// Steps of a contended run: strategies that poll lose a whole time slice
/// per poll to a competitor, so yield gets a tenth and spin (which also
/// loses a slice whenever more nodes than cores spin) a hundredth.
pub(super) fn steps(plan: &Plan, case: &Case, wait: WaitStrategy) -> u64 {
    let base = plan.contend_steps.min(case.steps);
    match wait {
        WaitStrategy::Adaptive | WaitStrategy::Block => base,
        WaitStrategy::Yield => (base / 10).max(1),
        WaitStrategy::Spin => (base / 100).max(1),
    }
}

/// `k` CPU-bound processes, killed when dropped.
pub(super) struct Competitors(Vec<Child>);

impl Competitors {
    /// Starts `k` of `attsync-bench burn`.
    pub fn start(bins: &Bins, k: u32) -> std::io::Result<Self> {
        let mut children = Vec::new();
        for _ in 0..k {
            let child = Command::new(&bins.bench)
                .arg("burn")
                .stdin(Stdio::null())
                .stdout(Stdio::null())
                .spawn();
            match child {
                Ok(c) => children.push(c),
                Err(e) => {
                    drop(Self(children));
                    return Err(e);
                }
            }
        }
        Ok(Self(children))
    }
}

impl Drop for Competitors {
    fn drop(&mut self) {
        for c in &mut self.0 {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

/// `attsync-bench burn`: spins forever (a CPU-bound competitor).
pub fn burn() -> ! {
    let mut x = 0u64;
    loop {
        x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
    }
}

impl Runner<'_> {
    /// The contention case for `case` and every strategy of `waits`.
    pub(super) fn contended(
        &mut self,
        o: &Options,
        res: &mut super::run::Results,
        ci: usize,
        plan: &Plan,
        waits: &[WaitStrategy],
    ) {
        let case = res.cases[ci].clone();
        let k = std::thread::available_parallelism().map_or(1, std::num::NonZero::get) as u32;
        for &wait in waits {
            let steps = steps(plan, &case, wait);
            let ring = ring_spec(case.nodes, steps, wait);
            let sets = case.sets_for(steps);
            let mut row = ContendRow {
                case: ci,
                wait,
                steps,
                idle: Agg::default(),
                loaded: Agg::default(),
                ring_idle: BareAgg::default(),
                ring_loaded: BareAgg::default(),
            };
            let (mut idle, mut loaded) = (Vec::new(), Vec::new());
            let (mut ri, mut rl) = (Vec::new(), Vec::new());
            for rep in 0..plan.reps {
                let what = |load: &str| {
                    format!("{load} {} rep {}", crate::measure::wait_name(wait), rep + 1)
                };
                let engine = Engine::Processes(wait);
                idle.push(self.attsync(&case, engine, &sets, &what("idle")));
                row.ring_idle
                    .push(self.bare_once(&ring, "ring idle"), &mut ri);
                let load = match Competitors::start(&o.bins, k) {
                    Ok(c) => c,
                    Err(e) => {
                        row.loaded.errors.push(format!("starting competitors: {e}"));
                        continue;
                    }
                };
                loaded.push(self.attsync_now(
                    &case,
                    engine,
                    &sets,
                    &what(&format!("{k} competitors,")),
                ));
                row.ring_loaded
                    .push(self.bare_now(&ring, "ring loaded"), &mut rl);
                drop(load);
            }
            row.idle = Agg::collect(idle);
            row.loaded = Agg::collect(loaded);
            res.contended.push(row);
        }
    }
}

//! The in-process engine: every node in one loop, in lockstep, on one
//! thread or several.
//!
//! It runs exactly the protocol of [`crate::agent`] that the
//! process-per-agent engine runs over shared memory, so both produce
//! bit-identical trajectories. On several threads ([`InProcess::with_threads`])
//! each thread steps a contiguous chunk of the agents and the exchanges are
//! barriers; an agent's arithmetic depends only on its own state and the
//! values it holds, so the results are bit-identical for any thread count.
//! At an output sample [`InProcess::run_with`] has each thread also do a
//! caller's per-agent work for its own agents (recording's rows), so the
//! serial part of a sample is only what cannot be shared (writing files).
//!
//! A sample of step n (t = n·dt) carries every agent's torque at stage 0
//! of step n ([`Snapshot::torques`]), so it is handed out once that stage
//! was evaluated: after the divergence check of the step's start state,
//! stage 0 of step n, then the sample, then stages 1–3. The state is still
//! the step's start state then; between samples nothing extra is done.
//!
//! # Layout
//! - `pass`: one stage over a run of agents (receive, advance, publish, check).
//! - `crew`: the parallel step (shares of agents, the exchange barrier).
//! - `board`: the values threads leave for each other (atomic words, bit-exact).
//! - `barrier`: a barrier that spins briefly, then blocks.

mod barrier;
mod board;
mod crew;
mod pass;

use crate::agent::Agent;
use crate::guard::{self, Divergence, Violation};
use crate::network::{AgentState, Exchanged, Network};
use crate::reference::{Leader, LeaderState};
use crate::schedule::{Schedule, Slot};
use board::Judged;
use crew::{Board, Plan, Share};
use nalgebra::Vector3;
use pass::{Stage, pass};

/// Fewest agents per thread [`InProcess::with_threads`] gives a thread:
/// below it the barriers cost more than the thread saves (measured in
/// BENCHMARKS.md, "In-process engine at scale").
pub const MIN_AGENTS_PER_THREAD: usize = 64;

/// The network's state at an output sample.
#[derive(Debug)]
pub struct Snapshot<'a> {
    /// Step index (t = step · dt).
    pub step: u64,
    /// Leader state.
    pub leader: &'a LeaderState,
    /// Agent states, in the order of `Network::agents`.
    pub agents: &'a [AgentState],
    /// Every agent's torque `τᵢ` at stage 0 of step `step` (t = step·dt,
    /// from the states above), after the actuator's limits, N·m, body
    /// frame, in the order of `agents`: NaN at the run's last step (no
    /// torque is applied after it) and where a node did not report it.
    pub torques: &'a [Vector3<f64>],
}

/// The torque recorded where none was applied (after the run's last step)
/// or none was reported.
pub const NO_TORQUE: Vector3<f64> = Vector3::new(f64::NAN, f64::NAN, f64::NAN);

/// All nodes of a network in one process.
#[derive(Debug)]
pub struct InProcess {
    net: Network,
    leader: Leader,
    agents: Vec<Agent>,
    /// For each agent, the index in `agents` of each neighbour.
    nbr_index: Vec<Vec<usize>>,
    step: u64,
    /// Whether stage 0 of step `step` was evaluated already (a sample of
    /// it is taken after that stage; the rest of the step follows).
    begun: bool,
    states: Vec<AgentState>,
    /// Every agent's torque at stage 0 of the last sampled step.
    torques: Vec<Vector3<f64>>,
    /// The step of the last snapshot `run` handed out, and each agent's
    /// peak torque then (at the step's start, before its stage 0).
    sampled: (u64, Vec<f64>),
    /// Threads [`Self::run`] uses (1: the calling thread only).
    threads: usize,
    /// The published values as their receivers hold them ([`Judged::held`])
    /// and their verdicts ([`crate::network::Exchanged::trust`], judged once
    /// per sender): the next exchange reads `published[0]`, `published[1]`
    /// holds the last exchange's (read between exchanges); a pass at an
    /// exchange writes the values of the exchange after it into
    /// `published[1]`, then the two swap. The crew starts from them and
    /// leaves them as it found them.
    published: [Vec<Judged>; 2],
    /// Every agent's neighbour values, one agent at a time (see `pass`).
    scratch: Vec<Exchanged>,
    /// The exchange (step, stage) whose values the last pass published.
    ready: Option<(u64, u32)>,
}

impl InProcess {
    /// Builds the nodes of `net`, to run on the calling thread.
    #[must_use]
    pub fn new(net: &Network) -> Self {
        let leader = Leader::new(net.p, net.leader, net.dt).with_repoints(net.repoint.clone());
        let agents: Vec<Agent> = net
            .agents
            .iter()
            .map(|a| Agent::new(a.model.clone(), a.initial, net.dt))
            .collect();
        let n = agents.len();
        let nbr_index = net.neighbour_indices();
        let states = agents.iter().map(|a| *a.state()).collect();
        Self {
            net: net.clone(),
            leader,
            agents,
            nbr_index,
            step: 0,
            begun: false,
            states,
            torques: Vec::new(),
            sampled: (0, Vec::new()),
            threads: 1,
            published: [vec![Judged::default(); n], vec![Judged::default(); n]],
            scratch: Vec::new(),
            ready: None,
        }
    }

    /// Every agent with `law` in place of its scheme's torque
    /// ([`crate::law`]), run on the calling thread only (a law from
    /// outside may not be callable from several at once).
    #[must_use]
    pub fn with_law(mut self, law: crate::law::SharedLaw) -> Self {
        self.agents = (std::mem::take(&mut self.agents).into_iter())
            .map(|a| a.with_law(law.clone()))
            .collect();
        self.threads = 1;
        self
    }

    /// Runs on up to `threads` threads, each with at least
    /// [`MIN_AGENTS_PER_THREAD`] agents (so a small network stays on one).
    #[must_use]
    pub fn with_threads(self, threads: usize) -> Self {
        let most = (self.agents.len() / MIN_AGENTS_PER_THREAD).max(1);
        self.with_exact_threads(threads.min(most))
    }

    /// Runs on exactly `threads` threads (at most one per agent), however
    /// few agents each gets.
    #[must_use]
    pub fn with_exact_threads(mut self, threads: usize) -> Self {
        self.threads = threads.min(self.agents.len()).max(1);
        self
    }

    /// Threads [`Self::run`] uses.
    #[must_use]
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Steps done so far.
    #[must_use]
    pub fn step_index(&self) -> u64 {
        self.step
    }

    /// The horizon, in steps ([`Network::steps`] until [`Self::extend_to`]).
    #[must_use]
    pub fn horizon(&self) -> u64 {
        self.net.steps
    }

    /// Moves the horizon to `steps` (at least the steps done), so that the
    /// next [`Self::run_until`] goes on from where the last one stopped:
    /// what `--until settled` does. The state, the held values and the
    /// links carry over; a run extended at a step that is a multiple of
    /// `sample_every` is bit-identical, sample for sample, to a run given
    /// the longer horizon from the start (the only sample a horizon adds
    /// is its last step's).
    pub fn extend_to(&mut self, steps: u64) {
        assert!(steps >= self.step, "a horizon before the steps done");
        self.net.steps = steps;
    }

    /// The nodes' agents (for peak torques and models).
    #[must_use]
    pub fn agents(&self) -> &[Agent] {
        &self.agents
    }

    /// The current state as a snapshot; its torques are those of the last
    /// sample (this step's right after it was sampled).
    #[must_use]
    pub fn snapshot(&self) -> Snapshot<'_> {
        Snapshot {
            step: self.step,
            leader: self.leader.state(),
            agents: &self.states,
            torques: &self.torques,
        }
    }

    /// Evaluates stage 0 of the current step, unless it was already or the
    /// horizon is reached, and returns every agent's torque of it
    /// ([`Agent::torque`]; `None` at the horizon). The step goes on from
    /// stage 1 at the next [`Self::run`] or [`Self::step`], bit-identical.
    /// What a run extended past its horizon ([`Self::extend_to`]) uses to
    /// complete the torques of its former last sample, which had none.
    pub fn begin_step(&mut self) -> Option<&[Vector3<f64>]> {
        if self.step >= self.net.steps {
            return None;
        }
        self.begin_serial();
        self.torques.clear();
        self.torques.extend(self.agents.iter().map(Agent::torque));
        Some(&self.torques)
    }

    /// Advances every node by one step (four stages, exchanging as the
    /// coupling says), on the calling thread.
    pub fn step(&mut self) {
        self.advance_step();
        self.refresh_states();
    }

    /// One step on the calling thread (from stage 1 if stage 0 was
    /// evaluated already), one [`pass`] over the agents per stage; returns
    /// the first agent whose new state is outside the envelope (index,
    /// violation). Leaves `states` as it was.
    fn advance_step(&mut self) -> Option<(usize, Violation)> {
        let schedule = Schedule::new(self.net.coupling, self.net.steps);
        let skip = usize::from(std::mem::take(&mut self.begun));
        let mut found = None;
        for slot in schedule.stages(self.step).skip(skip) {
            found = self.advance_stage(schedule, slot);
        }
        self.step += 1;
        found
    }

    /// Stage 0 of the current step on the calling thread, once (see
    /// [`Self::begin_step`]).
    fn begin_serial(&mut self) {
        if self.begun || self.step >= self.net.steps {
            return;
        }
        let schedule = Schedule::new(self.net.coupling, self.net.steps);
        let first = schedule
            .stages(self.step)
            .next()
            .expect("a step has stages");
        // Stage 0 does not end a step: nothing is checked against the envelope.
        self.advance_stage(schedule, first);
        self.begun = true;
    }

    /// One stage `slot` of `schedule` on the calling thread: the leader
    /// and one [`pass`] over the agents; at the step's end, the first agent
    /// whose new state is outside the envelope (index, violation).
    fn advance_stage(&mut self, schedule: Schedule, slot: Slot) -> Option<(usize, Violation)> {
        let leader = slot.exchange.then(|| {
            self.publish_if_needed(slot);
            Judged::of(self.leader.stage_exchange())
        });
        self.leader.advance();
        let next = schedule.next(slot).filter(|x| x.exchange);
        let stage = Stage {
            leader,
            publish: next.is_some(),
            check: slot.ends_step().then_some(&self.net.guard),
        };
        // Read this exchange's buffer; write the next exchange's (the
        // other one at an exchange; nothing is read otherwise).
        let [now, after] = &mut self.published;
        let (read, out) = if slot.exchange {
            (&*now, after)
        } else {
            (&*after, now)
        };
        let found = pass(
            &mut self.agents,
            &self.nbr_index,
            (stage, &mut self.scratch),
            |j| &read[j],
            |k, a| {
                let Judged(x, trusted) = &mut out[k];
                *trusted = a.publish_into(x);
                if !*trusted {
                    *x = read[k].0;
                }
            },
        );
        if slot.exchange {
            self.published.swap(0, 1);
        }
        if let Some(x) = next {
            self.ready = Some((x.step, x.stage));
        }
        found
    }

    /// Publishes every agent's stage state into `published[0]` for the
    /// exchange `slot`, unless the last pass did.
    fn publish_if_needed(&mut self, slot: Slot) {
        if self.ready != Some((slot.step, slot.stage)) {
            let [now, last] = &mut self.published;
            for ((p, before), a) in now.iter_mut().zip(&*last).zip(&mut self.agents) {
                let (x, trusted) = a.stage_exchange_judged();
                *p = Judged::held(x, trusted, &before.0);
            }
        }
    }

    /// Every agent's state at the start of its current step into `states`.
    fn refresh_states(&mut self) {
        for (s, a) in self.states.iter_mut().zip(&self.agents) {
            *s = *a.state();
        }
    }

    /// The step of the last snapshot [`InProcess::run`] handed out, and
    /// each agent's peak torque at that step (what a diverged run reports).
    #[must_use]
    pub fn last_sample(&self) -> (u64, &[f64]) {
        (self.sampled.0, &self.sampled.1)
    }

    /// Books the current step as sampled (its peak torques first), evaluates
    /// its stage 0 for the torques ([`Self::begin_serial`]; NaN at the
    /// horizon), does `work` for every agent into `outs`, then hands the
    /// snapshot and `outs` to `f`.
    fn sample<T>(
        &mut self,
        (work, outs): Work<'_, T, impl PerAgent<T>>,
        f: &mut impl OnSample<T>,
    ) -> bool {
        self.sampled.0 = self.step;
        self.sampled.1.clear();
        (self.sampled.1).extend(self.agents.iter().map(Agent::peak_torque));
        self.torques.clear();
        if self.step < self.net.steps {
            self.begin_serial();
            self.torques.extend(self.agents.iter().map(Agent::torque));
        } else {
            self.torques.resize(self.agents.len(), NO_TORQUE);
        }
        outs.clear();
        let leader = self.leader.state();
        outs.extend((self.states.iter().enumerate()).map(|(k, x)| work(k, x, leader)));
        f(&self.snapshot(), outs.as_slice())
    }

    /// The first node (the leader, then agents in network order) whose
    /// current state is outside the network's envelope ([`crate::guard`]).
    #[must_use]
    pub fn divergence(&self) -> Option<Divergence> {
        guard::first(&self.net, self.step, self.leader.state(), &self.states)
    }

    /// Runs to the end, calling `on_sample` at t = 0 and every
    /// `sample_every` steps (each once stage 0 of its step gave the
    /// torques). Stops early if `on_sample` returns `false` (then within
    /// the sampled step, after its stage 0), and at once (before sampling)
    /// when a state leaves the envelope: then it returns the divergence.
    /// The state is checked at t = 0 and after every step.
    pub fn run(&mut self, mut on_sample: impl FnMut(&Snapshot<'_>) -> bool) -> Option<Divergence> {
        self.run_with(|_, _, _| (), |snap, _| on_sample(snap))
    }

    /// [`Self::run`], and at every sample `work(k, state, leader)` for
    /// every agent `k` (network order), done by the thread that steps the
    /// agent — in parallel on several threads — and handed to `on_sample`
    /// beside the snapshot, in network order: the per-agent part of
    /// recording a sample, out of the serial part.
    pub fn run_with<T: Send>(
        &mut self,
        work: impl PerAgent<T> + Sync,
        on_sample: impl OnSample<T>,
    ) -> Option<Divergence> {
        self.run_until(work, on_sample, || false)
    }

    /// [`Self::run_with`], asking `stop` after every step that is not a
    /// sample: `true` ends the run there, with the last sample as its
    /// last record ([`Self::last_sample`]) — what stops a run whose
    /// samples are far apart (a stiff network's tiny `dt`) within one step.
    pub fn run_until<T: Send>(
        &mut self,
        work: impl PerAgent<T> + Sync,
        mut on_sample: impl OnSample<T>,
        stop: impl Fn() -> bool,
    ) -> Option<Divergence> {
        let mut outs = Vec::new();
        if self.step == 0 {
            if let Some(d) = self.divergence() {
                return Some(d);
            }
            if !self.sample((&work, &mut outs), &mut on_sample) {
                return None;
            }
        }
        if self.threads > 1 && self.step < self.net.steps {
            self.ready = None;
            let (diverged, begun) = self.run_parallel((&work, &mut outs), on_sample, stop);
            self.begun = begun;
            self.refresh_states();
            return diverged;
        }
        while self.step < self.net.steps {
            let found = self.advance_step();
            if let Some(d) = divergence_at(&self.net, self.step, self.leader.state(), found) {
                self.refresh_states();
                return Some(d);
            }
            if sample_due(&self.net, self.step) {
                self.refresh_states();
                if !self.sample((&work, &mut outs), &mut on_sample) {
                    return None;
                }
            } else if stop() {
                self.refresh_states();
                return None;
            }
        }
        None
    }

    /// [`Self::run_with`] on `self.threads` threads: the calling thread
    /// steps the leader and the first share and samples; a worker steps
    /// each other share (see `crew`). Returns the divergence, and whether
    /// it stopped within a step (after a sample's stage 0).
    fn run_parallel<T: Send>(
        &mut self,
        (work, all): Work<'_, T, impl PerAgent<T> + Sync>,
        mut on_sample: impl OnSample<T>,
        stop: impl Fn() -> bool,
    ) -> (Option<Divergence>, bool) {
        let Self {
            net,
            leader,
            agents,
            nbr_index,
            step,
            begun,
            states,
            torques,
            threads,
            sampled,
            published,
            ..
        } = self;
        let board = Board::new(published, *threads);
        let plan = Plan {
            schedule: Schedule::new(net.coupling, net.steps),
            nbr_index,
            sample_every: net.sample_every,
            guard: &net.guard,
        };
        let (from, outs) = ((*step, *begun), crew::outputs::<T>(*threads));
        let (diverged, parity, within) = std::thread::scope(|scope| {
            let mut shares = Share::split(agents, *threads).into_iter();
            let mut mine = shares.next().expect("at least one share");
            for (share, out) in shares.zip(&outs[1..]) {
                let board = &board;
                scope.spawn(move || crew::work(share, board, plan, from, (work, out)));
            }
            let ended = |mine: &Share<'_>, d, within| (d, mine.parity(), within);
            let mut skip = usize::from(*begun);
            while *step < net.steps {
                mine.step(&board, plan, (*step, skip), Some(leader));
                skip = 0;
                *step += 1;
                let due = plan.sample_due(*step);
                if due {
                    crew::read_states(&board, states);
                    let now = (leader.state(), &states[..]);
                    crew::gather(&mine, &board, (work, &outs), now, all);
                }
                let found = crew::read_found(&board);
                if let Some(d) = divergence_at(net, *step, leader.state(), found) {
                    crew::release(&board, false);
                    return ended(&mine, Some(d), false);
                }
                if !due {
                    let go_on = !stop();
                    crew::release(&board, go_on);
                    if !go_on {
                        return ended(&mine, None, false);
                    }
                    continue;
                }
                sampled.0 = *step;
                crew::read_peaks(&board, &mut sampled.1);
                // Stage 0 of the sampled step, for its torques (none after
                // the last step).
                let begins = *step < net.steps;
                if begins {
                    crew::release(&board, true);
                    mine.begin(&board, plan, *step, Some(leader));
                    crew::read_torques(&board, torques);
                    skip = 1;
                } else {
                    torques.clear();
                    torques.resize(states.len(), NO_TORQUE);
                }
                let snapshot = Snapshot {
                    step: *step,
                    leader: leader.state(),
                    agents: states,
                    torques,
                };
                let go_on = on_sample(&snapshot, all.as_slice());
                crew::release(&board, go_on);
                if !go_on {
                    return ended(&mine, None, begins);
                }
            }
            ended(&mine, None, false)
        });
        crew::read_published(&board, parity, published);
        (diverged, within)
    }
}

/// Per-agent work at a sample ([`InProcess::run_with`]): agent index
/// (network order), its state, the leader's state.
pub trait PerAgent<T>: Fn(usize, &AgentState, &LeaderState) -> T {}

impl<T, F: Fn(usize, &AgentState, &LeaderState) -> T> PerAgent<T> for F {}

/// What [`InProcess::run_with`] calls at a sample: the snapshot and every
/// agent's work, in network order; `false` stops the run.
pub trait OnSample<T>: FnMut(&Snapshot<'_>, &[T]) -> bool {}

impl<T, F: FnMut(&Snapshot<'_>, &[T]) -> bool> OnSample<T> for F {}

/// The per-agent work and where its results go.
type Work<'a, T, W> = (&'a W, &'a mut Vec<T>);

/// The divergence of the network at `step`: the leader's state if it is
/// outside the envelope, else the first agent `found` outside it (index in
/// `net.agents`, violation), as [`guard::first`] orders them.
fn divergence_at(
    net: &Network,
    step: u64,
    leader: &LeaderState,
    found: Option<(usize, Violation)>,
) -> Option<Divergence> {
    let at = |node: u32, violation: Violation| Divergence {
        step,
        node,
        violation,
    };
    match guard::check_leader(leader, &net.guard) {
        Some(v) => Some(at(0, v)),
        None => found.map(|(k, v)| at(net.agents[k].model.id, v)),
    }
}

/// Whether the state after `step` steps is an output sample.
fn sample_due(net: &Network, step: u64) -> bool {
    crew::sample_due(net.sample_every, net.steps, step)
}

//! The exchanges with the candidate, walking the run's
//! [`Schedule`]: at each exchange the neighbourhood publishes the
//! candidate's inputs, reads its state and feeds it to the neighbours
//! (rules `in-order`, `valid-states`); once it holds the inputs back
//! (`waits-for-inputs`) and once it sends a NaN (`refuses-invalid`).

use super::harness::{Drive, Halt};
use super::law::ExchangeRecord;
use super::neighbourhood::Neighbourhood;
use super::rules::RuleId;
use crate::launch::supervise::describe;
use attitude::network::Exchanged;
use attitude::schedule::{Schedule, Slot};
use msgs::{PROTOCOL_VERSION, StateMsg};
use std::time::{Duration, Instant};

/// From this step on, the neighbourhood holds its inputs back at the next
/// exchange that has a successor, to see whether the candidate advances
/// without them.
const WITHHOLD_FROM: u64 = 5;
/// How long the inputs are held back.
const WITHHOLD_FOR: Duration = Duration::from_millis(300);
/// From this step on, the first input carries a NaN at the next exchange.
const NAN_FROM: u64 = 8;

/// The first exchange at or after step `from` that is followed by another
/// exchange.
fn exchange_from(schedule: &Schedule, from: u64) -> Option<Slot> {
    let mut it = schedule.exchanges().skip_while(|x| x.step < from);
    let first = it.next()?;
    it.next().map(|_| first)
}

/// Where the exchanges stand.
#[derive(Debug)]
struct Exchanges {
    /// The exchange whose inputs are held back.
    withhold_at: Option<Slot>,
    /// The exchange whose first input carries a NaN.
    nan_at: Option<Slot>,
    /// A state the candidate published while its inputs were held back.
    early: Option<StateMsg>,
    /// The NaN has been sent.
    after_nan: bool,
    /// The candidate's last valid state, which its neighbours hold.
    last_cand: Option<Exchanged>,
}

impl Drive<'_> {
    /// Every stage of the run: the neighbourhood advances, exchanging with
    /// the candidate where the schedule says so.
    pub(super) fn lockstep(&mut self) -> Result<(), Halt> {
        let schedule = Schedule::new(self.cfg.coupling, self.cfg.steps);
        let withhold_at = exchange_from(&schedule, WITHHOLD_FROM);
        let mut x = Exchanges {
            withhold_at,
            nan_at: exchange_from(
                &schedule,
                NAN_FROM.max(withhold_at.map_or(0, |w| w.step + 1)),
            ),
            early: None,
            after_nan: false,
            last_cand: None,
        };
        let mut hood = Neighbourhood::new(self.net, self.index);
        for slot in schedule.slots() {
            if slot.exchange {
                self.exchange(slot, &mut hood, &mut x)?;
                hood.exchange(x.last_cand);
            }
            hood.advance();
            if slot.ends_step() {
                self.drain_telemetry();
            }
        }
        self.lockstep_verdicts(&x);
        Ok(())
    }

    /// One exchange with the candidate at `slot`.
    fn exchange(
        &mut self,
        slot: Slot,
        hood: &mut Neighbourhood,
        x: &mut Exchanges,
    ) -> Result<(), Halt> {
        let (n, s) = (slot.step, slot.stage);
        let withhold = Some(slot) == x.withhold_at;
        let nan = Some(slot) == x.nan_at;
        // What the candidate receives at this exchange, and (below) what it publishes.
        let inputs = hood.inputs(self.net, &self.cfg.inputs);
        let mut delivered = Vec::new();
        if !withhold {
            delivered = self.wires.publish(slot, &inputs, nan);
        }
        let msg = self.await_state(slot, x)?;
        self.wires.discard_others();
        let id = self.cfg.id;
        if msg.version != PROTOCOL_VERSION || msg.sender != id {
            self.report.fail(
                RuleId::InOrder,
                format!(
                    "message of version {} from sender {} (expected version {PROTOCOL_VERSION}, sender {id})",
                    msg.version, msg.sender
                ),
            );
        }
        if (msg.step, msg.stage) != (n, s) {
            self.report.fail(
                RuleId::InOrder,
                format!(
                    "sent step {} stage {} where step {n} stage {s} was due",
                    msg.step, msg.stage
                ),
            );
            self.skip_rest("it lost lockstep");
            return Err(Halt::Kill);
        }
        let cand = self.validated(slot, &msg, x.after_nan);
        if withhold {
            self.check_waits(slot, x);
            delivered = self.wires.publish(slot, &inputs, nan);
        }
        self.record.exchanges.push(ExchangeRecord {
            step: n,
            stage: s,
            inputs: delivered,
            published: msg.exchanged(),
        });
        x.after_nan |= nan;
        x.last_cand = cand.or(x.last_cand);
        Ok(())
    }

    /// The candidate's state of `slot`, within the stage timeout.
    fn await_state(&mut self, slot: Slot, x: &mut Exchanges) -> Result<StateMsg, Halt> {
        let (n, s) = (slot.step, slot.stage);
        let deadline = Instant::now() + Duration::from_secs_f64(self.opts.stage_timeout);
        loop {
            if let Some(m) = x.early.take().or_else(|| self.wires.receive()) {
                return Ok(m);
            }
            self.drain_telemetry();
            if let Some(st) = self.cand.try_exit() {
                let why = format!(
                    "it ended ({}) at step {n} stage {s}; its last output:\n{}",
                    describe(&st),
                    super::candidate::log_tail(self.opts)
                );
                if x.after_nan {
                    self.report
                        .fail(RuleId::RefusesInvalid, format!("after a NaN input {why}"));
                }
                self.report.fail(RuleId::InOrder, why);
                self.skip_rest("it exited during the run");
                return Err(Halt::Exited);
            }
            if Instant::now() > deadline {
                let why = format!(
                    "no state for step {n} stage {s} within {} s",
                    self.opts.stage_timeout
                );
                self.report.fail(RuleId::InOrder, why);
                self.skip_rest("it stopped publishing");
                return Err(Halt::Kill);
            }
            std::hint::spin_loop();
            std::thread::yield_now();
        }
    }

    /// Rule `valid-states` for `msg`: its value, if valid.
    fn validated(&mut self, slot: Slot, msg: &StateMsg, after_nan: bool) -> Option<Exchanged> {
        let (n, s) = (slot.step, slot.stage);
        match msg.validated() {
            Ok(x) => Some(x),
            Err(why) => {
                self.report
                    .fail(RuleId::ValidStates, format!("step {n} stage {s}: {why}"));
                if after_nan {
                    self.report.fail(
                        RuleId::RefusesInvalid,
                        format!("after a NaN input, its state at step {n} stage {s}: {why}"),
                    );
                }
                None
            }
        }
    }

    /// Rule `waits-for-inputs`: it has published `slot`; without our
    /// inputs it must not go on.
    fn check_waits(&mut self, slot: Slot, x: &mut Exchanges) {
        std::thread::sleep(WITHHOLD_FOR);
        if let Some(m) = self.wires.receive() {
            self.report.fail(
                RuleId::WaitsForInputs,
                format!(
                    "published step {} stage {} while its inputs of step {} stage {} were held back",
                    m.step, m.stage, slot.step, slot.stage
                ),
            );
            x.early = Some(m);
        } else {
            self.report.pass(RuleId::WaitsForInputs);
        }
    }

    /// The verdicts of a lockstep run to its end.
    fn lockstep_verdicts(&mut self, x: &Exchanges) {
        self.report.pass(RuleId::InOrder);
        self.report.pass(RuleId::ValidStates);
        if x.after_nan {
            self.report.pass(RuleId::RefusesInvalid);
        } else {
            self.report.not_checked(
                RuleId::RefusesInvalid,
                "the run is too short to inject a NaN",
            );
        }
        if x.withhold_at.is_none() {
            self.report.not_checked(
                RuleId::WaitsForInputs,
                "the run is too short to hold inputs back",
            );
        }
    }
}

//! Communication impairments of one directed link (sender → receiver),
//! applied on the receiving side, in simulated time, inside lockstep.
//!
//! # Semantics
//! Time is counted in **exchange slots** `(n, s)`: step n, RKMK4 stage s.
//! Every message a sender publishes is stamped with its slot. On an impaired
//! link a message stamped `(m, s)`:
//! - is dropped with the link's loss model (Bernoulli, or Gilbert–Elliott
//!   bursts), drawn from a per-link pseudo-random stream seeded by
//!   `(seed, from, to)` and advanced once per message in stamp order;
//! - otherwise is delivered at slot `(m + d, s)` with `d = delay + J` steps,
//!   `J` uniform in `0..=jitter` (whole steps);
//! - a link with an exchange `period` of p steps carries only the messages
//!   stamped `(m, 0)` with `m % p == 0`.
//!
//! At every slot the receiver holds the freshest delivered message (largest
//! stamp); a late, older message never replaces a newer one, and a lost
//! message means the receiver keeps what it had. Before the first delivery
//! the receiver holds the first valid message it was offered, normally the
//! sender's state at t = 0 (the history of a delayed system before t = 0 is
//! its initial state). With a constant delay of k steps the receiver uses
//! at stage s of step n exactly the sender's stage-s state of step n − k:
//! RK4 applied to the delay equation by the method of steps.
//! A link may also be down for whole steps (an outage, [`crate::timeline`]):
//! a message stamped in one is dropped after the draws above.
//! `PROTOCOL.md` § 10.9 states all this for plug-ins.
//!
//! A link without impairments is not filtered at all, so an unimpaired run
//! stays byte-identical to the plain engine.

use crate::network::Exchanged;
use crate::random::SplitMix64;
use crate::timeline::Outage;
use serde::{Deserialize, Serialize};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// A message's loss process.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Loss {
    /// Nothing is lost.
    None,
    /// Each message is lost independently with probability `p`.
    Bernoulli {
        /// Loss probability in [0, 1].
        p: f64,
    },
    /// Two-state Markov chain (good/bad), advanced once per message.
    GilbertElliott {
        /// P(good → bad) per message.
        p_gb: f64,
        /// P(bad → good) per message.
        p_bg: f64,
        /// Loss probability in the good state.
        loss_good: f64,
        /// Loss probability in the bad state.
        loss_bad: f64,
    },
}

/// Impairments of one directed link, in whole steps.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LinkModel {
    /// Constant delay, steps.
    pub delay: u64,
    /// Largest extra delay, steps (uniform in `0..=jitter`).
    pub jitter: u64,
    /// Loss process.
    pub loss: Loss,
    /// Exchange period of this link, steps (`None`: every exchange).
    pub period: Option<u64>,
    /// Seed of the link's random stream (already mixed with the link's ends).
    pub seed: u64,
}

impl LinkModel {
    /// A link that changes nothing (what an outage acts on when the link
    /// has no impairment of its own).
    #[must_use]
    pub fn ideal() -> Self {
        Self {
            delay: 0,
            jitter: 0,
            loss: Loss::None,
            period: None,
            seed: 0,
        }
    }

    /// Whether the link changes anything.
    #[must_use]
    pub fn is_impaired(&self) -> bool {
        self.delay > 0 || self.jitter > 0 || self.loss != Loss::None || self.period.is_some()
    }
}

/// Mixes a scenario seed with a link's ends into the link's seed.
#[must_use]
pub fn link_seed(seed: u64, from: u32, to: u32) -> u64 {
    let mut s = SplitMix64(seed ^ (u64::from(from) << 32 | u64::from(to)).rotate_left(17));
    s.next_u64()
}

/// Counters of one link, for the results.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct LinkStats {
    /// Messages the sender offered on this link.
    pub sent: u64,
    /// Messages delivered to the receiver.
    pub delivered: u64,
    /// Messages lost.
    pub lost: u64,
    /// Sum of the age of information over evaluated stages, s
    /// (age = receiver stage time − send time of the held value).
    pub age_sum: f64,
    /// Largest age of information, s.
    pub age_max: f64,
    /// Stages evaluated.
    pub evaluations: u64,
    /// Messages the receiver refused as invalid (non-finite numbers, or a
    /// matrix that is not a rotation); counted by the receiving agent
    /// (`Agent::receive_neighbour` / `receive_leader`) in every engine.
    #[serde(default)]
    pub rejected: u64,
    /// The median age of information, s, when the runtime measured it
    /// (real time: from a histogram, within 3.2 %); the model leaves it out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub age_p50: Option<f64>,
    /// The 99th percentile of the age of information, s, likewise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub age_p99: Option<f64>,
}

/// A message on its way: delivery slot, stamp, value (ordered by slot, then stamp).
#[derive(Debug, Clone, Copy)]
struct InFlight {
    at: (u64, u32),
    stamp: (u64, u32),
    x: Exchanged,
}

impl PartialEq for InFlight {
    fn eq(&self, o: &Self) -> bool {
        (self.at, self.stamp) == (o.at, o.stamp)
    }
}

impl Eq for InFlight {}

impl PartialOrd for InFlight {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}

impl Ord for InFlight {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        (self.at, self.stamp).cmp(&(o.at, o.stamp))
    }
}

/// The receiving end of an impaired link.
#[derive(Debug, Clone)]
pub struct Link {
    model: LinkModel,
    rng: SplitMix64,
    bad: bool,
    /// Not yet delivered, earliest delivery first.
    inflight: BinaryHeap<Reverse<InFlight>>,
    held: Option<(u64, u32, Exchanged)>,
    stats: LinkStats,
    /// Steps in which the link carries nothing ([`crate::timeline`]).
    outages: Vec<Outage>,
}

impl Link {
    /// A link with `model`.
    #[must_use]
    pub fn new(model: LinkModel) -> Self {
        Self::with_outages(model, Vec::new())
    }

    /// A link with `model` that carries nothing during `outages`: a
    /// message stamped in one is dropped after the loss and jitter draws
    /// and counted as lost.
    #[must_use]
    pub fn with_outages(model: LinkModel, outages: Vec<Outage>) -> Self {
        Self {
            rng: SplitMix64(model.seed),
            model,
            bad: false,
            inflight: BinaryHeap::new(),
            held: None,
            stats: LinkStats::default(),
            outages,
        }
    }

    /// The link's delay, steps.
    #[must_use]
    pub fn delay(&self) -> u64 {
        self.model.delay
    }

    /// Offers the sender's message stamped `(m, s)`.
    pub fn offer(&mut self, m: u64, s: u32, x: Exchanged) {
        if self.held.is_none() {
            // History before t = 0: the sender's initial state.
            self.held = Some((0, 0, x));
        }
        if let Some(p) = self.model.period {
            if s != 0 || m % p != 0 {
                return;
            }
        }
        self.stats.sent += 1;
        let lost = match self.model.loss {
            Loss::None => false,
            Loss::Bernoulli { p } => self.rng.unit() < p,
            Loss::GilbertElliott {
                p_gb,
                p_bg,
                loss_good,
                loss_bad,
            } => {
                let flip = self.rng.unit();
                self.bad = if self.bad { flip >= p_bg } else { flip < p_gb };
                self.rng.unit() < if self.bad { loss_bad } else { loss_good }
            }
        };
        if lost {
            self.stats.lost += 1;
            return;
        }
        let jitter = if self.model.jitter > 0 {
            self.rng.next_u64() % (self.model.jitter + 1)
        } else {
            0
        };
        if self.outages.iter().any(|o| o.covers(m)) {
            self.stats.lost += 1;
            return;
        }
        self.inflight.push(Reverse(InFlight {
            at: (m + self.model.delay + jitter, s),
            stamp: (m, s),
            x,
        }));
    }

    /// The value the receiver uses at slot `(n, s)`; `dt` converts ages to seconds.
    pub fn value_at(&mut self, n: u64, s: u32, dt: f64) -> Option<Exchanged> {
        while self.inflight.peek().is_some_and(|f| f.0.at <= (n, s)) {
            let Reverse(f) = self.inflight.pop().expect("peeked");
            self.stats.delivered += 1;
            let (m, ms) = f.stamp;
            if self.held.is_none_or(|(hm, hs, _)| (m, ms) >= (hm, hs)) {
                self.held = Some((m, ms, f.x));
            }
        }
        let (hm, hs, x) = self.held?;
        let c = crate::integrate::stage_time_fraction;
        let age = ((n as f64 + c(s as usize)) - (hm as f64 + c(hs as usize))) * dt;
        self.stats.age_sum += age;
        self.stats.age_max = self.stats.age_max.max(age);
        self.stats.evaluations += 1;
        Some(x)
    }

    /// Whether the receiver leaves the input out of its law at step `n`
    /// (an outage with `forget` covers it).
    #[must_use]
    pub fn forgotten_at(&self, n: u64) -> bool {
        self.outages.iter().any(|o| o.forget && o.covers(n))
    }

    /// Whether any outage of the link says `forget`.
    #[must_use]
    pub fn ever_forgets(&self) -> bool {
        self.outages.iter().any(|o| o.forget)
    }

    /// The link's counters.
    #[must_use]
    pub fn stats(&self) -> LinkStats {
        self.stats
    }

    /// The link with its counters starting from `stats` (a link of an agent
    /// that restarted: its counters carry on).
    #[must_use]
    pub fn counting_from(mut self, stats: LinkStats) -> Self {
        self.stats = stats;
        self
    }
}

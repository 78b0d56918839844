//! The candidate's side of the state exchange, played by the harness: a
//! publisher for each input the candidate reads, subscribers of the
//! candidate's state (one per receiver it expects), and its wake notifier.

use super::ConformError;
use crate::processes::Ports;
use attitude::network::Exchanged;
use attitude::schedule::Slot;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use msgs::config::NodeConfig;
use msgs::iox::iox;
use msgs::{Limits, StateMsg};

/// The harness's state ports towards the candidate.
#[derive(Debug)]
pub(super) struct Wires {
    /// One per input of the candidate, in the order of `cfg.inputs`.
    inputs: Vec<Publisher<ipc::Service, StateMsg, ()>>,
    /// Subscribers of the candidate's state; the first is read, the others drained.
    states: Vec<Subscriber<ipc::Service, StateMsg, ()>>,
    /// Wakes the candidate after its inputs are published.
    wake: Notifier<ipc::Service>,
}

impl Wires {
    /// Opens the ports of candidate `cfg` on `ports`' node.
    pub(super) fn open(
        ports: &Ports,
        cfg: &NodeConfig,
        limits: &Limits,
    ) -> Result<Self, ConformError> {
        let (node, run, id) = (ports.node(), ports.run(), cfg.id);
        let inputs = (cfg.inputs.iter())
            .map(|&j| -> Result<_, ConformError> {
                Ok(msgs::open::state(node, run, j, limits)?
                    .publisher_builder()
                    .create()
                    .map_err(iox("input publisher"))?)
            })
            .collect::<Result<_, _>>()?;
        let own = msgs::open::state(node, run, id, limits)?;
        let states = (0..cfg.outputs.len().max(1))
            .map(|_| {
                own.subscriber_builder()
                    .buffer_size(limits.state_buffer)
                    .create()
                    .map_err(iox("candidate subscriber"))
            })
            .collect::<Result<_, _>>()?;
        let wake = msgs::open::wake(node, run, id, limits)?
            .notifier_builder()
            .create()
            .map_err(iox("candidate wake notifier"))?;
        Ok(Self {
            inputs,
            states,
            wake,
        })
    }

    /// Publishes the candidate's `inputs` of `slot` (a NaN in the first
    /// one's ω if `nan`) and wakes it.
    /// Returns the values as sent (the NaN included), for rule `law`.
    pub(super) fn publish(
        &self,
        slot: Slot,
        inputs: &[(u32, Exchanged)],
        nan: bool,
    ) -> Vec<Exchanged> {
        let mut sent = Vec::with_capacity(inputs.len());
        for (k, (&(j, x), p)) in inputs.iter().zip(&self.inputs).enumerate() {
            let mut m = StateMsg::new(j, slot.step, slot.stage, &x);
            if nan && k == 0 {
                m.w[0] = f64::NAN;
            }
            sent.push(m.exchanged());
            let _ = p.send_copy(m);
        }
        let _ = self.wake.notify();
        sent
    }

    /// The candidate's next state, if one has arrived.
    pub(super) fn receive(&self) -> Option<StateMsg> {
        self.states[0].receive().ok().flatten().map(|m| *m)
    }

    /// Drops what the other subscribers of the candidate's state hold.
    pub(super) fn discard_others(&self) {
        for sub in &self.states[1..] {
            while let Ok(Some(_)) = sub.receive() {}
        }
    }
}

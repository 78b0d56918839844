//! Override hooks: the runtime asks a [`Hooks`] at each point where a test
//! or a fault injector may want to step in, whether to do it as usual, skip
//! it, or fail (as copper-rs's `SimOverride` does for a simulated task).
//! Every method has a no-op default; [`NoHooks`] is the runtime of record.

use super::{NodeError, port};
use attitude::schedule::Slot;
use msgs::{ControlCommand, StateMsg, Telemetry};

/// What the runtime does at a hooked point.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum Override {
    /// Do it as usual, with whatever the hook changed.
    #[default]
    Run,
    /// Leave it out: the hook has done it, or wants it not done.
    Skip,
    /// Fail the node ([`super::NodeError::Injected`]) with this reason.
    Fail(String),
}

/// Callbacks at the points where a run can be altered. The defaults change
/// nothing.
pub trait Hooks {
    /// Before state `msg` of exchange `slot` is published: may alter it;
    /// [`Override::Skip`] publishes nothing (the receivers get nothing).
    fn before_publish(&mut self, slot: Slot, msg: &mut StateMsg) -> Override {
        let _ = (slot, msg);
        Override::Run
    }

    /// On message `msg` received from input `k`, before any check: may alter
    /// it; [`Override::Skip`] drops it as if it never arrived.
    fn on_receive(&mut self, k: usize, msg: &mut StateMsg) -> Override {
        let _ = (k, msg);
        Override::Run
    }

    /// Before telemetry `t` is reported: may alter it; [`Override::Skip`]
    /// does not send it.
    fn before_report(&mut self, t: &mut Telemetry) -> Override {
        let _ = t;
        Override::Run
    }

    /// On a command from the orchestrator: [`Override::Skip`] ignores it
    /// (the node keeps waiting for another, as long as the orchestrator
    /// lives, bounded as ever).
    fn on_command(&mut self, command: ControlCommand) -> Override {
        let _ = command;
        Override::Run
    }
}

/// No hooks: the runtime as it is.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoHooks;

impl Hooks for NoHooks {}

impl<H: Hooks + ?Sized> Hooks for &mut H {
    fn before_publish(&mut self, slot: Slot, msg: &mut StateMsg) -> Override {
        (**self).before_publish(slot, msg)
    }
    fn on_receive(&mut self, k: usize, msg: &mut StateMsg) -> Override {
        (**self).on_receive(k, msg)
    }
    fn before_report(&mut self, t: &mut Telemetry) -> Override {
        (**self).before_report(t)
    }
    fn on_command(&mut self, command: ControlCommand) -> Override {
        (**self).on_command(command)
    }
}

/// A node's ports seen through its hooks: every publish, receive and report
/// of the loops goes through here.
pub(crate) struct Hooked<'a, S: iceoryx2::service::Service, H: Hooks> {
    /// The ports.
    pub ports: &'a super::ports::Ports<S>,
    hooks: H,
    id: u32,
}

impl<'a, S: iceoryx2::service::Service, H: Hooks> Hooked<'a, S, H> {
    pub(crate) fn new(ports: &'a super::ports::Ports<S>, hooks: H, id: u32) -> Self {
        Self { ports, hooks, id }
    }

    /// Reports `t` (as the hook has it).
    pub(crate) fn report(&mut self, mut t: Telemetry) -> Result<(), NodeError> {
        match self.hooks.before_report(&mut t) {
            Override::Run => self.ports.report(self.id, &t),
            Override::Skip => Ok(()),
            Override::Fail(why) => Err(NodeError::Injected(why)),
        }
    }

    /// Publishes `msg` at exchange `slot` (as the hook has it).
    pub(crate) fn publish(
        &mut self,
        slot: Slot,
        mut msg: StateMsg,
        notify: bool,
    ) -> Result<(), NodeError> {
        match self.hooks.before_publish(slot, &mut msg) {
            Override::Run => self.ports.publish(msg, notify),
            Override::Skip => Ok(()),
            Override::Fail(why) => Err(NodeError::Injected(why)),
        }
    }

    /// The next message of input `k`, if any (as the hook has it).
    pub(crate) fn receive(&mut self, k: usize) -> Result<Option<StateMsg>, NodeError> {
        while let Some(sample) = self.ports.inputs[k]
            .receive()
            .map_err(port("state receive"))?
        {
            let mut msg = *sample;
            match self.hooks.on_receive(k, &mut msg) {
                Override::Run => return Ok(Some(msg)),
                Override::Skip => {}
                Override::Fail(why) => return Err(NodeError::Injected(why)),
            }
        }
        Ok(None)
    }

    /// Whether to obey `command`: `Ok(false)` ignores it.
    pub(crate) fn obey(&mut self, command: ControlCommand) -> Result<bool, NodeError> {
        match self.hooks.on_command(command) {
            Override::Run => Ok(true),
            Override::Skip => Ok(false),
            Override::Fail(why) => Err(NodeError::Injected(why)),
        }
    }
}

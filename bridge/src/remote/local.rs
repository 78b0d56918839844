//! A run's iceoryx2 namespace on this side, as the bridge threads see it:
//! each thread opens its own iceoryx2 node in it (iceoryx2's ports stay on
//! the thread that made them).

use iceoryx2::node::Node;
use iceoryx2::prelude::*;
use msgs::Limits;
use msgs::iox::{IoxError, create_node};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

/// A namespace and the run's limits.
#[derive(Debug, Clone)]
pub struct LocalNs {
    /// The local run id (iceoryx2 service names).
    pub run: String,
    /// The iceoryx2 root.
    pub dir: PathBuf,
    /// The run's service limits.
    pub limits: Limits,
    /// The longest wait of one exchange (the stage timeout).
    pub stage_timeout: std::time::Duration,
    /// The run is in real time (PROTOCOL § 7): its cut edges carry the
    /// newest states first instead of every state.
    pub realtime: bool,
}

impl LocalNs {
    /// An iceoryx2 node `name` in this namespace.
    pub fn node(&self, name: &str) -> Result<Node<ipc::Service>, IoxError> {
        create_node::<ipc::Service>(&self.run, &self.dir, name)
    }

    /// An iceoryx2 node `name` whose ports may be shared between threads
    /// (the same services and shared memory as [`Self::node`]'s).
    pub fn shared_node(&self, name: &str) -> Result<Node<ipc_threadsafe::Service>, IoxError> {
        create_node::<ipc_threadsafe::Service>(&self.run, &self.dir, name)
    }
}

/// What every bridge thread of a run shares: the stop flag and the first failure.
#[derive(Debug, Clone, Default)]
pub struct Shared {
    stop: Arc<AtomicBool>,
    failure: Arc<Mutex<Option<String>>>,
}

impl Shared {
    /// Asks every thread to stop.
    pub fn stop(&self) {
        self.stop.store(true, Ordering::Relaxed);
    }

    /// Whether the threads are asked to stop.
    #[must_use]
    pub fn stopping(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    /// Records `what` as the failure (the first one is kept).
    pub fn fail(&self, what: String) {
        if let Ok(mut f) = self.failure.lock() {
            f.get_or_insert(what);
        }
    }

    /// The first failure, if any.
    #[must_use]
    pub fn failure(&self) -> Option<String> {
        self.failure.lock().ok()?.clone()
    }
}

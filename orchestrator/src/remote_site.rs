//! A run across machines as the process engine sees it: a [`Plan`] opens
//! a [`Remote`] (the `attsync-bridge` crate), which is the [`Site`] of
//! every node placed on a host.

use crate::failure::Failure;
use crate::processes::ProcessError;
use crate::processes::site::{Elsewhere, Setup, Site, SiteExit};
use crate::remote::local::LocalNs;
use crate::remote::wire::{PluginCommand, RemoteNode};
use crate::remote::{Plan, Remote};
use msgs::ControlMsg;
use std::path::Path;

impl Elsewhere for Plan {
    fn open(&self, run: &str) -> Result<Box<dyn Site>, ProcessError> {
        Ok(Box::new(Remote::connect(self, run)?))
    }
}

impl Site for Remote {
    fn places(&self, id: u32) -> bool {
        Remote::places(self, id)
    }

    fn host_of(&self, id: u32) -> Option<String> {
        Remote::host_of(self, id)
    }

    fn start(&mut self, setup: &Setup<'_>) -> Result<(), Failure> {
        let ns = LocalNs {
            run: setup.run.to_string(),
            dir: setup.dir.to_owned(),
            limits: setup.limits,
            stage_timeout: setup.stage_timeout,
            realtime: setup.realtime,
        };
        let nodes: Vec<RemoteNode> = (setup.configs.iter().zip(&setup.nodes))
            .map(|(c, n)| RemoteNode {
                name: n.name.clone(),
                config: c.clone(),
                plugin: n.plugin.map(PluginCommand::of),
            })
            .collect();
        Ok(Remote::start(self, &ns, &nodes)?)
    }

    fn control(&self, msg: ControlMsg) -> Result<(), Failure> {
        Ok(Remote::control(self, msg)?)
    }

    fn ended(&mut self) -> Result<Vec<SiteExit>, Failure> {
        Ok(Remote::check(self)?)
    }

    fn finish(&mut self, kill: bool, logs: &Path) -> Vec<SiteExit> {
        Remote::finish(self, kill, logs)
    }
}

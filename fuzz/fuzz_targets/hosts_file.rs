//! HOSTS.toml: the input is a hosts file's text, read and checked as
//! `attsync run --hosts` and `attsync check --hosts` do, then placed
//! against a scenario of 7 agents and described.
#![no_main]

use attitude::network::Network;
use attsync::hosts::{self, Placement, report};
use attsync::scenario;
// Its allocator: a request over MAX_ALLOCATION is a crash.
use attsync_fuzz as _;
use libfuzzer_sys::fuzz_target;
use std::path::Path;
use std::sync::OnceLock;

/// The network of the fixture run's scenario (7 agents and a leader).
fn network() -> &'static Network {
    static NET: OnceLock<Network> = OnceLock::new();
    NET.get_or_init(|| {
        let text = include_str!("../fixtures/run/scenario.toml");
        let l = scenario::load_str(Path::new("scenario.toml"), text, &[]).expect("the fixture");
        l.resolved.network
    })
}

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let path = Path::new("HOSTS.toml");
    match hosts::load_str(path, text) {
        Ok(h) => match Placement::of(&h, network()) {
            Ok(p) => {
                let _ = report::describe(path, &p);
            }
            Err(e) => {
                let _ = e.to_string();
            }
        },
        Err(e) => {
            let _ = e.to_string();
        }
    }
});

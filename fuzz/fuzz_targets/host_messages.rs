//! Messages from other hosts over Zenoh, decoded with the functions the
//! daemon and the orchestrator call on each payload (Zenoh itself is not
//! fuzzed). The input is tried as every one of them:
//! - a daemon's: a run offer and an end request (JSON), a run request
//!   (JSON, put back together from pieces), the orchestrator's control
//!   command and a bridged state (fixed-size bytes);
//! - the orchestrator's: a daemon's answer, its end reply and its events
//!   (JSON).
//!
//! For the pieces, the input is also cut into pieces, each behind a
//! 2-byte little-endian length, and handed to `pieces::Assembly`.
#![no_main]

use attsync::remote::host_run::decode_request;
use attsync::remote::pieces::Assembly;
use attsync::remote::wire::{Answer, EndReply, EndRequest, HostEvent, RunOffer};
// Its allocator: a request over MAX_ALLOCATION is a crash.
use attsync_fuzz as _;
use libfuzzer_sys::fuzz_target;
use msgs::bytes::Bytes;
use msgs::{ControlMsg, StateMsg};

/// The offer a request is checked against (the seeds' run and host).
fn offer() -> RunOffer {
    RunOffer {
        run: "r1".into(),
        host: "lab-a".into(),
    }
}

/// `data` cut into pieces, each behind its 2-byte length, assembled.
fn assemble(mut data: &[u8]) -> Option<Vec<u8>> {
    let mut a = Assembly::default();
    while let Some((len, rest)) = data.split_first_chunk::<2>() {
        let len = usize::from(u16::from_le_bytes(*len)).min(rest.len());
        let (piece, rest) = rest.split_at(len);
        data = rest;
        match a.add(piece) {
            Ok(true) => return a.finish().ok(),
            Ok(false) => {}
            Err(e) => {
                let _ = e.to_string();
                return None;
            }
        }
    }
    let _ = a.finish();
    None
}

fuzz_target!(|data: &[u8]| {
    // The daemon's.
    let _ = serde_json::from_slice::<RunOffer>(data);
    let _ = serde_json::from_slice::<EndRequest>(data);
    let _ = decode_request(data, &offer());
    if let Some(whole) = assemble(data) {
        let _ = decode_request(&whole, &offer());
        let _ = serde_json::from_slice::<EndReply>(&whole);
    }
    if let Ok(m) = ControlMsg::from_bytes(data) {
        let _ = m.command();
    }
    if let Ok(m) = StateMsg::from_bytes(data) {
        let _ = m.validated();
    }
    // The orchestrator's.
    let _ = serde_json::from_slice::<Answer>(data);
    let _ = serde_json::from_slice::<EndReply>(data);
    let _ = serde_json::from_slice::<HostEvent>(data);
});

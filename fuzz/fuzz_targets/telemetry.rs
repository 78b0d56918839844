//! Plug-ins' telemetry: the input is a frame of a host's telemetry link
//! (a service id, then the message's bytes) and, when it has the size of
//! one, a telemetry message as a node publishes it. Every message that
//! decodes must encode back to the same report.
#![no_main]

use attsync::remote::telemetry::unframe;
// Its allocator: a request over MAX_ALLOCATION is a crash.
use attsync_fuzz as _;
use libfuzzer_sys::fuzz_target;
use msgs::TelemetryMsg;
use msgs::bytes::Bytes;

/// Decodes `m` and checks that its report survives a round trip.
fn decode(m: &TelemetryMsg) {
    match m.decode() {
        Ok(t) => {
            let back = TelemetryMsg::encode(m.sender, &t).decode();
            assert_eq!(format!("{back:?}"), format!("{:?}", Ok::<_, ()>(t)));
        }
        Err(e) => {
            let _ = e.to_string();
        }
    }
}

fuzz_target!(|data: &[u8]| {
    if let Ok((_, m)) = unframe(data) {
        decode(&m);
    }
    if let Ok(m) = TelemetryMsg::from_bytes(data) {
        decode(&m);
    }
});

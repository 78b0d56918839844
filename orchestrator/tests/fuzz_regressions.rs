//! Inputs the fuzz targets (fuzz/, docs/fuzzing.md) found crashing,
//! hanging or allocating without bound, each fed to the same function the
//! program calls on those bytes: every one is now an error that says why.
//! The inputs are also in the targets' corpora (fuzz/corpus/<target>/regression-*).

use attsync::results::states;
use std::path::Path;

/// The fixture run's `states.bin` (fuzz/fixtures/run: 7 agents, 0.05 s).
const STATES: &[u8] = include_bytes!("../../fuzz/fixtures/run/states.bin");

/// `bytes` as a file `name` in a fresh temporary directory.
fn file(name: &str, bytes: &[u8]) -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    (dir, path)
}

/// A states file's every reader: `read` (export --csv), `open` and its records
/// (view, verify, export --mcap).
fn read_states(path: &Path) -> Result<usize, states::StatesError> {
    let (_, records) = states::read(path)?;
    let mut n = 0;
    for r in states::open(path)? {
        r?;
        n += 1;
    }
    assert_eq!(n, records.len());
    Ok(n)
}

/// states_file: a header whose name claims 17 TB (a length field's high
/// bytes changed) was allocated for before reading: an abort.
#[test]
fn states_header_with_a_huge_name_length_is_refused() {
    let bytes = include_bytes!("../../fuzz/corpus/states_file/regression-huge-name-length.bin");
    let (_dir, path) = file("states.bin", bytes);
    let e = read_states(&path).unwrap_err().to_string();
    assert!(e.contains("states.bin"), "{e}");
}

/// states_file: the fixture itself still reads whole.
#[test]
fn the_fixture_states_file_reads() {
    let (_dir, path) = file("states.bin", STATES);
    assert_eq!(read_states(&path).map_err(|e| e.to_string()), Ok(6));
}

/// host_messages: a run request whose node has a negative, zero or huge
/// timeout (or real-time factor) was accepted, and the host's run thread then
/// panicked in `Duration::from_secs_f64` (found while writing the target,
/// which now goes through the check); a node name with a `/` put its log
/// outside the run's directory.
#[test]
fn run_requests_with_unusable_nodes_are_refused() {
    use attsync::remote::host_run::decode_request;
    use attsync::remote::wire::RunOffer;
    let text = include_str!("../../fuzz/corpus/host_messages/run-request.json");
    let offer = RunOffer {
        run: "r1".into(),
        host: "lab-a".into(),
    };
    assert!(decode_request(text.as_bytes(), &offer).is_ok());
    let bad = [
        (
            "\"stage_timeout\": 10.0",
            "\"stage_timeout\": -1.0",
            "stage_timeout",
        ),
        (
            "\"stage_timeout\": 10.0",
            "\"stage_timeout\": 1e300",
            "stage_timeout",
        ),
        (
            "\"start_timeout\": 35.0",
            "\"start_timeout\": 0.0",
            "start_timeout",
        ),
        ("\"realtime\": null", "\"realtime\": -2.0", "realtime"),
        (
            "\"name\": \"agent-1\"",
            "\"name\": \"../../agent-1\"",
            "name",
        ),
    ];
    for (from, to, field) in bad {
        let e = (decode_request(text.replacen(from, to, 1).as_bytes(), &offer).unwrap_err())
            .to_string();
        assert!(
            e.contains(field) && e.starts_with("a bad request"),
            "{to}: {e}"
        );
    }
}

//! `attsync export DIR --parquet` (issue 36, part 4): a run's errors,
//! states and leader as Parquet tables, row counts as the run's (read back
//! with the parquet crate's own reader; python/tests/test_tables.py reads
//! them with pandas against `Run.to_parquet`), accepted as DIR or
//! DIR/states.bin, into `--out`; bad input names the file and the line, and
//! leaves no file behind.

mod common;

use common::{attsync, paper, run_args};
use parquet::file::reader::{FileReader, SerializedFileReader};
use std::fs;
use std::path::Path;

fn rows(file: &Path) -> i64 {
    let f = fs::File::open(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let r = SerializedFileReader::new(f).expect("a Parquet file");
    r.metadata().file_metadata().num_rows()
}

fn columns(file: &Path) -> Vec<String> {
    let r = SerializedFileReader::new(fs::File::open(file).unwrap()).unwrap();
    let schema = r.metadata().file_metadata().schema_descr_ptr();
    schema
        .columns()
        .iter()
        .map(|c| c.name().to_string())
        .collect()
}

#[test]
fn the_three_tables_hold_every_sample_and_agent() {
    let tmp = tempfile::tempdir().unwrap();
    let args = run_args(
        paper("timevarying"),
        "in-process",
        "r",
        &["simulation.duration=0.5"],
    );
    attsync(tmp.path(), &args).assert_code(0);
    let out = attsync(tmp.path(), &["export", "r", "--parquet"]);
    out.assert_code(0);
    assert!(out.stdout.contains("errors.parquet"), "{}", out.stdout);
    let dir = tmp.path().join("r");
    // 0.5 s sampled every 10 ms: 51 samples; 7 agents.
    assert_eq!(rows(&dir.join("leader.parquet")), 51);
    assert_eq!(rows(&dir.join("states.parquet")), 51 * 7);
    assert_eq!(rows(&dir.join("errors.parquet")), 51 * 7);
    let states = columns(&dir.join("states.parquet"));
    assert_eq!(states.len(), 2 + 9 + 3 + 9 + 3 + 3 + 3);
    assert_eq!(
        (&states[..3], &states[states.len() - 1][..]),
        (&["t".to_string(), "agent".into(), "r11".into()][..], "tau3")
    );
    assert_eq!(columns(&dir.join("errors.parquet"))[2], "att_err");
    // DIR/states.bin and --out work too, and give the same bytes.
    let again = attsync(
        tmp.path(),
        &["export", "r/states.bin", "--parquet", "--out", "again"],
    );
    again.assert_code(0);
    for f in ["errors.parquet", "states.parquet", "leader.parquet"] {
        assert_eq!(
            fs::read(dir.join(f)).unwrap(),
            fs::read(tmp.path().join("again").join(f)).unwrap(),
            "{f}"
        );
    }
}

#[test]
fn bad_input_names_the_file_and_leaves_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let args = run_args(
        paper("constant-observerless"),
        "in-process",
        "r",
        &["simulation.duration=0.2"],
    );
    attsync(tmp.path(), &args).assert_code(0);
    let csv = tmp.path().join("r/errors.csv");
    let text = fs::read_to_string(&csv).unwrap();
    fs::write(&csv, text.replacen("\n0,", "\nzero,", 1)).unwrap();
    let out = attsync(tmp.path(), &["export", "r", "--parquet", "--out", "t"]);
    out.assert_code(1);
    assert!(
        out.stderr.contains("errors.csv: line 2: t \"zero\""),
        "{}",
        out.stderr
    );
    let left: Vec<_> = fs::read_dir(tmp.path().join("t")).unwrap().collect();
    assert!(left.is_empty(), "files left: {left:?}");
    let out = attsync(tmp.path(), &["export", "nowhere", "--parquet"]);
    out.assert_code(1);
    assert!(out.stderr.contains("nowhere"), "{}", out.stderr);
}

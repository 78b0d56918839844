//! `states.bin` and `attsync export --csv`: the full trajectory, readable
//! back, and consistent with `errors.csv` (the attitude errors recomputed from
//! the exported matrices match the reported ones).

mod common;

use common::{Out, attsync, paper, run_args};
use std::ffi::OsStr;
use std::path::Path;

/// `attsync export STATES --csv`, in `cwd`.
fn export_csv(cwd: &Path, states: &Path) -> Out {
    let args = [
        OsStr::new("export"),
        states.as_os_str(),
        OsStr::new("--csv"),
    ];
    attsync(cwd, &args)
}

#[test]
fn export_matches_errors_csv() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let sets = ["simulation.duration=0.1"];
    let run = run_args(paper("timevarying"), "in-process", &out, &sets);
    attsync(dir.path(), &run).assert_ok();
    let exported = export_csv(dir.path(), &out.join("states.bin"));
    exported.assert_ok();
    let text = exported.stdout;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header.len(), 2 + 9 + 3 + 9 + 3 + 3 + 3);
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 11 * 8, "11 samples × (leader + 7 agents)");
    let errors = std::fs::read_to_string(out.join("errors.csv")).unwrap();
    let errs: Vec<Vec<&str>> = errors
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    let mut k = 0;
    for chunk in rows.chunks(8) {
        let leader = &chunk[0];
        assert_eq!(leader[1], "0");
        let r0 = mat(&leader[2..11]);
        for a in &chunk[1..] {
            let e = &errs[k];
            k += 1;
            assert_eq!((a[0], a[1]), (e[0], e[1]), "same time and agent");
            let r = mat(&a[2..11]);
            let att = attitude::so3::abs_i(&(r * r0.transpose()));
            let reported: f64 = e[2].parse().unwrap();
            assert_eq!(att, reported, "t {} agent {}", a[0], a[1]);
        }
    }
    assert_eq!(k, errs.len());
}

fn mat(v: &[&str]) -> nalgebra::Matrix3<f64> {
    let x: Vec<f64> = v.iter().map(|s| s.parse().unwrap()).collect();
    nalgebra::Matrix3::from_row_slice(&x)
}

#[test]
fn truncated_states_file_is_refused_with_its_name() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let sets = ["simulation.duration=0.05"];
    let run = run_args(paper("constant-observerless"), "in-process", &out, &sets);
    attsync(dir.path(), &run).assert_ok();
    let file = out.join("states.bin");
    let mut bytes = std::fs::read(&file).unwrap();
    bytes.truncate(bytes.len() - 7);
    std::fs::write(&file, bytes).unwrap();
    let r = export_csv(dir.path(), &file);
    assert_ne!(r.code, Some(0));
    let err = &r.stderr;
    assert!(
        err.contains("states.bin") && err.contains("truncated"),
        "{err}"
    );
}

//! `states.bin` and `attsync export --csv`: the full trajectory, readable
//! back, and consistent with `errors.csv` (the attitude errors recomputed from
//! the exported matrices match the reported ones).

use std::path::PathBuf;
use std::process::Command;

fn attsync() -> Command {
    Command::new(env!("CARGO_BIN_EXE_attsync"))
}

fn scenario(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios/paper")
        .join(name)
}

#[test]
fn export_matches_errors_csv() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let st = attsync()
        .args([
            "run",
            "--engine",
            "in-process",
            "--quiet",
            "--set",
            "simulation.duration=0.1",
        ])
        .arg(scenario("timevarying.toml"))
        .arg("--out")
        .arg(&out)
        .status()
        .unwrap();
    assert!(st.success());
    let exported = attsync()
        .arg("export")
        .arg(out.join("states.bin"))
        .arg("--csv")
        .output()
        .unwrap();
    assert!(
        exported.status.success(),
        "{}",
        String::from_utf8_lossy(&exported.stderr)
    );
    let text = String::from_utf8(exported.stdout).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header.len(), 2 + 9 + 3 + 9 + 3 + 3);
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
    assert!(
        attsync()
            .args([
                "run",
                "--engine",
                "in-process",
                "--quiet",
                "--set",
                "simulation.duration=0.05"
            ])
            .arg(scenario("constant-observerless.toml"))
            .arg("--out")
            .arg(&out)
            .status()
            .unwrap()
            .success()
    );
    let file = out.join("states.bin");
    let mut bytes = std::fs::read(&file).unwrap();
    bytes.truncate(bytes.len() - 7);
    std::fs::write(&file, bytes).unwrap();
    let r = attsync()
        .arg("export")
        .arg(&file)
        .arg("--csv")
        .output()
        .unwrap();
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("states.bin") && err.contains("truncated"),
        "{err}"
    );
}

//! `attsync mc --engine processes` (issue 13): every trial is a normal
//! process-engine run in its own iceoryx2 namespace. The engines are
//! bit-identical, so a few trials give the same `trials.csv` and
//! `initial.csv` as in-process, and `mc.json` differs only in `engine`;
//! trial K alone with the process engine gives row K; nothing is left
//! behind (namespaces, `/dev/shm`), and a converged trial keeps no logs.

use attsync_tests::{Attsync, Sandbox, paper, read};

fn mc_args(engine: &str, out: &str) -> Vec<String> {
    let scenario = paper("constant-observerless").display().to_string();
    [
        "mc",
        &scenario,
        "--trials",
        "3",
        "--engine",
        engine,
        "--out",
        out,
        "--quiet",
        "--set",
        "simulation.duration=0.5",
    ]
    .map(String::from)
    .to_vec()
}

#[test]
fn processes_trials_equal_in_process_trials() {
    let tmp = Sandbox::new("mc_processes");
    Attsync::new(tmp.path())
        .args(mc_args("processes", "p"))
        .output()
        .assert_ok()
        .assert_no_leftovers();
    Attsync::new(tmp.path())
        .args(mc_args("in-process", "i"))
        .output()
        .assert_ok();
    let (p, i) = (tmp.join("p"), tmp.join("i"));
    assert_eq!(read(&p.join("trials.csv")), read(&i.join("trials.csv")));
    assert_eq!(read(&p.join("initial.csv")), read(&i.join("initial.csv")));
    let json = |d: &std::path::Path| -> serde_json::Value {
        let mut v: serde_json::Value = serde_json::from_str(&read(&d.join("mc.json"))).unwrap();
        v.as_object_mut().unwrap().remove("engine");
        v
    };
    assert_eq!(json(&p), json(&i));
    assert!(
        !p.join("logs").join("trial-0").exists(),
        "a trial that ran keeps no logs"
    );
    let row = read(&i.join("trials.csv"))
        .lines()
        .nth(2)
        .unwrap()
        .to_string();
    let mut alone = mc_args("processes", "t1");
    alone.splice(2..4, ["--trial".to_string(), "1".to_string()]);
    let out = Attsync::new(tmp.path()).args(alone).output();
    out.assert_ok().assert_no_leftovers();
    assert!(
        out.stdout.lines().any(|l| l == row),
        "row 1 {row}\n{}",
        out.stdout
    );
}

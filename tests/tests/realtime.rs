//! Real-time mode (`attsync run --realtime [factor]`): nodes run free
//! against the wall clock, never wait for their inputs, and the transport's
//! real latency shows up as a measured age of information on every link.

use attsync_tests::{Attsync, Sandbox, paper, run_args, summary};

#[test]
fn realtime_runs_and_measures_a_nonzero_age_of_information() {
    let tmp = Sandbox::new("realtime");
    let out = tmp.join("rt");
    let mut args = run_args(
        &paper("constant-observerless"),
        "processes",
        &out,
        &["simulation.duration=1"],
    );
    args.push("--realtime".into());
    let run = Attsync::new(tmp.path()).args(args).output();
    run.assert_ok().assert_no_leftovers();
    let s = summary(&out);
    assert_eq!(s["complete"], true, "{s:#}");
    assert_eq!(s["realtime"], 1.0, "{s:#}");
    // 1 s of simulated time at factor 1 cannot take much less than 1 s.
    assert!(s["wall_seconds"].as_f64().unwrap() >= 0.95, "{s:#}");
    // Every directed link of the paper graph is measured: 5 edges both
    // ways and 2 leader links.
    let links = s["links"].as_array().expect("links");
    assert_eq!(links.len(), 12, "{s:#}");
    for l in links {
        let exchanges = 1000 * 4;
        assert_eq!(l["sent"], exchanges, "{l}");
        let delivered = l["delivered"].as_u64().unwrap();
        assert!(delivered >= exchanges / 2, "{l}");
        assert_eq!(l["lost"].as_u64().unwrap(), exchanges - delivered, "{l}");
        let (mean, max) = (
            l["aoi_mean"].as_f64().unwrap(),
            l["aoi_max"].as_f64().unwrap(),
        );
        assert!(mean > 0.0 && mean <= max, "{l}");
        // Shared memory on one machine: far below a second.
        assert!(max < 0.5, "{l}");
        // The quantiles are a histogram's bins (within 3.2 %) of the same ages.
        let (p50, p99) = (
            l["aoi_p50"].as_f64().expect("aoi_p50"),
            l["aoi_p99"].as_f64().expect("aoi_p99"),
        );
        assert!(0.0 < p50 && p50 <= p99 && p99 <= max * 1.032, "{l}");
    }
    for a in s["agents"].as_array().unwrap() {
        assert!(a["late_stages"].is_u64(), "{a}");
        assert!(a["max_lateness"].is_f64(), "{a}");
    }
    // The real-time trajectory stays close to the lockstep one after 1 s
    // (the AoI is a fraction of a step): same errors to 25 % (generous: a
    // loaded machine delays nodes by whole steps).
    let lock = tmp.join("lockstep");
    Attsync::new(tmp.path())
        .args(run_args(
            &paper("constant-observerless"),
            "in-process",
            &lock,
            &["simulation.duration=1"],
        ))
        .output()
        .assert_ok();
    let l = summary(&lock);
    for (a, b) in s["agents"]
        .as_array()
        .unwrap()
        .iter()
        .zip(l["agents"].as_array().unwrap())
    {
        let (x, y) = (
            a["final_att_err"].as_f64().unwrap(),
            b["final_att_err"].as_f64().unwrap(),
        );
        assert!((x - y).abs() <= 0.25 * y, "real-time {x} vs lockstep {y}");
    }
}

#[test]
fn realtime_at_factor_4_takes_a_quarter_of_the_time() {
    let tmp = Sandbox::new("realtime-x4");
    let out = tmp.join("rt");
    let mut args = run_args(
        &paper("constant-observerless"),
        "processes",
        &out,
        &["simulation.duration=2"],
    );
    args.extend(["--realtime".into(), "4".into()]);
    Attsync::new(tmp.path()).args(args).output().assert_ok();
    let s = summary(&out);
    assert_eq!(s["realtime"], 4.0);
    let wall = s["wall_seconds"].as_f64().unwrap();
    assert!(wall >= 0.48, "2 s at ×4 took {wall} s of wall time");
}

#[test]
fn realtime_refuses_what_it_cannot_honour() {
    let tmp = Sandbox::new("realtime-refusals");
    let scenario = paper("constant-observerless");
    let mut with_delay = run_args(
        &scenario,
        "processes",
        &tmp.join("a"),
        &["network.delay=0.01"],
    );
    with_delay.push("--realtime".into());
    let r = Attsync::new(tmp.path()).args(with_delay).output();
    r.assert_code(2);
    assert!(
        r.stderr
            .contains("--realtime cannot be combined with [network]"),
        "{}",
        r.describe()
    );

    let mut in_process = run_args(&scenario, "in-process", &tmp.join("b"), &[]);
    in_process.extend(["--realtime".into(), "2".into()]);
    let r = Attsync::new(tmp.path()).args(in_process).output();
    r.assert_code(2);
    assert!(r.stderr.contains("--engine processes"), "{}", r.describe());

    let mut zero = run_args(&scenario, "processes", &tmp.join("c"), &[]);
    zero.extend(["--realtime".into(), "0".into()]);
    let r = Attsync::new(tmp.path()).args(zero).output();
    r.assert_code(2);
    assert!(r.stderr.contains("positive"), "{}", r.describe());
    assert!(!tmp.join("a").exists() && !tmp.join("b").exists() && !tmp.join("c").exists());
}

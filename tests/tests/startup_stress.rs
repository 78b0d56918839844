//! Start-up survives a busy machine (issue 33, part 3).
//!
//! With load average 10–20 on 2 cores, built-in agents used to fail at
//! start-up with `cannot open service …: DoesNotExist` (iceoryx2's
//! open-or-create gives up after its own creation timeout while another
//! process is still creating the service). Now every open retries
//! iceoryx2's transient failures within the start timeout
//! (`msgs::open::retry`).
//!
//! The test runs the paper's time-varying scenario (processes engine,
//! shortened to [`DURATION`]) [`RUNS`] times back to back beside
//! 2 × cores CPU-bound competitors and one that writes, fsyncs and reads a
//! few hundred MB and fills a large buffer (as a parallel compile does),
//! all started by the test and killed when it ends, panics included (and
//! by themselves once the test process is gone). Every run must complete,
//! leave nothing behind, and give results byte-identical to the first.

use attsync_tests::{Attsync, Sandbox, assert_same_results, paper, run_args, summary};
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::Instant;

/// Runs back to back.
const RUNS: usize = 30;
/// The simulated duration of each run: short, so that 30 runs on a busy
/// 2-core machine take minutes, not tens of minutes; start-up, which this
/// test is about, is the same whatever the duration.
const DURATION: &str = "simulation.duration=0.5";
/// CPU-bound competitors per core.
const HOGS_PER_CORE: usize = 2;
/// What the I/O competitor writes, fsyncs and reads back each round, MB;
/// also the buffer it fills (`dd`'s block).
const IO_MB: usize = 256;

/// A CPU-bound loop that ends once the test process (its parent) is gone.
const CPU_HOG: &str = "p=$PPID; while kill -0 $p 2>/dev/null; do i=0; \
     while [ $i -lt 20000 ]; do i=$((i+1)); done; done";

/// The I/O and memory competitor's loop (`$1`: its directory, `$2`: MB),
/// also ending with the test process.
const IO_HOG: &str = "p=$PPID; while kill -0 $p 2>/dev/null; do \
     dd if=/dev/zero of=\"$1/hog\" bs=1M count=\"$2\" conv=fsync status=none; \
     dd if=\"$1/hog\" of=/dev/null bs=\"$2M\" count=1 status=none; \
     rm -f \"$1/hog\"; done";

/// The competitors, each the leader of its own process group; killed (the
/// whole group) when dropped.
struct Competitors(Vec<Child>);

impl Competitors {
    /// 2 × cores CPU hogs and one I/O hog writing under `dir`.
    fn start(dir: &Path) -> Self {
        let cores = std::thread::available_parallelism().map_or(1, usize::from);
        let sh = |script: &str, args: &[&str]| {
            Command::new("sh")
                .args(["-c", script, "competitor"])
                .args(args)
                .stdin(Stdio::null())
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .process_group(0)
                .spawn()
                .expect("start a competitor")
        };
        let mut children: Vec<Child> = (0..HOGS_PER_CORE * cores)
            .map(|_| sh(CPU_HOG, &[]))
            .collect();
        let dir = dir.display().to_string();
        children.push(sh(IO_HOG, &[&dir, &IO_MB.to_string()]));
        Self(children)
    }
}

impl Drop for Competitors {
    fn drop(&mut self) {
        for c in &mut self.0 {
            let group = format!("-{}", c.id());
            let _ = Command::new("kill")
                .args(["-KILL", "--", &group])
                .stderr(Stdio::null())
                .status();
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

/// Runs the paper scenario into `out`; what went wrong, if the run failed.
fn paper_run(cwd: &Path, out: &Path) -> Option<String> {
    let finished = Attsync::new(cwd)
        .args(run_args(
            &paper("timevarying"),
            "processes",
            out,
            &[DURATION],
        ))
        .output();
    if finished.code() != Some(0) {
        return Some(finished.describe());
    }
    finished.assert_no_leftovers();
    None
}

#[test]
fn thirty_paper_runs_beside_busy_competitors_all_complete_identically() {
    let tmp = Sandbox::new("startup-stress");
    let hogs_dir = tmp.join("hogs");
    std::fs::create_dir_all(&hogs_dir).expect("the competitors' directory");
    let began = Instant::now();
    let _competitors = Competitors::start(&hogs_dir);
    let first = tmp.join("run-0");
    let mut failed = Vec::new();
    for k in 0..RUNS {
        let out = tmp.join(format!("run-{k}"));
        if let Some(why) = paper_run(tmp.path(), &out) {
            eprintln!("run {k} failed:\n{why}");
            failed.push(k);
            continue;
        }
        assert_eq!(summary(&out)["complete"], true, "run {k} is incomplete");
        if k > 0 && first.exists() {
            assert_same_results(&first, &out);
            let _ = std::fs::remove_dir_all(&out);
        }
    }
    eprintln!(
        "{RUNS} runs in {:.1} s, {} failed",
        began.elapsed().as_secs_f64(),
        failed.len()
    );
    assert!(
        failed.is_empty(),
        "runs that failed beside the competitors: {failed:?}"
    );
}

//! The Python package (`python/`, issue 36): its pytest suite
//! (`python/tests/`) against the native module the workspace built
//! (`target/<profile>/lib_attsync.so`, what maturin packs), assembled into a
//! package directory of the test's own with the Python sources beside it.
//! `pip install ./python` builds the same module with maturin (README).

use attsync_tests::bin_dir;
use attsync_tests::{Sandbox, require_python_modules};
use std::fs;
use std::path::Path;
use std::process::Command;

/// `dir/attsync/`: the package's Python sources and the built native module.
fn assemble(dir: &Path) {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let pkg = dir.join("attsync");
    fs::create_dir_all(&pkg).expect("package directory");
    for e in fs::read_dir(repo.join("python/attsync")).expect("python/attsync") {
        let p = e.expect("entry").path();
        if p.extension().is_some_and(|x| x == "py") {
            fs::copy(&p, pkg.join(p.file_name().expect("name"))).expect("copy a source");
        }
    }
    let native = bin_dir().join("lib_attsync.so");
    assert!(
        native.is_file(),
        "{} not found: `cargo build --release --workspace` builds it",
        native.display()
    );
    fs::copy(&native, pkg.join("_attsync.abi3.so")).expect("copy the native module");
}

#[test]
fn the_python_packages_tests_pass() {
    require_python_modules(
        "numpy, pandas, pyarrow, pytest, matplotlib, dask, distributed, nbclient, nbformat, ipykernel",
        "tools/test-deps.sh (or `python3 -m pip install -r python/requirements.txt`)",
    );
    let tmp = Sandbox::new("python_package");
    assemble(tmp.path());
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .canonicalize()
        .expect("repository");
    let out = Command::new("python3")
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider", "--basetemp"])
        .arg(tmp.join("pytest"))
        .arg(repo.join("python/tests"))
        .env("PYTHONPATH", tmp.path())
        .env("ATTSYNC_REPO", &repo)
        .env("ATTSYNC_BIN_DIR", bin_dir())
        .current_dir(tmp.path())
        .output()
        .expect("python3 runs");
    let text =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "pytest failed:\n{text}");
    assert!(text.contains(" passed"), "{text}");
    assert!(
        !text.contains("skipped"),
        "a skipped test is not a passing one:\n{text}"
    );
}

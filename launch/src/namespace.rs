//! A run's iceoryx2 namespace on this machine: a root directory
//! `<base>/attsync-iox2/<run>/` (`<base>`: `$TMPDIR`, else `/dev/shm`; [`base_dir`]) and the file prefix `as<run>_` (see
//! [`msgs::namespace`]). Removing both removes everything the run created;
//! namespaces whose owner process is gone are removed on start.

use std::fs;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};

/// Where shared-memory segments live.
const SHM_DIR: &str = "/dev/shm";

/// The namespace of one run. Removed on drop.
#[derive(Debug)]
pub struct Namespace {
    run: String,
    dir: PathBuf,
}

/// The name of the directory, in the temporary directory, of every run's namespace.
const BASE_NAME: &str = "attsync-iox2";

/// Longest [`base_dir`] path, in bytes: iceoryx2's Unix socket paths
/// (`<base>/<run>/<prefix><service>…`) must fit in 108 bytes (`sun_path`),
/// and a run id takes up to 15.
pub const MAX_BASE_LEN: usize = 40;

/// Parent directory of every run's namespace: `$TMPDIR/attsync-iox2` where
/// `TMPDIR` is set, else `/dev/shm/attsync-iox2`, else `/tmp/attsync-iox2`.
/// tmpfs first because iceoryx2 fsyncs each service's static configuration
/// (3 fsyncs per service, 5 + degree services per node): on a disk busy with
/// other work each fsync waits for the device, and start-up took 65–86 ms
/// per node against 14–17 on tmpfs (BENCHMARKS.md, "Start-up and
/// capacity"). A `$TMPDIR` base longer than [`MAX_BASE_LEN`] is replaced by
/// `/tmp/attsync-iox2` if `/tmp` is writable (said with `ATTSYNC_DEBUG`).
#[must_use]
pub fn base_dir() -> PathBuf {
    let Some(tmp) = std::env::var_os("TMPDIR").filter(|t| !t.is_empty()) else {
        return default_base();
    };
    let base = PathBuf::from(tmp).join(BASE_NAME);
    if base.as_os_str().len() <= MAX_BASE_LEN {
        return base;
    }
    let short = Path::new("/tmp").join(BASE_NAME);
    if fs::create_dir_all(&short).is_ok() {
        tracing_free_log(&format!(
            "{} is longer than {MAX_BASE_LEN} bytes (too long for Unix socket paths): using {}",
            base.display(),
            short.display()
        ));
        return short;
    }
    base
}

/// The base without `TMPDIR`: on tmpfs (`/dev/shm`) where it can be
/// created, else in `/tmp`.
fn default_base() -> PathBuf {
    let shm = Path::new("/dev/shm").join(BASE_NAME);
    if fs::create_dir_all(&shm).is_ok() {
        shm
    } else {
        Path::new("/tmp").join(BASE_NAME)
    }
}

/// An error if `base` (from [`base_dir`]) is too long for socket paths.
fn check_base(base: &Path) -> std::io::Result<()> {
    if base.as_os_str().len() <= MAX_BASE_LEN {
        return Ok(());
    }
    Err(std::io::Error::new(
        std::io::ErrorKind::InvalidInput,
        format!(
            "TMPDIR is too long: the namespace directory {} has {} bytes, at most {MAX_BASE_LEN} \
             fit in Unix socket paths (108 bytes), and /tmp is not writable; set TMPDIR to a \
             shorter directory (at most {} bytes)",
            base.display(),
            base.as_os_str().len(),
            MAX_BASE_LEN - BASE_NAME.len() - 1
        ),
    ))
}

impl Namespace {
    /// Creates a fresh namespace with a unique run id, after removing stale
    /// namespaces of dead runs.
    pub fn create() -> std::io::Result<Self> {
        static COUNTER: AtomicU32 = AtomicU32::new(0);
        remove_stale();
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.subsec_nanos());
        let run = format!(
            "{:x}r{:x}r{:x}",
            std::process::id(),
            COUNTER.fetch_add(1, Ordering::Relaxed),
            nanos & 0xffff
        );
        // Build the directory with its owner file under a hidden name and
        // rename it into place, so that another attsync's stale-namespace
        // sweep never sees a namespace without an owner.
        let base = base_dir();
        check_base(&base)?;
        fs::create_dir_all(&base)?;
        let tmp = base.join(format!(".{run}.creating"));
        fs::create_dir_all(&tmp)?;
        fs::write(tmp.join("owner"), std::process::id().to_string())?;
        let dir = base.join(&run);
        fs::rename(&tmp, &dir)?;
        Ok(Self { run, dir })
    }

    /// The run id.
    #[must_use]
    pub fn run(&self) -> &str {
        &self.run
    }

    /// The iceoryx2 root path (and where node configs are written).
    #[must_use]
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Every file of this run still present (shared memory and root dir).
    #[must_use]
    pub fn leftovers(run: &str) -> Vec<PathBuf> {
        let mut out = shm_files(run);
        let dir = base_dir().join(run);
        if dir.exists() {
            out.push(dir);
        }
        out
    }
}

impl Drop for Namespace {
    fn drop(&mut self) {
        remove(&self.run);
    }
}

fn shm_files(run: &str) -> Vec<PathBuf> {
    let prefix = msgs::namespace::prefix(run);
    fs::read_dir(SHM_DIR)
        .map(|rd| {
            rd.filter_map(Result::ok)
                .filter(|e| e.file_name().to_string_lossy().starts_with(&prefix))
                .map(|e| e.path())
                .collect()
        })
        .unwrap_or_default()
}

/// Removes run `run`'s shared memory and root directory.
pub fn remove(run: &str) {
    for f in shm_files(run) {
        let _ = fs::remove_file(f);
    }
    let _ = fs::remove_dir_all(base_dir().join(run));
}

/// Removes the namespaces whose owner process no longer exists.
pub fn remove_stale() {
    let Ok(rd) = fs::read_dir(base_dir()) else {
        return;
    };
    for e in rd.filter_map(Result::ok) {
        let name = e.file_name().to_string_lossy().into_owned();
        let owner = fs::read_to_string(e.path().join("owner")).ok();
        if let Some(creating) = name.strip_prefix('.') {
            // A namespace being created: leave it unless its creator is dead.
            let dead = owner
                .as_deref()
                .and_then(|p| p.trim().parse::<u32>().ok())
                .is_some_and(|pid| !attsync_sched::process::exists(pid));
            if dead {
                let _ = fs::remove_dir_all(e.path());
            }
            let _ = creating;
            continue;
        }
        let run = name;
        let alive = owner
            .and_then(|p| p.trim().parse::<u32>().ok())
            .is_some_and(attsync_sched::process::exists);
        if !alive {
            tracing_free_log(&format!("removing stale iceoryx2 namespace of run {run}"));
            remove(&run);
        }
    }
}

fn tracing_free_log(msg: &str) {
    if std::env::var_os("ATTSYNC_DEBUG").is_some() {
        eprintln!("attsync: {msg}");
    }
}

/// `node-<id>.json`, node `id`'s configuration in its run's namespace directory.
#[must_use]
pub fn node_config_file(id: u32) -> String {
    format!("node-{id}.json")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_base_too_long_for_socket_paths_is_refused_naming_tmpdir() {
        assert!(check_base(Path::new("/tmp/attsync-iox2")).is_ok());
        let long = PathBuf::from(format!("/{}/attsync-iox2", "t".repeat(40)));
        let e = check_base(&long).unwrap_err().to_string();
        assert!(
            e.contains("TMPDIR is too long") && e.contains("at most 27 bytes"),
            "{e}"
        );
    }
}

//! Where the shared real data is (`../shared/data` beside the workspace), and temporary folders.
//! A test that needs the real data fails without it, naming where it looked, unless the user opts
//! out with `TERRAMP_SKIP_SHARED=1`: then it is skipped, and says so on the terminal (past the
//! test harness's capture) with how many were skipped so far, so a green run without the data is
//! never mistaken for a run with it.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The environment variable that lets real-data tests be skipped when `../shared/data` is absent.
pub const SKIP_SHARED: &str = "TERRAMP_SKIP_SHARED";

/// Tests of this binary skipped for want of the shared data.
static SKIPPED: AtomicUsize = AtomicUsize::new(0);

/// Where the shared data should be: `<workspace>/../shared/data`.
pub fn shared_data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data")
}

/// `<workspace>/../shared/data`. When it is absent the calling test fails, naming the folder,
/// unless `TERRAMP_SKIP_SHARED=1`: then `None`, and the skip is printed with the count so far.
pub fn shared_data() -> Option<PathBuf> {
    let dir = shared_data_dir();
    if dir.join("README.md").is_file() {
        return Some(dir);
    }
    if std::env::var(SKIP_SHARED).is_ok_and(|v| v == "1") {
        let skipped = SKIPPED.fetch_add(1, Ordering::Relaxed) + 1;
        // Straight to the terminal: the harness hides what a passing test prints.
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED (no {}, {SKIP_SHARED}=1): {skipped} real-data test(s) of this binary skipped so far",
            dir.display()
        );
        return None;
    }
    panic!(
        "{} is missing: the real-data tests need ../shared beside the repository \
         (set {SKIP_SHARED}=1 to skip them, and be told how many were)",
        dir.display()
    );
}

/// The test run's scratch folder: `tmp/` in cargo's target folder (what `CARGO_TARGET_TMPDIR`
/// names for integration tests), found from the running test binary, so each checkout has its own.
pub fn target_tmp_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    // Cargo marks its target folder with CACHEDIR.TAG, whatever the profile or target triple.
    let target = exe.ancestors().find(|dir| dir.join("CACHEDIR.TAG").is_file());
    let dir = target.map_or_else(|| std::env::temp_dir().join("terramp-tests"), |t| t.join("tmp"));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A temporary folder, removed when dropped.
pub struct TempDir(PathBuf);

impl TempDir {
    /// A fresh, empty folder named after `name` and the process.
    pub fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("terramp-test-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }

    pub fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

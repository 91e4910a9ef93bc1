//! Where the shared real data is (`../shared/data` beside the workspace), and temporary folders.
//! Under `CI=true` the data's absence is a failure, never a silent skip.

use std::path::{Path, PathBuf};

/// `<workspace>/../shared/data`, or `None` (after saying why) when it is absent outside CI. Under
/// `CI=true` its absence panics: CI must run with `../shared` beside the repository.
pub fn shared_data() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data");
    if dir.join("README.md").is_file() {
        return Some(dir);
    }
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!("{} is missing: CI must run with ../shared beside the repository", dir.display());
    }
    eprintln!("skipping: {} is not there", dir.display());
    None
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

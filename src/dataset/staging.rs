//! How it works: a dataset is built in a hidden sibling folder (`.NAME.partial-PID`) and put in
//! place (`crate::publish`: exchanged with the previous dataset in one step) only once every pack
//! and the manifest are written and synced. A build that fails or is dropped removes its staging
//! folder; one that is killed leaves only that hidden folder (or, killed just after the exchange,
//! the previous dataset under that name), which the next build in the same place sweeps away.
//! `DIR` is therefore either absent, the previous complete dataset, or the new complete one: never
//! half of anything (`data-tools/tests/kill9.rs` kills builds anywhere and checks it).

use std::fs;
use std::path::{Path, PathBuf};

use super::DatasetError;
use super::manifest::{MANIFEST_FILE, Manifest};

/// A dataset build in progress: a hidden sibling folder that `commit` renames onto the output and
/// that dropping uncommitted removes.
pub struct Staging {
    out: PathBuf,
    staging: PathBuf,
    committed: bool,
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> DatasetError + '_ {
    move |source| DatasetError::Io { path: path.to_owned(), source }
}

impl Staging {
    /// Starts a build whose result will be `out`. An existing `out` is replaced only on commit.
    pub fn begin(out: &Path) -> Result<Self, DatasetError> {
        if out.file_name().and_then(|n| n.to_str()).is_none() {
            return Err(DatasetError::BadOutput { path: out.to_owned() });
        }
        if out.exists() && !out.join(MANIFEST_FILE).exists() {
            // Refuse to replace something that is not a dataset: it may be the user's folder.
            return Err(DatasetError::NotADataset { path: out.to_owned() });
        }
        let staging =
            crate::publish::begin_staging(out).map_err(|(path, source)| DatasetError::Io { path, source })?;
        Ok(Self { out: out.to_owned(), staging, committed: false })
    }

    /// Where to write `file` during the build.
    pub fn path(&self, file: &str) -> PathBuf {
        self.staging.join(file)
    }

    /// Writes the manifest and puts the finished dataset in place.
    pub fn commit(mut self, manifest: &Manifest) -> Result<PathBuf, DatasetError> {
        let text =
            toml::to_string_pretty(manifest).map_err(|e| DatasetError::ManifestWrite(e.to_string()))?;
        let manifest_path = self.staging.join(MANIFEST_FILE);
        fs::write(&manifest_path, text).map_err(io(&manifest_path))?;
        fs::File::open(&manifest_path).and_then(|f| f.sync_all()).map_err(io(&manifest_path))?;
        let old = crate::publish::swap_into_place(&self.staging, &self.out).map_err(io(&self.out))?;
        self.committed = true;
        if let Some(old) = old {
            fs::remove_dir_all(&old).map_err(io(&old))?;
        }
        Ok(self.out.clone())
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if !self.committed {
            let _ = fs::remove_dir_all(&self.staging);
        }
    }
}

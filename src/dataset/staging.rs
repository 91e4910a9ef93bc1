//! How it works: a dataset is built in a hidden sibling folder (`.NAME.partial-PID`) and put in
//! place (`crate::publish`: exchanged with the previous dataset in one step) only once every pack
//! and the manifest are written and the manifest synced. A build that fails or is dropped removes
//! its staging folder; one that is killed leaves hidden folders beside `DIR` (its staging folder,
//! or the previous dataset once it has been exchanged out), which the next build in the same place
//! sweeps away. `DIR` is therefore the previous complete dataset or the new complete one, or (only
//! where the exchange is unavailable, killed between the fallback's two renames) absent until the
//! next build there puts the previous one back: never half of anything. `data-tools/tests/kill9.rs`
//! kills `synth` and `build` at each step of `crate::publish::Step` and checks it.

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
        crate::publish::publish(&self.staging, &self.out)
            .map_err(|(path, source)| DatasetError::Io { path, source })?;
        self.committed = true;
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

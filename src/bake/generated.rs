//! How it works: where the baker finds a model by name: `<folder>/<name>.glb` when that file
//! exists, else, when the name is a generated tree's (`tree::ModelName`, e.g.
//! `tree-spruce-s7-h80`), the generator grows it and writes it into a scratch folder of its own,
//! removed when the source is dropped. So a class table may name generated trees beside model
//! files, and the embedded default needs no model folder at all.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};

use super::BakeError;
use crate::tree::ModelName;

/// Models by name: a folder's `.glb` files, then the tree generator.
pub struct ModelSource {
    folder: PathBuf,
    scratch: Option<PathBuf>,
}

impl ModelSource {
    /// Models read from `folder` (which need not exist: generated trees need none).
    pub fn new(folder: &Path) -> Self {
        Self { folder: folder.to_path_buf(), scratch: None }
    }

    /// The glTF file of model `name`: the folder's, or a generated tree's written now; `None`
    /// when there is neither.
    pub fn file(&mut self, name: &str) -> Result<Option<PathBuf>, BakeError> {
        let in_folder = self.folder.join(format!("{name}.glb"));
        if in_folder.is_file() {
            return Ok(Some(in_folder));
        }
        let Some(tree) = ModelName::parse(name) else { return Ok(None) };
        let failed = |problem: String| BakeError::Generated { name: name.to_string(), problem };
        let grown = tree.generate().map_err(|e| failed(e.to_string()))?;
        let scratch = match &self.scratch {
            Some(dir) => dir.clone(),
            None => {
                static NEXT: AtomicU32 = AtomicU32::new(0);
                let unique = NEXT.fetch_add(1, Ordering::Relaxed);
                let dir = std::env::temp_dir().join(format!("terramp-trees-{}-{unique}", std::process::id()));
                std::fs::create_dir_all(&dir)
                    .map_err(|e| failed(format!("creating {}: {e}", dir.display())))?;
                self.scratch.insert(dir).clone()
            }
        };
        let file = scratch.join(format!("{name}.glb"));
        std::fs::write(&file, grown.to_glb())
            .map_err(|e| failed(format!("writing {}: {e}", file.display())))?;
        Ok(Some(file))
    }
}

impl Drop for ModelSource {
    fn drop(&mut self) {
        if let Some(dir) = &self.scratch {
            // Scratch only: a leftover in the temporary folder harms nothing.
            let _ = std::fs::remove_dir_all(dir);
        }
    }
}

//! How it works: the names of the dataset's streamed tile layers, which every part of streaming
//! (the loader, its injected faults, the caches) keys tiles by; a module of its own so that none
//! of them imports another for it.

/// Which of the dataset's tile layers a request reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
pub enum LayerKind {
    /// The DEM's height tiles (samples, with a border for normals).
    Height,
    /// The aerial imagery's tiles, with their mips and filtering border.
    Imagery,
    /// The land-cover map's tiles (palette indices, in the levels of the LCC quadtree).
    Landcover,
}

impl LayerKind {
    /// The layer's lower-case name, as logs and reports write it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Height => "height",
            Self::Imagery => "imagery",
            Self::Landcover => "landcover",
        }
    }
}

impl std::fmt::Display for LayerKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

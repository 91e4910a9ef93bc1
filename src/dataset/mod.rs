//! How it works: a dataset is a folder with `manifest.toml` and one pack per layer (heights, their
//! validity mask, imagery, land cover). `Dataset::open` checks the manifest and every pack's
//! header, length and index up front; tile payloads are read when asked for (positioned reads,
//! never a mapping: `pack`), checksummed, decoded and checked against the value range their index
//! entry records (`layer_pack`), so a damaged tile, or a pack changed on disk while open, is an
//! error for that tile alone and the caller decides how to degrade.
//!
//! The manifest's format version is read on its own before the rest, so a dataset of another
//! version is reported as such (and rebuilt by whoever owns it), not as a malformed manifest.
//! Land cover is an LCC quadtree (`lcc`): its words are read back through the manifest's
//! `LccCoding`, never as raw class codes.
//!
//! Writing goes through `Staging` (atomic publication) and `layer_writer::write_layer` (one pack,
//! tile by tile; `lcc::write_lcc_layer` for land cover), shared by `terramp-data build` and the
//! synthetic generator.

#[cfg(feature = "bc-encode")]
pub mod block_encode;
pub mod imagery_format;
mod layer_pack;
pub mod layer_writer;
pub mod lcc;
pub mod manifest;
pub mod pack;
pub mod partition;
pub mod pose;
pub mod pyramid;
pub mod staging;
pub mod surface;
pub mod vegetation;

use std::path::{Path, PathBuf};

use serde::Deserialize;
use thiserror::Error;

use layer_pack::word_of;
use lcc::{LCC_LEVELS, LCC_SOURCE_LEVEL, LccCoding};

pub use imagery_format::{ImageryFormat, MipLayout};
pub use layer_pack::{LayerPack, ValueCheck};
pub use layer_writer::{LayerError, LayerSpec, Reduce, Texel, Window, write_layer};
pub use manifest::{
    CellLayer, ClassName, Crs, FORMAT_VERSION, HeightLayer, LandcoverLayer, MANIFEST_FILE, Manifest,
    Vegetation,
};
pub use pack::{Codec, Damage, PACK_VERSION, Pack, PackError, Predictor};
pub use pyramid::{Pyramid, Sampling, TileId};
pub use staging::Staging;

/// The tiles' shapes: cells, texels, borders and mips per layer (defined with every other
/// constant the shaders share, in `gpu::layout`).
pub use crate::gpu::layout::{
    CELL_TILE_TEXELS, HEIGHT_BORDER, HEIGHT_TILE_CELLS, IMAGERY_BORDER, IMAGERY_MIPS, LANDCOVER_BORDER,
};

/// Why a dataset could not be opened, or a build could not stage or publish it.
#[derive(Debug, Error)]
pub enum DatasetError {
    /// Reading the manifest, or creating, writing or renaming a file or folder of a build, failed.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder the operation was on.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The folder has no `manifest.toml`: at `Dataset::open`, or when a build would replace a
    /// folder that is not a dataset (it may be the user's).
    #[error(
        "{path}: no dataset here (no {MANIFEST_FILE}); build one with `terramp-data build` or `terramp-data synth`"
    )]
    NotADataset {
        /// The folder without a manifest.
        path: PathBuf,
    },
    /// The manifest does not parse as this format, or its land-cover layer is inconsistent (an
    /// invalid LCC coding, or not 3 levels, 1 mip and no border).
    #[error("{path}: bad manifest: {message}")]
    Manifest {
        /// The manifest file.
        path: PathBuf,
        /// What is wrong, from the TOML parser or the land-cover checks.
        message: String,
    },
    /// The manifest's `format_version` is not `FORMAT_VERSION`: the dataset must be rebuilt.
    #[error("{path}: dataset format version {found}, this build reads version {FORMAT_VERSION}; rebuild it")]
    Version {
        /// The manifest file.
        path: PathBuf,
        /// The version the manifest declares.
        found: u32,
    },
    /// Serialising the manifest to TOML failed at `Staging::commit`; holds the serialiser's message.
    #[error("writing the manifest: {0}")]
    ManifestWrite(String),
    /// A build's output path has no final component usable as a folder name (none, or not UTF-8).
    #[error("{path}: not a usable output folder name")]
    BadOutput {
        /// The output path as given.
        path: PathBuf,
    },
    /// A pack's tile count or payload size disagrees with the pyramid, mips and texel size the
    /// manifest describes for its layer.
    #[error(
        "{path}: pack holds {found} tiles of {found_bytes} bytes, the manifest describes {expected} of {expected_bytes}"
    )]
    PackShape {
        /// The pack file.
        path: PathBuf,
        /// Tiles the pack's header holds.
        found: u64,
        /// Payload bytes per tile in the pack's header.
        found_bytes: u64,
        /// Tiles the manifest's pyramid numbers.
        expected: u64,
        /// Payload bytes per tile the manifest implies: texels of all mips × bytes per texel.
        expected_bytes: u64,
    },
    /// A pack failed its checks at open (magic, version, length or index checksum).
    #[error(transparent)]
    Pack(#[from] PackError),
}

/// An opened dataset.
pub struct Dataset {
    /// The dataset folder, as given to `open`.
    pub dir: PathBuf,
    /// The parsed `manifest.toml`: frame, CRS and the description of every layer.
    pub manifest: Manifest,
    /// The heights: f32 metres at grid vertices, one mip per tile.
    pub height: LayerPack,
    /// 1 where the DEM had a value, 0 where it was filled; absent when nothing was filled.
    pub valid_mask: Option<LayerPack>,
    /// The aerial imagery, RGBA8 sRGB texels with their mips, plain or in BC1/BC7 blocks
    /// (`LayerPack::block_format`); absent when the dataset has none.
    pub imagery: Option<LayerPack>,
    /// The land cover's LCC quadtree of palette-index words (read through `lcc_coding`); absent
    /// when the dataset has none.
    pub landcover: Option<LayerPack>,
}

impl Dataset {
    /// Opens the dataset in folder `dir`: checks the manifest (its version first), then opens every
    /// pack and checks its header, length and shape against it. Tile checksums wait for each read.
    pub fn open(dir: &Path) -> Result<Self, DatasetError> {
        let manifest_path = dir.join(MANIFEST_FILE);
        if !manifest_path.exists() {
            return Err(DatasetError::NotADataset { path: dir.to_owned() });
        }
        let text = std::fs::read_to_string(&manifest_path)
            .map_err(|source| DatasetError::Io { path: manifest_path.clone(), source })?;
        let bad = |message: String| DatasetError::Manifest { path: manifest_path.clone(), message };
        // The version alone first: other versions' manifests need not parse as this one's.
        #[derive(Deserialize)]
        struct Version {
            format_version: u32,
        }
        let version: Version = toml::from_str(&text).map_err(|e| bad(e.to_string()))?;
        if version.format_version != FORMAT_VERSION {
            return Err(DatasetError::Version { path: manifest_path, found: version.format_version });
        }
        let manifest: Manifest = toml::from_str(&text).map_err(|e| bad(e.to_string()))?;
        manifest.check_numbers().map_err(bad)?;
        let height =
            LayerPack::open_plain(dir, &manifest.height.pack, manifest.height.pyramid, 1, size_of::<f32>())?
                .with_check(ValueCheck::Heights);
        let valid_mask = manifest
            .height
            .valid_mask_pack
            .as_ref()
            .map(|pack| LayerPack::open_plain(dir, pack, manifest.height.pyramid, 1, 1))
            .transpose()?;
        let imagery = match &manifest.imagery {
            Some(l) => {
                let format = ImageryFormat::from_name(&l.format).ok_or_else(|| {
                    let known: Vec<&str> = ImageryFormat::ALL.iter().map(|f| f.name()).collect();
                    bad(format!("imagery: format {:?} is none of {}", l.format, known.join(", ")))
                })?;
                let bytes = format.tile_bytes(&l.pyramid, l.mips);
                let blocks = format.is_block_compressed().then_some(format);
                Some(LayerPack::open(dir, &l.pack, l.pyramid, l.mips, bytes, blocks)?)
            }
            None => None,
        };
        let landcover = match &manifest.landcover {
            Some(l) => {
                l.coding.validate().map_err(|e| bad(format!("land cover: {e}")))?;
                let p = &l.layer.pyramid;
                if p.levels != LCC_LEVELS || p.border != LANDCOVER_BORDER || l.layer.mips != 1 {
                    let message = format!(
                        "land cover: an LCC quadtree has {LCC_LEVELS} levels, 1 mip and no border, this one \
                         {} levels, {} mips, a border of {}",
                        p.levels, l.layer.mips, p.border
                    );
                    return Err(bad(message));
                }
                let layer = LayerPack::open_plain(dir, &l.layer.pack, *p, 1, l.coding.word_bytes())?;
                Some(layer.with_check(ValueCheck::Landcover(l.coding.clone())))
            }
            None => None,
        };
        Ok(Self { dir: dir.to_owned(), manifest, height, valid_mask, imagery, landcover })
    }

    /// The height tile's samples, `tile_extent`² f32 metres, south row first.
    pub fn height_tile(&self, id: TileId) -> Result<Vec<f32>, PackError> {
        Ok(bytemuck::pod_collect_to_vec(&self.height.tile_bytes(id)?))
    }

    /// Conservative [min, max] of every level-0 height under tile `id`, metres; O(1).
    pub fn height_range(&self, id: TileId) -> Result<[f32; 2], PackError> {
        let fallback = [self.manifest.height.min_m, self.manifest.height.max_m];
        Ok(self.height.tile_range(id)?.unwrap_or(fallback))
    }

    /// Height of the drawn ground at grid-space position (`x_m`, `y_m`) from `level`: the
    /// triangle of the cell under it as the terrain mesh splits it (`surface::drawn_height`),
    /// clamped to the dataset. Reads at most four tiles; for camera placement and tests, not the
    /// per-frame path.
    pub fn height_at(&self, x_m: f64, y_m: f64, level: u32) -> Result<f64, PackError> {
        Ok(self.ground_at(x_m, y_m, level)?.0)
    }

    /// `height_at`'s height and the slopes of the triangle holding the point, metres of height per
    /// cell of `level` along x and y (`surface::drawn_height`).
    pub fn ground_at(&self, x_m: f64, y_m: f64, level: u32) -> Result<(f64, [f64; 2]), PackError> {
        let pyramid = &self.height.pyramid;
        let level = level.min(pyramid.levels - 1);
        let spacing = self.manifest.height.spacing_m * f64::from(1u32 << level);
        let size = pyramid.size_at(level);
        // The cell (its south-west sample) and the position in it; the last samples close the last cells.
        let axis = |v_m: f64, n: u32| {
            let g = (v_m / spacing).clamp(0.0, f64::from(n - 1));
            let i = (g.floor() as u32).min(n.saturating_sub(2));
            (i, g - f64::from(i))
        };
        let ((ix, fx), (iy, fy)) = (axis(x_m, size[0]), axis(y_m, size[1]));
        let sample = |x: u32, y: u32| self.height_sample(level, x.min(size[0] - 1), y.min(size[1] - 1));
        let corners = [sample(ix, iy)?, sample(ix + 1, iy)?, sample(ix, iy + 1)?, sample(ix + 1, iy + 1)?];
        Ok(surface::drawn_height([ix, iy], corners, [fx, fy]))
    }

    /// The land cover's LCC coding, if the dataset has land cover.
    pub fn lcc_coding(&self) -> Option<&LccCoding> {
        self.manifest.landcover.as_ref().map(|l| &l.coding)
    }

    /// Land-cover tile `id`'s words widened to u32, south row first (palette indices at levels 0
    /// and 1, packed sub-codes at level 2: see `LccCoding::decode`). A dataset without land cover
    /// answers `PackError::NoLayer`.
    pub fn landcover_words(&self, id: TileId) -> Result<Vec<u32>, PackError> {
        let (layer, coding) = self.landcover_layer()?;
        let bytes = layer.tile_bytes(id)?;
        Ok(bytes.chunks_exact(coding.word_bytes()).map(word_of).collect())
    }

    /// Palette index of level-1 (source) texel `q`, clamped to the layer, as read from `level`
    /// (0, 1 or 2: all agree). Reads one tile: for tests and the exact oracle, not per frame. A
    /// dataset without land cover is bare everywhere (index 0).
    pub fn landcover_index(&self, level: u32, q: [u32; 2]) -> Result<u32, PackError> {
        if self.landcover.is_none() {
            return Ok(crate::dataset::lcc::LCC_BARE_INDEX);
        }
        let (layer, coding) = self.landcover_layer()?;
        let pyramid = &layer.pyramid;
        let size = pyramid.size_at(LCC_SOURCE_LEVEL);
        let q = [0, 1].map(|a| q[a].min(size[a] - 1));
        let texel = LccCoding::texel_of(level, q);
        let (tile, local) = (texel.map(|v| v / pyramid.tile), texel.map(|v| v % pyramid.tile));
        let bytes = layer.tile_bytes(TileId::new(level, tile[0], tile[1]))?;
        let at = (local[1] * pyramid.tile_extent() + local[0]) as usize * coding.word_bytes();
        Ok(coding.decode(level, word_of(&bytes[at..at + coding.word_bytes()]), q))
    }

    fn landcover_layer(&self) -> Result<(&LayerPack, &LccCoding), PackError> {
        match (&self.landcover, self.lcc_coding()) {
            (Some(layer), Some(coding)) => Ok((layer, coding)),
            _ => Err(PackError::NoLayer { path: self.dir.clone(), layer: "land-cover" }),
        }
    }

    /// The stored sample (`x`, `y`) of `level`, in metres.
    pub fn height_sample(&self, level: u32, x: u32, y: u32) -> Result<f64, PackError> {
        let pyramid = &self.height.pyramid;
        let tiles = pyramid.tiles_at(level);
        let (tx, ty) = ((x / pyramid.tile).min(tiles[0] - 1), (y / pyramid.tile).min(tiles[1] - 1));
        let tile = self.height.tile_bytes(TileId::new(level, tx, ty))?;
        let extent = pyramid.tile_extent();
        let (lx, ly) = (x - tx * pyramid.tile + pyramid.border, y - ty * pyramid.tile + pyramid.border);
        let at = (ly * extent + lx) as usize * size_of::<f32>();
        Ok(f64::from(bytemuck::pod_read_unaligned::<f32>(&tile[at..at + size_of::<f32>()])))
    }
}

/// Where level-0 imagery texel `t` lies: the tile holding it and the texel's index within that
/// tile's stored texels (its border included), as `LayerPack::tile_texels` returns them.
pub fn imagery_texel_at(t: [u32; 2]) -> (TileId, usize) {
    use crate::gpu::layout::{IMAGERY_TILE_EXTENT, IMAGERY_TILE_TEXELS};
    let tile = t.map(|v| v / IMAGERY_TILE_TEXELS);
    let local = [0, 1].map(|a| t[a] - tile[a] * IMAGERY_TILE_TEXELS + IMAGERY_BORDER);
    (TileId::new(0, tile[0], tile[1]), (local[1] * IMAGERY_TILE_EXTENT + local[0]) as usize)
}

#[cfg(test)]
mod tests;

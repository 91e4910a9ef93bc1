//! How it works: texcells (Decaudin & Neyret 2004), the forest far away as a volumetric texture
//! mapped over the ground. A dense land-cover class gets a *forest sample*, baked once
//! (`bake::forest`): that class's trees placed over a square of `REFERENCE_CELLS`² ground cells
//! (`tiling`: eight edge-compatible triangular tiles, the square wrapping like a torus) and
//! rendered from above into 2^N horizontal slices of the slab `height_m` thick, premultiplied
//! RGBA; from them (`pyramid`) the slice pyramid `S_i` (fewer, smaller slices aggregated by
//! opacity), a mip chain per slice, and the 3D texture with its own mip chain for silhouettes.
//!
//! On disk (`store`) a sample is a folder `<impostors>/texcells/<class code>/` beside the
//! impostors: `texcell.toml` (format version, what was baked, the trees placed, where each image
//! lies) and `texels.bin` (every image, RGBA8 with the premultiplied colour sRGB-encoded, one
//! CRC-32 over the whole), written atomically; `preview.png` shows the sample from above.

pub mod pyramid;
mod store;
pub mod tiling;

use std::path::PathBuf;

use serde::{Deserialize, Serialize};
use thiserror::Error;

pub use store::{load, sample_dir, save};

/// The version of the folder's layout; a folder of another version is refused, named.
pub const FORMAT_VERSION: u32 = 1;
/// The manifest's name in a sample's folder.
pub const MANIFEST_FILE: &str = "texcell.toml";
/// The images' file.
pub const TEXELS_FILE: &str = "texels.bin";
/// The picture of the sample from above (every slice composited), for people.
pub const PREVIEW_FILE: &str = "preview.png";
/// The folder of samples under an impostor folder.
pub const TEXCELLS_DIR: &str = "texcells";

/// Why a forest sample could not be read or written; each names the file.
#[derive(Debug, Error)]
pub enum TexcellError {
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// What the file system said.
        source: std::io::Error,
    },
    /// The manifest is not valid TOML of the expected shape.
    #[error("{path}: {message}")]
    Manifest {
        /// The manifest.
        path: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// The folder was written in another format version.
    #[error("{path}: format version {found}; this build reads version {FORMAT_VERSION} (bake it again)")]
    Version {
        /// The manifest.
        path: PathBuf,
        /// The version it states.
        found: u32,
    },
    /// The manifest and the images disagree, or the images fail their checksum.
    #[error("{path}: {problem}")]
    Corrupt {
        /// The file found wrong.
        path: PathBuf,
        /// What is wrong with it.
        problem: String,
    },
}

/// A tree of the sample, as placed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SampleTree {
    /// Its model (a glTF stem, as the class table names it).
    pub model: String,
    /// Where it stands in the sample, metres from its south-west corner (x east, y north).
    pub position_m: [f32; 2],
    /// Its height, metres.
    pub height_m: f32,
    /// Its turn about the vertical, degrees.
    pub angle_deg: f32,
}

/// One image and its mip chain: level m is `side >> m` texels square (none below 1), RGBA8.
#[derive(Debug, Clone, PartialEq)]
pub struct Chain {
    /// Level 0's side, texels.
    pub side: u32,
    /// Every level, finest first, `4 · side_m²` bytes each.
    pub levels: Vec<Vec<u8>>,
}

/// One level of the 3D texture's chain.
#[derive(Debug, Clone, PartialEq)]
pub struct VolumeLevel {
    /// Texels along x and y.
    pub side: u32,
    /// Slices along z.
    pub depth: u32,
    /// `4 · side² · depth` bytes, slice by slice, bottom first.
    pub bytes: Vec<u8>,
}

/// A land-cover class's baked forest sample.
#[derive(Debug, Clone, PartialEq)]
pub struct ForestSample {
    /// The class it is the forest of (its land-cover code).
    pub class_code: u8,
    /// The class's name, for people.
    pub class_name: String,
    /// The ground cell's side, metres: the sample spans `tiling::REFERENCE_CELLS` of them.
    pub cell_m: f32,
    /// The slab's thickness, metres: the tallest tree of the class, and a margin.
    pub height_m: f32,
    /// The trees placed.
    pub trees: Vec<SampleTree>,
    /// The slice pyramid, `S_N` first: entry k holds 2^(N − k) slices (bottom first), each with
    /// its mip chain, of side L / 2^k.
    pub slices: Vec<Vec<Chain>>,
    /// The 3D texture (`S_N` stacked) and its mip chain, finest first.
    pub volume: Vec<VolumeLevel>,
}

/// The images a sample stores, made from its finest slices (bottom first): the slice pyramid, each
/// slice with its mip chain, and the 3D texture's chain, encoded as stored (`pyramid::encode`).
pub fn sample_images(finest: Vec<pyramid::Layer>) -> (Vec<Vec<Chain>>, Vec<VolumeLevel>) {
    let volume = pyramid::volume_chain(&finest)
        .into_iter()
        .map(|v| VolumeLevel { side: v.side, depth: v.depth, bytes: pyramid::encode(&v.texels) })
        .collect();
    let chain = |layer: pyramid::Layer| {
        let side = layer.side;
        Chain { side, levels: pyramid::mip_chain(layer).iter().map(|l| pyramid::encode(&l.texels)).collect() }
    };
    let slices = pyramid::slice_pyramid(finest)
        .into_iter()
        .map(|level| level.into_iter().map(chain).collect())
        .collect();
    (slices, volume)
}

impl ForestSample {
    /// Slices of the finest level (2^N).
    pub fn slice_count(&self) -> u32 {
        self.slices.first().map_or(0, |l| l.len() as u32)
    }

    /// Side of the finest slices, texels (L).
    pub fn texels(&self) -> u32 {
        self.slices.first().and_then(|l| l.first()).map_or(0, |c| c.side)
    }

    /// The mean linear albedo of what the sample shows from above (its top view, each texel
    /// weighted by its opacity): the colour follow-up's yardstick (`texcells.ground_blend`).
    /// Black where the sample is empty.
    pub fn albedo_from_above(&self) -> [f32; 3] {
        let texels = pyramid::decode(&self.top_view());
        let opacity: f32 = texels.iter().map(|t| t[3]).sum();
        if opacity <= 0.0 {
            return [0.0; 3];
        }
        std::array::from_fn(|c| texels.iter().map(|t| t[c]).sum::<f32>() / opacity)
    }

    /// The sample seen from above: every finest slice composited over the next lower one,
    /// premultiplied, as RGBA8 (colour sRGB-encoded).
    pub fn top_view(&self) -> Vec<u8> {
        let Some(coarsest) = self.volume.first() else { return Vec::new() };
        let side = coarsest.side as usize;
        let texels = pyramid::decode(&coarsest.bytes);
        let mut out = vec![[0.0f32; 4]; side * side];
        for slice in texels.chunks_exact(side * side) {
            for (o, &t) in out.iter_mut().zip(slice) {
                *o = pyramid::over(t, *o);
            }
        }
        pyramid::encode(&out)
    }
}

#[cfg(test)]
mod tests {
    use super::pyramid::Layer;
    use super::*;

    #[test]
    fn the_albedo_from_above_is_the_top_view_s_colour_per_opacity() {
        // An opaque green floor under a layer whose left half is half-covered red (premultiplied)
        // and right half empty: from above, the left half is red over green, the right green.
        let side = 8u32;
        let green = [0.1, 0.4, 0.1, 1.0];
        let floor = Layer { side, texels: vec![green; 64] };
        let top = Layer {
            side,
            texels: (0..64)
                .map(|i| if i % side < side / 2 { [0.5, 0.0, 0.0, 0.5] } else { [0.0; 4] })
                .collect(),
        };
        let (slices, volume) = sample_images(vec![floor, top]);
        let sample = ForestSample {
            class_code: 5,
            class_name: "forest".into(),
            cell_m: 32.0,
            height_m: 13.0,
            trees: Vec::new(),
            slices,
            volume,
        };
        let left = [0.5 + 0.5 * green[0], 0.5 * green[1], 0.5 * green[2]];
        let want: [f32; 3] = std::array::from_fn(|c| 0.5 * (left[c] + green[c]));
        let got = sample.albedo_from_above();
        // Stored as 8-bit sRGB colour and 8-bit alpha: within 1 % of each channel.
        for c in 0..3 {
            assert!((got[c] - want[c]).abs() <= 0.01 * want[c], "{got:?} against {want:?}");
        }
        let empty = ForestSample { slices: Vec::new(), volume: Vec::new(), ..sample };
        assert_eq!(empty.albedo_from_above(), [0.0; 3]);
    }
}

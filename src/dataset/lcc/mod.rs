//! How it works: the LCC quadtree (paper § 4.1) stores land-cover classes losslessly in 3 levels
//! of one word type, so a class read at any level agrees with the others and seeds never pop.
//!
//! Texels hold *palette indices*, not raw codes: index 0 is reserved ("bare / no class"), indices
//! 1..=n name the distinct source codes in ascending order (nodata and codes missing from the class
//! table included, so decoding gives back every source code). Level 1 holds one index per source
//! texel; level 0, twice as fine, repeats it on its 2 × 2 children; level 2, twice as coarse, packs
//! the 4 level-1 indices (2x + dx, 2y + dy) it covers into one word, sub-code k = dx + 2·dy at bits
//! [k·b, (k + 1)·b) with b = word_bits / 4. The word is the narrowest that holds the palette: 8 bits
//! (b = 2: 3 codes, the paper's coding), 16 (15 codes) or 32 (255). All levels share it, so a
//! dataset needs one texture format. `decode` is the whole reading rule, and the shader repeats it.
//!
//! Writing (`write_lcc_layer`, `writer`) takes a source of codes on the level-1 grid,
//! edge-replicated beyond it: level 1 is cut from the source tile by tile, levels 0 and 2 are
//! derived from level 1 as written in the pack. The palette must be known first: `scan_codes`
//! counts every code.

mod writer;

use indicatif::ProgressBar;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use thiserror::Error;

pub(crate) use writer::LccTiles;
pub use writer::write_lcc_layer;

use super::{CELL_TILE_TEXELS, LANDCOVER_BORDER, LayerError, Pyramid, Sampling, Window};

/// The levels of the LCC quadtree (whatever the layer's size) and the level that holds the
/// source's texels, as the shaders read them.
pub use crate::gpu::layout::{LCC_LEVELS, LCC_PACKED_LEVEL, LCC_SOURCE_LEVEL};
/// Word widths, narrowest first.
pub const LCC_WORD_BITS: [u32; 3] = [8, 16, 32];
/// Palette index that no source texel gets: "bare ground / no class".
pub const LCC_BARE_INDEX: u32 = 0;
/// Side of the source windows `scan_codes` reads.
const SCAN_WINDOW_TEXELS: u32 = 1024;
const LAYER_NAME: &str = "land cover";

/// Why an LCC coding could not be made or is invalid, or a code could not be written with it.
#[derive(Debug, Error)]
pub enum LccError {
    /// `LccCoding::for_codes` finds more distinct codes than the 32-bit word's palette holds (255).
    #[error("{count} distinct land-cover codes: the widest LCC word (32 bits) holds at most 255")]
    TooManyCodes {
        /// Distinct codes found.
        count: usize,
    },
    /// A coding (from a manifest) has a word width other than 8, 16 or 32 bits.
    #[error("LCC words of {word_bits} bits: use 8, 16 or 32")]
    WordBits {
        /// The width it gives, bits.
        word_bits: u32,
    },
    /// A coding's palette has more codes than its word's level-2 sub-codes can address.
    #[error("LCC palette of {count} codes does not fit {word_bits}-bit words (at most {max})")]
    PaletteTooLong {
        /// Codes in the palette.
        count: usize,
        /// The coding's word width, bits.
        word_bits: u32,
        /// Codes that width addresses: 2^(word_bits / 4) − 1, index 0 being reserved.
        max: usize,
    },
    /// A coding's palette is not strictly ascending (a repeated code, or one out of order).
    #[error("LCC palette is not sorted and unique: code {code} at entry {entry}")]
    PaletteOrder {
        /// Position in `palette` of the first code not above the one before it.
        entry: usize,
        /// That code.
        code: u8,
    },
    /// While writing, the source gives a code the palette lacks: it changed since `scan_codes`.
    #[error("land-cover code {code} is not in the LCC palette (did the source change after the scan?)")]
    NotInPalette {
        /// The source code missing from the palette.
        code: u8,
    },
}

/// One dataset's LCC coding: its word width and palette.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LccCoding {
    /// 8, 16 or 32.
    pub word_bits: u32,
    /// `palette[i - 1]` is the source code of palette index `i`; sorted, unique.
    pub palette: Vec<u8>,
}

impl LccCoding {
    /// The coding of a source holding `codes` (in any order, repeats allowed): the sorted distinct
    /// codes as palette, in the narrowest word that holds them.
    pub fn for_codes(codes: impl IntoIterator<Item = u8>) -> Result<Self, LccError> {
        let mut seen = [false; 256];
        for code in codes {
            seen[usize::from(code)] = true;
        }
        let palette: Vec<u8> = (0..=u8::MAX).filter(|&c| seen[usize::from(c)]).collect();
        let word_bits = LCC_WORD_BITS
            .into_iter()
            .find(|&bits| palette.len() <= max_codes(bits))
            .ok_or(LccError::TooManyCodes { count: palette.len() })?;
        Ok(Self { word_bits, palette })
    }

    /// Checks a coding read from a manifest.
    pub fn validate(&self) -> Result<(), LccError> {
        let word_bits = self.word_bits;
        if !LCC_WORD_BITS.contains(&word_bits) {
            return Err(LccError::WordBits { word_bits });
        }
        let (count, max) = (self.palette.len(), max_codes(word_bits));
        if count > max {
            return Err(LccError::PaletteTooLong { count, word_bits, max });
        }
        match self.palette.windows(2).position(|pair| pair[0] >= pair[1]) {
            Some(entry) => Err(LccError::PaletteOrder { entry: entry + 1, code: self.palette[entry + 1] }),
            None => Ok(()),
        }
    }

    /// What the texels hold, for the manifest's `format`, e.g. "lcc r16 palette indices".
    pub fn format_name(&self) -> String {
        format!("lcc r{} palette indices", self.word_bits)
    }

    /// Bits of one level-2 sub-code.
    pub fn sub_bits(&self) -> u32 {
        self.word_bits / 4
    }

    /// Bytes of one stored word (1, 2 or 4), the same at every level.
    pub fn word_bytes(&self) -> usize {
        (self.word_bits / 8) as usize
    }

    /// The GPU texture format of every level's tiles.
    pub fn texture_format(&self) -> wgpu::TextureFormat {
        match self.word_bits {
            8 => wgpu::TextureFormat::R8Uint,
            16 => wgpu::TextureFormat::R16Uint,
            _ => wgpu::TextureFormat::R32Uint,
        }
    }

    /// The palette index of `code`, or `LCC_BARE_INDEX` (0) when the palette lacks it.
    pub fn index_of(&self, code: u8) -> u32 {
        self.palette.binary_search(&code).map_or(LCC_BARE_INDEX, |entry| entry as u32 + 1)
    }

    /// The source code of palette index `index`; `None` for 0 (bare) and indices past the palette.
    pub fn code_of(&self, index: u32) -> Option<u8> {
        let entry = usize::try_from(index).ok()?.checked_sub(1)?;
        self.palette.get(entry).copied()
    }

    /// The level-2 word of 4 level-1 indices, `children[dx + 2·dy]`.
    pub fn pack(&self, children: [u32; 4]) -> u32 {
        let b = self.sub_bits();
        debug_assert!(children.iter().all(|&c| c >> b == 0), "{children:?} do not fit {b} bits");
        (0..4).fold(0, |word, k| word | children[k as usize] << (b * k))
    }

    /// Texel of `level` that holds level-1 (source) texel `q`: level 0 → 2q, 1 → q, 2 → q >> 1.
    pub fn texel_of(level: u32, q: [u32; 2]) -> [u32; 2] {
        match level {
            0 => q.map(|v| 2 * v),
            _ => q.map(|v| v >> (level - 1)),
        }
    }

    /// Palette index of level-1 texel `q`, from the `word` read at `texel_of(level, q)`.
    pub fn decode(&self, level: u32, word: u32, q: [u32; 2]) -> u32 {
        if level < 2 {
            return word;
        }
        let b = self.sub_bits();
        let k = (q[0] & 1) + 2 * (q[1] & 1);
        (word >> (b * k)) & ((1 << b) - 1)
    }
}

/// Codes a word of `word_bits` can address in each level-2 sub-code (index 0 is reserved).
fn max_codes(word_bits: u32) -> usize {
    (1usize << (word_bits / 4)) - 1
}

/// The land-cover pyramid over a source of `source_size` texels: 3 levels, level 1 the source's.
pub fn lcc_pyramid(source_size: [u32; 2]) -> Pyramid {
    Pyramid {
        size: source_size.map(|n| 2 * n.max(1)),
        tile: CELL_TILE_TEXELS,
        border: LANDCOVER_BORDER,
        sampling: Sampling::Cell,
        levels: LCC_LEVELS,
    }
}

/// How many source texels carry each code.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CodeCounts {
    /// Source texels carrying each code, indexed by the code.
    pub texels: [u64; 256],
}

impl CodeCounts {
    /// The codes that occur, ascending.
    pub fn present(&self) -> impl Iterator<Item = u8> + '_ {
        (0..=u8::MAX).filter(|&c| self.texels[usize::from(c)] > 0)
    }
}

/// Counts every code of a source of `source_size` texels, window by window, in parallel.
pub fn scan_codes<S>(
    source_size: [u32; 2],
    source: &S,
    progress: &ProgressBar,
) -> Result<CodeCounts, LayerError>
where
    S: Fn(Window) -> Result<Vec<u8>, String> + Sync,
{
    let blocks = source_size.map(|n| n.div_ceil(SCAN_WINDOW_TEXELS));
    let windows: Vec<Window> = (0..blocks[1])
        .flat_map(|by| (0..blocks[0]).map(move |bx| [bx, by].map(|b| b * SCAN_WINDOW_TEXELS)))
        .map(|[x0, y0]| Window {
            x0,
            y0,
            width: SCAN_WINDOW_TEXELS.min(source_size[0] - x0),
            height: SCAN_WINDOW_TEXELS.min(source_size[1] - y0),
        })
        .collect();
    progress.set_length(windows.len() as u64);
    let counts = windows
        .par_iter()
        .map(|&window| -> Result<[u64; 256], LayerError> {
            let codes = source(window).map_err(|message| LayerError::Source {
                layer: LAYER_NAME,
                window,
                message,
            })?;
            let expected = window.width as usize * window.height as usize;
            if codes.len() != expected {
                let actual = codes.len();
                return Err(LayerError::SourceSize { layer: LAYER_NAME, window, expected, actual });
            }
            let mut counts = [0u64; 256];
            for code in codes {
                counts[usize::from(code)] += 1;
            }
            progress.inc(1);
            Ok(counts)
        })
        .try_reduce(|| [0; 256], |a, b| Ok(std::array::from_fn(|c| a[c] + b[c])))?;
    Ok(CodeCounts { texels: counts })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_narrowest_word_that_holds_the_palette_is_chosen() {
        let bits = |n: u8| LccCoding::for_codes((0..n).map(|c| c.wrapping_mul(17))).unwrap().word_bits;
        assert_eq!([bits(1), bits(3), bits(4), bits(15), bits(16), bits(255)], [8, 8, 16, 16, 32, 32]);
        let coding = LccCoding::for_codes([42, 7, 255, 7, 1, 42]).unwrap();
        assert_eq!(coding, LccCoding { word_bits: 16, palette: vec![1, 7, 42, 255] });
        assert_eq!((coding.sub_bits(), coding.word_bytes()), (4, 2));
        assert_eq!(coding.texture_format(), wgpu::TextureFormat::R16Uint);
        assert_eq!(coding.format_name(), "lcc r16 palette indices");
        assert_eq!(LccCoding::for_codes([]).unwrap().word_bits, 8);
    }

    #[test]
    fn more_than_255_codes_or_a_bad_manifest_coding_are_errors() {
        assert!(matches!(LccCoding::for_codes(0..=u8::MAX), Err(LccError::TooManyCodes { count: 256 })));
        let coding = |word_bits, palette: &[u8]| LccCoding { word_bits, palette: palette.to_vec() };
        assert!(matches!(coding(12, &[1]).validate(), Err(LccError::WordBits { word_bits: 12 })));
        assert!(matches!(coding(8, &[1, 2, 3, 4]).validate(), Err(LccError::PaletteTooLong { max: 3, .. })));
        assert!(matches!(coding(8, &[3, 1]).validate(), Err(LccError::PaletteOrder { entry: 1, code: 1 })));
        assert!(matches!(coding(8, &[1, 1]).validate(), Err(LccError::PaletteOrder { .. })));
        let all: Vec<u8> = (0..255).collect();
        assert!(coding(32, &all).validate().is_ok() && coding(16, &all).validate().is_err());
    }

    #[test]
    fn palette_indices_start_at_one_and_name_every_code() {
        let coding = LccCoding::for_codes([11, 90, 255]).unwrap();
        assert_eq!([11, 90, 255, 12].map(|c| coding.index_of(c)), [1, 2, 3, LCC_BARE_INDEX]);
        assert_eq!([0, 1, 2, 3, 4].map(|i| coding.code_of(i)), [None, Some(11), Some(90), Some(255), None]);
    }

    #[test]
    fn packed_words_decode_to_every_child_at_every_width() {
        for word_bits in LCC_WORD_BITS {
            let coding = LccCoding { word_bits, palette: Vec::new() };
            let top = (1u32 << coding.sub_bits()) - 1;
            for pattern in 0..=top {
                let children = [pattern, top - pattern, (pattern * 7) & top, top];
                let word = coding.pack(children);
                assert!(word_bits == 32 || word >> word_bits == 0, "{word_bits}: {word:#x} overflows");
                for k in 0..4u32 {
                    // Level-1 texel q, anywhere, whose position in its level-2 texel is k.
                    let q = [2 * 37 + (k & 1), 2 * 11 + (k >> 1)];
                    assert_eq!(LccCoding::texel_of(2, q), [37, 11]);
                    assert_eq!(coding.decode(2, word, q), children[k as usize], "{word_bits} bits, k {k}");
                }
            }
            assert_eq!(coding.decode(0, top, [5, 9]), top);
            assert_eq!(coding.decode(1, top, [5, 9]), top);
        }
        assert_eq!([0, 1, 2].map(|level| LccCoding::texel_of(level, [5, 8])), [[10, 16], [5, 8], [2, 4]]);
        let paper = LccCoding { word_bits: 8, palette: vec![1, 2, 3] };
        assert_eq!(paper.pack([1, 2, 3, 0]), 0b00_11_10_01);
    }

    #[test]
    fn three_levels_whatever_the_size() {
        let small = lcc_pyramid([3, 1]);
        assert_eq!(
            (small.levels, small.size_at(0), small.size_at(1), small.size_at(2)),
            (3, [6, 2], [3, 1], [2, 1])
        );
        let large = lcc_pyramid([5000, 3000]);
        assert_eq!((large.levels, large.tiles_at(0), large.tiles_at(2)), (3, [20, 12], [5, 3]));
    }
}

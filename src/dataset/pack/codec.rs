//! How it works: how a pack stores its tiles, one codec per pack (a layer's tiles are alike).
//! `Raw` stores the payload as it is (read straight from the mapping, no copy). `Zstd` stores it
//! compressed by zstd, losslessly, after a predictor that turns smooth data into small numbers:
//! - `Delta32`, for `f32` heights: each 32-bit word minus its prediction from the words to its
//!   west, south and south-west (`w + s − sw`, the plane through them, on the bit patterns, wrapping,
//!   so it is exact for any value, NaN included; a square tile's rows are found from its size, any
//!   other is one row), then the four byte planes one after another, so that the nearly constant
//!   high bytes compress to almost nothing;
//! - `Grid32`, for `f32` heights that lie on a grid of a power of two (a DEM rounded to a stated
//!   step when it was built, `terramp-data build --height-step-m`): the tile's coarsest such grid
//!   is found, each sample becomes its integer count of steps, and the counts go through the same
//!   plane prediction, as zigzagged residues (small either side of zero), in byte planes. The
//!   words of the bit patterns would carry the fractions' noise into every residue; the counts
//!   carry none. A tile off any such grid (NaN, infinities, `-0.0`, counts beyond `i32`) is
//!   stored as `Delta32` would store it; a leading byte says which;
//! - `Planes(n)`, for `n`-byte texels (RGBA imagery, masks): the byte planes, each as
//!   differences from the byte before in its plane (PNG's "sub" filter, per channel);
//! - `None`, for data a predictor does not help (land cover's bit-packed LCC words).
//!
//! The codec is recorded in the pack's header; a reader decodes whatever the header says.

use super::PackError;
use std::path::Path;

/// zstd's level for tiles: fast to write (a build compresses every tile once) and to read.
const ZSTD_LEVEL: i32 = 3;
/// The most bytes a stored tile may decode to. zstd's bulk decompressor allocates the size it is
/// given before it reads a byte, and a pack's header gives any size; no tile terramp makes comes
/// near (the largest a manifest may describe, `MAX_TILE_EXTENT`² RGBA8 texels and their mips, is
/// 358 MB).
const MAX_TILE_BYTES: usize = 1 << 30;

/// What is done to a tile's bytes before zstd compresses them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Predictor {
    /// Nothing.
    None,
    /// 32-bit word differences, then byte planes (`f32` heights).
    Delta32,
    /// Byte planes of `n`-byte texels, each as differences along its plane.
    Planes(u8),
    /// Integer steps of a power-of-two grid when every sample lies on one, else `Delta32`
    /// (`f32` heights rounded to a step).
    Grid32,
}

/// `Grid32`'s leading byte: the tile is stored as `Delta32` stores it.
const GRID_OFF: u8 = 0;
/// `Grid32`'s leading byte: the tile is stored as steps of a grid, whose exponent follows (i16).
const GRID_ON: u8 = 1;

/// How a pack stores its tiles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Codec {
    /// As they are.
    Raw,
    /// zstd after a predictor.
    Zstd(Predictor),
}

impl Codec {
    /// The codec as the header's word: kind, predictor and texel bytes, one byte each.
    pub(super) fn word(self) -> u32 {
        match self {
            Self::Raw => 0,
            Self::Zstd(Predictor::None) => 1,
            Self::Zstd(Predictor::Delta32) => 1 | 1 << 8,
            Self::Zstd(Predictor::Planes(n)) => 1 | 2 << 8 | u32::from(n) << 16,
            Self::Zstd(Predictor::Grid32) => 1 | 3 << 8,
        }
    }

    /// The codec of a header's word; `None` for a word this build does not know.
    pub(super) fn from_word(word: u32) -> Option<Self> {
        let [kind, predictor, bytes, _] = word.to_le_bytes();
        match (kind, predictor, bytes) {
            (0, 0, 0) => Some(Self::Raw),
            (1, 0, 0) => Some(Self::Zstd(Predictor::None)),
            (1, 1, 0) => Some(Self::Zstd(Predictor::Delta32)),
            (1, 2, n) if n > 0 => Some(Self::Zstd(Predictor::Planes(n))),
            (1, 3, 0) => Some(Self::Zstd(Predictor::Grid32)),
            _ => None,
        }
    }

    /// The bytes stored for `payload`.
    pub(super) fn encode(self, payload: &[u8], path: &Path) -> Result<Vec<u8>, PackError> {
        let Self::Zstd(predictor) = self else { return Ok(payload.to_vec()) };
        let predicted = match predictor {
            Predictor::None => None,
            Predictor::Delta32 => Some(planes(&delta32(payload), 4)),
            Predictor::Planes(n) => {
                let mut p = planes(payload, usize::from(n));
                sub_filter(&mut p, payload.len() / usize::from(n).max(1));
                Some(p)
            }
            Predictor::Grid32 => Some(grid32(payload)),
        };
        zstd::bulk::compress(predicted.as_deref().unwrap_or(payload), ZSTD_LEVEL)
            .map_err(|source| PackError::Io { path: path.to_owned(), source })
    }

    /// The payload of `stored` bytes, `tile_bytes` long; `None` when they do not decode to that.
    pub(super) fn decode(self, stored: &[u8], tile_bytes: usize) -> Option<Vec<u8>> {
        let Self::Zstd(predictor) = self else {
            return (stored.len() == tile_bytes).then(|| stored.to_vec());
        };
        if tile_bytes > MAX_TILE_BYTES {
            return None;
        }
        // Grid32 leads with its mode and the grid's exponent.
        let header = if predictor == Predictor::Grid32 { GRID_HEADER } else { 0 };
        let bytes = zstd::bulk::decompress(stored, tile_bytes + header).ok()?;
        match predictor {
            Predictor::Grid32 => ungrid32(&bytes, tile_bytes),
            _ if bytes.len() != tile_bytes => None,
            Predictor::None => Some(bytes),
            Predictor::Delta32 => Some(undelta32(&unplanes(&bytes, 4))),
            Predictor::Planes(n) => {
                let (n, mut bytes) = (usize::from(n), bytes);
                add_filter(&mut bytes, tile_bytes / n.max(1));
                Some(unplanes(&bytes, n))
            }
        }
    }
}

/// Bytes before `Grid32`'s planes: the mode, then the exponent of the grid's step (i16).
const GRID_HEADER: usize = 3;

/// A payload of `f32` words as `Grid32` stores it (before zstd).
fn grid32(payload: &[u8]) -> Vec<u8> {
    let Some((exponent, steps)) = grid_steps(payload) else {
        let mut out = vec![GRID_OFF, 0, 0];
        out.extend(planes(&delta32(payload), 4));
        return out;
    };
    let residues: Vec<u32> = residues(&steps)
        .into_iter()
        .map(|r| {
            let r = r as i32;
            ((r << 1) ^ (r >> 31)) as u32
        })
        .collect();
    let mut out = vec![GRID_ON];
    out.extend(exponent.to_le_bytes());
    out.extend(planes(bytemuck::cast_slice(&residues), 4));
    out
}

/// The payload `grid32` made, `tile_bytes` long; `None` when the bytes are not one.
fn ungrid32(bytes: &[u8], tile_bytes: usize) -> Option<Vec<u8>> {
    let [mode, e0, e1] = *bytes.first_chunk::<GRID_HEADER>()?;
    let body = &bytes[GRID_HEADER..];
    if body.len() != tile_bytes {
        return None;
    }
    match mode {
        GRID_OFF => Some(undelta32(&unplanes(body, 4))),
        GRID_ON if tile_bytes.is_multiple_of(4) => {
            let step = 2f64.powi(i32::from(i16::from_le_bytes([e0, e1])));
            let mut steps: Vec<u32> = unplanes(body, 4)
                .chunks_exact(4)
                .map(|w| {
                    let z = u32::from_le_bytes([w[0], w[1], w[2], w[3]]);
                    ((z >> 1) as i32 ^ -((z & 1) as i32)) as u32
                })
                .collect();
            add_predictions(&mut steps);
            Some(steps.iter().flat_map(|&k| ((f64::from(k as i32) * step) as f32).to_le_bytes()).collect())
        }
        _ => None,
    }
}

/// The exponent of the coarsest power-of-two grid every `f32` word of `payload` lies on, and each
/// word's count of its steps; `None` when a word lies on none that `i32` counts reach (NaN,
/// infinities, `-0.0`, or a payload that is not whole words).
fn grid_steps(payload: &[u8]) -> Option<(i16, Vec<u32>)> {
    if payload.is_empty() || !payload.len().is_multiple_of(4) {
        return None;
    }
    let values: Vec<f32> =
        payload.chunks_exact(4).map(|w| f32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect();
    let mut exponent = i32::MAX;
    for &v in &values {
        let bits = v.to_bits();
        if !v.is_finite() || bits == 0x8000_0000 {
            return None;
        }
        if bits != 0 {
            // v = mantissa · 2^(field − 150) (subnormals: field 1, no hidden bit).
            let field = ((bits >> 23) & 0xff) as i32;
            let mantissa = (bits & 0x7f_ffff) | if field > 0 { 0x80_0000 } else { 0 };
            exponent = exponent.min(field.max(1) - 150 + mantissa.trailing_zeros() as i32);
        }
    }
    let exponent = if exponent == i32::MAX { 0 } else { exponent };
    let per_step = 2f64.powi(-exponent);
    let steps = values
        .iter()
        .map(|&v| {
            let k = f64::from(v) * per_step;
            (k.abs() <= f64::from(i32::MAX)).then_some(k as i32 as u32)
        })
        .collect::<Option<Vec<u32>>>()?;
    Some((i16::try_from(exponent).ok()?, steps))
}

/// Byte `b` of every `n`-byte element, for b = 0..n, one plane after another. A tail shorter
/// than an element stays at the end as it is.
fn planes(bytes: &[u8], n: usize) -> Vec<u8> {
    let whole = bytes.len() / n * n;
    let mut out = Vec::with_capacity(bytes.len());
    for b in 0..n {
        out.extend(bytes[..whole].iter().skip(b).step_by(n));
    }
    out.extend_from_slice(&bytes[whole..]);
    out
}

fn unplanes(planes: &[u8], n: usize) -> Vec<u8> {
    let count = planes.len() / n;
    let mut out = vec![0u8; planes.len()];
    for b in 0..n {
        for (i, &v) in planes[b * count..(b + 1) * count].iter().enumerate() {
            out[i * n + b] = v;
        }
    }
    out[count * n..].copy_from_slice(&planes[count * n..]);
    out
}

/// Each byte minus the one before it within its plane of `plane_len` bytes.
fn sub_filter(bytes: &mut [u8], plane_len: usize) {
    for plane in bytes.chunks_mut(plane_len.max(1)) {
        for i in (1..plane.len()).rev() {
            plane[i] = plane[i].wrapping_sub(plane[i - 1]);
        }
    }
}

fn add_filter(bytes: &mut [u8], plane_len: usize) {
    for plane in bytes.chunks_mut(plane_len.max(1)) {
        for i in 1..plane.len() {
            plane[i] = plane[i].wrapping_add(plane[i - 1]);
        }
    }
}

/// Words per row of a payload of `words` 32-bit words: a square tile's side, else all of them.
fn row_words(words: usize) -> usize {
    let side = (words as f64).sqrt().round() as usize;
    if side > 0 && side * side == words { side } else { words.max(1) }
}

/// The plane predictor of word `i` from the words already known (west, south, south-west).
fn predict(words: &[u32], i: usize, row: usize) -> u32 {
    let (x, y) = (i % row, i / row);
    match (x, y) {
        (0, 0) => 0,
        (_, 0) => words[i - 1],
        (0, _) => words[i - row],
        _ => words[i - 1].wrapping_add(words[i - row]).wrapping_sub(words[i - row - 1]),
    }
}

/// Little-endian 32-bit words, each minus its plane prediction (wrapping); a tail stays as it is.
/// Each word minus its plane prediction (wrapping).
fn residues(words: &[u32]) -> Vec<u32> {
    let row = row_words(words.len());
    (0..words.len()).map(|i| words[i].wrapping_sub(predict(words, i, row))).collect()
}

/// Undoes `residues` in place, in the order the predictions need.
fn add_predictions(words: &mut [u32]) {
    let row = row_words(words.len());
    for i in 0..words.len() {
        words[i] = words[i].wrapping_add(predict(words, i, row));
    }
}

fn delta32(bytes: &[u8]) -> Vec<u8> {
    let words: Vec<u32> =
        bytes.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect();
    let mut out: Vec<u8> = residues(&words).iter().flat_map(|w| w.to_le_bytes()).collect();
    out.extend_from_slice(&bytes[out.len()..]);
    out
}

fn undelta32(bytes: &[u8]) -> Vec<u8> {
    let mut words: Vec<u32> =
        bytes.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect();
    add_predictions(&mut words);
    let mut out: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    out.extend_from_slice(&bytes[out.len()..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const CODECS: [Codec; 6] = [
        Codec::Raw,
        Codec::Zstd(Predictor::None),
        Codec::Zstd(Predictor::Delta32),
        Codec::Zstd(Predictor::Grid32),
        Codec::Zstd(Predictor::Planes(4)),
        Codec::Zstd(Predictor::Planes(3)),
    ];

    #[test]
    fn every_codec_gives_back_every_byte_and_its_header_word_names_it() {
        let heights: Vec<f32> = (0..4096).map(|i| 100.0 + (i as f32 * 0.01).sin() * 30.0).collect();
        let mut payload: Vec<u8> = bytemuck::cast_slice(&heights).to_vec();
        payload[8..12].copy_from_slice(&f32::NAN.to_bits().to_le_bytes());
        payload.extend([7, 1, 9]); // a tail no element size divides
        let path = Path::new("test.pack");
        for codec in CODECS {
            let stored = codec.encode(&payload, path).unwrap();
            assert_eq!(codec.decode(&stored, payload.len()).unwrap(), payload, "{codec:?}");
            assert_eq!(Codec::from_word(codec.word()), Some(codec));
            assert!(
                codec.decode(&stored, payload.len() + 1).is_none(),
                "{codec:?}: the wrong size is refused"
            );
        }
        assert_eq!(Codec::from_word(0x0000_0907), None);
    }

    #[test]
    fn predictors_shrink_smooth_heights_and_imagery_well_below_plain_zstd() {
        let heights: Vec<f32> =
            (0..65536).map(|i| ((i % 256) as f32 * 0.7 + (i / 256) as f32 * 1.3).round()).collect();
        let bytes: &[u8] = bytemuck::cast_slice(&heights);
        let path = Path::new("test.pack");
        let plain = Codec::Zstd(Predictor::None).encode(bytes, path).unwrap().len();
        let delta = Codec::Zstd(Predictor::Delta32).encode(bytes, path).unwrap().len();
        assert!(delta * 2 < plain, "delta {delta} against plain {plain} bytes");
        let rgba: Vec<u8> = (0..65536u32).flat_map(|i| [(i % 251) as u8, (i / 256) as u8, 40, 255]).collect();
        let planes = Codec::Zstd(Predictor::Planes(4)).encode(&rgba, path).unwrap().len();
        assert!(planes < rgba.len() / 20, "{planes} of {} bytes", rgba.len());
    }

    /// Heights as a DEM build rounds them: a bilinear-looking field on quarter metres, with zeros
    /// and negatives.
    fn quarter_metre_heights() -> Vec<f32> {
        (0..65 * 65)
            .map(|i| {
                let (x, y) = ((i % 65) as f32, (i / 65) as f32);
                let h = 40.0 * (x * 0.11).sin() * (y * 0.07).cos() + x * 0.37 - 3.0;
                ((h * 4.0).round() * 0.25 + 0.0).max(0.0) - if y > 60.0 { 2.5 } else { 0.0 }
            })
            .collect()
    }

    #[test]
    fn grid32_gives_back_every_grid_and_off_grid_word() {
        let path = Path::new("test.pack");
        let codec = Codec::Zstd(Predictor::Grid32);
        let on_grid = quarter_metre_heights();
        let mut cases = vec![on_grid.clone(), vec![0.0; 16], vec![8752.0, -500.0, 1e-40, 3.0e38]];
        for off in [f32::NAN, f32::INFINITY, -0.0, 1.0e30, 0.1] {
            let mut tile = on_grid.clone();
            tile[100] = off;
            cases.push(tile);
        }
        for heights in cases {
            let payload: &[u8] = bytemuck::cast_slice(&heights);
            let stored = codec.encode(payload, path).unwrap();
            let back = codec.decode(&stored, payload.len()).unwrap();
            assert_eq!(back, payload, "{:?}", &heights[..4]);
            assert!(codec.decode(&stored, payload.len() - 4).is_none());
        }
    }

    #[test]
    fn grid32_stores_rounded_heights_in_fewer_bytes_than_their_bit_patterns() {
        let heights = quarter_metre_heights();
        let bytes: &[u8] = bytemuck::cast_slice(&heights);
        let path = Path::new("test.pack");
        let delta = Codec::Zstd(Predictor::Delta32).encode(bytes, path).unwrap().len();
        let grid = Codec::Zstd(Predictor::Grid32).encode(bytes, path).unwrap().len();
        assert!(grid * 3 < delta * 2, "grid {grid} against delta {delta} bytes");
    }
}

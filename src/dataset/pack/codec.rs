//! How it works: how a pack stores its tiles, one codec per pack (a layer's tiles are alike).
//! `Raw` stores the payload as it is (read straight from the mapping, no copy). `Zstd` stores it
//! compressed by zstd, losslessly, after a predictor that turns smooth data into small numbers:
//! - `Delta32`, for `f32` heights: each 32-bit word minus its prediction from the words to its
//!   west, south and south-west (`w + s − sw`, the plane through them, on the bit patterns, wrapping,
//!   so it is exact for any value, NaN included; a square tile's rows are found from its size, any
//!   other is one row), then the four byte planes one after another, so that the nearly constant
//!   high bytes compress to almost nothing;
//! - `Planes(n)`, for `n`-byte texels (RGBA imagery, masks): the byte planes, each as
//!   differences from the byte before in its plane (PNG's "sub" filter, per channel);
//! - `None`, for data a predictor does not help (land cover's bit-packed LCC words).
//!
//! The codec is recorded in the pack's header; a reader decodes whatever the header says.

use super::PackError;
use std::path::Path;

/// zstd's level for tiles: fast to write (a build compresses every tile once) and to read.
const ZSTD_LEVEL: i32 = 3;

/// What is done to a tile's bytes before zstd compresses them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Predictor {
    /// Nothing.
    None,
    /// 32-bit word differences, then byte planes (`f32` heights).
    Delta32,
    /// Byte planes of `n`-byte texels, each as differences along its plane.
    Planes(u8),
}

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
        };
        zstd::bulk::compress(predicted.as_deref().unwrap_or(payload), ZSTD_LEVEL)
            .map_err(|source| PackError::Io { path: path.to_owned(), source })
    }

    /// The payload of `stored` bytes, `tile_bytes` long; `None` when they do not decode to that.
    pub(super) fn decode(self, stored: &[u8], tile_bytes: usize) -> Option<Vec<u8>> {
        let Self::Zstd(predictor) = self else {
            return (stored.len() == tile_bytes).then(|| stored.to_vec());
        };
        let mut bytes = zstd::bulk::decompress(stored, tile_bytes).ok()?;
        if bytes.len() != tile_bytes {
            return None;
        }
        match predictor {
            Predictor::None => {}
            Predictor::Delta32 => bytes = undelta32(&unplanes(&bytes, 4)),
            Predictor::Planes(n) => {
                let n = usize::from(n);
                add_filter(&mut bytes, tile_bytes / n.max(1));
                bytes = unplanes(&bytes, n);
            }
        }
        Some(bytes)
    }
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
fn delta32(bytes: &[u8]) -> Vec<u8> {
    let words: Vec<u32> =
        bytes.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect();
    let row = row_words(words.len());
    let mut out = bytes.to_vec();
    for (i, chunk) in out.chunks_exact_mut(4).enumerate() {
        chunk.copy_from_slice(&words[i].wrapping_sub(predict(&words, i, row)).to_le_bytes());
    }
    out
}

fn undelta32(bytes: &[u8]) -> Vec<u8> {
    let mut words: Vec<u32> =
        bytes.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect();
    let row = row_words(words.len());
    for i in 0..words.len() {
        words[i] = words[i].wrapping_add(predict(&words, i, row));
    }
    let mut out: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    out.extend_from_slice(&bytes[out.len()..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const CODECS: [Codec; 5] = [
        Codec::Raw,
        Codec::Zstd(Predictor::None),
        Codec::Zstd(Predictor::Delta32),
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
}

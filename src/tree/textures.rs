//! How it works: the generated trees' two textures, painted texel by texel from the species and
//! the tree's health, then PNG-encoded (sRGB, as glTF's base colour is). A leaf texture is a shape
//! in [0, 1]² (u across the leaf, v from its tip at the top to its base at the bottom) whose alpha
//! is 1 inside and 0 outside, for alpha-masked cards: an oval with a midrib and veins, a small
//! toothed triangle (birch), a spray of needles either side of a twig, or a tuft of needles fanning
//! from the base. A sick tree's leaves fade towards straw. Bark is lattice value noise stretched
//! along the stem (fissures), or pale with dark horizontal lenticels (birch). Texel colour varies
//! by a hash of its position only, so a texture is the same bytes on every run.

use image::ImageEncoder;
use image::codecs::png::PngEncoder;

use super::mesh::BARK_TEXELS;
use super::species::{LeafKind, Leaves, Species};

/// Leaf textures are this many texels square.
pub const LEAF_TEXELS: u32 = 128;

/// The colour a dying leaf fades towards (linear RGB).
const STRAW: [f32; 3] = [0.30, 0.22, 0.07];

/// The leaf texture of `leaves` at `health`, as PNG bytes.
pub fn leaf_png(leaves: &Leaves, health: f32) -> Result<Vec<u8>, image::ImageError> {
    let n = LEAF_TEXELS;
    let fade = 0.7 * (1.0 - health.clamp(0.0, 1.0));
    let colour = lerp3(leaves.colour, STRAW, fade);
    let twig = [0.12, 0.08, 0.05];
    let mut rgba = Vec::with_capacity((n * n * 4) as usize);
    for y in 0..n {
        for x in 0..n {
            let u = (x as f32 + 0.5) / n as f32;
            let v = (y as f32 + 0.5) / n as f32;
            let (inside, shade, is_twig) = match leaves.kind {
                LeafKind::Broad => broad(u, 1.0 - v),
                LeafKind::Birch => birch(u, 1.0 - v),
                LeafKind::NeedleSpray => needle_spray(u, 1.0 - v),
                LeafKind::NeedleTuft => needle_tuft(u, 1.0 - v),
            };
            let noise = 0.85 + 0.3 * unit_hash(x, y, 0x1eaf);
            let base = if is_twig { twig } else { colour };
            let texel = base.map(|c| c * shade * noise);
            rgba.extend_from_slice(&srgb8(texel, inside));
        }
    }
    png(&rgba, [n, n])
}

/// The bark texture of `species`, as PNG bytes (opaque).
pub fn bark_png(species: &Species) -> Result<Vec<u8>, image::ImageError> {
    let [w, h] = BARK_TEXELS;
    let mut rgba = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h {
        for x in 0..w {
            let (u, v) = (x as f32 / w as f32, y as f32 / h as f32);
            let shade = if species.birch_bark {
                let band = value_noise(u * 3.0, v * 24.0, [3, 24], 0xb1c);
                let lenticel = if band > 0.72 { 0.25 } else { 1.0 };
                let patch = 0.8 + 0.2 * value_noise(u * 4.0, v * 8.0, [4, 8], 0x9a7);
                lenticel * patch
            } else {
                let fissure = value_noise(u * 12.0, v * 3.0, [12, 3], 0xba4);
                let plate = value_noise(u * 6.0, v * 6.0, [6, 6], 0x91a);
                0.55 + 0.35 * fissure * fissure + 0.25 * plate
            };
            let noise = 0.9 + 0.2 * unit_hash(x, y, 0xba4c);
            rgba.extend_from_slice(&srgb8(species.bark_colour.map(|c| c * shade * noise), true));
        }
    }
    png(&rgba, [w, h])
}

/// An oval leaf: (inside, shade, twig) at u across, t from base (0) to tip (1).
fn broad(u: f32, t: f32) -> (bool, f32, bool) {
    let x = u - 0.5;
    if t < 0.12 {
        return (x.abs() < 0.025, 1.0, true);
    }
    let s = (t - 0.12) / 0.88;
    let half_width = 0.46 * (std::f32::consts::PI * s).sin().powf(0.75) * (1.0 - 0.35 * s);
    let inside = x.abs() < half_width;
    let vein = ((s * 9.0 - 2.5 * x.abs()).fract() - 0.5).abs() < 0.08;
    let shade = if x.abs() < 0.018 {
        1.35
    } else if vein {
        0.85
    } else {
        1.0 + 0.25 * (0.5 - x.abs())
    };
    (inside, shade, false)
}

/// A birch leaf: a toothed triangle widest at a third of its length.
fn birch(u: f32, t: f32) -> (bool, f32, bool) {
    let x = u - 0.5;
    if t < 0.1 {
        return (x.abs() < 0.025, 1.0, true);
    }
    let s = (t - 0.1) / 0.9;
    let outline = if s < 0.35 { s / 0.35 } else { (1.0 - s) / 0.65 };
    let teeth = 0.035 * ((s * 40.0).fract() - 0.5).abs();
    let inside = x.abs() < 0.45 * outline.powf(0.8) + teeth;
    let shade = if x.abs() < 0.016 { 1.3 } else { 1.0 };
    (inside, shade, false)
}

/// Needles either side of a twig up the middle of the card.
fn needle_spray(u: f32, t: f32) -> (bool, f32, bool) {
    let x = u - 0.5;
    if x.abs() < 0.02 {
        return (true, 1.0, true);
    }
    // Needles leave the twig every 1/24 of its length at 55° forward, 0.2–0.45 long.
    let spacing = 1.0 / 24.0;
    let (sin, cos) = 55f32.to_radians().sin_cos();
    let along_needle = x.abs() / sin;
    let start = t - along_needle * cos;
    let nearest = (start / spacing).round();
    let offset = (start - nearest * spacing).abs() * sin;
    let length = 0.2 + 0.25 * unit_hash(nearest as u32, u32::from(x > 0.0), 0x5b1e);
    let inside = (0.0..=1.0).contains(&(nearest * spacing)) && offset < 0.011 && along_needle < length;
    (inside, 0.8 + 0.4 * along_needle / length, false)
}

/// Long needles fanning from the card's base.
fn needle_tuft(u: f32, t: f32) -> (bool, f32, bool) {
    let (x, y) = (u - 0.5, t);
    let r = (x * x + y * y).sqrt();
    if r < 0.05 {
        return (true, 1.0, true);
    }
    // 19 needles over ±75° from the card's axis, each a ray of a random length.
    let angle = x.atan2(y);
    let step = 150f32.to_radians() / 18.0;
    let nearest = ((angle + 75f32.to_radians()) / step).round();
    let ray = nearest * step - 75f32.to_radians();
    let off_ray = r * (angle - ray).sin().abs();
    let length = 0.7 + 0.28 * unit_hash(nearest as u32, 7, 0x7f7);
    let inside = (0.0..=18.0).contains(&nearest) && off_ray < 0.009 + 0.004 * (1.0 - r) && r < length;
    (inside, 0.75 + 0.5 * r / length, false)
}

fn lerp3(a: [f32; 3], b: [f32; 3], t: f32) -> [f32; 3] {
    [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t]
}

/// Linear RGB to sRGB8, with alpha 255 when `opaque`, else 0 (and black: masked texels are cut).
fn srgb8(linear: [f32; 3], opaque: bool) -> [u8; 4] {
    if !opaque {
        return [0; 4];
    }
    let encode = |c: f32| {
        let c = c.clamp(0.0, 1.0);
        let s = if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
        (s * 255.0).round() as u8
    };
    [encode(linear[0]), encode(linear[1]), encode(linear[2]), 255]
}

/// A hash of a texel and a salt, uniform in [0, 1).
fn unit_hash(x: u32, y: u32, salt: u32) -> f32 {
    let mut h = x.wrapping_mul(0x8da6_b343) ^ y.wrapping_mul(0xd816_3841) ^ salt.wrapping_mul(0xcb1a_b31f);
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    (h >> 8) as f32 / (1u32 << 24) as f32
}

/// Smooth lattice noise in [0, 1], wrapping every `period` lattice cells (the texture tiles).
fn value_noise(x: f32, y: f32, period: [u32; 2], salt: u32) -> f32 {
    let (ix, iy) = (x.floor(), y.floor());
    let (fx, fy) = (x - ix, y - iy);
    let smooth = |t: f32| t * t * (3.0 - 2.0 * t);
    let corner = |dx: u32, dy: u32| {
        let cx = (ix as u32 + dx) % period[0];
        let cy = (iy as u32 + dy) % period[1];
        unit_hash(cx, cy, salt)
    };
    let (sx, sy) = (smooth(fx), smooth(fy));
    let top = corner(0, 0) + (corner(1, 0) - corner(0, 0)) * sx;
    let bottom = corner(0, 1) + (corner(1, 1) - corner(0, 1)) * sx;
    top + (bottom - top) * sy
}

fn png(rgba: &[u8], size: [u32; 2]) -> Result<Vec<u8>, image::ImageError> {
    let mut bytes = Vec::new();
    PngEncoder::new(&mut bytes).write_image(rgba, size[0], size[1], image::ExtendedColorType::Rgba8)?;
    Ok(bytes)
}

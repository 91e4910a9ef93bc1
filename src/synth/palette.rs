//! How it works: the colours of the synthetic imagery, picked as sRGB bytes the way one reads
//! them off an aerial photo, converted once to linear light (where mixing and shading are
//! physically meaningful), and a table that encodes linear values back to sRGB bytes without a
//! `powf` per channel.

pub type Rgb = [f32; 3];

/// Steps of the linear → sRGB table: fine enough that neighbouring steps never skip a byte
/// above the darkest shades.
pub const SRGB_STEPS: usize = 4096;

/// Palette entries, written as sRGB bytes the way a photo picker reports them.
mod srgb {
    pub const DEEP_WATER: [u8; 3] = [24, 46, 58];
    pub const SHALLOW_WATER: [u8; 3] = [62, 92, 88];
    pub const SAND: [u8; 3] = [198, 186, 150];
    pub const ROCK: [u8; 3] = [132, 128, 120];
    pub const MEADOW: [u8; 3] = [120, 138, 72];
    pub const DRY_GRASS: [u8; 3] = [166, 156, 100];
    pub const SHRUB: [u8; 3] = [92, 100, 60];
    pub const SHRUB_DARK: [u8; 3] = [54, 64, 38];
    pub const BROADLEAF: [u8; 3] = [58, 82, 42];
    pub const CONIFER: [u8; 3] = [34, 54, 38];
    pub const CROPS: [[u8; 3]; 5] =
        [[104, 140, 62], [198, 178, 104], [140, 112, 84], [150, 166, 90], [176, 150, 92]];
    pub const HEDGE: [u8; 3] = [64, 80, 44];
    pub const TRACK: [u8; 3] = [172, 160, 132];
    pub const ROOFS: [[u8; 3]; 5] =
        [[152, 150, 148], [150, 82, 66], [84, 84, 90], [204, 202, 196], [120, 100, 90]];
    pub const STREET: [u8; 3] = [96, 96, 100];
    pub const YARD: [u8; 3] = [112, 124, 82];
}

/// The palette in linear light.
pub struct Palette {
    pub deep_water: Rgb,
    pub shallow_water: Rgb,
    pub sand: Rgb,
    pub rock: Rgb,
    pub meadow: Rgb,
    pub dry_grass: Rgb,
    pub shrub: Rgb,
    pub shrub_dark: Rgb,
    pub broadleaf: Rgb,
    pub conifer: Rgb,
    pub crops: [Rgb; 5],
    pub hedge: Rgb,
    pub track: Rgb,
    pub roofs: [Rgb; 5],
    pub street: Rgb,
    pub yard: Rgb,
}

fn linear(c: [u8; 3]) -> Rgb {
    c.map(|v| {
        let s = f32::from(v) / 255.0;
        if s <= 0.04045 { s / 12.92 } else { ((s + 0.055) / 1.055).powf(2.4) }
    })
}

pub fn mix(a: Rgb, b: Rgb, t: f32) -> Rgb {
    let t = t.clamp(0.0, 1.0);
    [0, 1, 2].map(|c| a[c] + (b[c] - a[c]) * t)
}

pub fn scale(a: Rgb, k: f32) -> Rgb {
    a.map(|v| v * k)
}

impl Default for Palette {
    fn default() -> Self {
        Self {
            deep_water: linear(srgb::DEEP_WATER),
            shallow_water: linear(srgb::SHALLOW_WATER),
            sand: linear(srgb::SAND),
            rock: linear(srgb::ROCK),
            meadow: linear(srgb::MEADOW),
            dry_grass: linear(srgb::DRY_GRASS),
            shrub: linear(srgb::SHRUB),
            shrub_dark: linear(srgb::SHRUB_DARK),
            broadleaf: linear(srgb::BROADLEAF),
            conifer: linear(srgb::CONIFER),
            crops: srgb::CROPS.map(linear),
            hedge: linear(srgb::HEDGE),
            track: linear(srgb::TRACK),
            roofs: srgb::ROOFS.map(linear),
            street: linear(srgb::STREET),
            yard: linear(srgb::YARD),
        }
    }
}

/// sRGB bytes of linear values `i / (SRGB_STEPS - 1)`.
pub fn srgb_table() -> Vec<u8> {
    (0..SRGB_STEPS)
        .map(|i| {
            let l = i as f32 / (SRGB_STEPS - 1) as f32;
            let s = if l <= 0.003_130_8 { 12.92 * l } else { 1.055 * l.powf(1.0 / 2.4) - 0.055 };
            (s * 255.0 + 0.5) as u8
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversions_match_the_srgb_curve() {
        let grey = linear([128, 128, 128]);
        assert!((grey[0] - 0.2158).abs() < 1e-3);
        let table = srgb_table();
        assert_eq!(table[((grey[0] * (SRGB_STEPS - 1) as f32) + 0.5) as usize], 128);
        assert_eq!(mix([0.0; 3], [1.0; 3], 2.0), [1.0; 3]);
    }
}

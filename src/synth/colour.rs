//! How it works: an imagery texel is painted from the ground under its centre: the class picks an
//! albedo from a small palette of aerial-photo colours (sRGB, converted to linear once), textured
//! by what each cover looks like from above at metre scale (tree crowns, crop rows along each
//! parcel, hedges on parcel edges, roofs on a street grid with their shadows, shallow and deep
//! water, sand and scree), then lit by a hillshade of the stored surface (sun in the north-west,
//! 45° up) and encoded back to sRGB through a table, because `powf` per channel would cost more
//! than the terrain itself. Colour maths is f32: an error there moves a shade, nothing more.
//!
//! Imagery is 16 times the DEM's texels, so `paint_window` evaluates the relief (the costly part)
//! on every second texel of a lattice anchored on the layer and interpolates it in between;
//! classes and textures are still evaluated at every texel.

use super::noise::{Octave, floor, hash2, mix32, salt, wrap};
use super::palette::{Palette, Rgb, SRGB_STEPS, mix, scale, srgb_table};
use super::terrain::{Ground, Terrain, code};
use crate::dataset::Window;

/// Hillshade light: unit vector towards the sun (east, north, up), azimuth 315°, elevation 45°.
const SUN: [f32; 3] = [-0.5, 0.5, std::f32::consts::FRAC_1_SQRT_2];
/// Street grid of towns, in the field grid's frame: block period, street width, lot size.
const BLOCK_M: [f64; 2] = [77.0, 41.0];
const STREET_M: f64 = 7.0;
/// Lots of a block (after its street): 5 × 2 per block.
const LOT_M: [f64; 2] = [14.0, 17.0];
/// Sampling stream of the colour noises, apart from the terrain's.
const STREAM: u32 = 40;

/// Paints the synthetic world's imagery: RGBA8 sRGB texels from the ground's class, cover texture and
/// hillshade, with its sRGB table and noises built once per dataset.
pub struct Painter {
    to_srgb: Vec<u8>,
    palette: Palette,
    grain: Octave,
    patch: Octave,
    crowns: [Octave; 2],
    block_salt: u32,
    /// Offset towards the sun in the field grid's frame: a point is in a roof's shadow when this
    /// far towards the sun lies the roof.
    sunward_in_frame_m: [f64; 2],
}

impl Painter {
    /// The painter of the world `terrain` made from `seed`: its colour noises, the street grid's salt
    /// and the roofs' shadow offset in that world's field frame.
    pub fn new(seed: u64, terrain: &Terrain) -> Self {
        let (to_srgb, palette) = (srgb_table(), Palette::default());
        let [cos, sin] = terrain.frame();
        let sunward_m = [-2.5, 2.5];
        Self {
            to_srgb,
            palette,
            grain: Octave::new(seed, STREAM, 0, 4.0, 1.0),
            patch: Octave::new(seed, STREAM + 1, 0, 30.0, 1.0),
            crowns: [Octave::new(seed, STREAM + 2, 0, 7.0, 1.0), Octave::new(seed, STREAM + 3, 0, 2.9, 1.0)],
            block_salt: salt(seed, STREAM + 4),
            sunward_in_frame_m: [
                cos * sunward_m[0] + sin * sunward_m[1],
                cos * sunward_m[1] - sin * sunward_m[0],
            ],
        }
    }

    /// The imagery texels of window `w`, south row first, for texels of `texel_m` whose grid
    /// tiles the DEM's pixel area from half a `spacing_m` south-west of sample (0, 0).
    ///
    /// Relief dominates the cost of a texel, so it is evaluated exactly only at even texels
    /// (a lattice anchored on the layer, not the window, so every tile sees the same values) and
    /// interpolated between them: a quarter of the cost, and gradients that vary over metres
    /// interpolate well over one texel. Classes and colour are still evaluated per texel.
    pub fn paint_window(&self, terrain: &Terrain, w: Window, spacing_m: f64, texel_m: f64) -> Vec<[u8; 4]> {
        let centre = |i: u32| (f64::from(i) + 0.5) * texel_m - 0.5 * spacing_m;
        let (kx0, ky0) = (w.x0 / 2, w.y0 / 2);
        let nodes_x = (w.x0 + w.width - 1) / 2 + 2 - kx0;
        let nodes_y = (w.y0 + w.height - 1) / 2 + 2 - ky0;
        let mut nodes = Vec::with_capacity(nodes_x as usize * nodes_y as usize);
        for ky in ky0..ky0 + nodes_y {
            nodes.extend((kx0..kx0 + nodes_x).map(|kx| terrain.relief(centre(2 * kx), centre(2 * ky))));
        }
        let node = |kx: u32, ky: u32| nodes[((ky - ky0) * nodes_x + kx - kx0) as usize];
        let mut out = Vec::with_capacity(w.width as usize * w.height as usize);
        for j in w.y0..w.y0 + w.height {
            let (ky, odd_y) = (j / 2, j % 2 == 1);
            for i in w.x0..w.x0 + w.width {
                let (kx, odd_x) = (i / 2, i % 2 == 1);
                let mut relief = node(kx, ky);
                if odd_x {
                    relief = (relief + node(kx + 1, ky)) * 0.5;
                }
                if odd_y {
                    let north = if odd_x {
                        (node(kx, ky + 1) + node(kx + 1, ky + 1)) * 0.5
                    } else {
                        node(kx, ky + 1)
                    };
                    relief = (relief + north) * 0.5;
                }
                let (x_m, y_m) = (centre(i), centre(j));
                out.push(self.paint(&terrain.ground_on(x_m, y_m, relief), x_m, y_m));
            }
        }
        out
    }

    /// The sRGB colour of the texel centred at grid position (`x_m`, `y_m`) on `ground`.
    pub fn paint(&self, ground: &Ground, x_m: f64, y_m: f64) -> [u8; 4] {
        let albedo = self.albedo(x_m, y_m, ground);
        // The stored surface is flat over water, so is its shading.
        let (dx, dy) = if ground.class == code::WATER {
            (0.0, 0.0)
        } else {
            (ground.relief.dx as f32, ground.relief.dy as f32)
        };
        let lambert = (SUN[2] - SUN[0] * dx - SUN[1] * dy) / (1.0 + dx * dx + dy * dy).sqrt();
        // Flat ground keeps its albedo; sky light keeps the shadowed side readable.
        let shade = 0.3 + 0.7 * lambert.max(0.0) / SUN[2];
        let encode = |v: f32| self.to_srgb[((v * shade).clamp(0.0, 1.0) * (SRGB_STEPS - 1) as f32) as usize];
        [encode(albedo[0]), encode(albedo[1]), encode(albedo[2]), 255]
    }

    fn albedo(&self, x_m: f64, y_m: f64, ground: &Ground) -> Rgb {
        let p = &self.palette;
        let (jitter, height_m) = (ground.jitter, ground.relief.v as f32);
        let grain = self.grain.value(x_m, y_m);
        match ground.class {
            code::WATER => {
                let depth = (-height_m / 8.0).clamp(0.0, 1.0);
                scale(mix(p.shallow_water, p.deep_water, depth.sqrt()), 1.0 + 0.03 * grain)
            }
            code::SEDIMENT => {
                let rocky = ((height_m - 6.0) / 20.0 + ground.relief.slope() as f32 * 0.5).clamp(0.0, 1.0);
                scale(mix(p.sand, p.rock, rocky), 1.0 + 0.12 * grain + 0.08 * jitter)
            }
            code::HERBACEOUS => {
                let dry = 0.5 + 0.6 * self.patch.value(x_m, y_m) + 0.3 * jitter;
                scale(mix(p.meadow, p.dry_grass, dry), 1.0 + 0.08 * grain)
            }
            code::SHRUBLAND => {
                let bush = (0.5 + 0.9 * self.crowns[0].value(x_m, y_m) + 0.3 * grain).clamp(0.0, 1.0);
                mix(p.shrub, p.shrub_dark, bush)
            }
            code::FOREST => self.canopy(x_m, y_m, height_m, jitter),
            code::AGRICULTURE => self.field(ground, grain),
            code::DEVELOPED => self.town(x_m, y_m, ground, grain),
            _ => p.rock,
        }
    }

    fn canopy(&self, x_m: f64, y_m: f64, height_m: f32, jitter: f32) -> Rgb {
        let p = &self.palette;
        let conifer = (height_m - 260.0) / 200.0 + 0.5 * jitter;
        let base = mix(p.broadleaf, p.conifer, conifer);
        // Crowns: bright tops, dark gaps between them.
        let crowns = 0.7 * self.crowns[0].value(x_m, y_m) + 0.3 * self.crowns[1].value(x_m, y_m);
        scale(base, 0.8 + 0.5 * crowns + 0.08 * self.patch.value(x_m, y_m))
    }

    fn field(&self, ground: &Ground, grain: f32) -> Rgb {
        let p = &self.palette;
        let parcel = &ground.parcel;
        let h = mix32(parcel.hash ^ 0x5bd1_e995);
        let edge_m = [0, 1].map(|a| parcel.in_m[a].min(parcel.size_m[a] - parcel.in_m[a]));
        let edge_m = edge_m[0].min(edge_m[1]);
        if edge_m < 1.5 {
            return if h & 1 == 0 { p.hedge } else { p.track };
        }
        let crop = p.crops[(h >> 1) as usize % p.crops.len()];
        // Rows run along one axis of the parcel, 2.5–6 m apart.
        let axis = ((h >> 4) & 1) as usize;
        let period_m = 2.5 + f64::from((h >> 5) & 7) * 0.5;
        let phase = (wrap(parcel.along_m[axis], period_m) / period_m) as f32;
        let rows = 1.0 - 0.12 * (phase - 0.5).abs() * 4.0;
        scale(crop, rows * (1.0 + 0.06 * grain + 0.05 * ground.jitter))
    }

    /// Blocks between streets, cut into lots; most lots hold a house whose gabled roof shows a
    /// lit and a shaded half, and which throws a shadow away from the sun.
    fn town(&self, x_m: f64, y_m: f64, ground: &Ground, grain: f32) -> Rgb {
        let p = &self.palette;
        let along = ground.parcel.along_m;
        let block = [0, 1].map(|a| wrap(along[a], BLOCK_M[a]));
        if block[0] < STREET_M || block[1] < STREET_M {
            return scale(p.street, 1.0 + 0.05 * grain);
        }
        let house = |along: [f64; 2]| -> Option<(u32, [f64; 2])> {
            let in_block = [0, 1].map(|a| wrap(along[a], BLOCK_M[a]) - STREET_M);
            let lot = [0, 1].map(|a| floor(in_block[a] / LOT_M[a]));
            let in_lot = [0, 1].map(|a| in_block[a] - lot[a] * LOT_M[a]);
            let cell = [0, 1].map(|a| floor(along[a] / BLOCK_M[a]) * 8.0 + lot[a]);
            let h = hash2(cell[0] as i64, cell[1] as i64, self.block_salt);
            let inset = [2.0 + f64::from(h & 3) * 0.5, 2.5 + f64::from((h >> 2) & 3) * 0.5];
            let built = in_block.iter().all(|&v| v >= 0.0)
                && !h.is_multiple_of(5)
                && (0..2).all(|a| in_lot[a] > inset[a] && in_lot[a] < LOT_M[a] - inset[a]);
            built.then_some((h, in_lot))
        };
        if let Some((h, in_lot)) = house(along) {
            // The ridge runs along the lot's long side; one slope faces the sun.
            let half = if in_lot[1] < 0.5 * LOT_M[1] { 1.12 } else { 0.82 };
            return scale(p.roofs[(h >> 4) as usize % p.roofs.len()], half * (1.0 + 0.03 * grain));
        }
        let sunward = [0, 1].map(|a| along[a] + self.sunward_in_frame_m[a]);
        let shadow = if house(sunward).is_some() { 0.45 } else { 1.0 };
        let tree = (0.8 * self.crowns[0].value(x_m, y_m) + 0.2 * grain - 0.25).max(0.0) * 2.5;
        scale(mix(p.yard, p.broadleaf, tree), shadow * (1.0 + 0.1 * grain))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn even_texels_are_exact_and_windows_agree() {
        let terrain = Terrain::new(4, 100.0);
        let painter = Painter::new(4, &terrain);
        let (spacing_m, texel_m) = (10.0, 2.5);
        let a = painter.paint_window(
            &terrain,
            Window { x0: 37, y0: 90, width: 40, height: 30 },
            spacing_m,
            texel_m,
        );
        let b = painter.paint_window(
            &terrain,
            Window { x0: 50, y0: 101, width: 9, height: 7 },
            spacing_m,
            texel_m,
        );
        let centre = |i: u32| (f64::from(i) + 0.5) * texel_m - 0.5 * spacing_m;
        for j in 0..30 {
            for i in 0..40 {
                let (x, y) = (37 + i, 90 + j);
                let colour = a[(j * 40 + i) as usize];
                assert_eq!(colour[3], 255);
                if x % 2 == 0 && y % 2 == 0 {
                    let exact = painter.paint(&terrain.ground(centre(x), centre(y)), centre(x), centre(y));
                    assert_eq!(colour, exact, "texel ({x}, {y})");
                }
                if (50..59).contains(&x) && (101..108).contains(&y) {
                    assert_eq!(colour, b[((y - 101) * 9 + x - 50) as usize], "texel ({x}, {y})");
                }
            }
        }
    }

    #[test]
    fn srgb_table_spans_the_range() {
        let terrain = Terrain::new(1, 0.0);
        let painter = Painter::new(1, &terrain);
        assert_eq!((painter.to_srgb[0], painter.to_srgb[SRGB_STEPS - 1]), (0, 255));
        assert!(painter.to_srgb.windows(2).all(|w| w[0] <= w[1]));
        // Mid-grey in linear light is about 188 in sRGB.
        assert!((187..=189).contains(&painter.to_srgb[SRGB_STEPS / 2]));
    }
}

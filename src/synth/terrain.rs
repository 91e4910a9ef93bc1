//! How it works: the synthetic world is one continuous function of grid position (metres east and
//! north of the south-west height sample), so every layer at every resolution samples the same
//! world and a sample never depends on its neighbours or on the dataset's size or spacing.
//!
//! Relief is one octave stack of gradient noise (9 octaves, 6 km down to 23 m, plus one that
//! warps): the two coarsest shape the land (basins that flood into lakes, uplands), the third
//! raises massifs and, with the warp octave, bends the frame of the finer ones. Those are read
//! twice in one loop: as a ridged multifractal (sharp crests, whose detail fades into the valleys
//! it carves) for the mountains and as a smooth fBm for the rolling lowlands, blended by how high
//! the coarse shape is. Every step carries its exact gradient (`Field`), which gives slope for the
//! class rules and normals for hillshading from the same evaluation. Heights are relative to the
//! water surface while computing; below it the stored surface is the flat water.
//!
//! Classes follow the `nc` scheme from altitude, slope and noise, the cheap tests first: water
//! below the surface, sand on low flat shores, bare rock on cliffs, meadow above a ragged tree
//! line with shrubs just beneath it, towns in flat lowland blobs, fields on a rotated parcel grid
//! (each parcel a crop, a pasture or a woodlot), and elsewhere forest broken by clearings.

use super::noise::{Field, Octave, floor, hash2, mix32, salt, unit};

/// Land-cover codes of the built-in `nc` class table.
pub mod code {
    /// Towns: roofs on a street grid, in flat lowland blobs.
    pub const DEVELOPED: u8 = 1;
    /// Crop parcels on the rotated field grid of the flat lowlands.
    pub const AGRICULTURE: u8 = 2;
    /// Meadow: above the tree line, in forest clearings and as pasture parcels.
    pub const HERBACEOUS: u8 = 3;
    /// Shrubs: a band beneath the tree line, and around clearings and on steep woodland.
    pub const SHRUBLAND: u8 = 4;
    /// Forest, the default cover of the land, and woodlot parcels.
    pub const FOREST: u8 = 5;
    /// Lakes: everywhere the relief lies below the water surface.
    pub const WATER: u8 = 6;
    /// Bare ground: sand on low flat shores, rock and scree on cliffs and above the tree line.
    pub const SEDIMENT: u8 = 7;
}

const RELIEF_OCTAVES: usize = 9;
/// Octaves 0 and 1 shape the land, octave 2 the mountain massifs; the finer ones, from this one
/// on, carry the ridges and hills.
const DETAIL_FROM: usize = 3;
const RELIEF_WAVELENGTH_M: f64 = 6000.0;
/// Amplitude ratio between detail octaves: below ½ so slopes stay bounded as octaves are added.
const DETAIL_GAIN: f64 = 0.4;
const RIDGE_HEIGHT_M: f64 = 420.0;
const SHAPE_HEIGHT_M: f64 = 170.0;
/// How far the massif and warp octaves push the detail octaves' frame.
const WARP_M: f64 = 300.0;
const WARP_WAVELENGTH_M: f64 = 1300.0;
const MASSIF_HEIGHT_M: f64 = 110.0;
const HILL_HEIGHT_M: f64 = 45.0;
/// Land height above the water where the coarse shape is 0: sets how much of the basins floods
/// (about a sixth of a typical 10 km world).
const LAND_OFFSET_M: f64 = 40.0;
/// Meadow starts here above the water (before noise).
pub const TREE_LINE_M: f64 = 500.0;
/// Parcel edges (metres along the rotated field grid).
pub const PARCEL_M: [f64; 2] = [190.0, 110.0];

/// Named random streams, so that adding one never reshuffles the others.
mod stream {
    pub const RELIEF: u32 = 1;
    pub const JITTER: u32 = 2;
    pub const TOWN: u32 = 3;
    pub const CLEARING: u32 = 4;
    pub const PARCEL: u32 = 5;
    pub const FRAME: u32 = 6;
    pub const WARP: u32 = 7;
}

/// Where a point lies in its field parcel.
#[derive(Debug, Clone, Copy)]
pub struct Parcel {
    /// The parcel's (or its strip's) hash: picks its crop and colour, the same for every point of it.
    pub hash: u32,
    /// Position inside the parcel along the grid's two axes, metres from its corner.
    pub in_m: [f64; 2],
    /// The parcel's extent along the grid's two axes, metres.
    pub size_m: [f64; 2],
    /// Position along the grid's axes, metres (for stripes and building rows).
    pub along_m: [f64; 2],
}

/// One point of the synthetic ground.
#[derive(Debug, Clone, Copy)]
pub struct Ground {
    /// Height above the water surface (negative: depth), with its gradient.
    pub relief: Field,
    /// Its land-cover code (`code`, the `nc` scheme).
    pub class: u8,
    /// Smooth noise in about [-1, 1] that jittered the class edges; colour reuses it.
    pub jitter: f32,
    /// The field parcel it lies in (used by fields and towns alike).
    pub parcel: Parcel,
}

/// The synthetic world of one seed: evaluate it anywhere, in any order.
pub struct Terrain {
    relief: [Octave; RELIEF_OCTAVES],
    warp: Octave,
    amplitude: [f64; RELIEF_OCTAVES],
    jitter: [Octave; 2],
    town: [Octave; 2],
    clearing: Octave,
    parcel_salt: u32,
    /// cos and sin of the field grid's angle.
    frame: [f64; 2],
    /// Height of the lakes' surface, metres: the relief is relative to it.
    pub water_level_m: f64,
}

impl Terrain {
    /// The world of `seed` around a water surface at `water_level_m`: every octave salted once, so
    /// any point can then be evaluated alone.
    pub fn new(seed: u64, water_level_m: f64) -> Self {
        let relief =
            std::array::from_fn(|i| Octave::new(seed, stream::RELIEF, i as u32, RELIEF_WAVELENGTH_M, 2.0));
        let amplitude = std::array::from_fn(|i| DETAIL_GAIN.powi(i as i32 - DETAIL_FROM as i32 + 1));
        let angle = 0.5 * std::f64::consts::PI * unit(salt(seed, stream::FRAME));
        Self {
            relief,
            amplitude,
            warp: Octave::new(seed, stream::WARP, 0, WARP_WAVELENGTH_M, 1.0),
            jitter: std::array::from_fn(|i| Octave::new(seed, stream::JITTER, i as u32, 90.0, 3.7)),
            town: std::array::from_fn(|i| Octave::new(seed, stream::TOWN, i as u32, 1100.0, 3.3)),
            clearing: Octave::new(seed, stream::CLEARING, 0, 420.0, 2.0),
            parcel_salt: salt(seed, stream::PARCEL),
            frame: [angle.cos(), angle.sin()],
            water_level_m,
        }
    }

    /// cos and sin of the angle of the field grid (parcels, streets) against grid x.
    pub fn frame(&self) -> [f64; 2] {
        self.frame
    }

    /// Height above the water surface at grid position (`x_m`, `y_m`), with its gradient.
    pub fn relief(&self, x_m: f64, y_m: f64) -> Field {
        let at = |i: usize| self.relief[i].sample(x_m, y_m);
        let shape = at(0) + at(1) * 0.5;
        let massif = at(2);
        // Finer octaves are sampled in a frame warped by two noises of about a massif's size,
        // which bends the ridged noise's rings into irregular ranges. Their gradients are then
        // taken back through the warp's Jacobian: ∇p = Jᵀ ∇w, with J = I + WARP_M · ∇(warp).
        let warp = [massif, self.warp.sample(x_m, y_m)];
        let (wx_m, wy_m) = (x_m + WARP_M * warp[0].v, y_m + WARP_M * warp[1].v);
        let (mut hills, mut ridges) = (Field::ZERO, Field::ZERO);
        let mut weight = Field::constant(1.0);
        for (octave, &amplitude) in self.relief[DETAIL_FROM..].iter().zip(&self.amplitude[DETAIL_FROM..]) {
            let n = octave.sample(wx_m, wy_m);
            hills = hills + n * amplitude;
            // Musgrave's ridged multifractal: crests where the noise crosses zero, and each octave
            // weighted by the one before, so crests are rough and valley floors smooth.
            let crest = (Field::constant(1.0) - n.abs()).square();
            ridges = ridges + crest * weight * amplitude;
            weight = (crest * 1.6).saturate();
        }
        let unwarp = |f: Field| Field {
            v: f.v,
            dx: f.dx * (1.0 + WARP_M * warp[0].dx) + f.dy * WARP_M * warp[1].dx,
            dy: f.dx * WARP_M * warp[0].dy + f.dy * (1.0 + WARP_M * warp[1].dy),
        };
        let (hills, ridges) = (unwarp(hills) + massif, unwarp(ridges));
        let mountains = shape.smoothstep(0.1, 0.85);
        let lowland = Field::constant(1.0) - shape.smoothstep(-0.35, 0.35);
        // Hills shrink towards the valley floors, leaving room for flat fields and lakes.
        let hill_height = (Field::constant(1.0) - lowland * 0.8) * HILL_HEIGHT_M;
        let massif_m = (massif + 1.0) * MASSIF_HEIGHT_M;
        shape * SHAPE_HEIGHT_M
            + mountains * (ridges * RIDGE_HEIGHT_M + massif_m)
            + hills * hill_height
            + LAND_OFFSET_M
    }

    /// The stored DEM height at (`x_m`, `y_m`): the ground, or the flat water surface above it.
    pub fn height_m(&self, x_m: f64, y_m: f64) -> f64 {
        self.water_level_m + self.relief(x_m, y_m).v.max(0.0)
    }

    /// The parcel of the rotated field grid that holds (`x_m`, `y_m`). Grid cells are split
    /// into one to three strips, so fields vary in size like real ones.
    pub fn parcel(&self, x_m: f64, y_m: f64) -> Parcel {
        let [cos, sin] = self.frame;
        let along_m = [cos * x_m + sin * y_m, cos * y_m - sin * x_m];
        let cell = [0, 1].map(|a| floor(along_m[a] / PARCEL_M[a]));
        let hash = hash2(cell[0] as i64, cell[1] as i64, self.parcel_salt);
        let mut in_m = [0, 1].map(|a| along_m[a] - cell[a] * PARCEL_M[a]);
        let mut size_m = PARCEL_M;
        let (axis, strips) = ((hash >> 30) as usize & 1, f64::from(1 + (hash >> 28) % 3));
        size_m[axis] /= strips;
        let strip = floor(in_m[axis] / size_m[axis]).min(strips - 1.0);
        in_m[axis] -= strip * size_m[axis];
        Parcel { hash: mix32(hash ^ strip as u32), in_m, size_m, along_m }
    }

    /// Height, class and colour inputs at (`x_m`, `y_m`).
    pub fn ground(&self, x_m: f64, y_m: f64) -> Ground {
        self.ground_on(x_m, y_m, self.relief(x_m, y_m))
    }

    /// As `ground`, on a `relief` the caller already has (or interpolated).
    pub fn ground_on(&self, x_m: f64, y_m: f64, relief: Field) -> Ground {
        let jitter = 0.65 * self.jitter[0].value(x_m, y_m) + 0.35 * self.jitter[1].value(x_m, y_m);
        let parcel = self.parcel(x_m, y_m);
        let class = self.classify(x_m, y_m, relief, f64::from(jitter), &parcel);
        Ground { relief, class, jitter, parcel }
    }

    fn classify(&self, x_m: f64, y_m: f64, relief: Field, jitter: f64, parcel: &Parcel) -> u8 {
        let (height_m, slope) = (relief.v, relief.slope());
        if height_m < 0.0 {
            return code::WATER;
        }
        if height_m < 2.5 + 1.5 * jitter && slope < 0.25 {
            return code::SEDIMENT;
        }
        if slope > 1.1 + 0.25 * jitter {
            return code::SEDIMENT;
        }
        let tree_line_m = TREE_LINE_M + 45.0 * jitter;
        if height_m > tree_line_m {
            return if slope > 0.75 { code::SEDIMENT } else { code::HERBACEOUS };
        }
        if height_m > tree_line_m - 70.0 {
            return code::SHRUBLAND;
        }
        let flat = slope < 0.09 + 0.03 * jitter;
        if flat && height_m < 110.0 {
            let town = 0.75 * self.town[0].value(x_m, y_m)
                + 0.25 * self.town[1].value(x_m, y_m)
                + 0.1 * jitter as f32;
            if town > 0.5 && height_m > 3.0 {
                return code::DEVELOPED;
            }
        }
        if flat && height_m < 170.0 {
            return match unit(mix32(parcel.hash)) {
                p if p < 0.68 => code::AGRICULTURE,
                p if p < 0.84 => code::HERBACEOUS,
                _ => code::FOREST,
            };
        }
        let clearing = self.clearing.value(x_m, y_m) as f64 + 0.25 * jitter;
        if clearing > 0.55 {
            code::HERBACEOUS
        } else if clearing > 0.4 || slope > 0.8 {
            code::SHRUBLAND
        } else {
            code::FOREST
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relief_gradient_matches_finite_differences_away_from_kinks() {
        let terrain = Terrain::new(3, 100.0);
        let h = 1e-3;
        let mut checked = 0;
        for k in 0..400 {
            let (x, y) = (31.7 * f64::from(k), 5000.0 - 23.3 * f64::from(k % 37));
            let f = terrain.relief(x, y);
            let ddx = (terrain.relief(x + h, y).v - terrain.relief(x - h, y).v) / (2.0 * h);
            let ddy = (terrain.relief(x, y + h).v - terrain.relief(x, y - h).v) / (2.0 * h);
            // |n| and the clamps have kinks; where one falls inside the stencil the check is moot.
            if (f.dx - ddx).abs() < 1e-3 * (1.0 + f.slope()) && (f.dy - ddy).abs() < 1e-3 * (1.0 + f.slope())
            {
                checked += 1;
            }
        }
        assert!(checked > 390, "{checked}");
    }

    #[test]
    fn water_is_below_the_surface_and_only_there() {
        let terrain = Terrain::new(1, 100.0);
        for k in 0..5000 {
            let (x, y) = (f64::from(k % 71) * 143.0, f64::from(k / 71) * 139.0);
            let g = terrain.ground(x, y);
            assert_eq!(g.class == code::WATER, g.relief.v < 0.0);
            assert!(terrain.height_m(x, y) >= 100.0);
        }
    }
}

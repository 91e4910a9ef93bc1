//! How it works: the exact oracle of seed visibility, what the accuracy of pass 3 is measured
//! against (CPU, f64, full resolution, no tolerance). It owes the GPU nothing: it enumerates the
//! seeds itself, every seed of every ring-0 cell within reach of the camera, and judges each in the
//! GPU pass's order of culls (class, rule: altitude, slope and the imagery's vegetation index,
//! `vegetation`; distance, frustum, occlusion), but exactly. The seeded
//! world (patterns, hashes, rank thinning, sizes) is the shared definition in `crate::seeds`.
//!
//! The ground is the surface the finest terrain mesh draws over the level-0 height samples (sample
//! (i, j) at grid (i·spacing, j·spacing)), each cell split into two triangles as the mesh splits
//! it (`dataset::surface`); a seed's slope is that triangle's gradient. Its class is the level-1
//! land-cover texel under it, the land-cover grid starting half a spacing south-west of grid
//! space's origin. Its bounding sphere (centred half-way up its sunk trunk, grown for a plant by
//! how far the wind moves it: pass 3's rule, `seeds::wind`) must reach the inner side of each of
//! the five planes of the view (left, right, bottom, top, near). Occlusion is exact: the
//! eye→summit segment (bar its last 1e-6; the summit raised by the same sway) must never pass
//! strictly below that ground.
//! The walk visits the DEM cells the segment's horizontal projection crosses, in order (2D DDA,
//! each crossing's parameter computed directly, so no error accumulates); in a cell the ground
//! along the segment is linear on each side of the cell's diagonal and the segment's height
//! linear, so their difference is checked at the stretch's ends and where it crosses the
//! diagonal. Outside the dataset there is no terrain; an eye below the surface sees nothing.
//!
//! On the Earth (the renderer's placing, `earth::placing`) a seed's distance and its sphere's
//! centre are placed by the exact mapping (f64), the sphere's centre up the local vertical; the
//! eye→summit segment is straight in space, so over the grid it sags below the line between its
//! ends' heights by t (1 − t) (L² + 2 Δz²) / 2R at the grid's fraction t (L its length over the
//! grid, Δz its rise, R the mean radius of curvature at the eye: the Earth's fall under it, and
//! the verticals' convergence, which puts its higher points over nearer grid points; second
//! order in the bend), and its ground track is taken as the grid's straight line. The clearance is then a convex parabola on each planar piece, checked also at
//! its vertex.
//! Speed: the level-0 heights around the camera are copied once into a dense window and the
//! land-cover tiles under it decoded once; cells are judged in parallel (rayon). The result is
//! deterministic: visible seeds sorted by (cell address, rank), counts summed.

mod frame;
mod ground;
mod near;
mod vegetation;

use glam::{DVec2, DVec3, DVec4};
use rayon::prelude::*;
use thiserror::Error;

use crate::camera::{Camera, CameraError};
use crate::config::Settings;
use crate::dataset::{Dataset, PackError};
use crate::earth::placing::ExactPlacing;
use crate::gpu::gpu_types::SeedSpecies;
use crate::reference::seed_select::class_offset;
use crate::seeds::patterns::SeedPatterns;
use crate::seeds::{SeedTables, cell_pattern, seed_hash, seed_height_m, seed_variant, species_of_rank};
use frame::ViewFrame;
use ground::{DemWindow, LandcoverTiles};
pub use near::seeds_within;
use vegetation::Vegetation;

/// How much farther than their reach, on the grid, the cells judged on the Earth reach.
const REACH_MARGIN: f64 = 1.01;

/// The fraction of an eye→summit segment, at the summit's end, the occlusion test ignores.
pub const SEGMENT_END_SKIP: f64 = 1e-6;

/// Why the oracle could not judge a view.
#[derive(Debug, Error)]
pub enum OracleError {
    /// The camera is invalid or has no projection for the viewport.
    #[error("oracle: {0}")]
    Camera(#[from] CameraError),
    /// A height or land-cover tile of the dataset's pack could not be read.
    #[error("oracle: {0}")]
    Pack(#[from] PackError),
    /// The seed patterns given are not the `tlm.patterns` asked for, or their positions do not fill
    /// `count × seeds_per_pattern`.
    #[error(
        "oracle: the patterns hold {count} patterns of {seeds_per_pattern} seeds in {positions} positions; \
         tlm.patterns asks for {wanted}"
    )]
    Patterns {
        /// Patterns the set holds.
        count: u32,
        /// Seeds (ranks) per pattern.
        seeds_per_pattern: u32,
        /// Unit-square positions it holds in all.
        positions: usize,
        /// Patterns `tlm.patterns` asks for.
        wanted: u32,
    },
    /// A ring-0 cell within reach has an address beyond i32, which the seeds' hash (and the GPU)
    /// cannot name.
    #[error("oracle: ring-0 cell ({0}, {1}) has no 32-bit address (tlm.cell_m too small for this dataset)")]
    Address(i64, i64),
}

/// What the oracle reads.
pub struct OracleInputs<'a> {
    /// The dataset whose level-0 heights and level-1 land cover define the ground and the classes.
    pub dataset: &'a Dataset,
    /// Reads `tlm.cell_m`, `tlm.patterns`, `tlm.seed`, `draw_seeds.reach_m`,
    /// `seeds.reference_height_m` and `seeds.sink_fraction`.
    pub settings: &'a Settings,
    /// The class and species tables: which species a rank of a class grows, its rules and sizes.
    pub tables: &'a SeedTables,
    /// The ranks judged per cell are `patterns.seeds_per_pattern`.
    pub patterns: &'a SeedPatterns,
    /// `position_m` in CRS metres; grid space is that minus (`origin_m`, 0).
    pub camera: &'a Camera,
    /// The view's size, pixels: with the camera, the projection.
    pub viewport_px: [u32; 2],
}

/// A visible seed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OracleSeed {
    /// Global ring-0 cell address.
    pub address: [i64; 2],
    /// Its rank in its cell's pattern: with the address, its identity.
    pub rank: u32,
    /// Index into `SeedTables::species`: the variant it is drawn as (`seeds::seed_variant`).
    pub species: u32,
    /// Where it stands, grid space, metres.
    pub position_grid_m: [f64; 2],
    /// The drawn ground's height under the seed (its anchor sinks below it).
    pub ground_m: f64,
    /// Its height (its size), metres.
    pub height_m: f64,
    /// Its draw LOD: the first `draw_seeds.reach_m` (scaled by size) the seed is within, among
    /// the first `SeedClass::lods` of them.
    pub lod: u32,
}

/// Seeds judged, and where each went: every candidate lands in exactly one other field.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct OracleCounts {
    /// Every seed of every ring-0 cell within reach: `seeds_per_pattern` per cell.
    pub candidates: u64,
    /// Culled by class: outside the dataset, no class, or a class whose density leaves this rank out.
    pub class: u64,
    /// Culled by the species' altitude or slope rule.
    pub rule: u64,
    /// Beyond every `draw_seeds.reach_m` its class draws, scaled by the seed's size.
    pub distance: u64,
    /// Bounding sphere outside one of the view's five planes.
    pub frustum: u64,
    /// Eye→summit segment passes below the terrain (or the eye is underground).
    pub occlusion: u64,
    /// Survived every cull: the seeds returned.
    pub visible: u64,
}

impl OracleCounts {
    fn add(&mut self, o: &Self) {
        self.candidates += o.candidates;
        self.class += o.class;
        self.rule += o.rule;
        self.distance += o.distance;
        self.frustum += o.frustum;
        self.occlusion += o.occlusion;
        self.visible += o.visible;
    }
}

/// Which culls judge a seed: the GPU's selection (`Culls::SELECTION`) or the ground truth's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Culls {
    /// One reach for every seed, metres, its draw LOD always 0; `None`: `draw_seeds.reach_m`,
    /// scaled by the seed's size, as pass 3 reaches.
    pub reach_m: Option<f64>,
    /// Whether a seed whose eye→summit segment passes below the terrain is culled. The ground
    /// truth keeps it: whether any part of it shows is for its image to say.
    pub occlusion: bool,
    /// Whether a seed whose bounding sphere lies outside the view is culled: always for what is
    /// drawn; not for the plants standing near a point (`seeds_within`), seen or not.
    pub frustum: bool,
}

impl Culls {
    /// Pass 3's culls, exact: reach by size, frustum (bounding sphere), occlusion (summit).
    pub const SELECTION: Self = Self { reach_m: None, occlusion: true, frustum: true };
    /// The plants the view grows, seen or not: class, rules and reach by size, no view cull.
    pub const GROWN: Self = Self { reach_m: None, occlusion: false, frustum: false };
}

/// The visible seeds of the view, sorted by (address, rank), and the counts of every fate.
pub fn visible_seeds(inputs: &OracleInputs) -> Result<(Vec<OracleSeed>, OracleCounts), OracleError> {
    judge_seeds(inputs, Culls::SELECTION)
}

/// The seeds of the view that survive `culls`, sorted by (address, rank), and the counts of every
/// fate.
pub fn judge_seeds(
    inputs: &OracleInputs,
    culls: Culls,
) -> Result<(Vec<OracleSeed>, OracleCounts), OracleError> {
    let frame = ViewFrame::new(inputs)?;
    let (eye, extent_m) = (frame.eye, frame.extent_m);
    let cell_m = inputs.settings.tlm.cell_m;
    let reach_m = culls
        .reach_m
        .unwrap_or_else(|| inputs.settings.draw_seeds.reach_m.iter().fold(0.0f64, |a, &b| a.max(b)));

    // Ring-0 cells overlapping the height rectangle whose square comes within reach.
    let [(x0, x1), (y0, y1)] = cell_span(extent_m, cell_m, eye.truncate(), reach_m);
    // On the Earth reach is measured placed, and a projection may shrink distances by its scale
    // factor (UTM's by up to 0.04 % at a zone's edge): cells a little beyond reach on the grid
    // are judged too.
    let reach_m = if frame.placing.is_round() { REACH_MARGIN * reach_m } else { reach_m };
    let mut cells = Vec::new();
    for gy in y0..=y1 {
        for gx in x0..=x1 {
            let gap = |g: i64, c: f64| (g as f64 * cell_m - c).max(c - (g + 1) as f64 * cell_m).max(0.0);
            if DVec2::new(gap(gx, eye.x), gap(gy, eye.y)).length() < reach_m {
                cells.push([gx, gy]);
            }
        }
    }
    if cells.is_empty() {
        return Ok((Vec::new(), OracleCounts::default()));
    }
    let (region_min, region_max) = span_region(extent_m, cell_m, [(x0, x1), (y0, y1)]);
    let view = frame.view(inputs, culls, region_min.to_array(), region_max.to_array())?;
    let judged: Vec<(Vec<OracleSeed>, OracleCounts)> =
        cells.par_iter().map(|&address| view.cell(address)).collect::<Result<_, _>>()?;
    let mut counts = OracleCounts::default();
    let mut seeds = Vec::with_capacity(judged.iter().map(|(s, _)| s.len()).sum());
    for (cell_seeds, cell_counts) in judged {
        seeds.extend(cell_seeds);
        counts.add(&cell_counts);
    }
    seeds.sort_by_key(|s| (s.address, s.rank));
    Ok((seeds, counts))
}

/// The first and last ring-0 cell along x and y whose squares a disc of `radius_m` around grid
/// point `centre_m` may overlap, clamped to the dataset's `extent_m` (empty where first > last).
fn cell_span(extent_m: [f64; 2], cell_m: f64, centre_m: DVec2, radius_m: f64) -> [(i64, i64); 2] {
    [0, 1].map(|a| {
        let last = (extent_m[a] / cell_m).floor();
        let lo = ((centre_m[a] - radius_m) / cell_m).floor().max(0.0);
        let hi = ((centre_m[a] + radius_m) / cell_m).floor().min(last);
        (lo as i64, hi as i64)
    })
}

/// The grid rectangle the cells of `span` cover, clamped to the dataset's `extent_m`.
fn span_region(extent_m: [f64; 2], cell_m: f64, [(x0, x1), (y0, y1)]: [(i64, i64); 2]) -> (DVec2, DVec2) {
    let min = DVec2::new(x0 as f64 * cell_m, y0 as f64 * cell_m);
    let max = DVec2::new((x1 + 1) as f64 * cell_m, (y1 + 1) as f64 * cell_m).min(DVec2::from(extent_m));
    (min, max)
}

/// How each of `seeds` (named by address and rank; judged before in a view of the same dataset,
/// with any culls) fares under `culls` in the view of `inputs`: what the oracle would have done
/// with it, seed by seed, in order.
pub fn fates_of(inputs: &OracleInputs, culls: Culls, seeds: &[OracleSeed]) -> Result<Vec<Fate>, OracleError> {
    let frame = ViewFrame::new(inputs)?;
    let (mut lo, mut hi) = (frame.eye.truncate(), frame.eye.truncate());
    for s in seeds {
        lo = lo.min(DVec2::from(s.position_grid_m));
        hi = hi.max(DVec2::from(s.position_grid_m));
    }
    let view = frame.view(inputs, culls, lo.to_array(), hi.to_array())?;
    seeds
        .par_iter()
        .map(|s| match s.address.map(i32::try_from) {
            [Ok(x), Ok(y)] => view.seed(s.address, [x, y], s.rank, DVec2::from(s.position_grid_m)),
            _ => Err(OracleError::Address(s.address[0], s.address[1])),
        })
        .collect()
}

/// Whether the segment eye→target (grid space, metres) clears the full-resolution DEM: it never
/// passes strictly below its drawn ground (`dataset::surface`) where the dataset has terrain. The last
/// `SEGMENT_END_SKIP` of the segment, at the target's end, is ignored. On the flat sheet: the
/// segment does not sag as a straight one on the Earth does.
pub fn segment_clears_dem(
    dataset: &Dataset,
    eye_grid_m: DVec3,
    target_grid_m: DVec3,
) -> Result<bool, PackError> {
    Ok(segment_min_clearance_m(dataset, eye_grid_m, target_grid_m, true)? >= 0.0)
}

/// The least height of the segment above the surface (∞ where it meets no terrain); with `stop`,
/// any negative value as soon as one is found.
fn segment_min_clearance_m(
    dataset: &Dataset,
    eye: DVec3,
    target: DVec3,
    stop: bool,
) -> Result<f64, PackError> {
    let (lo, hi) = (eye.min(target), eye.max(target));
    let dem = DemWindow::load(dataset, [lo.x, lo.y], [hi.x, hi.y])?;
    Ok(dem.min_clearance_m(eye, target, 1.0 - SEGMENT_END_SKIP, 0.0, stop))
}

/// A seed's fate: the first cull it fails, in pass 3's order, or none.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Fate {
    /// Outside the dataset, no class there, or a class whose density leaves its rank out.
    Class,
    /// Its species' altitude or slope rule.
    Rule,
    /// Beyond its reach.
    Distance,
    /// Its bounding sphere lies outside the view.
    Frustum,
    /// Its eye→summit segment passes below the terrain (with the occlusion cull).
    Occlusion,
    /// Survives every cull.
    Visible(OracleSeed),
}

struct View<'a> {
    inputs: &'a OracleInputs<'a>,
    culls: Culls,
    dem: DemWindow,
    landcover: LandcoverTiles,
    vegetation: Vegetation,
    planes: [DVec4; 5],
    eye: DVec3,
    eye_underground: bool,
    extent_m: [f64; 2],
    /// How far the wind moves a plant's points at most, per metre of its height (pass 3's).
    wind_reach_per_height: f64,
    placing: ExactPlacing,
    sag_per_m2: f64,
}

impl View<'_> {
    fn cell(&self, address: [i64; 2]) -> Result<(Vec<OracleSeed>, OracleCounts), OracleError> {
        let i32_address = match address.map(i32::try_from) {
            [Ok(x), Ok(y)] => [x, y],
            _ => return Err(OracleError::Address(address[0], address[1])),
        };
        let tlm = &self.inputs.settings.tlm;
        let spp = self.inputs.patterns.seeds_per_pattern;
        let pattern = cell_pattern(i32_address, tlm.seed, tlm.corner_colours());
        let positions = &self.inputs.patterns.positions_unit[(pattern * spp) as usize..][..spp as usize];
        let mut counts = OracleCounts { candidates: u64::from(spp), ..Default::default() };
        let mut seeds = Vec::new();
        for (rank, &[ux, uy]) in (0..spp).zip(positions) {
            let position = DVec2::new(
                address[0] as f64 * tlm.cell_m + f64::from(ux) * tlm.cell_m,
                address[1] as f64 * tlm.cell_m + f64::from(uy) * tlm.cell_m,
            );
            match self.seed(address, i32_address, rank, position)? {
                Fate::Class => counts.class += 1,
                Fate::Rule => counts.rule += 1,
                Fate::Distance => counts.distance += 1,
                Fate::Frustum => counts.frustum += 1,
                Fate::Occlusion => counts.occlusion += 1,
                Fate::Visible(seed) => {
                    counts.visible += 1;
                    seeds.push(seed);
                }
            }
        }
        Ok((seeds, counts))
    }

    fn seed(
        &self,
        address: [i64; 2],
        i32_address: [i32; 2],
        rank: u32,
        p: DVec2,
    ) -> Result<Fate, OracleError> {
        let OracleInputs { dataset, settings, tables, .. } = *self.inputs;
        if !(p.x >= 0.0 && p.y >= 0.0 && p.x <= self.extent_m[0] && p.y <= self.extent_m[1]) {
            return Ok(Fate::Class);
        }
        // Pass 3's dithered class boundary: the read moved by up to half a level-1 texel, between
        // classes that grow (a seed whose own texel grows nothing stays bare).
        let offset = class_offset(i32_address, rank, settings.tlm.seed).map(f64::from);
        let dither = if settings.seeds.class_edge_dither { 1.0 } else { 0.0 };
        let moved = p + DVec2::from(offset) * self.landcover.texel_m() * dither;
        if !self.landcover.same_texel(p, moved) {
            let own = self.landcover.index(dataset, p)?;
            if !tables.classes.get(own as usize).is_some_and(|c| c.rank_limit[0] > 0.0) {
                return Ok(Fate::Class);
            }
        }
        let index = self.landcover.index(dataset, moved)?;
        let class = tables.classes.get(index as usize);
        let found = class.and_then(|class| species_of_rank(class, rank));
        let Some((species_index, species)) = found.and_then(|k| Some((k, tables.species.get(k as usize)?)))
        else {
            return Ok(Fate::Class);
        };
        let (ground_m, gradient) = self.dem.ground(p);
        let altitude = species.altitude_m.map(f64::from);
        if !(ground_m >= altitude[0] && ground_m <= altitude[1])
            || gradient.length_squared() > f64::from(species.max_slope_tan_sq)
        {
            return Ok(Fate::Rule);
        }
        let seeds = &settings.seeds;
        let hash = seed_hash(i32_address, rank, settings.tlm.seed);
        if !self.vegetation.grows(p, hash) {
            return Ok(Fate::Rule);
        }
        let height_m = f64::from(seed_height_m(species, hash));
        let distance_m = self.placing.position_rel_m(DVec3::new(p.x, p.y, ground_m)).length();
        let scale = (height_m / seeds.reference_height_m).min(1.0);
        let lod = match self.culls.reach_m {
            Some(reach_m) => (distance_m < reach_m).then_some(0),
            None => {
                // Its class draws its seeds to its own last LOD (`Class::seed_lods`).
                let lods = class.map_or(0, |c| c.lods as usize);
                settings.draw_seeds.reach_m.iter().take(lods).position(|&r| distance_m < r * scale)
            }
        };
        let Some(lod) = lod else {
            return Ok(Fate::Distance);
        };
        let sway_m = self.sway_m(species, height_m);
        // The sphere's centre half-way up the sunk trunk, along the local vertical.
        let centre_m = ground_m + height_m * (0.5 - seeds.sink_fraction);
        let centre = self.placing.position_rel_m(DVec3::new(p.x, p.y, centre_m));
        if self.culls.frustum && !self.in_frustum(species, centre, height_m, sway_m) {
            return Ok(Fate::Frustum);
        }
        // Pass 3's rule: swaying, the summit may rise into view by as far as the wind moves it.
        let summit = DVec3::new(p.x, p.y, ground_m - seeds.sink_fraction * height_m + height_m + sway_m);
        // The fall of the Earth under the segment and its verticals' convergence (`frame::sag_per_m2`).
        let rise = summit - self.eye;
        let sag_m = self.sag_per_m2 * (rise.truncate().length_squared() + 2.0 * rise.z * rise.z);
        if self.culls.occlusion
            && (self.eye_underground
                || self.dem.min_clearance_m(self.eye, summit, 1.0 - SEGMENT_END_SKIP, sag_m, true) < 0.0)
        {
            return Ok(Fate::Occlusion);
        }
        Ok(Fate::Visible(OracleSeed {
            address,
            rank,
            species: species_index + seed_variant(hash, species.variants),
            position_grid_m: [p.x, p.y],
            ground_m,
            height_m,
            lod: lod as u32,
        }))
    }

    /// How far the wind moves any point of a seed of `species` `height_m` tall (none for rocks).
    fn sway_m(&self, species: &SeedSpecies, height_m: f64) -> f64 {
        height_m * f64::from(species.wind_bend) * self.wind_reach_per_height
    }

    /// Whether the bounding sphere of a seed centred `centre` from the eye, grown by its sway
    /// `sway_m`, reaches inside every plane of the view.
    fn in_frustum(&self, species: &SeedSpecies, centre: DVec3, height_m: f64, sway_m: f64) -> bool {
        let radius_m = height_m * f64::from(species.radius_per_height) + sway_m;
        self.planes.iter().all(|plane| plane.truncate().dot(centre) + plane.w >= -radius_m)
    }
}

#[cfg(test)]
mod tests;

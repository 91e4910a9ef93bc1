//! Frame audits for the extreme-case tests (`tests/extremes.rs`, `data-tools/tests/extremes.rs`):
//! every GPU output of the last frame is read back and checked
//! (depth, colour, the Tile Load Map, pass 3's records and counters), and the frame's coverage is
//! judged against rays cast through the full-resolution DEM in f64.
//!
//! The ray oracle is deliberately tolerant where it cannot be sure and strict where it can: a ray
//! that enters the dataset at least `height_m` above the finest mesh and later dips `height_m`
//! below it (inside the dataset shrunk by `margin_m`) must show ground; a ray that stays `height_m`
//! above it wherever it passes over the dataset must show sky; anything else (silhouettes within
//! the LOD error, rays under the dataset's edge where skirts hang, rays that meet the ground before
//! the near plane) is not judged. Where the frame
//! shows ground, the point its depth puts on the pixel's ray must lie within `height_m` of the DEM.
//! The ground rays meet and seeds stand on is the finest terrain mesh (the DEM's cells split into
//! triangles as the mesh splits them), derived here on its own.

use glam::{DMat4, DVec3, DVec4};
use terramp::camera::Camera;
use terramp::dataset::{Dataset, TileId};
use terramp::earth::placing::{EarthPlacing, ExactPlacing};
use terramp::frame::Renderer;
use terramp::gpu::gpu_types::{SeedCounters, SeedRecord, TlmCell};
use terramp::gpu::layout::{LevelRange, RADIAL_INACTIVE, SpeciesLod, TLM_CULLED, TLM_FIRST_PATTERN};
use terramp::passes::terrain::select::Lods;

#[path = "audit_round.rs"]
pub mod round;

/// The level-0 DEM of a dataset, whole, in f64: the oracle's ground.
pub struct Dem {
    pub spacing_m: f64,
    pub size: [u32; 2],
    pub min_m: f64,
    pub max_m: f64,
    heights_m: Vec<f64>,
}

impl Dem {
    pub fn load(dataset: &Dataset) -> Self {
        let pyramid = &dataset.height.pyramid;
        let size = pyramid.size;
        let [nx, ny] = pyramid.tiles_at(0);
        let extent = pyramid.tile_extent();
        let mut heights_m = vec![0.0; size[0] as usize * size[1] as usize];
        for ty in 0..ny {
            for tx in 0..nx {
                let tile = dataset.height_tile(TileId::new(0, tx, ty)).unwrap();
                let owned = |t: u32, n: u32, count: u32| {
                    t * pyramid.tile..if t + 1 == count { n } else { (t + 1) * pyramid.tile }
                };
                for y in owned(ty, size[1], ny) {
                    for x in owned(tx, size[0], nx) {
                        let local =
                            [x - tx * pyramid.tile + pyramid.border, y - ty * pyramid.tile + pyramid.border];
                        heights_m[(y * size[0] + x) as usize] =
                            f64::from(tile[(local[1] * extent + local[0]) as usize]);
                    }
                }
            }
        }
        let h = &dataset.manifest.height;
        Self { spacing_m: h.spacing_m, size, min_m: f64::from(h.min_m), max_m: f64::from(h.max_m), heights_m }
    }

    /// Grid-space extent the terrain mesh covers, metres (one cell at least, as the mesh draws).
    pub fn span_m(&self) -> [f64; 2] {
        self.size.map(|n| f64::from(n.saturating_sub(1).max(1)) * self.spacing_m)
    }

    pub fn covers(&self, x_m: f64, y_m: f64, margin_m: f64) -> bool {
        let span = self.span_m();
        x_m >= margin_m && y_m >= margin_m && x_m <= span[0] - margin_m && y_m <= span[1] - margin_m
    }

    /// Sample (`i`, `j`), metres (clamped to the dataset).
    pub fn sample_m(&self, i: u32, j: u32) -> f64 {
        self.heights_m[(j.min(self.size[1] - 1) * self.size[0] + i.min(self.size[0] - 1)) as usize]
    }

    /// The cell holding grid position (x, y) (clamped to the samples), the position in it, and its
    /// corners' heights (sw, se, nw, ne).
    pub fn cell(&self, x_m: f64, y_m: f64) -> ([u32; 2], [f64; 2], [f64; 4]) {
        let sample = |i: u32, j: u32| self.sample_m(i, j);
        let axis = |v: f64, n: u32| {
            let g = (v / self.spacing_m).clamp(0.0, f64::from(n.saturating_sub(1)));
            let i = (g.floor() as u32).min(n.saturating_sub(2));
            (i, g - f64::from(i))
        };
        let ((i, u), (j, v)) = (axis(x_m, self.size[0]), axis(y_m, self.size[1]));
        ([i, j], [u, v], [sample(i, j), sample(i + 1, j), sample(i, j + 1), sample(i + 1, j + 1)])
    }

    /// Height of the finest terrain mesh at (x, y): two triangles per cell, the diagonal
    /// alternating like a checkerboard (`terramp::passes::terrain::frame::grid_indices`),
    /// south-west to north-east on even cells. The ground seeds stand on, and where a camera is
    /// above the ground.
    pub fn mesh_height_m(&self, x_m: f64, y_m: f64) -> f64 {
        let ([i, j], [u, v], [h00, h10, h01, h11]) = self.cell(x_m, y_m);
        match ((i + j) % 2 == 0, u >= v, u + v <= 1.0) {
            (true, true, _) => h00 + (h10 - h00) * u + (h11 - h10) * v,
            (true, false, _) => h00 + (h11 - h01) * u + (h01 - h00) * v,
            (false, _, true) => h00 + (h10 - h00) * u + (h01 - h00) * v,
            (false, _, false) => h11 + (h01 - h11) * (1.0 - u) + (h10 - h11) * (1.0 - v),
        }
    }
}

/// What the oracle may not judge: the terrain mesh's departure from the finest mesh, vertically,
/// and a band along the dataset's edges.
#[derive(Debug, Clone, Copy)]
pub struct Tolerance {
    /// Where the finest LOD is drawn (nearer than `Lods::morph_start_m[0]`).
    pub height_m: f64,
    /// Beyond, where coarser levels stand in (datasets of one level never get there).
    pub coarse_height_m: f64,
    pub margin_m: f64,
}

impl Tolerance {
    /// The same slack at every distance.
    pub fn flat(height_m: f64, margin_m: f64) -> Self {
        Self { height_m, coarse_height_m: height_m, margin_m }
    }
}

/// The vertical slack `tol` allows at distance `distance_m`, with the finest LOD drawn out to
/// `fine_within_m`.
pub(crate) fn slack_m(tol: &Tolerance, fine_within_m: f64, distance_m: f64) -> f64 {
    if distance_m < fine_within_m { tol.height_m } else { tol.coarse_height_m }
}

/// What a pixel must show.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Expect {
    Ground,
    Sky,
    Unknown,
}

/// The ray through a pixel's centre, from the camera (camera-relative, unit direction), and where
/// the renderer's placing (`terramp::earth::placing`) puts the grid.
pub struct Rays {
    pub eye_grid_m: DVec3,
    pub forward: DVec3,
    world_from_clip: DMat4,
    pub width: u32,
    pub height: u32,
    /// The renderer's placing from this camera: flat, or on the Earth.
    pub exact: ExactPlacing,
}

impl Rays {
    pub fn new(r: &Renderer, camera: &Camera) -> Self {
        let (width, height) = (r.settings.render.width, r.settings.render.height);
        let clip = camera.clip_from_view(width, height).unwrap() * camera.view_from_world();
        let m = &r.dataset.manifest;
        let o = m.origin_m;
        let eye_grid_m = camera.position_m - DVec3::new(o[0], o[1], 0.0);
        let placing = EarthPlacing::new(m.earth.as_ref(), o, r.settings.render.curved_earth);
        Self {
            eye_grid_m,
            forward: camera.forward(),
            world_from_clip: clip.inverse(),
            width,
            height,
            exact: placing.exact(eye_grid_m),
        }
    }

    pub fn dir(&self, x: u32, y: u32) -> DVec3 {
        let ndc_x = (f64::from(x) + 0.5) / f64::from(self.width) * 2.0 - 1.0;
        let ndc_y = 1.0 - (f64::from(y) + 0.5) / f64::from(self.height) * 2.0;
        // Reversed-Z: the near plane is at z = 1.
        let p = self.world_from_clip * DVec4::new(ndc_x, ndc_y, 1.0, 1.0);
        (p.truncate() / p.w).normalize()
    }

    /// The camera-relative point a reversed-Z depth puts on the ray through pixel (x, y).
    pub fn point_rel(&self, x: u32, y: u32, depth: f32, near_m: f64) -> DVec3 {
        let dir = self.dir(x, y);
        let along_forward_m = near_m / f64::from(depth);
        dir * (along_forward_m / dir.dot(self.forward))
    }

    /// The grid-space point (x, y and a height) a reversed-Z depth puts on the ray through pixel
    /// (x, y), where the renderer's placing puts it.
    pub fn point(&self, x: u32, y: u32, depth: f32, near_m: f64) -> DVec3 {
        self.exact.grid_m(self.point_rel(x, y, depth, near_m))
    }
}

/// What the ray from `eye` along `dir` must show over `dem`, from `t_near` on (where the ray
/// crosses the near plane: nothing before it is drawn), with the finest LOD out to `fine_within_m`.
pub fn expect(dem: &Dem, eye: DVec3, dir: DVec3, t_near: f64, tol: Tolerance, fine_within_m: f64) -> Expect {
    let slack = |t: f64| slack_m(&tol, fine_within_m, t);
    let widest = tol.height_m.max(tol.coarse_height_m);
    let span = dem.span_m();
    let (mut t_lo, mut t_hi) = (t_near, f64::INFINITY);
    for a in 0..2 {
        if dir[a].abs() < 1e-12 {
            if eye[a] < 0.0 || eye[a] > span[a] {
                return Expect::Sky;
            }
            continue;
        }
        let (t1, t2) = ((0.0 - eye[a]) / dir[a], (span[a] - eye[a]) / dir[a]);
        t_lo = t_lo.max(t1.min(t2));
        t_hi = t_hi.min(t1.max(t2));
    }
    if t_lo > t_hi {
        return Expect::Sky;
    }
    let band = [dem.min_m - widest - 1.0, dem.max_m + widest + 1.0];
    let z_at = |t: f64| eye.z + dir.z * t;
    let clearance = |t: f64| {
        let p = eye + dir * t;
        p.z - dem.mesh_height_m(p.x, p.y)
    };
    // The ray must enter over the dataset from above the ground to be judged at all.
    let entry = z_at(t_lo);
    if entry < band[0] || (entry <= band[1] && clearance(t_lo) <= slack(t_lo)) {
        return Expect::Unknown;
    }
    // Only the stretch within the height band can meet the ground.
    let (mut a, mut b) = (t_lo, t_hi);
    if dir.z.abs() > 1e-12 {
        let (ta, tb) = ((band[0] - eye.z) / dir.z, (band[1] - eye.z) / dir.z);
        a = a.max(ta.min(tb));
        b = b.min(ta.max(tb));
    } else if eye.z > band[1] {
        return Expect::Sky;
    }
    if a > b {
        return Expect::Sky;
    }
    let horizontal = dir.truncate().length();
    let step = (0.25 * dem.spacing_m / horizontal.max(1e-300))
        .min(0.5 * tol.height_m.min(widest) / dir.z.abs().max(1e-300));
    let steps = ((b - a) / step).ceil().min(1e6) as u64;
    let mut near_miss = false;
    for k in 0..=steps {
        let t = if steps == 0 { b } else { a + (b - a) * k as f64 / steps as f64 };
        let c = clearance(t);
        if c < -slack(t) {
            let p = eye + dir * t;
            return if dem.covers(p.x, p.y, tol.margin_m) { Expect::Ground } else { Expect::Unknown };
        }
        near_miss |= c <= slack(t);
    }
    if near_miss { Expect::Unknown } else { Expect::Sky }
}

/// Everything wrong (and a few figures) in the last frame of a renderer.
#[derive(Debug, Default, Clone)]
pub struct Audit {
    pub pixels: usize,
    pub depth_not_finite: usize,
    pub depth_out_of_range: usize,
    pub ground_px: usize,
    /// Pixels whose light (`Renderer::read_light`) is not finite or is 0 in every channel:
    /// a NaN, or a pixel nothing was drawn on; by day neither the sky, the air nor lit imagery
    /// is without light (the display's tone curve may show very dark light as black).
    pub black_px: usize,
    /// Rays judged, and what they found.
    pub rays: usize,
    pub expect_ground: usize,
    pub expect_sky: usize,
    /// Sky where the ground must be, ground where nothing may be.
    pub holes: usize,
    pub spurious: usize,
    /// Ground pixels whose depth puts the point farther than the tolerance from the DEM.
    pub off_dem_px: usize,
    /// Where the finest LOD is drawn, and beyond.
    pub worst_height_error_m: f64,
    pub worst_coarse_height_error_m: f64,
    pub tlm_cells: usize,
    pub tlm_visible: usize,
    pub tlm_bad: usize,
    pub seeds: usize,
    pub counters: Option<SeedCounters>,
    pub counters_bad: bool,
    pub seeds_not_finite: usize,
    /// Seeds whose base is not sunk exactly `sink_fraction` of their height below their ground
    /// height (a gap under a seed, or one buried), or whose ground is off the finest mesh.
    pub seeds_off_ground: usize,
    pub seeds_outside: usize,
    pub worst_seed_ground_error_m: f64,
    /// The largest height of a seed's base above the finest mesh under it: the gap one would see
    /// under a seed standing above the mesh's triangle.
    pub worst_seed_gap_m: f64,
}

impl Audit {
    /// No non-finite value or out-of-range depth anywhere, no hole, nothing where the sky must
    /// be, no TLM cell or seed record out of its ranges.
    pub fn assert_sound(&self, what: &str) {
        assert_eq!(self.depth_not_finite, 0, "{what}: {self:?}");
        assert_eq!(self.depth_out_of_range, 0, "{what}: {self:?}");
        assert_eq!(self.black_px, 0, "{what}: {self:?}");
        assert_eq!(self.holes, 0, "{what}: {self:?}");
        assert_eq!(self.spurious, 0, "{what}: {self:?}");
        assert_eq!(self.off_dem_px, 0, "{what}: {self:?}");
        assert_eq!(self.tlm_bad, 0, "{what}: {self:?}");
        assert!(!self.counters_bad, "{what}: {self:?}");
        assert_eq!(self.seeds_not_finite, 0, "{what}: {self:?}");
        assert_eq!(self.seeds_off_ground, 0, "{what}: {self:?}");
        assert_eq!(self.seeds_outside, 0, "{what}: {self:?}");
    }
}

/// Audits the last frame `r` rendered from `camera` (as rendered: lifted, if it was), judging
/// every `ray_step_px`-th pixel of each axis against the DEM.
pub fn audit(r: &Renderer, camera: &Camera, dem: &Dem, tol: Tolerance, ray_step_px: u32) -> Audit {
    let mut a = Audit::default();
    let rays = Rays::new(r, camera);
    let lods = Lods::for_view(&r.dataset, &r.settings.terrain, camera, rays.height);
    let fine_within_m = lods.morph_start_m.first().copied().unwrap_or(f64::INFINITY);
    let depth = r.read_depth().unwrap();
    let light = r.read_light().unwrap();
    a.pixels = depth.len();
    a.depth_not_finite = depth.iter().filter(|d| !d.is_finite()).count();
    a.depth_out_of_range = depth.iter().filter(|&&d| !(0.0..=1.0).contains(&d)).count();
    a.ground_px = depth.iter().filter(|&&d| d > 0.0).count();
    a.black_px =
        light.iter().filter(|p| p.iter().any(|c| !c.is_finite()) || p.iter().all(|&c| c == 0.0)).count();
    let at = |x: u32, y: u32| depth[(y * rays.width + x) as usize];
    for y in (ray_step_px / 2..rays.height).step_by(ray_step_px as usize) {
        for x in (ray_step_px / 2..rays.width).step_by(ray_step_px as usize) {
            a.rays += 1;
            let d = at(x, y);
            let dir = rays.dir(x, y);
            let t_near = camera.near_m / dir.dot(rays.forward);
            let expected = match rays.exact.is_round() {
                true => round::expect(dem, &rays.exact, dir, t_near, tol, fine_within_m),
                false => expect(dem, rays.eye_grid_m, dir, t_near, tol, fine_within_m),
            };
            match expected {
                Expect::Ground => {
                    a.expect_ground += 1;
                    a.holes += usize::from(d == 0.0);
                }
                Expect::Sky => {
                    a.expect_sky += 1;
                    a.spurious += usize::from(d > 0.0);
                }
                Expect::Unknown => {}
            }
            if d > 0.0 && d.is_finite() {
                let p = rays.point(x, y, d, camera.near_m);
                if dem.covers(p.x, p.y, tol.margin_m) {
                    let (error_m, distance_m) =
                        (p.z - dem.mesh_height_m(p.x, p.y), (p - rays.eye_grid_m).length());
                    let worst = if distance_m < fine_within_m {
                        &mut a.worst_height_error_m
                    } else {
                        &mut a.worst_coarse_height_error_m
                    };
                    *worst = worst.max(error_m.abs());
                    a.off_dem_px += usize::from(error_m.abs() > slack_m(&tol, fine_within_m, distance_m));
                }
            }
        }
    }
    audit_tlm(r, &mut a);
    audit_seeds(r, &rays, dem, &mut a);
    a
}

/// Every TLM cell within its fields' ranges: a NaN in the pass shows as a level or pattern no
/// dataset has.
fn audit_tlm(r: &Renderer, a: &mut Audit) {
    let Some(cells) = r.read_tile_load_map().unwrap() else { return };
    let cells_per_ring = (r.settings.tlm.cells * r.settings.tlm.cells) as usize;
    let height_levels = r.dataset.height.pyramid.levels;
    let imagery_levels = r.dataset.imagery.as_ref().map_or(1, |l| l.pyramid.levels);
    a.tlm_cells = cells.len();
    for (i, c) in cells.iter().enumerate() {
        let TlmCell { visibility, imagery_lod, height_lod, radial_lod } = *c;
        let ring0 = i < cells_per_ring;
        // A level range holds nothing beyond its two fields, finest first, within the levels.
        let pair_ok = |v: u32, levels: u32| {
            let range = LevelRange::unpack(v);
            range.pack() == v && range.min <= range.max && range.max < levels
        };
        let ok = visibility <= if ring0 { r.settings.tlm.patterns } else { TLM_FIRST_PATTERN }
            && radial_lod <= RADIAL_INACTIVE
            && (visibility == TLM_CULLED
                || (pair_ok(imagery_lod, imagery_levels) && pair_ok(height_lod, height_levels)));
        a.tlm_visible += usize::from(visibility != TLM_CULLED);
        a.tlm_bad += usize::from(!ok);
    }
}

/// Pass 3's records: finite, over the dataset, their base sunk into the ground they stand on by
/// exactly their sink, that ground on the finest mesh (level-0 seeds, to 1 cm); and its counters
/// adding up.
fn audit_seeds(r: &Renderer, rays: &Rays, dem: &Dem, a: &mut Audit) {
    let Some((records, counters)) = r.read_seeds().unwrap() else { return };
    let s = &r.settings.seeds;
    a.seeds = records.len();
    a.counters = Some(counters);
    let culled = counters.class + counters.rule + counters.distance + counters.frustum + counters.occlusion;
    a.counters_bad = counters.checked != counters.selected + culled
        || records.len() as u32 != counters.selected.min(s.capacity)
        || counters.overflow != counters.selected.saturating_sub(s.capacity);
    for record in &records {
        let SeedRecord { position_rel_m, height_m, radius_m, ground_m, .. } = *record;
        let finite = position_rel_m.iter().chain(&[height_m, radius_m, ground_m]).all(|v| v.is_finite());
        if !finite || height_m <= 0.0 || radius_m <= 0.0 {
            a.seeds_not_finite += 1;
            continue;
        }
        let p = rays.exact.grid_m(DVec3::from(position_rel_m.map(f64::from)));
        a.seeds_outside += usize::from(!dem.covers(p.x, p.y, -1e-3));
        let sink_m = f64::from(height_m) * s.sink_fraction;
        let gap_m = f64::from(ground_m) - sink_m - p.z;
        // f32 relative positions: a centimetre, or f32's step at the camera's height.
        let slack_m = 0.01f64.max(rays.eye_grid_m.z.abs() * 2e-7);
        let mut off = gap_m.abs() > slack_m;
        a.worst_seed_gap_m = a.worst_seed_gap_m.max(p.z - dem.mesh_height_m(p.x, p.y));
        if SpeciesLod::unpack(record.species_lod).height_level == 0 {
            let error_m = (f64::from(ground_m) - dem.mesh_height_m(p.x, p.y)).abs();
            a.worst_seed_ground_error_m = a.worst_seed_ground_error_m.max(error_m);
            off |= error_m > 0.01;
        }
        a.seeds_off_ground += usize::from(off);
    }
}

/// A camera `above_m` over the ground at fraction (fx, fy) of the dataset, in CRS metres.
pub fn camera_over(
    r: &Renderer,
    dem: &Dem,
    [fx, fy]: [f64; 2],
    above_m: f64,
    yaw_deg: f64,
    pitch_deg: f64,
) -> Camera {
    let span = dem.span_m();
    camera_at(r, dem, [fx * span[0], fy * span[1]], above_m, yaw_deg, pitch_deg)
}

/// A camera `above_m` over the ground (the finest mesh) at grid position `grid_m`, in CRS metres.
pub fn camera_at(
    r: &Renderer,
    dem: &Dem,
    grid_m: [f64; 2],
    above_m: f64,
    yaw_deg: f64,
    pitch_deg: f64,
) -> Camera {
    let o = r.dataset.manifest.origin_m;
    let ground = dem.mesh_height_m(grid_m[0], grid_m[1]);
    Camera {
        position_m: DVec3::new(o[0] + grid_m[0], o[1] + grid_m[1], ground + above_m),
        yaw_deg,
        pitch_deg,
        roll_deg: 0.0,
        fov_deg: 60.0,
        near_m: 0.1,
    }
}

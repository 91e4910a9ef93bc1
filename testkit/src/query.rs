//! The host's questions held to what the GPU drew, for any dataset (`tests/query.rs` on synthetic
//! ones, `data-tools/tests/query_real.rs` on nc and zion):
//! - `picks`: pixels of a settled view picked on the CPU (`Renderer::drawn_ground`) land where
//!   the depth buffer has the ground, within `PICK_FLOOR_M` or the depth buffer's own precision;
//!   the drawn ground's height under each pick is the pick's within `HEIGHT_M`;
//! - `plants`: the plants pass 3 keeps near picked points (`Plants::Selected`) are the seeds its
//!   records name there, and every one is among those the view grows (`Plants::Grown`).

use glam::{DVec2, DVec3, Vec2};
use terramp::camera::Camera;
use terramp::frame::{Plants, Renderer};
use terramp::gpu::layout::SpeciesLod;

/// Pixels picked per view.
pub const PICKS: usize = 1000;
/// Least distance between a pick and the depth buffer's point, metres, whatever the precision.
pub const PICK_FLOOR_M: f64 = 0.01;
/// Bits of the rasteriser's subpixel grid the bound allows: Vulkan's least (lavapipe has 8). A
/// vertex may move across the screen by 2^-bits of a pixel.
pub const SUBPIXEL_BITS: i32 = 4;
/// How far the drawn ground's height at a picked point may be from the pick's, metres.
pub const HEIGHT_M: f64 = 0.001;
/// Most share of the pixels showing sky whose ray the pick finds ground on: silhouette pixels,
/// where the rasteriser's coverage rule and the f64 ray part ways by a sliver.
pub const SKY_PICKED: f64 = 0.01;
/// Radius of the plants asked for around each point, metres.
pub const PLANTS_RADIUS_M: f64 = 15.0;
/// Points asked about.
pub const PLANT_POINTS: usize = 100;
/// Most seeds, as a share of those near the points, that the exact oracle keeps and pass 3 drops
/// (f32, its occlusion against the depth): seeds on a cull's very edge.
pub const PLANTS_DROPPED: f64 = 0.01;
/// Most seeds, as a share of those near the points, that pass 3 keeps and the exact oracle drops:
/// pass 3 culls conservatively, keeping summits hidden by less than `seeds.occlusion_tolerance_m`
/// and spheres within its frustum margin (docs/seeds.md measures its precision against the oracle).
pub const PLANTS_KEPT: f64 = 0.05;

/// A deterministic stream of pixels of a viewport.
struct Pixels {
    state: u64,
    size: [u32; 2],
}

impl Pixels {
    fn next(&mut self) -> [u32; 2] {
        self.state =
            self.state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        let bits = self.state >> 16;
        [(bits % u64::from(self.size[0])) as u32, ((bits >> 20) % u64::from(self.size[1])) as u32]
    }
}

fn pixels(r: &Renderer, seed: u64) -> Pixels {
    Pixels { state: seed, size: [r.settings.render.width, r.settings.render.height] }
}

/// What the picks of one view measured.
#[derive(Debug, Default)]
pub struct Picks {
    pub picked: usize,
    pub within_floor: usize,
    pub worst_m: f64,
    pub worst_over_bound: f64,
    /// Pixels showing sky, and those of them that have no pick.
    pub sky: usize,
    pub sky_agrees: usize,
}

impl Picks {
    /// Prints what they measured and holds the sky's pixels to `SKY_PICKED`.
    pub fn check(&self, what: &str) {
        println!(
            "{what}: {} picks, {} within {PICK_FLOOR_M} m of the depth buffer's point, worst {:.4} m ({:.4} of its bound); sky pixels without a pick {}/{}",
            self.picked, self.within_floor, self.worst_m, self.worst_over_bound, self.sky_agrees, self.sky
        );
        let picked = self.sky - self.sky_agrees;
        assert!(picked as f64 <= SKY_PICKED * self.sky as f64, "sky pixels picked: {picked}/{}", self.sky);
    }
}

/// Settles the view from `pose`, picks `PICKS` ground pixels and holds each to the depth buffer:
/// within `PICK_FLOOR_M`, or the depth's precision there (its f32 rounding, and the rasteriser's
/// subpixel snap of the triangle, which moves the ground along the ray by that much of a pixel's
/// footprint over the tangent of the ray's angle to the normal).
pub fn picks(r: &mut Renderer, pose: &Camera) -> Picks {
    r.render_resolved(pose).unwrap();
    let depth = r.read_depth().unwrap();
    let ground = r.drawn_ground().unwrap().unwrap();
    let width = r.settings.render.width;
    let pixel_rad = pose.fov_deg.to_radians() / f64::from(r.settings.render.height);
    let mut pixels = pixels(r, 7);
    let mut p = Picks::default();
    let mut tries = 0;
    while p.picked < PICKS {
        tries += 1;
        assert!(tries < 50 * PICKS, "too little ground in view");
        let px = pixels.next();
        let d = depth[(px[1] * width + px[0]) as usize];
        let hit = ground.pick_pixel(px);
        if d == 0.0 {
            p.sky += 1;
            p.sky_agrees += usize::from(hit.is_none());
            continue;
        }
        let at = ground.depth_point(px, d);
        let hit = hit.unwrap_or_else(|| panic!("pixel {px:?} shows ground at {at} and the pick meets none"));
        let distance_m = at.length();
        let cos = hit.normal.dot(-at / distance_m).abs().max(1e-3);
        let footprint_m = distance_m * pixel_rad;
        let bound_m = PICK_FLOOR_M
            + distance_m * 4.0 * f64::from(f32::EPSILON)
            + 2f64.powi(-SUBPIXEL_BITS) * footprint_m * (1.0 - cos * cos).sqrt() / cos;
        let off_m = (hit.rel_m - at).length();
        p.worst_m = p.worst_m.max(off_m);
        p.within_floor += usize::from(off_m <= PICK_FLOOR_M);
        p.worst_over_bound = p.worst_over_bound.max(off_m / bound_m);
        assert!(
            off_m <= bound_m,
            "pixel {px:?}: pick {off_m} m from the depth's point {at} (bound {bound_m} m)"
        );
        let under = ground.at_grid(hit.grid_m.x, hit.grid_m.y).unwrap();
        assert!(
            (under.height_m - hit.height_m).abs() <= HEIGHT_M,
            "{} against {}",
            under.height_m,
            hit.height_m
        );
        p.picked += 1;
    }
    p
}

/// What the plants near the points of one view measured.
#[derive(Debug, Default)]
pub struct PlantCheck {
    pub points: usize,
    /// Seeds selected near the points (by pass 3 or the oracle, whichever names more).
    pub near: usize,
    /// Seeds the oracle names near the points and pass 3 does not.
    pub dropped: usize,
    /// Seeds pass 3 names near the points and the oracle does not.
    pub kept: usize,
    /// Plants grown near the points.
    pub grown: usize,
}

/// Asks for the plants within `PLANTS_RADIUS_M` of `PLANT_POINTS` picked points of the settled
/// view from `pose` and holds `Plants::Selected` to the seeds pass 3 wrote (read back, by
/// identity and species; those within a millimetre of the circle left out, as f32 may put them
/// either side), and `Plants::Grown` to holding every selected one and standing within the radius.
pub fn plants(r: &mut Renderer, pose: &Camera) -> PlantCheck {
    r.render_resolved(pose).unwrap();
    // Pass 3 runs on the cells of a Tile Load Map a frame or two old: let the latest arrive.
    for _ in 0..3 {
        r.render(pose).unwrap();
    }
    let (records, _) = r.read_seeds().unwrap().unwrap();
    let camera_grid_m =
        pose.position_m - DVec3::new(r.dataset.manifest.origin_m[0], r.dataset.manifest.origin_m[1], 0.0);
    let drawn: Vec<([i64; 2], u32, u32, DVec2)> = records
        .iter()
        .map(|s| {
            let grid =
                camera_grid_m.truncate() + Vec2::new(s.position_rel_m[0], s.position_rel_m[1]).as_dvec2();
            (s.address.map(i64::from), s.rank, SpeciesLod::unpack(s.species_lod).species, grid)
        })
        .collect();
    let ground = r.drawn_ground().unwrap().unwrap();
    let mut pixels = pixels(r, 3);
    let mut c = PlantCheck::default();
    let mut tries = 0;
    while c.points < PLANT_POINTS {
        tries += 1;
        assert!(tries < 50 * PLANT_POINTS, "too little ground in view");
        let Some(hit) = ground.pick_pixel(pixels.next()) else { continue };
        let centre = DVec2::new(hit.grid_m.x, hit.grid_m.y);
        c.points += 1;
        let selected =
            r.plants_near(pose, centre.to_array(), PLANTS_RADIUS_M, Plants::Selected).unwrap().unwrap();
        let grown = r.plants_near(pose, centre.to_array(), PLANTS_RADIUS_M, Plants::Grown).unwrap().unwrap();
        c.grown += grown.len();
        let off_edge = |p: DVec2| (p.distance(centre) - PLANTS_RADIUS_M).abs() > 1e-3;
        let by_gpu: Vec<_> = drawn
            .iter()
            .filter(|d| d.3.distance(centre) <= PLANTS_RADIUS_M && off_edge(d.3))
            .map(|d| (d.0, d.1, d.2))
            .collect();
        let by_oracle: Vec<_> = selected
            .iter()
            .filter(|p| off_edge(p.position_grid_m.truncate()))
            .map(|p| (p.address, p.rank, p.species))
            .collect();
        c.near += by_gpu.len().max(by_oracle.len());
        c.kept += by_gpu.iter().filter(|d| !by_oracle.contains(d)).count();
        c.dropped += by_oracle.iter().filter(|o| !by_gpu.contains(o)).count();
        for p in &selected {
            assert!(grown.iter().any(|g| g.address == p.address && g.rank == p.rank), "{p:?} not grown");
        }
        for g in &grown {
            assert!(g.position_grid_m.truncate().distance(centre) <= PLANTS_RADIUS_M);
            assert!(g.radius_m > 0.0 && g.height_m > 0.0);
        }
    }
    c
}

impl PlantCheck {
    /// Prints what was measured and holds it to `PLANTS_DROPPED` and `PLANTS_KEPT`; some seed
    /// must stand near.
    pub fn check(&self, what: &str) {
        println!(
            "{what}: {} points, {PLANTS_RADIUS_M} m around each: {} seeds selected near them; {} the oracle keeps and pass 3 drops, {} pass 3 keeps and the oracle drops; {} grown",
            self.points, self.near, self.dropped, self.kept, self.grown
        );
        assert!(self.near > 0, "no seed near any point");
        let share = |n: usize| n as f64 / self.near as f64;
        assert!(share(self.dropped) <= PLANTS_DROPPED, "{} of {} dropped", self.dropped, self.near);
        assert!(share(self.kept) <= PLANTS_KEPT, "{} of {} kept", self.kept, self.near);
    }
}

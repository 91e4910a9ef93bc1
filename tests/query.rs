//! The host's questions about the ground (`Renderer::drawn_ground`, `ground_at`), answered on the
//! CPU and held to what the GPU drew: a pick through a pixel's centre lands where the depth
//! buffer says that pixel's ground is, within the depth buffer's precision; the drawn ground's
//! height under a picked point is the pick's; on the finest data, the height is the dataset's.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use terramp::camera::Camera;
use terramp::frame::{Plants, Renderer};
use terramp::gpu::Gpu;
use terramp::gpu::layout::SpeciesLod;
use terramp_testkit::earth::synth_on_nc;
use terramp_testkit::{camera, gpu, renderer, small_settings, synth_dataset};

const SIZE: [u32; 2] = [320, 180];
/// Pixels picked per view.
const PICKS: usize = 1000;
/// Least distance between a pick and the depth buffer's point, metres, whatever the precision.
const PICK_FLOOR_M: f64 = 0.01;
/// Bits of the rasteriser's subpixel grid the bound allows: Vulkan's least (lavapipe has 8). A
/// vertex may move across the screen by 2^-bits of a pixel.
const SUBPIXEL_BITS: i32 = 4;
/// How far the drawn ground's height at a picked point may be from the pick's, metres.
const HEIGHT_M: f64 = 0.001;

/// A deterministic stream of pixels.
struct Pixels(u64);

impl Pixels {
    fn next(&mut self) -> [u32; 2] {
        self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        let bits = self.0 >> 16;
        [(bits % u64::from(SIZE[0])) as u32, ((bits >> 20) % u64::from(SIZE[1])) as u32]
    }
}

/// What the picks of one view measured.
struct Picks {
    picked: usize,
    within_floor: usize,
    worst_m: f64,
    worst_over_bound: f64,
    sky_agrees: usize,
    sky: usize,
}

/// Picks `PICKS` ground pixels of the settled view from `pose` and holds each to the depth
/// buffer: within `PICK_FLOOR_M`, or the depth's precision there (its f32 rounding, and the
/// rasteriser's subpixel snap of the triangle, which moves the ground along the ray by that much
/// of a pixel's footprint over the tangent of the ray's angle to the normal).
fn picks(r: &mut Renderer, pose: &Camera) -> Picks {
    r.render_resolved(pose).unwrap();
    let depth = r.read_depth().unwrap();
    let ground = r.drawn_ground().unwrap().unwrap();
    let pixel_rad = pose.fov_deg.to_radians() / f64::from(SIZE[1]);
    let mut pixels = Pixels(7);
    let mut p =
        Picks { picked: 0, within_floor: 0, worst_m: 0.0, worst_over_bound: 0.0, sky_agrees: 0, sky: 0 };
    let mut tries = 0;
    while p.picked < PICKS {
        tries += 1;
        assert!(tries < 50 * PICKS, "too little ground in view");
        let px = pixels.next();
        let d = depth[(px[1] * SIZE[0] + px[0]) as usize];
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
            "pixel {px:?}: pick {} m from the depth's point {at} (bound {bound_m} m)",
            off_m
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

fn report(what: &str, p: &Picks) {
    println!(
        "{what}: {} picks, {} within {PICK_FLOOR_M} m of the depth buffer's point, worst {:.4} m ({:.4} of its bound); sky pixels without a pick {}/{}",
        p.picked, p.within_floor, p.worst_m, p.worst_over_bound, p.sky_agrees, p.sky
    );
}

#[test]
fn picks_land_where_the_depth_buffer_has_the_ground() {
    let dir = synth_dataset(300, 7);
    let mut r = renderer(&dir, small_settings(SIZE[0], SIZE[1]));
    for (what, pose) in [
        ("synthetic, 25 m up, looking along", camera::over_fraction(&r, [0.45, 0.35], 25.0, 20.0, -10.0)),
        ("synthetic, 600 m up, looking down", camera::over_fraction(&r, [0.3, 0.3], 600.0, 45.0, -35.0)),
    ] {
        let p = picks(&mut r, &pose);
        report(what, &p);
        assert!(
            p.sky == 0 || p.sky_agrees * 100 >= p.sky * 99,
            "sky pixels picked: {}/{}",
            p.sky - p.sky_agrees,
            p.sky
        );
    }
}

#[test]
fn picks_land_where_the_depth_buffer_has_the_ground_on_the_earth() {
    let dataset = synth_on_nc(512, 30.0, 11);
    let gpu: Gpu = gpu();
    let mut r = Renderer::new(gpu, dataset, small_settings(SIZE[0], SIZE[1])).unwrap();
    let pose = camera::over_fraction(&r, [0.2, 0.2], 2_000.0, 45.0, -8.0);
    let p = picks(&mut r, &pose);
    report("synthetic on nc's State Plane, on the Earth, 2 km up", &p);
}

#[test]
fn the_finest_grounds_height_is_the_datasets() {
    let dir = synth_dataset(300, 7);
    let r = renderer(&dir, small_settings(SIZE[0], SIZE[1]));
    let spacing_m = r.dataset.manifest.height.spacing_m;
    for (i, j) in [(3u32, 5u32), (100, 40), (250, 299)] {
        let at = r.ground_at(f64::from(i) * spacing_m, f64::from(j) * spacing_m).unwrap();
        assert_eq!(at.height_m, r.dataset.height_sample(0, i, j).unwrap());
        assert!((at.normal.length() - 1.0).abs() < 1e-12 && at.normal.z > 0.0);
    }
    // A plane's normal: between samples, the triangle's, which points away from the rise.
    let at = r.ground_at(100.5 * spacing_m, 40.25 * spacing_m).unwrap();
    let east = r.ground_at(100.75 * spacing_m, 40.25 * spacing_m).unwrap();
    let rise = east.height_m - at.height_m;
    assert!(rise == 0.0 || (at.normal.x < 0.0) == (rise > 0.0), "{at:?} {rise}");
}

/// Radius of the plants asked for around each point, metres.
const PLANTS_RADIUS_M: f64 = 15.0;
/// Points asked about.
const PLANT_POINTS: usize = 100;
/// Most seeds, as a share of those near the points, on which the exact oracle and pass 3 (f32,
/// its occlusion against the depth) may disagree: seeds on a cull's very edge.
const PLANTS_DISAGREEING: f64 = 0.01;

#[test]
fn the_plants_near_a_point_are_the_seeds_pass_3_selected_there() {
    let dir = synth_dataset(300, 7);
    let mut r = renderer(&dir, small_settings(SIZE[0], SIZE[1]));
    let pose = camera::over_fraction(&r, [0.45, 0.35], 25.0, 20.0, -10.0);
    r.render_resolved(&pose).unwrap();
    // Pass 3 runs on the cells of a Tile Load Map a frame or two old: let the latest arrive.
    for _ in 0..3 {
        r.render(&pose).unwrap();
    }
    let (records, _) = r.read_seeds().unwrap().unwrap();
    let camera_grid_m = pose.position_m
        - glam::DVec3::new(r.dataset.manifest.origin_m[0], r.dataset.manifest.origin_m[1], 0.0);
    let drawn: Vec<([i64; 2], u32, u32, glam::DVec2)> = records
        .iter()
        .map(|s| {
            let grid = camera_grid_m.truncate()
                + glam::Vec2::new(s.position_rel_m[0], s.position_rel_m[1]).as_dvec2();
            (s.address.map(i64::from), s.rank, SpeciesLod::unpack(s.species_lod).species, grid)
        })
        .collect();
    let ground = r.drawn_ground().unwrap().unwrap();
    let mut pixels = Pixels(3);
    let (mut points, mut near, mut disagree, mut grown_total) = (0, 0, 0, 0);
    while points < PLANT_POINTS {
        let Some(hit) = ground.pick_pixel(pixels.next()) else { continue };
        let centre = [hit.grid_m.x, hit.grid_m.y];
        points += 1;
        let selected = r.plants_near(&pose, centre, PLANTS_RADIUS_M, Plants::Selected).unwrap().unwrap();
        let grown = r.plants_near(&pose, centre, PLANTS_RADIUS_M, Plants::Grown).unwrap().unwrap();
        grown_total += grown.len();
        // Seeds within a millimetre of the circle may fall either side of it in f32.
        let off_edge =
            |p: glam::DVec2| (p.distance(glam::DVec2::from(centre)) - PLANTS_RADIUS_M).abs() > 1e-3;
        let by_gpu: Vec<_> = drawn
            .iter()
            .filter(|d| d.3.distance(glam::DVec2::from(centre)) <= PLANTS_RADIUS_M && off_edge(d.3))
            .map(|d| (d.0, d.1, d.2))
            .collect();
        let by_oracle: Vec<_> = selected
            .iter()
            .filter(|p| off_edge(p.position_grid_m.truncate()))
            .map(|p| (p.address, p.rank, p.species))
            .collect();
        near += by_gpu.len().max(by_oracle.len());
        disagree += by_gpu.iter().filter(|d| !by_oracle.contains(d)).count();
        disagree += by_oracle.iter().filter(|o| !by_gpu.contains(o)).count();
        // Every selected plant is grown there, and every grown one stands within the radius.
        for p in &selected {
            assert!(grown.iter().any(|g| g.address == p.address && g.rank == p.rank), "{p:?} not grown");
        }
        for g in &grown {
            assert!(g.position_grid_m.truncate().distance(glam::DVec2::from(centre)) <= PLANTS_RADIUS_M);
            assert!(g.radius_m > 0.0 && g.height_m > 0.0);
        }
    }
    println!(
        "{points} points, {PLANTS_RADIUS_M} m around each: {near} seeds selected near them, {disagree} on which the oracle and pass 3 disagree; {grown_total} grown"
    );
    assert!(near > 0, "no seed near any point");
    assert!(disagree as f64 <= PLANTS_DISAGREEING * near as f64, "{disagree} of {near}");
}

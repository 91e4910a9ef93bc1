//! Slicings seen around one tree: a white oak (Tree_1) of the synthetic forest, under a table that
//! grows nothing else, drawn as its mesh, its 17-plane cloud or its slicings (LOD 1):
//! - orbiting it, the slicings' view-blending switch (primary and secondary slicings trading
//!   places every 60°, cross-fading between) pops no more than the cloud, measured as the largest
//!   4 × 4 block change between consecutive frames beyond the mesh's own (`Popping`), with the oak
//!   drawn in every frame and both poppings above zero;
//! - what pass 4 draws of it with slicings is what the CPU model of the blend draws
//!   (`reference::slicing::SlicingView`, the model behind docs/slicings.md's table of the blend's
//!   error and its orbit strip), pixel by pixel, at the table's views and two more;
//! - the figure of docs/slicings.md, from three sides (ignored: it writes the docs).
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::path::{Path, PathBuf};

use glam::{DVec3, DVec4};
use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::frame::Renderer;
use terramp::gpu::gpu_types::SeedRecord;
use terramp::gpu::layout::{SeedJitter, SpeciesLod};
use terramp::impostor::Impostor;
use terramp::reference::frame_change::Popping;
use terramp::reference::slicing::SlicingView;

/// nc's table with nothing growing but white oaks (Tree_1), `per_km2` of them in its forest.
fn lone_oaks_table(per_km2: f64) -> PathBuf {
    let nc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/config/classes/nc.toml")).unwrap();
    let (mut text, mut skipping) = (String::new(), false);
    for line in nc.lines() {
        if skipping {
            skipping = line != "]";
            continue;
        }
        if line.starts_with("seeds = [") {
            skipping = !line.ends_with(']');
            continue;
        }
        text.push_str(line);
        text.push('\n');
        if line == "name = \"forest\"" {
            text.push_str(&format!("seeds = [{{ species = \"white oak\", per_km2 = {per_km2} }}]\n"));
        }
    }
    let path = std::env::temp_dir().join(format!("terramp-lone-oaks-{}.toml", std::process::id()));
    std::fs::write(&path, text).unwrap();
    path
}

/// How LOD 1 is drawn, and how far meshes reach: a row of the figure.
const MESH: ([f64; 4], bool) = ([1000.0, 1100.0, 1400.0, 3000.0], false);
const CLOUD: ([f64; 4], bool) = ([0.0, 1000.0, 1400.0, 3000.0], false);
const SLICINGS: ([f64; 4], bool) = ([0.0, 1000.0, 1400.0, 3000.0], true);

/// One oak and what draws it.
struct LoneOak {
    dataset: PathBuf,
    table: PathBuf,
    impostors: &'static Path,
    /// Its foot, dataset CRS (x, y), and its middle's height.
    foot_m: DVec3,
    middle_m: f64,
    /// Its turn about the vertical (`SeedJitter::angle`), radians.
    turn_rad: f64,
}

impl LoneOak {
    /// The oak nearest a view over the synthetic forest, or `None` without the shared models.
    fn find() -> Option<Self> {
        let impostors = terramp_testkit::nc_sliced_impostors()?;
        let mut oak = Self {
            dataset: terramp_testkit::synth_dataset(300, 7),
            table: lone_oaks_table(60.0),
            impostors,
            foot_m: DVec3::ZERO,
            middle_m: 0.0,
            turn_rad: 0.0,
        };
        let mut r = terramp_testkit::renderer(&oak.dataset, oak.settings(MESH, [320, 240]));
        let above = terramp_testkit::camera::over_fraction(&r, [0.45, 0.35], 80.0, 20.0, -35.0);
        r.render_resolved(&above).unwrap();
        let (records, _) = r.read_seeds().unwrap().unwrap();
        let distance = |s: &SeedRecord| glam::Vec3::from(s.position_rel_m).length();
        let nearest =
            records.iter().filter(|s| s.height_m > 8.0).min_by(|a, b| distance(a).total_cmp(&distance(b)));
        let nearest = nearest.expect("an oak in view");
        let white_oak = r.class_table().unwrap().species_index("white oak").unwrap() as u32;
        assert_eq!(SpeciesLod::unpack(nearest.species_lod).species, white_oak);
        let rel = nearest.position_rel_m.map(f64::from);
        oak.foot_m = above.position_m + DVec3::new(rel[0], rel[1], 0.0);
        oak.middle_m = f64::from(nearest.ground_m) + 0.5 * f64::from(nearest.height_m);
        oak.turn_rad = f64::from(turn_rad(nearest));
        Some(oak)
    }

    fn settings(&self, (reach_m, slicings): ([f64; 4], bool), [width, height]: [u32; 2]) -> Settings {
        let mut s = terramp_testkit::small_settings(width, height);
        s.draw_seeds.impostors = self.impostors.to_str().unwrap().to_owned();
        s.seeds.class_table = self.table.to_str().unwrap().to_owned();
        s.draw_seeds.reach_m = reach_m;
        s.draw_seeds.slicings = slicings;
        s
    }

    /// Looking along `yaw_deg` at the oak from `distance_m`, level with its middle.
    fn camera(&self, yaw_deg: f64, distance_m: f64, fov_deg: f64) -> Camera {
        let (sin, cos) = yaw_deg.to_radians().sin_cos();
        let position_m =
            DVec3::new(self.foot_m.x - distance_m * sin, self.foot_m.y - distance_m * cos, self.middle_m);
        Camera { position_m, yaw_deg, pitch_deg: 0.0, roll_deg: 0.0, fov_deg, near_m: 0.1 }
    }

    /// Looking at the oak's middle from `distance_m` along `eye_model` (a direction from its
    /// middle in its model space: x and z horizontal, y up).
    fn camera_from_model(&self, eye_model: glam::Vec3, distance_m: f64, fov_deg: f64) -> Camera {
        let eye = model_to_world(eye_model.as_dvec3().normalize(), self.turn_rad);
        let position_m = DVec3::new(self.foot_m.x, self.foot_m.y, self.middle_m) + eye * distance_m;
        let (yaw_deg, pitch_deg) = ((-eye.x).atan2(-eye.y).to_degrees(), (-eye.z).asin().to_degrees());
        Camera { position_m, yaw_deg, pitch_deg, roll_deg: 0.0, fov_deg, near_m: 0.1 }
    }
}

/// A seed's turn about the vertical, radians, as pass 4 takes it from its jitter.
fn turn_rad(record: &SeedRecord) -> f32 {
    SeedJitter::unpack(record.jitter).angle as f32 * (std::f32::consts::TAU / 65536.0)
}

/// Model space (x, y up, z) to world (x east, y north, z up), turned by `turn_rad` about the
/// vertical: the shader's `model_to_world`.
fn model_to_world(v: DVec3, turn_rad: f64) -> DVec3 {
    let (s, c) = turn_rad.sin_cos();
    let w = DVec3::new(v.x, -v.z, v.y);
    DVec3::new(c * w.x - s * w.y, s * w.x + c * w.y, w.z)
}

/// Its inverse.
fn world_to_model(v: DVec3, turn_rad: f64) -> DVec3 {
    let (s, c) = turn_rad.sin_cos();
    let w = DVec3::new(c * v.x + s * v.y, c * v.y - s * v.x, v.z);
    DVec3::new(w.x, w.z, -w.y)
}

/// The oak's record in `r`'s last frame from `camera` (the seed anchored at its foot), checked to
/// be drawn as `lod`, and every record of the frame.
fn oak_record(r: &Renderer, oak: &LoneOak, camera: &Camera, lod: u32) -> (SeedRecord, Vec<SeedRecord>) {
    let (records, _) = r.read_seeds().unwrap().unwrap();
    let foot_rel = oak.foot_m - camera.position_m;
    let off = |s: &SeedRecord| {
        (f64::from(s.position_rel_m[0]) - foot_rel.x).hypot(f64::from(s.position_rel_m[1]) - foot_rel.y)
    };
    let seed = *records.iter().min_by(|a, b| off(a).total_cmp(&off(b))).expect("seeds in view");
    assert!(off(&seed) < 0.01, "the oak was not selected: the nearest seed is {} m off", off(&seed));
    assert_eq!(SpeciesLod::unpack(seed.species_lod).lod, lod, "the oak is not drawn as LOD {lod}");
    (seed, records)
}

/// Pixels of `r`'s last frame where a seed was drawn (its depth in front of the terrain's).
fn seed_pixels(r: &Renderer) -> u32 {
    let (depth, terrain) = (r.read_depth().unwrap(), r.terrain_depth().unwrap());
    depth.iter().zip(&terrain).filter(|(d, t)| d > t).count() as u32
}

#[test]
fn orbiting_a_tree_the_slicings_switch_pops_no_more_than_the_cloud() {
    let Some(oak) = LoneOak::find() else { return };
    // 90° around it in 1° steps from 40 m, through the switches at 30° and 90° (and a cross-fade
    // everywhere in between). Every frame has the oak in it, drawn as the row's LOD: its fewest
    // seed pixels are kept.
    let orbit = |row: ([f64; 4], bool)| {
        let mut r = terramp_testkit::renderer(&oak.dataset, oak.settings(row, [240, 180]));
        let lod = if row.0[0] > 0.0 { 0 } else { 1 };
        let mut fewest_px = u32::MAX;
        let frames = (0..=90)
            .map(|step| {
                let camera = oak.camera(f64::from(step), 40.0, 30.0);
                let frame = terramp_testkit::settled_colour(&mut r, &camera);
                oak_record(&r, &oak, &camera, lod);
                fewest_px = fewest_px.min(seed_pixels(&r));
                frame
            })
            .collect::<Vec<_>>();
        (frames, fewest_px)
    };
    let ((mesh, mesh_px), (cloud, cloud_px), (slicings, slicings_px)) =
        (orbit(MESH), orbit(CLOUD), orbit(SLICINGS));
    let cloud_popping = Popping::of(&cloud, &mesh).unwrap();
    let slicings_popping = Popping::of(&slicings, &mesh).unwrap();
    println!(
        "orbiting an oak, 1° a frame, 40 m away: popping beyond its mesh's: 17-plane cloud {cloud_popping:?}, slicings {slicings_popping:?}; the fewest seed pixels of a frame: mesh {mesh_px}, cloud {cloud_px}, slicings {slicings_px} of {}",
        240 * 180
    );
    // Real quantities: the oak is drawn in every frame (at least 1,362 pixels measured), and both
    // LOD 1s pop beyond the mesh (a comparison of two zeros would say nothing).
    assert!(mesh_px.min(cloud_px).min(slicings_px) > 1000, "the oak is hardly in view");
    assert_eq!((cloud_popping.pairs, slicings_popping.pairs), (90, 90));
    assert!(
        cloud_popping.popping > 1.0 && slicings_popping.popping > 1.0,
        "nothing pops: {cloud_popping:?}, {slicings_popping:?}"
    );
    // Shown failing with the dither ranges given by role (the shader before db73959): 18.1.
    assert!(
        slicings_popping.popping <= cloud_popping.popping,
        "slicings pop {} beyond the mesh, the cloud {}",
        slicings_popping.popping,
        cloud_popping.popping
    );
}

/// Side of the GPU == model views, pixels.
const BLEND_VIEW_PX: u32 = 160;

/// One view of the oak drawn by pass 4 with slicings, against the CPU model of what it draws
/// (`reference::slicing::SlicingView`: the stochastic blend's nearest kept opaque texel, or the
/// trunk mesh), pixel by pixel over those the oak's bounding sphere covers.
#[derive(Debug, Clone, Copy, Default)]
struct Coverage {
    /// Pixels the oak's sphere covers.
    region: u32,
    /// Of them, those the model draws the oak on (in front of the terrain).
    model: u32,
    /// Those pass 4 drew a seed on (its depth in front of the terrain's).
    gpu: u32,
    /// Both.
    both: u32,
    /// Pixels of the region inside another seed's bounding sphere (where it might draw).
    others: u32,
}

impl Coverage {
    /// Pixels both draw over pixels either draws.
    fn agreement(&self) -> f64 {
        f64::from(self.both) / f64::from(self.model + self.gpu - self.both).max(1.0)
    }
}

/// What a model of the blend is given: the eye it blends for (model space) and the dither's
/// shift, by default those pass 4 used.
#[derive(Debug, Clone, Copy)]
struct ModelInput {
    /// Turns the eye about the vertical before the blend is chosen, degrees.
    eye_turn_deg: f32,
    /// Added to the seed's rank for the dither's shift.
    shift_offset: u32,
}

const AS_DRAWN: ModelInput = ModelInput { eye_turn_deg: 0.0, shift_offset: 0 };

/// The last frame of `r` (slicings, `BLEND_VIEW_PX`² from `camera`) against the model of the
/// oak's seed, given `input`.
fn blend_coverage(
    r: &Renderer,
    oak: &LoneOak,
    tree: &Impostor,
    camera: &Camera,
    input: ModelInput,
) -> Coverage {
    let px = BLEND_VIEW_PX;
    let (seed, records) = oak_record(r, oak, camera, 1);
    let turn = f64::from(turn_rad(&seed));
    let anchor = DVec3::from(seed.position_rel_m.map(f64::from));
    let height_m = f64::from(seed.height_m);
    // Model space is scaled by the seed's height over the model's (its mesh's top, as pass 4's
    // assets measure it).
    let top_m = tree.mesh.vertices.iter().map(|v| v.position_model_m[1]).fold(f32::MIN, f32::max);
    let scale = height_m / f64::from(top_m);
    // The eye from the crown's middle, as pass 4's `slice_blend` takes it.
    let sink = r.settings.seeds.sink_fraction;
    let middle = anchor + DVec3::Z * height_m * (sink + 0.5);
    let eye_model = world_to_model(-middle, turn).as_vec3();
    let eye_model = glam::Quat::from_rotation_y(-input.eye_turn_deg.to_radians()) * eye_model;
    let view = SlicingView::new(tree, eye_model, r.settings.draw_seeds.slicing_brightness as f32).unwrap();
    let shift = (seed.rank + input.shift_offset) & 15;
    let sphere = &tree.bounding_sphere;
    let centre = anchor + model_to_world(glam::Vec3::from(sphere.centre_model_m).as_dvec3() * scale, turn);
    let radius_m = f64::from(sphere.radius_m) * scale;
    let origin_model = (world_to_model(-anchor, turn) / scale).as_vec3();

    let (depth, terrain) = (r.read_depth().unwrap(), r.terrain_depth().unwrap());
    let clip_from_world = camera.clip_from_view(px, px).unwrap() * camera.view_from_world();
    let world_from_clip = clip_from_world.inverse();
    let forward = camera.forward();
    let table = r.class_table().unwrap();
    let other_spheres: Vec<(DVec3, f64)> = records
        .iter()
        .filter(|s| s.address != seed.address || s.rank != seed.rank)
        .map(|s| {
            let h = f64::from(s.height_m);
            let species = &table.species[SpeciesLod::unpack(s.species_lod).species as usize];
            (
                DVec3::from(s.position_rel_m.map(f64::from)) + DVec3::Z * 0.5 * h,
                h * f64::from(species.radius_per_height),
            )
        })
        .collect();
    let mut c = Coverage::default();
    for y in 0..px {
        for x in 0..px {
            let i = (y * px + x) as usize;
            let ndc = DVec4::new(
                2.0 * (f64::from(x) + 0.5) / f64::from(px) - 1.0,
                1.0 - 2.0 * (f64::from(y) + 0.5) / f64::from(px),
                1.0,
                1.0,
            );
            let p = world_from_clip * ndc;
            let ray = (p.truncate() / p.w).normalize();
            let along = centre.dot(ray);
            if centre.length_squared() - along * along > radius_m * radius_m {
                continue;
            }
            c.region += 1;
            let within = |(centre, radius): &(DVec3, f64)| {
                let along = centre.dot(ray);
                centre.length_squared() - along * along <= radius * radius && along > 0.0
            };
            c.others += u32::from(other_spheres.iter().any(within));
            let dir_model = world_to_model(ray, turn).as_vec3();
            let slices = view.stochastic(origin_model, dir_model, [x, y], shift).map(|(t, _)| t);
            let trunk = view.trunk(origin_model, dir_model);
            let nearest = [slices, trunk].into_iter().flatten().min_by(f32::total_cmp);
            // Reversed-Z with an infinite far plane: depth is the near plane over the distance
            // along the view, the larger the nearer.
            let model = nearest.is_some_and(|t| {
                camera.near_m / (f64::from(t) * scale * ray.dot(forward)) > f64::from(terrain[i])
            });
            let gpu = depth[i] > terrain[i];
            c.model += u32::from(model);
            c.gpu += u32::from(gpu);
            c.both += u32::from(model && gpu);
        }
    }
    c
}

/// Pixels both draw over pixels either draws that the model and pass 4 must reach. The model
/// samples the baked atlas's nearest texel of mip 0; pass 4 filters the texture array's layer (the
/// atlas resampled to the layers' common size, and its mips) and alpha-tests that, so a crown's
/// edges differ by up to a texel: at 0°, where the dither plays no part, that alone leaves 0.950.
/// Measured 0.930 to 0.950 on lavapipe; a model with the wrong eye or the wrong dither shift
/// reaches at most 0.901.
const MIN_AGREEMENT: f64 = 0.915;

#[test]
fn the_gpu_draws_the_slicings_blend_the_model_draws() {
    let Some(oak) = LoneOak::find() else { return };
    let tree = terramp::impostor::load(oak.impostors, "Tree_1").unwrap();
    let mut r = terramp_testkit::renderer(&oak.dataset, oak.settings(SLICINGS, [BLEND_VIEW_PX; 2]));
    // The views of docs/slicings.md's table of the blend's error, 0° to 29° off slicing 0 (where
    // slicing 0 is the lower of the two blended), and two past half-way to slicing 1 (where it is
    // the higher), 0.2 above the horizon; here 40 m away, 30° wide.
    for degrees in [0.0f32, 10.0, 20.0, 29.0, 40.0, 50.0] {
        let a = degrees.to_radians();
        let camera = oak.camera_from_model(glam::Vec3::new(a.cos(), 0.2, a.sin()), 40.0, 30.0);
        r.render_resolved(&camera).unwrap();
        let c = blend_coverage(&r, &oak, &tree, &camera, AS_DRAWN);
        // The controls: a model blending for an eye 30° away, or shifting the dither otherwise.
        let turned = blend_coverage(&r, &oak, &tree, &camera, ModelInput { eye_turn_deg: 30.0, ..AS_DRAWN });
        let shifted = blend_coverage(&r, &oak, &tree, &camera, ModelInput { shift_offset: 5, ..AS_DRAWN });
        println!(
            "{degrees:>4}° from slicing 0: {c:?}, agreement {:.3}; the model's eye turned 30°: {:.3}; its dither shifted: {:.3}",
            c.agreement(),
            turned.agreement(),
            shifted.agreement()
        );
        assert_eq!(c.others, 0, "another seed may draw over the oak: {c:?}");
        assert!(c.model > 1000 && c.gpu > 1000, "the oak is hardly in view: {c:?}");
        assert!(c.agreement() >= MIN_AGREEMENT, "{degrees}°: pass 4 and the model differ: {c:?}");
        assert!(turned.agreement() < MIN_AGREEMENT, "{degrees}°: the wrong eye passes: {turned:?}");
        // On slicing 0's orientation one slicing is drawn whole: no dither to shift.
        if degrees > 0.0 {
            assert!(shifted.agreement() < MIN_AGREEMENT, "{degrees}°: the wrong dither passes: {shifted:?}");
        }
    }
}

/// The figure of docs/slicings.md: the oak as its mesh, its 17-plane cloud and its slicings
/// (rows), from three sides (columns), 15 m away. `cargo test --release --test slicings_views --
/// --ignored`.
#[test]
#[ignore = "writes docs/slicings_three_ways.png"]
fn three_ways_figure() {
    let oak = LoneOak::find().expect("../shared/data");
    let mut sheet = image::RgbaImage::from_pixel(3 * 324, 3 * 244, image::Rgba([255; 4]));
    for (row, lod1) in [MESH, CLOUD, SLICINGS].into_iter().enumerate() {
        let mut r = terramp_testkit::renderer(&oak.dataset, oak.settings(lod1, [320, 240]));
        for (column, yaw_deg) in [0.0f64, 120.0, 240.0].into_iter().enumerate() {
            let frame = terramp_testkit::settled_colour(&mut r, &oak.camera(yaw_deg, 15.0, 45.0));
            image::imageops::replace(&mut sheet, &frame, (column * 324) as i64, (row * 244) as i64);
        }
    }
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/slicings_three_ways.png");
    sheet.save(&path).unwrap();
    println!("wrote {}", path.display());
}

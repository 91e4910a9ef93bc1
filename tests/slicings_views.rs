//! Slicings seen around one tree: a white oak (Tree_1) of the synthetic forest, under a table that
//! grows nothing else, drawn as its mesh, its 17-plane cloud or its slicings (LOD 1):
//! - orbiting it, the slicings' view-blending switch (primary and secondary slicings trading
//!   places every 60°, cross-fading between) pops no more than the cloud, measured as the largest
//!   4 × 4 block change between consecutive frames beyond the mesh's own (`Popping`);
//! - the figure of docs/slicings.md, from three sides (ignored: it writes the docs).
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::path::{Path, PathBuf};

use glam::DVec3;
use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::gpu::gpu_types::SeedRecord;
use terramp::gpu::layout::SpeciesLod;
use terramp::reference::frame_change::Popping;

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
        Camera { position_m, yaw_deg, pitch_deg: 0.0, fov_deg, near_m: 0.1 }
    }
}

#[test]
fn orbiting_a_tree_the_slicings_switch_pops_no_more_than_the_cloud() {
    let Some(oak) = LoneOak::find() else { return };
    // 90° around it in 1° steps from 40 m, through the switches at 30° and 90° (and a cross-fade
    // everywhere in between).
    let orbit = |row| {
        let mut r = terramp_testkit::renderer(&oak.dataset, oak.settings(row, [240, 180]));
        (0..=90)
            .map(|step| terramp_testkit::settled_colour(&mut r, &oak.camera(f64::from(step), 40.0, 30.0)))
            .collect::<Vec<_>>()
    };
    let (mesh, cloud, slicings) = (orbit(MESH), orbit(CLOUD), orbit(SLICINGS));
    let cloud_popping = Popping::of(&cloud, &mesh).unwrap();
    let slicings_popping = Popping::of(&slicings, &mesh).unwrap();
    println!(
        "orbiting an oak, 1° a frame, 40 m away: popping beyond its mesh's: 17-plane cloud {cloud_popping:?}, slicings {slicings_popping:?}"
    );
    assert!(
        slicings_popping.popping <= cloud_popping.popping,
        "slicings pop {} beyond the mesh, the cloud {}",
        slicings_popping.popping,
        cloud_popping.popping
    );
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

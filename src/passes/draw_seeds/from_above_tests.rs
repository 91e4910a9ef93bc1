#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use glam::Vec3;

use super::{FromAbove, Layers, SeedLight, from_above, turned_facing};
use crate::gpu::gpu_types::{SeedDrawArgs, SeedMaterial, SeedVertex};
use crate::gpu::layout::{FOLIAGE_SKY, FOLIAGE_SUN, FOLIAGE_SUN_WRAP, MATERIAL_BARK, MATERIAL_TEXTURED};
use crate::texcell::pyramid::decode_srgb;

/// A unit square, model space (y up), `up` its normal's upward component (1: lying flat, 0:
/// standing), at height `y`, of material `material`, with texture coordinates over [0, 1]².
fn square(up: f32, y: f32, material: u32) -> [SeedVertex; 4] {
    let across = (1.0 - up * up).sqrt();
    // Two edges: x, and one tilted from z towards y so that the normal's y is `up`.
    let (e0, e1) = (Vec3::X, Vec3::new(0.0, across, -up));
    let corner = |p: Vec3, uv: [f32; 2]| SeedVertex {
        position_model_m: (p + Vec3::new(0.0, y, 0.0)).to_array(),
        normal_model: [0.0, up, across],
        uv,
        material,
        pivot_model_m: [0.0; 3],
    };
    [
        corner(Vec3::ZERO, [0.0, 0.0]),
        corner(e0, [1.0, 0.0]),
        corner(e0 + e1, [1.0, 1.0]),
        corner(e1, [0.0, 1.0]),
    ]
}

/// What squares `squares` (each: upward normal component, height, material) of `materials`
/// show from above, with texture layers `levels` of side `size`.
fn seen(
    squares: &[(f32, f32, u32)],
    materials: &[SeedMaterial],
    (levels, size): (&[Vec<Vec<u8>>], u32),
    crown_shading: f32,
) -> Option<FromAbove> {
    let vertices: Vec<SeedVertex> = squares.iter().flat_map(|&(up, y, m)| square(up, y, m)).collect();
    let indices: Vec<u32> =
        (0..squares.len() as u32).flat_map(|q| [0, 1, 2, 0, 2, 3].map(|i| 4 * q + i)).collect();
    let template = SeedDrawArgs { index_count: indices.len() as u32, ..Default::default() };
    let layers = Layers { levels, size };
    from_above(&template, (&vertices, &indices), materials, &layers, (crown_shading, 1.0))
}

fn plain(rgb: [f32; 3], flags: u32) -> SeedMaterial {
    SeedMaterial {
        base_colour: [rgb[0], rgb[1], rgb[2], 1.0],
        alpha_cutoff: 0.5,
        flags,
        ..Default::default()
    }
}

fn close(a: f32, b: f32, tolerance: f32) -> bool {
    (a - b).abs() <= tolerance
}

#[test]
fn the_sun_over_a_turning_normal_is_the_mean_of_its_turns() {
    // The closed form against the mean over 3,600 turns, for normals and suns of every height.
    for up in [0.0f32, 0.2, 0.5, 0.8, 1.0] {
        for elevation_deg in [-10.0f32, 5.0, 30.0, 60.0, 90.0] {
            let e = elevation_deg.to_radians();
            let sun = Vec3::new(0.3 * e.cos(), -(1.0f32 - 0.09).sqrt() * e.cos(), e.sin());
            let across = (1.0 - up * up).sqrt();
            let turns = 3600;
            let mean = (0..turns)
                .map(|k| {
                    let t = k as f32 / turns as f32 * std::f32::consts::TAU;
                    Vec3::new(across * t.cos(), across * t.sin(), up).dot(sun).max(0.0)
                })
                .sum::<f32>()
                / turns as f32;
            let closed = turned_facing(up, sun);
            // The sum's own error over 3,600 steps is about 1e-4.
            assert!(close(closed, mean, 1e-3), "up {up}, sun at {elevation_deg}°: {closed} against {mean}");
        }
    }
}

#[test]
fn flat_foliage_seen_from_above_is_scaled_to_the_ground_s_light() {
    let green = [0.1, 0.4, 0.05];
    let seen = seen(&[(1.0, 0.0, 0)], &[plain(green, 0)], (&[], 1), 0.0).unwrap();
    assert_eq!(seen.albedo, green);
    let sun = Vec3::new(0.0, 0.6, 0.8);
    // A reddened sun and a blue sky, as the air gives at a lowish sun.
    let air = SeedLight { sun: [0.9, 0.8, 0.6], sky: [0.05, 0.08, 0.15] };
    assert!(close(seen.facing(sun), 0.8, 1e-6));
    assert_eq!(seen.yardstick(sun), [green[0], green[1], green[2], seen.facing(sun)]);
    // A leaf lying flat faces the sun by its height: lit as foliage is, 0.8 of the sun's share.
    let lit = seen.lit(sun, &air);
    let scale = seen.photo_scale(sun, &air);
    for c in 0..3 {
        let foliage = air.sun[c] * (FOLIAGE_SUN * 0.8 + FOLIAGE_SUN_WRAP * 0.8) + air.sky[c] * FOLIAGE_SKY;
        assert!(close(lit[c], green[c] * foliage, 1e-5), "{lit:?}");
        let ground = air.sun[c] * 0.8 + air.sky[c];
        assert!(close(scale[c], ground / (green[c] * foliage), 1e-4), "{scale:?}");
    }
    // No light (the sun below the horizon, a dark sky): the model keeps its colours.
    let night = SeedLight { sun: [0.0; 3], sky: [0.0; 3] };
    assert_eq!(seen.photo_scale(sun, &night), [0.0; 3]);
}

#[test]
fn bark_is_left_out_and_nothing_but_bark_is_not_measured() {
    let (leaf, bark) = ([0.1, 0.5, 0.1], [0.4, 0.3, 0.2]);
    let materials = [plain(leaf, 0), plain(bark, MATERIAL_BARK)];
    let both = seen(&[(1.0, 0.0, 0), (1.0, 0.0, 1)], &materials, (&[], 1), 0.0).unwrap();
    assert_eq!(both.albedo, leaf);
    assert_eq!(seen(&[(1.0, 0.0, 1)], &materials, (&[], 1), 0.0), None);
}

#[test]
fn squares_weigh_by_how_squarely_they_face_up_and_by_the_texels_the_alpha_test_keeps() {
    // A textured layer 64² whose left half is cut away (alpha 0) and right half sRGB 128 grey.
    let size = 64;
    let texels: Vec<u8> = (0..size * size)
        .flat_map(|i| if i % size < size / 2 { [0, 0, 0, 0] } else { [128, 128, 128, 255] })
        .collect();
    let levels = vec![vec![texels]];
    let grey = decode_srgb(128);
    let textured = SeedMaterial { flags: MATERIAL_TEXTURED, layer: 0, ..plain([1.0, 0.0, 0.0], 0) };
    let red_leaf = seen(&[(1.0, 0.0, 0)], &[textured], (&levels, size), 0.0).unwrap();
    assert!(close(red_leaf.albedo[0], grey, 1e-5) && red_leaf.albedo[1] == 0.0, "{:?}", red_leaf.albedo);
    // With a flat opaque blue square beside it: the textured one weighs half (half its texels kept).
    let materials = [textured, plain([0.0, 0.0, 1.0], 0)];
    let both = seen(&[(1.0, 0.0, 0), (1.0, 0.0, 1)], &materials, (&levels, size), 0.0).unwrap();
    let want = [grey * 0.5 / 1.5, 0.0, 1.0 / 1.5];
    for c in 0..3 {
        assert!(close(both.albedo[c], want[c], 1e-5), "{:?} against {want:?}", both.albedo);
    }
    // An upright square counts as seen from 45°: half of a flat one's weight (`MIN_UP_FACING`).
    let materials = [plain([1.0, 0.0, 0.0], 0), plain([0.0, 0.0, 1.0], 0)];
    let upright = seen(&[(1.0, 0.0, 0), (0.0, 0.0, 1)], &materials, (&[], 1), 0.0).unwrap();
    let want = [1.0 / 1.5, 0.0, 0.5 / 1.5];
    for c in 0..3 {
        assert!(close(upright.albedo[c], want[c], 1e-5), "{:?} against {want:?}", upright.albedo);
    }
}

#[test]
fn crown_shading_darkens_the_low_crown_by_its_mean_over_the_turns() {
    let white = [plain([1.0; 3], 0)];
    // A flat square at the crown's top (height 1 of a model 1 m tall) and one at its foot.
    let top = seen(&[(1.0, 1.0, 0)], &white, (&[], 1), 0.4).unwrap();
    let foot = seen(&[(1.0, 0.0, 0)], &white, (&[], 1), 0.4).unwrap();
    // 1 − shading × (½ (1 − height) + ¼): the side term's mean over the turns is ¼.
    assert!(close(top.albedo[0], 1.0 - 0.4 * 0.25, 1e-6), "{:?}", top.albedo);
    assert!(close(foot.albedo[0], 1.0 - 0.4 * 0.75, 1e-6), "{:?}", foot.albedo);
}

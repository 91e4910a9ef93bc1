//! Slicings (Jakulin 2000) baked from the shared models (`terramp::bake`, `BakeOptions::slicing`):
//! the trunk and limbs (bark materials) stay the mesh, the crown goes onto 6 slicings of 5 slices;
//! a model without a crown gets none; the slices of a slicing line up (one box, equally spaced);
//! every crown vertex shows (an opaque texel within 2 texels of where it projects) on some slice
//! of some slicing, and in each slicing all but the few on leaves it sees edge-on; all of it read
//! back from the impostor folder. The 17-plane billboard cloud's figure is printed beside it.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use glam::Vec3;
use terramp::bake::{BakeOptions, SlicingOptions, bake_models};
use terramp::impostor::slicing::orientation;
use terramp::impostor::{Impostor, MipChain, Plane, load};
use terramp_testkit::{TempDir, shared_data};

const OPTIONS: SlicingOptions = SlicingOptions { orientations: 6, slices: 5 };

/// The model's crown vertices (those of its materials that are not bark), model space.
fn crown_vertices(impostor: &Impostor) -> Vec<Vec3> {
    let mesh = &impostor.mesh;
    mesh.submeshes
        .iter()
        .filter(|s| !mesh.materials[s.material as usize].is_bark())
        .flat_map(|s| &mesh.indices[s.first_index as usize..(s.first_index + s.index_count) as usize])
        .map(|&i| Vec3::from(mesh.vertices[i as usize].position_model_m))
        .collect()
}

/// Whether `plane`'s rectangle of `atlas` has an opaque texel within `reach` texels of where `p`
/// projects.
fn shows(atlas: &MipChain, plane: &Plane, p: Vec3, reach: i64) -> bool {
    let [w, h] = atlas.size;
    let corners = plane.corners_model_m.map(Vec3::from);
    let (right, up) = (corners[1] - corners[0], corners[3] - corners[0]);
    let (s, t) = (
        (p - corners[0]).dot(right) / right.length_squared(),
        (p - corners[0]).dot(up) / up.length_squared(),
    );
    // Corner 0 (bottom left) is at (uv_min.x, uv_max.y); v grows downwards.
    let u = plane.uv_min[0] + s * (plane.uv_max[0] - plane.uv_min[0]);
    let v = plane.uv_max[1] - t * (plane.uv_max[1] - plane.uv_min[1]);
    let (x, y) = ((u * w as f32) as i64, (v * h as f32) as i64);
    (-reach..=reach).any(|dy| {
        (-reach..=reach).any(|dx| {
            let (xx, yy) = (x + dx, y + dy);
            xx >= 0
                && yy >= 0
                && xx < i64::from(w)
                && yy < i64::from(h)
                && atlas.levels[0][4 * (yy as usize * w as usize + xx as usize) + 3] >= 128
        })
    })
}

#[test]
fn crowns_are_sliced_trunks_stay_meshes_and_every_crown_vertex_shows_in_a_slicing() {
    let Some(shared) = shared_data() else { return };
    let models = shared.join("models");
    let out = TempDir::new("slicings");
    let files: Vec<_> = ["Pine_1", "Bush_1", "DeadTree_1"].map(|m| models.join(format!("{m}.glb"))).into();
    let options = BakeOptions { texels: 512, slicing: Some(OPTIONS), ..Default::default() };
    bake_models(None, &files, out.path(), &options, false).unwrap();
    let [pine, bush, dead] = ["Pine_1", "Bush_1", "DeadTree_1"].map(|m| load(out.path(), m).unwrap());

    assert!(dead.slicing.is_none(), "an all-bark model has no crown to slice");
    let triangles = |i: &Impostor| i.mesh.indices.len() as u32 / 3;
    let bush_slicing = bush.slicing.as_ref().unwrap();
    assert_eq!((bush_slicing.crown_triangles, bush_slicing.trunk_triangles), (triangles(&bush), 0));
    let slicing = pine.slicing.as_ref().unwrap();
    println!(
        "Pine_1: crown {} triangles sliced, trunk {} left to the mesh, ε = {:.2} m",
        slicing.crown_triangles, slicing.trunk_triangles, slicing.lod.epsilon_m
    );
    assert_eq!(slicing.crown_triangles + slicing.trunk_triangles, triangles(&pine));
    assert!(slicing.trunk_triangles > 0 && slicing.crown_triangles > slicing.trunk_triangles);
    assert_eq!(slicing.lod.planes.len(), 30);

    let crown = crown_vertices(&pine);
    let slices = OPTIONS.slices as usize;
    for (i, planes) in slicing.lod.planes.chunks(slices).enumerate() {
        let normal = orientation(i as u32, OPTIONS.orientations);
        // One box: each slice is the first moved along the normal by a whole number of spacings.
        let spacing =
            normal.dot(Vec3::from(planes[1].corners_model_m[0]) - Vec3::from(planes[0].corners_model_m[0]));
        for (j, plane) in planes.iter().enumerate() {
            assert!((Vec3::from(plane.normal_model) - normal).length() < 1e-5);
            for (c, corner) in plane.corners_model_m.iter().enumerate() {
                let moved = Vec3::from(planes[0].corners_model_m[c]) + normal * spacing * j as f32;
                assert!((Vec3::from(*corner) - moved).length() < 1e-3, "slicing {i} slice {j} corner {c}");
            }
        }
        let atlas = &slicing.lod.atlas;
        let missing =
            crown.iter().filter(|&&p| !planes.iter().any(|plane| shows(atlas, plane, p, 2))).count();
        println!("slicing {i}: {missing} of {} crown vertices show on none of its slices", crown.len());
        // A leaf seen edge-on from the slicing's side draws nothing there (as in the mesh): the
        // reason two slicings are blended.
        assert!(missing * 10 <= crown.len(), "slicing {i} loses {missing} of {} crown vertices", crown.len());
    }
    let atlas = &slicing.lod.atlas;
    let in_none =
        crown.iter().filter(|&&p| !slicing.lod.planes.iter().any(|plane| shows(atlas, plane, p, 2))).count();
    println!("all slicings: {in_none} of {} crown vertices show on none of their slices", crown.len());
    assert_eq!(in_none, 0, "crown vertices lost by every slicing");
    let cloud = &pine.lods[0];
    let missing =
        crown.iter().filter(|&&p| !cloud.planes.iter().any(|plane| shows(&cloud.atlas, plane, p, 2))).count();
    println!("17-plane cloud: {missing} of {} crown vertices show on none of its planes", crown.len());
}

/// A frame of the synthetic forest from 30 m up, with every seed near enough drawn as LOD 1 (no
/// meshes), by `impostors` (or none), with slicings on or off.
fn lod1_frame(dir: &std::path::Path, impostors: &str, slicings: bool, brightness: f64) -> image::RgbaImage {
    let mut s = terramp_testkit::small_settings(320, 180);
    s.draw_seeds.impostors = impostors.to_owned();
    s.draw_seeds.reach_m = [0.0, 1000.0, 1400.0, 3000.0];
    s.draw_seeds.slicings = slicings;
    s.draw_seeds.slicing_brightness = brightness;
    let mut r = terramp_testkit::renderer(dir, s);
    let pose = terramp_testkit::camera::over_fraction(&r, [0.45, 0.35], 30.0, 20.0, -12.0);
    terramp_testkit::settled_colour(&mut r, &pose)
}

#[test]
fn slicings_draw_lod_1_where_the_clouds_would_with_their_trunks() {
    let Some(sliced) = terramp_testkit::nc_sliced_impostors() else { return };
    let sliced = sliced.to_str().unwrap();
    let dir = terramp_testkit::synth_dataset(300, 7);
    let bare = lod1_frame(&dir, "", false, 0.5);
    let clouds = lod1_frame(&dir, sliced, false, 0.5);
    let slices = lod1_frame(&dir, sliced, true, 0.5);
    let uncorrected = lod1_frame(&dir, sliced, true, 0.0);
    let trees = |frame: &image::RgbaImage| -> Vec<bool> {
        frame.pixels().zip(bare.pixels()).map(|(p, q)| p != q).collect()
    };
    let (by_clouds, by_slices, by_uncorrected) = (trees(&clouds), trees(&slices), trees(&uncorrected));
    let count = |mask: &[bool]| mask.iter().filter(|&&t| t).count();
    let both = by_clouds.iter().zip(&by_slices).filter(|&(&a, &b)| a && b).count();
    let either = by_clouds.iter().zip(&by_slices).filter(|&(&a, &b)| a || b).count();
    println!(
        "tree pixels: 17-plane clouds {}, slicings {} ({} without the brightness correction); both {both} of either {either}",
        count(&by_clouds),
        count(&by_slices),
        count(&by_uncorrected)
    );
    assert!(count(&by_clouds) > 3000, "too few trees to judge");
    // The same trees, drawn otherwise: they cover much the same pixels.
    let ratio = count(&by_slices) as f64 / count(&by_clouds) as f64;
    assert!((0.6..1.6).contains(&ratio), "slicings cover {ratio:.2} of the clouds' pixels");
    assert!(both * 2 > either, "slicings and clouds share only {both} of {either} tree pixels");
    // The correction makes up for the blend's thinning: more of each crown shows with it.
    assert!(count(&by_slices) > count(&by_uncorrected), "the brightness correction changed nothing");
    assert_ne!(slices, clouds);
}

#[test]
fn the_stochastic_blend_keeps_the_sorted_blends_picture_over_its_dither() {
    let Some(shared) = shared_data() else { return };
    let out = TempDir::new("slicing-blend");
    let options = BakeOptions { texels: 1024, slicing: Some(OPTIONS), ..Default::default() };
    bake_models(None, &[shared.join("models/Tree_1.glb")], out.path(), &options, false).unwrap();
    let tree = load(out.path(), "Tree_1").unwrap();
    let mut errors = Vec::new();
    for degrees in [0.0f32, 10.0, 20.0, 29.0] {
        let a = degrees.to_radians();
        let eye = Vec3::new(a.cos(), 0.2, a.sin());
        let e = terramp::reference::slicing::blend_error(&tree, eye, 0.5, 0).unwrap();
        println!(
            "{degrees:>4}° from slicing 0: {:.2} levels of 255 per 4 × 4 block over {} blocks, coverage {:.3} of the sorted blend's",
            e.mean_abs, e.blocks, e.coverage_ratio
        );
        errors.push(e);
    }
    // On an orientation one slicing is drawn, opaque: both blends are its nearest texels.
    assert_eq!(errors[0].mean_abs, 0.0);
    assert!((errors[0].coverage_ratio - 1.0).abs() < 1e-9);
    for e in &errors[1..] {
        assert!(e.blocks > 100 && e.mean_abs > 0.0, "{e:?}");
        assert!(e.mean_abs < 15.0 && (0.9..1.1).contains(&e.coverage_ratio), "{e:?}");
    }
}

/// The figure of docs/slicings.md: Tree_1's crown seen from 0° to 60° off slicing 0 (its slices
/// facing +X) in 10° steps, 0.2 above the horizon: the paper's sorted blend above, pass 4's
/// stochastic one below, over grey. `cargo test --release --test slicings -- --ignored`.
#[test]
#[ignore = "writes docs/slicings_orbit.png"]
fn orbit_figure() {
    let shared = shared_data().expect("../shared/data");
    let out = TempDir::new("slicing-orbit");
    let options = BakeOptions { texels: 1024, slicing: Some(OPTIONS), ..Default::default() };
    bake_models(None, &[shared.join("models/Tree_1.glb")], out.path(), &options, false).unwrap();
    let tree = load(out.path(), "Tree_1").unwrap();
    let px = terramp::reference::slicing::VIEW_PX as u32;
    let steps = 7u32;
    // The crown fills the top of the view (the bounding sphere's lower half is the trunk's).
    let rows = px * 5 / 8;
    let mut sheet = image::RgbaImage::from_pixel(steps * (px + 4), 2 * rows + 4, image::Rgba([255; 4]));
    for step in 0..steps {
        let a = (10.0 * step as f32).to_radians();
        let views = terramp::reference::slicing::blend_views(&tree, Vec3::new(a.cos(), 0.2, a.sin()), 0.5, 0)
            .unwrap();
        for (row, picture) in [&views.sorted, &views.stochastic].into_iter().enumerate() {
            for (i, p) in picture.iter().enumerate().take((rows * px) as usize) {
                let grey = 190.0 * (1.0 - p[3]);
                let rgb = [0, 1, 2].map(|k| (p[k] + grey).clamp(0.0, 255.0) as u8);
                let (x, y) = (step * (px + 4) + i as u32 % px, row as u32 * (rows + 4) + i as u32 / px);
                sheet.put_pixel(x, y, image::Rgba([rgb[0], rgb[1], rgb[2], 255]));
            }
        }
    }
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/slicings_orbit.png");
    sheet.save(&path).unwrap();
    println!("wrote {}", path.display());
}

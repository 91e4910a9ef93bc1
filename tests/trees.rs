//! Generated trees judged by what they show: each drawn through the baker's own pipeline
//! (`bake::contact_sheet`, side views on one scale) after a glTF round trip through the baker's
//! reader, as the demo's first run bakes them. A tree covers fewer texels as its health falls (the
//! Virtual Forest's health parameter seen, not counted), stands as tall as its mesh, and a bush is
//! a fraction of a tree. The baker reads a generated tree as written (each leaf's pivot for the
//! wind too), and the embedded default's
//! class table names generated trees only.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use terramp::impostor::Mesh;
use terramp_testkit::gpu;

const CELL: [u32; 2] = [160, 320];

/// Reads `tree` back through the baker, as any model.
fn baked_mesh(name: &str, seed: u64, health: f32) -> Mesh {
    let tree = terramp::tree::generate(name, seed, health).unwrap();
    let dir =
        std::env::temp_dir().join(format!("terramp-trees-{}-{name}-{seed}-{health}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("tree.glb");
    std::fs::write(&file, tree.to_glb()).unwrap();
    let mesh = terramp::bake::load_model(&file).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    mesh
}

/// Per cell: texels that are not the sheet's background, and the highest such row (from the top).
fn coverage(rgba: &[u8], size: [u32; 2], cells: usize) -> Vec<(usize, u32)> {
    let background = [&rgba[0..4], &rgba[((size[1] - 1) * size[0] * 4) as usize..][..4]];
    let columns = size[0] / CELL[0];
    (0..cells as u32)
        .map(|c| {
            let (x0, y0) = ((c % columns) * CELL[0], (c / columns) * CELL[1]);
            let mut count = 0;
            let mut top = CELL[1];
            for y in y0..y0 + CELL[1] {
                for x in x0..x0 + CELL[0] {
                    let i = ((y * size[0] + x) * 4) as usize;
                    if !background.contains(&&rgba[i..i + 4]) {
                        count += 1;
                        top = top.min(y - y0);
                    }
                }
            }
            (count, top)
        })
        .collect()
}

#[test]
fn a_tree_shows_less_of_itself_as_its_health_falls() {
    let gpu = gpu();
    let healths = [1.0, 0.7, 0.4, 0.1];
    for name in ["spruce", "broadleaf"] {
        let meshes: Vec<Mesh> = healths.iter().map(|&h| baked_mesh(name, 4, h)).collect();
        let (rgba, size) = terramp::bake::contact_sheet(&gpu, &meshes, healths.len() as u32, CELL).unwrap();
        let shown: Vec<usize> = coverage(&rgba, size, meshes.len()).iter().map(|c| c.0).collect();
        println!("{name}: texels shown at health {healths:?}: {shown:?}");
        assert!(shown.windows(2).all(|w| w[1] < w[0]), "{name}: {shown:?} does not fall with health");
        assert!(
            shown[3] * 3 < shown[0],
            "{name}: a dying tree still shows {} of {} texels",
            shown[3],
            shown[0]
        );
    }
}

#[test]
fn trees_stand_as_tall_as_their_meshes_and_a_bush_is_small() {
    let gpu = gpu();
    let names = ["spruce", "pine", "birch", "broadleaf", "bush"];
    let meshes: Vec<Mesh> = names.iter().map(|n| baked_mesh(n, 9, 1.0)).collect();
    let heights_m: Vec<f32> =
        meshes.iter().map(|m| m.vertices.iter().map(|v| v.position_model_m[1]).fold(0.0, f32::max)).collect();
    let (rgba, size) = terramp::bake::contact_sheet(&gpu, &meshes, names.len() as u32, CELL).unwrap();
    let cells = coverage(&rgba, size, names.len());
    // The tallest model spans 90 % of the cell above a ground line at 95 %.
    let tallest_m = heights_m.iter().copied().fold(0.0, f32::max);
    let px_per_m = 0.9 * CELL[1] as f32 / tallest_m;
    for ((name, height_m), (shown, top)) in names.iter().zip(&heights_m).zip(&cells) {
        let drawn_m = (0.95 * CELL[1] as f32 - *top as f32) / px_per_m;
        println!("{name}: {height_m:.1} m, drawn {drawn_m:.1} m tall, {shown} texels");
        assert!((drawn_m - height_m).abs() < 2.0 / px_per_m + 0.02 * height_m, "{name}: {drawn_m} m drawn");
    }
    let bush = cells[4].0;
    assert!(cells[..4].iter().all(|c| c.0 > 20 * bush), "{cells:?}: a bush is not small beside the trees");
}

#[test]
fn the_baker_reads_a_generated_tree_like_any_model() {
    let tree = terramp::tree::generate("pine", 3, 0.9).unwrap();
    let mesh = baked_mesh("pine", 3, 0.9);
    // The leaves, then a material per branching level, each with its continuous LOD.
    let levels = tree.mesh.stems_per_level.iter().filter(|&&n| n > 0).count();
    assert_eq!(mesh.materials.len(), 1 + levels);
    assert_eq!(mesh.indices.len(), tree.mesh.bark.indices.len() + tree.mesh.leaves.indices.len());
    let masked = mesh.materials.iter().filter(|m| m.alpha_mode == terramp::impostor::AlphaMode::Mask).count();
    assert_eq!(masked, 1);
    use terramp::impostor::Detail;
    assert_eq!(mesh.materials[0].detail, Some(Detail::Leaves { size_m: tree.mesh.leaf_size_m }));
    for (material, &diameter_m) in mesh.materials[1..].iter().zip(&tree.mesh.level_diameters_m) {
        assert_eq!(material.detail, Some(Detail::Stems { diameter_m }));
    }
    assert_eq!(mesh.submeshes[0].material, 0, "the leaves open the index buffer");

    // Each vertex keeps its pivot (`_PIVOT`): every leaf corner hangs from a point within a leaf's
    // length of it (under 2 m: the pine's tufts are the longest, 1 m), a quad's corners from one
    // point (leaves at a twig's very tip share theirs); a stem's vertices all name its base, so
    // each level has as many pivots as stems (two stems may start at one point).
    for (k, submesh) in mesh.submeshes.iter().enumerate() {
        let leaves =
            mesh.materials[submesh.material as usize].alpha_mode == terramp::impostor::AlphaMode::Mask;
        let range = submesh.first_index as usize..(submesh.first_index + submesh.index_count) as usize;
        let mut pivots = std::collections::HashSet::new();
        for &i in &mesh.indices[range] {
            let v = mesh.vertices[i as usize];
            let reach_m = glam::Vec3::from(v.position_model_m).distance(v.pivot_model_m.into());
            pivots.insert(v.pivot_model_m.map(f32::to_bits));
            if leaves {
                assert!(reach_m > 0.0 && reach_m < 2.0, "a leaf corner {reach_m} m from its pivot");
            }
        }
        let (pivots, parts) = match leaves {
            true => (pivots.len() as u32, tree.mesh.leaf_count),
            false => (pivots.len() as u32, tree.mesh.stems_per_level[k - 1]),
        };
        assert!(pivots <= parts && 2 * pivots > parts, "{pivots} pivots for {parts} leaves or stems");
    }
}

#[test]
fn the_generated_table_grows_the_same_classes_with_generated_trees_only() {
    use terramp::classes::ClassTable;
    assert_eq!(ClassTable::generated_for("nc"), Some("nc-generated"));
    assert_eq!(ClassTable::generated_for("nlcd"), None);
    let nc = ClassTable::load("nc").unwrap();
    let generated = ClassTable::load(ClassTable::generated_for("nc").unwrap()).unwrap();
    assert_eq!((generated.scheme.as_str(), generated.names()), (nc.scheme.as_str(), nc.names()));
    for s in &generated.species {
        assert!(terramp::tree::ModelName::parse(&s.model).is_some(), "{}: {}", s.name, s.model);
    }
    for code in [1, 2, 3, 4, 5, 7] {
        assert!(generated.density_per_km2(code) > 0.0, "class {code} grows nothing");
    }
    assert_eq!(generated.density_per_km2(5), nc.density_per_km2(5));
    let forest = generated.class(5).unwrap();
    assert!(forest.texcells);
}

/// Continuous LOD on the generated species as the draw pass lays them out (`assets::gather`, the
/// frame's `detail_templates`) and as each seed keeps them (`impostor::detail`, the shader's
/// rule), at 1280 × 720 through a 60° lens, for a seed of its model's height: the primitives drawn
/// (stems counted by the share of seeds that draw them) never grow with distance and fall to a
/// few per cent far away; the frame's index range always holds what its nearest seed keeps; every
/// drawn leaf (its own extent, grown) and every drawn stem level is at least a pixel across.
#[test]
fn continuous_lod_draws_fewer_primitives_with_distance_and_none_below_a_pixel() {
    use terramp::gpu::layout::DETAIL_MIN_PX;
    use terramp::impostor::detail::{leaf_kept, leaf_share, projected_px, stem_share};
    use terramp::impostor::{BoundingSphere, Impostor, ImpostorLod, MipChain, Plane};
    use terramp::passes::draw_seeds::{assets, frame::detail_templates};

    let focal_px = 360.0 / 30f32.to_radians().tan();
    let mut settings = terramp::config::Settings::preset("balanced").unwrap();
    settings.seeds.reference_height_m = 0.1;
    for name in ["spruce", "pine", "birch", "broadleaf", "bush"] {
        let mesh = baked_mesh(name, 5, 1.0);
        let top_m = mesh.vertices.iter().map(|v| v.position_model_m[1]).fold(0.0, f32::max);
        let plane = Plane {
            corners_model_m: [[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            normal_model: [0.0, 0.0, 1.0],
            uv_min: [0.0; 2],
            uv_max: [1.0; 2],
        };
        let lod = ImpostorLod {
            epsilon_m: 0.1,
            planes: vec![plane],
            atlas: MipChain { size: [4, 4], levels: vec![vec![0; 64], vec![0; 16]] },
        };
        let impostor = Impostor {
            name: name.into(),
            bounding_sphere: BoundingSphere { centre_model_m: [0.0, 0.5 * top_m, 0.0], radius_m: top_m },
            alpha_cutoff: 0.5,
            lods: vec![lod; 3],
            slicing: None,
            mesh,
        };
        let built = assets::gather(
            &[Some(impostor)],
            assets::LodChoices { continuous_lod: true, ..Default::default() },
        )
        .unwrap();
        let detail = built.details[0].clone().expect("a generated tree has continuous LOD");
        let leaves = detail.leaves.expect("its leaves are laid out for it");
        let whole = detail.whole.index_count / 3;
        // Each leaf's extent, model metres: its quad's longer side (a leaf laid on the ground
        // keeps it, its area does not).
        let quad = |i: u32| {
            let at = |k: u32| {
                let index = built.indices[(leaves.first_index + 6 * i) as usize + k as usize];
                glam::Vec3::from(
                    built.vertices[(detail.whole.base_vertex as u32 + index) as usize].position_model_m,
                )
            };
            let (a, b, c) = (at(0), at(1), at(2));
            (b - a).length().max((c - b).length())
        };
        let mut drawn_before = f32::MAX;
        let mut drawn = Vec::new();
        for distance_m in [1.0, 5.0, 20.0, 50.0, 100.0, 200.0, 400.0, 800.0, 1600.0f32] {
            let px = |size_m: f32| projected_px(size_m, 1.0, focal_px, distance_m);
            let (share, grow) = leaf_share(px(leaves.size_m));
            let kept_leaves: Vec<u32> =
                (0..leaves.count).filter(|&i| leaf_kept(i, leaves.count, share)).collect();
            for &i in &kept_leaves {
                let size_px = px(quad(i)) * grow;
                assert!(size_px >= DETAIL_MIN_PX, "{name} at {distance_m} m: leaf {i} drawn {size_px} px");
            }
            // Stems: on average their share of the seeds draw them, at least a pixel wide.
            let mut stems = 0.0;
            for (range, diameter_m) in &detail.stems {
                let (share, width_px) = stem_share(px(*diameter_m));
                assert!(width_px >= DETAIL_MIN_PX, "{name} at {distance_m} m: stems {width_px} px wide");
                stems += share * (range.len() / 3) as f32;
            }
            let primitives = 2.0 * kept_leaves.len() as f32 + stems;
            assert!(primitives <= drawn_before, "{name}: more primitives at {distance_m} m");
            drawn_before = primitives;
            // The frame's range, LOD 1 beginning at this distance, holds what this seed keeps.
            settings.draw_seeds.reach_m[0] = f64::from(distance_m);
            let frame = detail_templates(
                &built.templates,
                &built.details,
                &[top_m],
                &built.inv_model_height_m,
                &settings,
                focal_px,
            );
            let range = frame[1].first_index..frame[1].first_index + frame[1].index_count;
            let first_kept = leaves.first_index + 6 * kept_leaves.first().copied().unwrap_or(leaves.count);
            assert!(
                kept_leaves.is_empty() || range.start <= first_kept,
                "{name} at {distance_m} m: {range:?}"
            );
            let all_stems: usize = detail.stems.iter().map(|(r, _)| r.len() / 3).sum();
            let in_range = range.len() / 3;
            assert!(in_range <= whole as usize && in_range >= 2 * kept_leaves.len() + all_stems);
            drawn.push((distance_m, primitives, range.len() / 3));
        }
        println!("{name}: {whole} triangles whole; (distance m, drawn, in the range) {drawn:?}");
        let nearest = drawn[0].1;
        assert_eq!(nearest, whole as f32, "{name}: the whole tree is drawn 1 m away");
        // Real: still drawn at 1.6 km (a tree thinned to nothing would pass the bound below).
        assert!(drawn_before > 0.0, "{name}: nothing drawn at 1.6 km");
        assert!(
            drawn_before * 20.0 < nearest,
            "{name}: {drawn_before} of {nearest} primitives drawn at 1.6 km"
        );
    }
}

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
    assert_eq!(mesh.materials.len(), 2);
    assert_eq!(mesh.indices.len(), tree.mesh.bark.indices.len() + tree.mesh.leaves.indices.len());
    let masked = mesh.materials.iter().filter(|m| m.alpha_mode == terramp::impostor::AlphaMode::Mask).count();
    assert_eq!(masked, 1);

    // Each vertex keeps its leaf's pivot (`_PIVOT`): bark is rigid (its own pivot); every leaf
    // corner hangs from a point within a leaf's length of it (under 2 m: the pine's tufts are the
    // longest, 1 m), a quad's corners from one point
    // (leaves at a twig's very tip share theirs).
    for submesh in &mesh.submeshes {
        let leaves =
            mesh.materials[submesh.material as usize].alpha_mode == terramp::impostor::AlphaMode::Mask;
        let range = submesh.first_index as usize..(submesh.first_index + submesh.index_count) as usize;
        let mut pivots = std::collections::HashSet::new();
        for &i in &mesh.indices[range] {
            let v = mesh.vertices[i as usize];
            let reach_m = glam::Vec3::from(v.position_model_m).distance(v.pivot_model_m.into());
            pivots.insert(v.pivot_model_m.map(f32::to_bits));
            match leaves {
                true => assert!(reach_m > 0.0 && reach_m < 2.0, "a leaf corner {reach_m} m from its pivot"),
                false => assert_eq!(reach_m, 0.0, "a bark vertex off its pivot"),
            }
        }
        if leaves {
            let (pivots, leaves) = (pivots.len() as u32, tree.mesh.leaf_count);
            assert!(pivots <= leaves && 2 * pivots > leaves, "{pivots} pivots for {leaves} leaves");
        }
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

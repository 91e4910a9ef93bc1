use super::*;

const HEALTHS: [f32; 6] = [1.0, 0.8, 0.6, 0.4, 0.2, 0.0];

#[test]
fn the_same_inputs_give_the_same_bytes_and_another_seed_another_tree() {
    for name in NAMES {
        let a = generate(name, 7, 0.8).unwrap().to_glb();
        let b = generate(name, 7, 0.8).unwrap().to_glb();
        assert!(a == b, "{name}: two runs differ");
        let c = generate(name, 8, 0.8).unwrap().to_glb();
        assert!(a != c, "{name}: seeds 7 and 8 give the same tree");
    }
}

#[test]
fn leaves_and_branches_never_grow_as_health_falls() {
    for name in NAMES {
        for seed in [1, 2, 3] {
            let trees: Vec<Tree> = HEALTHS.iter().map(|&h| generate(name, seed, h).unwrap()).collect();
            for pair in trees.windows(2) {
                let (healthier, sicker) = (&pair[0].mesh, &pair[1].mesh);
                assert!(sicker.leaf_count <= healthier.leaf_count, "{name} {seed}: leaves grew");
                for (level, (s, h)) in
                    sicker.stems_per_level.iter().zip(&healthier.stems_per_level).enumerate()
                {
                    assert!(s <= h, "{name} {seed}: level {level} stems grew from {h} to {s}");
                }
                // A sicker tree is a subset of a healthier one, not another tree.
                let healthier_leaves: std::collections::HashSet<[u32; 3]> =
                    healthier.leaves.positions.iter().map(|p| p.map(f32::to_bits)).collect();
                assert!(
                    sicker.leaves.positions.iter().all(|p| healthier_leaves.contains(&p.map(f32::to_bits)))
                );
            }
            let (healthy, dead) = (&trees[0].mesh, &trees[HEALTHS.len() - 1].mesh);
            assert!(healthy.leaf_count > 100, "{name} {seed}: {} leaves", healthy.leaf_count);
            assert_eq!(dead.leaf_count, 0, "{name}: a dead tree keeps leaves");
            assert_eq!(dead.stems_per_level[0], 1, "{name}: the trunk stays");
            let deepest = healthy.stems_per_level.len() - 1;
            assert_eq!(dead.stems_per_level[deepest], 0, "{name}: a dead tree keeps twigs");
            assert!(dead.stems_per_level[1] > 0 && dead.stems_per_level[1] < healthy.stems_per_level[1]);
            // Moderate loss omits leaves only.
            let moderate = &trees[2].mesh;
            assert_eq!(
                moderate.stems_per_level, healthy.stems_per_level,
                "{name}: 0.6 already loses branches"
            );
            assert!(moderate.leaf_count < healthy.leaf_count);
        }
    }
}

#[test]
fn trees_stand_on_y_0_and_are_as_tall_as_their_species() {
    for name in NAMES {
        let tree = generate(name, 5, 1.0).unwrap();
        let all = tree.mesh.bark.positions.iter().chain(&tree.mesh.leaves.positions);
        let (lo, hi) = all.fold((f32::MAX, f32::MIN), |(lo, hi), p| (lo.min(p[1]), hi.max(p[1])));
        assert_eq!(lo, 0.0, "{name}: lowest vertex at {lo} m");
        let expected = species(name).unwrap();
        let nominal = expected.height_m * expected.levels[0].length;
        assert!(
            hi > 0.8 * nominal && hi < 1.6 * expected.height_m,
            "{name}: {hi} m tall, nominal {nominal} m"
        );
        for n in tree.mesh.bark.normals.iter().chain(&tree.mesh.leaves.normals) {
            let length = glam::Vec3::from(*n).length();
            assert!((length - 1.0).abs() < 1e-4, "{name}: normal of length {length}");
        }
    }
}

#[test]
fn bark_levels_are_contiguous_index_ranges_trunk_first() {
    for name in NAMES {
        let mesh = generate(name, 3, 1.0).unwrap().mesh;
        assert_eq!(mesh.bark_levels[0].start, 0);
        for pair in mesh.bark_levels.windows(2) {
            assert_eq!(pair[0].end, pair[1].start, "{name}: levels {pair:?} leave a gap");
        }
        assert_eq!(mesh.bark_levels.last().unwrap().end as usize, mesh.bark.indices.len());
        assert!(mesh.bark.indices.iter().all(|&i| (i as usize) < mesh.bark.positions.len()));
        assert!(mesh.leaves.indices.iter().all(|&i| (i as usize) < mesh.leaves.positions.len()));
        // Split by level, the bark is the same vertices in the same order, and each level's stems
        // are thinner than its parents' (the continuous LOD drops the finest first).
        let levels = mesh.bark_by_level();
        let positions: Vec<[f32; 3]> = levels.iter().flat_map(|p| p.positions.clone()).collect();
        assert_eq!(positions, mesh.bark.positions, "{name}");
        let kept: Vec<f32> = mesh
            .level_diameters_m
            .iter()
            .zip(&mesh.stems_per_level)
            .filter(|(_, n)| **n > 0)
            .map(|(d, _)| *d)
            .collect();
        assert!(kept.windows(2).all(|w| w[1] < w[0]), "{name}: diameters {kept:?}");
        assert!(mesh.leaf_size_m > 0.005 && mesh.leaf_size_m < 1.0, "{name}: leaves {} m", mesh.leaf_size_m);
    }
}

#[test]
fn bad_inputs_are_refused_by_name() {
    let unknown = generate("baobab", 1, 1.0).unwrap_err().to_string();
    assert!(unknown.contains("baobab") && unknown.contains("spruce"), "{unknown}");
    for health in [-0.1, 1.5, f32::NAN] {
        let error = generate("pine", 1, health).unwrap_err().to_string();
        assert!(error.contains("health"), "{error}");
    }
}

#[cfg(feature = "bake")]
#[test]
fn the_glb_reads_back_with_the_gltf_crate_as_written() {
    for (name, health) in [("spruce", 1.0), ("broadleaf", 0.5), ("birch", 0.0)] {
        let tree = generate(name, 11, health).unwrap();
        let bytes = tree.to_glb();
        let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
        let blob = gltf.blob.as_deref().unwrap();
        let mesh = gltf.meshes().next().unwrap();
        // Leaves first, then each level's bark; empty ones left out.
        let levels = tree.mesh.bark_by_level();
        let parts: Vec<&Part> =
            std::iter::once(&tree.mesh.leaves).chain(&levels).filter(|p| !p.indices.is_empty()).collect();
        assert_eq!(mesh.primitives().len(), parts.len(), "{name} {health}");
        assert_eq!(
            gltf.images().len(),
            1 + usize::from(!tree.mesh.leaves.indices.is_empty()),
            "one bark image"
        );
        let bark_triangles: usize = levels.iter().map(Part::triangles).sum();
        assert_eq!(bark_triangles, tree.mesh.bark.triangles());
        for (primitive, part) in mesh.primitives().zip(parts) {
            let reader = primitive.reader(|_| Some(blob));
            let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
            let normals: Vec<[f32; 3]> = reader.read_normals().unwrap().collect();
            let uvs: Vec<[f32; 2]> = reader.read_tex_coords(0).unwrap().into_f32().collect();
            let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
            assert_eq!(
                (&positions, &normals, &uvs, &indices),
                (&part.positions, &part.normals, &part.uvs, &part.indices)
            );
            let material = primitive.material();
            let leaves = material.name() == Some("leaves");
            let extras: serde_json::Value =
                serde_json::from_str(material.extras().as_ref().unwrap().get()).unwrap();
            let detail: crate::impostor::Detail =
                serde_json::from_value(extras[crate::impostor::detail::DETAIL_EXTRAS].clone()).unwrap();
            let expected = match leaves {
                true => crate::impostor::Detail::Leaves { size_m: tree.mesh.leaf_size_m },
                false => {
                    let level: usize = material.name().unwrap()["bark ".len()..].parse().unwrap();
                    crate::impostor::Detail::Stems { diameter_m: tree.mesh.level_diameters_m[level] }
                }
            };
            assert_eq!(detail, expected);
            let mode =
                if leaves { gltf::material::AlphaMode::Mask } else { gltf::material::AlphaMode::Opaque };
            assert_eq!(material.alpha_mode(), mode);
            assert_eq!(material.double_sided(), leaves);
            let texture = material.pbr_metallic_roughness().base_color_texture().unwrap().texture();
            let gltf::image::Source::View { view, mime_type } = texture.source().source() else {
                panic!("not embedded")
            };
            assert_eq!(mime_type, "image/png");
            let png = &blob[view.offset()..view.offset() + view.length()];
            let image = image::load_from_memory(png).unwrap().to_rgba8();
            let expected = if leaves { [LEAF_TEXELS; 2] } else { [64, 128] };
            assert_eq!([image.width(), image.height()], expected);
            if leaves {
                // A masked card: some texels cut away, some kept.
                let kept = image.pixels().filter(|p| p[3] == 255).count();
                assert!(kept > 200 && kept < image.pixels().len() - 200, "{name}: {kept} leaf texels kept");
            }
        }
    }
}

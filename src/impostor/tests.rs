use std::path::PathBuf;

use super::*;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("terramp-impostor-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// A 16 × 8 atlas: a disc of opaque texels in each half, the rest transparent.
fn atlas() -> Vec<u8> {
    (0..8u32)
        .flat_map(|y| (0..16u32).map(move |x| (x, y)))
        .flat_map(|(x, y)| {
            let (cx, cy) = ((x % 8) as f32 - 3.5, y as f32 - 3.5);
            let inside = cx * cx + cy * cy < 9.0;
            [200, (x * 10) as u8, 50, if inside { 255 } else { 0 }]
        })
        .collect()
}

fn sample() -> Impostor {
    let plane = |x: f32| Plane {
        corners_model_m: [[x, 0.0, 0.0], [x + 1.0, 0.0, 0.0], [x + 1.0, 1.0, 0.0], [x, 1.0, 0.0]],
        normal_model: [0.0, 0.0, 1.0],
        uv_min: [x / 2.0, 0.0],
        uv_max: [x / 2.0 + 0.5, 1.0],
    };
    let rects =
        [TexelRect { x: 0, y: 0, width: 8, height: 8 }, TexelRect { x: 8, y: 0, width: 8, height: 8 }];
    let vertex = |p: [f32; 3]| MeshVertex {
        position_model_m: p,
        normal_model: [0.0, 0.0, 1.0],
        uv: [p[0], p[1]],
        pivot_model_m: p,
    };
    Impostor {
        name: "Quads".into(),
        bounding_sphere: BoundingSphere { centre_model_m: [1.0, 0.5, 0.0], radius_m: 1.2 },
        alpha_cutoff: 0.5,
        lods: vec![ImpostorLod {
            epsilon_m: 0.1,
            planes: vec![plane(0.0), plane(1.0)],
            atlas: build_mip_chain(atlas(), [16, 8], 3, Some(0.5), &rects),
        }],
        slicing: Some(Slicing {
            orientations: 2,
            slices: 1,
            lod: ImpostorLod {
                epsilon_m: 0.5,
                planes: vec![plane(0.0), plane(1.0)],
                atlas: build_mip_chain(atlas(), [16, 8], 2, Some(0.5), &rects),
            },
            crown_triangles: 1,
            trunk_triangles: 0,
        }),
        mesh: Mesh {
            vertices: vec![vertex([0.0, 0.0, 0.0]), vertex([2.0, 0.0, 0.0]), vertex([2.0, 1.0, 0.0])],
            indices: vec![0, 1, 2],
            submeshes: vec![Submesh { material: 0, first_index: 0, index_count: 3 }],
            materials: vec![Material {
                name: "Leaves".into(),
                base_color_factor: [1.0, 0.5, 0.25, 1.0],
                alpha_mode: AlphaMode::Mask,
                alpha_cutoff: 0.5,
                double_sided: true,
                texture: Some(build_mip_chain(atlas(), [16, 8], 5, Some(0.5), &[])),
                detail: Some(super::Detail::Leaves { size_m: 0.125 }),
            }],
        },
    }
}

#[test]
fn saved_impostors_load_back_identical() {
    let dir = temp_dir("roundtrip");
    let impostor = sample();
    let folder = save(&dir, &impostor).unwrap();
    assert_eq!(folder, dir.join("Quads"));
    assert_eq!(load(&dir, "Quads").unwrap(), impostor);
    assert_eq!(models(&dir).unwrap(), vec!["Quads".to_string()]);
    // Saving again replaces the folder whole.
    save(&dir, &impostor).unwrap();
    assert_eq!(load(&dir, "Quads").unwrap(), impostor);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn other_versions_and_damaged_meshes_are_named() {
    let dir = temp_dir("damaged");
    let folder = save(&dir, &sample()).unwrap();
    let manifest = folder.join(MANIFEST_FILE);
    let text = std::fs::read_to_string(&manifest).unwrap();
    std::fs::write(
        &manifest,
        text.replace(&format!("format_version = {FORMAT_VERSION}"), "format_version = 99"),
    )
    .unwrap();
    let error = load(&dir, "Quads").unwrap_err();
    assert!(matches!(error, ImpostorError::Version { found: 99, .. }), "{error}");
    assert!(!is_current(&dir, "Quads") && !is_current(&dir, "Absent"));
    std::fs::write(&manifest, text).unwrap();
    assert!(is_current(&dir, "Quads"));
    let mesh = folder.join(MESH_FILE);
    let mut bytes = std::fs::read(&mesh).unwrap();
    let last = bytes.len() - 5;
    bytes[last] ^= 0xff;
    std::fs::write(&mesh, &bytes).unwrap();
    let error = load(&dir, "Quads").unwrap_err().to_string();
    assert!(error.contains("mesh.bin") && error.contains("checksum"), "{error}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn plane_vertices_follow_the_corners_and_their_atlas_rectangles() {
    let lod = &sample().lods[0];
    let vertices = lod.vertices();
    assert_eq!(vertices.len(), 8);
    assert_eq!(lod.indices(), vec![0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7]);
    // Corner 0 is the bottom left: the atlas rectangle's left column, bottom row.
    assert_eq!(vertices[4].position_model_m, [1.0, 0.0, 0.0]);
    assert_eq!(vertices[4].uv_atlas, [0.5, 1.0]);
    assert_eq!(vertices[6].uv_atlas, [1.0, 0.0]);
}

#[test]
fn mips_keep_alpha_tested_coverage_and_dilate_colour() {
    // A sparse checker of single opaque texels: plain averaging would give alpha 0.25 everywhere,
    // which fails a 0.5 test, so the foliage would vanish one mip down.
    let size = [32u32, 32u32];
    let level0: Vec<u8> = (0..size[0] * size[1])
        .flat_map(|i| {
            let (x, y) = (i % size[0], i / size[0]);
            let on = x % 2 == 0 && y % 2 == 0;
            [40, 160, 40, if on { 255 } else { 0 }]
        })
        .collect();
    let chain = build_mip_chain(level0, size, 4, Some(0.5), &[]);
    assert_eq!(chain.mip_count(), 4);
    for (m, level) in chain.levels.iter().enumerate() {
        let [w, h] = chain.level_size(m as u32);
        assert_eq!(level.len(), (4 * w * h) as usize);
        let passing = level.chunks_exact(4).filter(|t| t[3] >= 128).count() as f32 / (w * h) as f32;
        assert!(m == 0 || passing > 0.2, "mip {m}: coverage {passing}");
        // Every texel, covered or not, carries the foliage colour: no black fringes.
        assert!(level.chunks_exact(4).all(|t| t[1] > 120 && t[0] < 80), "mip {m}");
    }
}

#[test]
fn bounding_spheres_hold_their_points() {
    let points = [[0.0, 0.0, 0.0], [1.0, 4.0, -1.0], [-2.0, 8.0, 0.5], [0.3, 2.0, 3.0]];
    let sphere = BoundingSphere::enclosing(points);
    assert_eq!(sphere.centre_model_m[1], 4.0, "centred at mid-height");
    assert!(points.iter().all(|&p| sphere.contains(p)));
}

#[test]
fn a_slicing_with_other_than_orientations_times_slices_planes_is_refused() {
    let dir = temp_dir("slicing");
    let mut impostor = sample();
    if let Some(slicing) = impostor.slicing.as_mut() {
        slicing.slices = 2;
    }
    let error = save(&dir, &impostor).unwrap_err().to_string();
    assert!(error.contains("2 slices, not 2 × 2"), "{error}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bark_is_known_by_its_material_name() {
    let named = |name: &str| Material { name: name.into(), ..sample().mesh.materials[0].clone() };
    for bark in ["Bark", "Birch_Bark", "bark 0", "Trunk", "OakWood"] {
        assert!(named(bark).is_bark(), "{bark}");
    }
    for foliage in ["Pine_Leaves", "Green", "Rock", "leaves", "Berry"] {
        assert!(!named(foliage).is_bark(), "{foliage}");
    }
}

/// `impostor.toml`'s counts feed products and shifts: 2 orientations × (2^31 + 1) slices wraps
/// to 2 (the sample's plane count) in u32, and a 33rd mip of a 16 × 8 atlas shifts its size by 32
/// bits. Both panicked with overflow in a debug build (found by the overflow audit, issue 42) and
/// passed or misread in a release one; both are errors naming the manifest's fields now, as is an
/// atlas of width 0.
#[test]
fn manifest_counts_whose_arithmetic_would_overflow_are_refused_not_a_panic() {
    let dir = temp_dir("overflow");
    let folder = save(&dir, &sample()).unwrap();
    let manifest_path = folder.join(MANIFEST_FILE);
    let original: toml::Table = toml::from_str(&std::fs::read_to_string(&manifest_path).unwrap()).unwrap();
    let load_with = |edit: &dyn Fn(&mut toml::Table)| {
        let mut manifest = original.clone();
        edit(&mut manifest);
        std::fs::write(&manifest_path, toml::to_string(&manifest).unwrap()).unwrap();
        load(&dir, "Quads").map(|_| ()).unwrap_err().to_string()
    };
    let error = load_with(&|m| m["slicing"]["slices"] = toml::Value::Integer((1 << 31) + 1));
    assert!(error.contains("orientations × slices") && error.contains("2 × 2147483649"), "{error}");
    // The atlas's 3 mips, then a 2 × 1 and 1 × 1 images for the rest of 33 mips.
    for (name, size) in [("two.png", [2, 1]), ("one.png", [1, 1])] {
        let texels = vec![255; 4 * size[0] as usize];
        image::save_buffer(folder.join(name), &texels, size[0], size[1], image::ColorType::Rgba8).unwrap();
    }
    let error = load_with(&|m| {
        let atlas = &mut m["lods"][0]["atlas"];
        let files = atlas["files"].as_array_mut().unwrap();
        files.push("two.png".into());
        files.resize(33, "one.png".into());
        atlas["mip_count"] = toml::Value::Integer(33);
    });
    assert!(error.contains(MANIFEST_FILE) && error.contains("33 mips"), "{error}");
    // An atlas 0 texels wide, its one mip a 1 × 8 image (mips are never below 1 texel): loaded, it
    // made a texture of width 0 (found by the same audit).
    image::save_buffer(folder.join("thin.png"), &[255; 32], 1, 8, image::ColorType::Rgba8).unwrap();
    let error = load_with(&|m| {
        let atlas = &mut m["lods"][0]["atlas"];
        atlas["size"] = toml::Value::Array(vec![0.into(), 8.into()]);
        atlas["mip_count"] = toml::Value::Integer(1);
        atlas["files"] = toml::Value::Array(vec!["thin.png".into()]);
    });
    assert!(error.contains("lods[0].atlas: size 0 × 8"), "{error}");
    // The manifest as saved still loads: the checks refuse only what is wrong.
    std::fs::write(&manifest_path, toml::to_string(&original).unwrap()).unwrap();
    assert!(load(&dir, "Quads").is_ok());
    std::fs::remove_dir_all(&dir).unwrap();
}

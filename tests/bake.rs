//! `terramp::bake` on the shared models: three LODs of 17, 8 and 2 planes each, every plane with
//! something in its atlas rectangle down to the last mip, a bounding sphere holding every vertex
//! of the glTF, and `terramp::impostor::load` reading it all back. Broken inputs are named.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::path::{Path, PathBuf};

use terramp::bake::{BakeError, BakeOptions, bake_models};
use terramp::impostor::{Impostor, MipChain, Plane};
use terramp_testkit::shared_data;

/// A fresh folder under the target's temporary folder, removed when dropped.
struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> Self {
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }

    fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Every vertex position of the glTF at `path`, node transforms applied.
fn gltf_positions(path: &Path) -> Vec<glam::Vec3> {
    let gltf = gltf::Gltf::from_slice(&std::fs::read(path).unwrap()).unwrap();
    let blob = gltf.blob.clone().unwrap();
    let mut positions = Vec::new();
    let mut stack: Vec<(gltf::Node, glam::Mat4)> =
        gltf.default_scene().unwrap().nodes().map(|n| (n, glam::Mat4::IDENTITY)).collect();
    while let Some((node, parent)) = stack.pop() {
        let world = parent * glam::Mat4::from_cols_array_2d(&node.transform().matrix());
        stack.extend(node.children().map(|c| (c, world)));
        for primitive in node.mesh().iter().flat_map(|m| m.primitives()) {
            let reader = primitive.reader(|_| Some(&blob));
            positions.extend(reader.read_positions().unwrap().map(|p| world.transform_point3(p.into())));
        }
    }
    positions
}

/// Texels of `level` inside `plane`'s atlas rectangle with alpha above `alpha`.
fn texels_in(atlas: &MipChain, level: u32, plane: &Plane, alpha: u8) -> usize {
    let [w, h] = atlas.level_size(level);
    let x = |u: f32| ((u * w as f32).round() as usize).min(w as usize);
    let y = |v: f32| ((v * h as f32).round() as usize).min(h as usize);
    let texels = &atlas.levels[level as usize];
    (y(plane.uv_min[1])..y(plane.uv_max[1]))
        .flat_map(|row| (x(plane.uv_min[0])..x(plane.uv_max[0])).map(move |col| row * w as usize + col))
        .filter(|&i| texels[4 * i + 3] > alpha)
        .count()
}

fn check(impostor: &Impostor, glb: &Path) {
    let name = &impostor.name;
    let counts: Vec<usize> = impostor.lods.iter().map(|l| l.planes.len()).collect();
    assert_eq!(counts, [17, 8, 2], "{name}");
    for (l, lod) in impostor.lods.iter().enumerate() {
        assert_eq!(lod.atlas.size, [256, 256], "{name} LOD {l}");
        assert_eq!(lod.atlas.mip_count(), 3, "{name} LOD {l}");
        assert!(lod.epsilon_m > 0.0 && lod.epsilon_m <= impostor.bounding_sphere.radius_m, "{name} LOD {l}");
        assert_eq!(lod.vertices().len(), 4 * lod.planes.len());
        for (p, plane) in lod.planes.iter().enumerate() {
            assert!(plane.uv_min[0] < plane.uv_max[0] && plane.uv_min[1] < plane.uv_max[1], "{name} {l}/{p}");
            // Something is drawn on every plane, and alpha-aware mips keep it to the last level.
            assert!(texels_in(&lod.atlas, 0, plane, 0) > 0, "{name} LOD {l} plane {p}: empty");
            let last = lod.atlas.mip_count() - 1;
            assert!(
                texels_in(&lod.atlas, last, plane, 127) > 0,
                "{name} LOD {l} plane {p}: vanishes at mip {last}"
            );
            // The quad's corners stay near the model (a plane is framed on what it draws).
            let sphere = impostor.bounding_sphere;
            for corner in plane.corners_model_m {
                let d = glam::Vec3::from(corner).distance(sphere.centre_model_m.into());
                assert!(d < 2.0 * sphere.radius_m, "{name} LOD {l} plane {p}: corner {corner:?}");
            }
        }
        for (p, a) in lod.planes.iter().enumerate() {
            for b in &lod.planes[p + 1..] {
                let apart = a.uv_max[0] <= b.uv_min[0]
                    || b.uv_max[0] <= a.uv_min[0]
                    || a.uv_max[1] <= b.uv_min[1]
                    || b.uv_max[1] <= a.uv_min[1];
                assert!(apart, "{name} LOD {l}: atlas rectangles overlap");
            }
        }
    }
    let positions = gltf_positions(glb);
    assert_eq!(impostor.mesh.vertices.len(), positions.len(), "{name}");
    let sphere = impostor.bounding_sphere;
    let (low, high) =
        positions.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| (lo.min(p.y), hi.max(p.y)));
    for p in positions {
        assert!(sphere.contains(p.to_array()), "{name}: {p} outside {sphere:?}");
    }
    // Centred at mid-height, as the paper's seeds expect.
    assert!((sphere.centre_model_m[1] - 0.5 * (low + high)).abs() < 1e-3, "{name}: {sphere:?}");
    assert_eq!(impostor.mesh.submeshes.len(), impostor.mesh.materials.len(), "{name}");
}

#[test]
fn baking_every_model_gives_three_lods_with_their_planes_and_non_empty_atlases() {
    let Some(data) = shared_data() else { return };
    let mut models: Vec<PathBuf> = std::fs::read_dir(data.join("models"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "glb"))
        .collect();
    models.sort();
    assert!(!models.is_empty(), "no .glb in {}", data.join("models").display());
    let out = TempDir::new("bake");
    // The caller's adapter, as the demo passes its own.
    let gpu = terramp_testkit::gpu();
    let options = BakeOptions { texels: 256, ..Default::default() };
    let reports =
        bake_models(Some(&gpu), &models, out.path(), &options, true).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(reports.len(), models.len());
    let mut names = Vec::new();
    for (glb, report) in models.iter().zip(&reports) {
        let name = glb.file_stem().unwrap().to_str().unwrap();
        assert_eq!(report.name, name);
        assert_eq!(report.folder, out.path().join(name));
        assert!(report.triangles > 0, "{report:?}");
        let impostor = terramp::impostor::load(out.path(), name).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(impostor.name, name);
        check(&impostor, glb);
        names.push(name.to_owned());
    }
    assert_eq!(terramp::impostor::models(out.path()).unwrap(), names);
}

/// Models that made the glTF crate panic, found by `fuzz/`'s `gltf_model`, are refused with an
/// error naming what is wrong: a POSITION naming an accessor past the file's (its validation
/// indexed it), indices stored as floats (its reader's `unreachable!`), a GLB header's length under
/// 12 bytes (its reader's underflow); and a node that is its own child (a walk of the scene that
/// never ends).
#[test]
fn malformed_models_found_by_fuzzing_are_refused_not_a_panic() {
    let dir = TempDir::new("bake-fuzzed");
    // One triangle: positions (3 float VEC3s), then its 3 indices (read as u32 or, damaged, f32).
    let positions = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let mut bin: Vec<u8> = positions.iter().flat_map(|v| v.to_le_bytes()).collect();
    bin.extend([0u32, 1, 2].iter().flat_map(|i| i.to_le_bytes()));
    std::fs::write(dir.path().join("tri.bin"), &bin).unwrap();
    let triangle = |nodes: &str, indices_type: u32, position: u32| {
        format!(
            r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}], "nodes": {nodes},
            "buffers": [{{"uri": "tri.bin", "byteLength": 48}}],
            "bufferViews": [{{"buffer": 0, "byteLength": 36}}, {{"buffer": 0, "byteOffset": 36, "byteLength": 12}}],
            "accessors": [
                {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}},
                {{"bufferView": 1, "componentType": {indices_type}, "count": 3, "type": "SCALAR"}}],
            "meshes": [{{"primitives": [{{"attributes": {{"POSITION": {position}}}, "indices": 1}}]}}]}}"#
        )
    };
    let tree = r#"[{"mesh": 0}]"#;
    let cases = [
        ("Sound", triangle(tree, 5125, 0), None),
        (
            "Ghost",
            triangle(tree, 5125, 2),
            Some("takes its POSITION from accessor 2, and the file has 2 accessors"),
        ),
        ("Floats", triangle(tree, 5126, 0), Some("indices accessor 1: (F32, Scalar) elements")),
        ("Loop", triangle(r#"[{"mesh": 0, "children": [0]}]"#, 5125, 0), Some("node 0 is reached twice")),
        // A GLB header whose length, 0, is under the header's own 12 bytes (the glTF crate took
        // 12 from it: an underflow, found once the fuzz build checked overflow, issue 42).
        (
            "ShortGlb",
            format!("glTF\u{2}\0\0\0{}", "\0".repeat(40)),
            Some("the GLB header gives a length of 0 bytes"),
        ),
    ];
    for (name, json, expected) in cases {
        let model = dir.path().join(format!("{name}.gltf"));
        std::fs::write(&model, json).unwrap();
        match (terramp::bake::load_model(&model), expected) {
            (Ok(mesh), None) => assert_eq!(mesh.indices.len(), 3, "{name}"),
            (Err(e), Some(expected)) => assert!(e.to_string().contains(expected), "{name}: {e}"),
            (result, _) => panic!("{name}: {:?}", result.map(|m| m.indices)),
        }
    }
}

#[test]
fn missing_corrupt_and_same_named_models_are_named() {
    let dir = TempDir::new("bake-errors");
    let bake = |models: &[PathBuf]| bake_models(None, models, dir.path(), &BakeOptions::default(), false);
    let missing = dir.path().join("Nothing.glb");
    let err = bake(std::slice::from_ref(&missing)).unwrap_err();
    assert!(matches!(err, BakeError::NoSuchModel(_)) && err.to_string().contains("Nothing.glb"), "{err}");
    let corrupt = dir.path().join("Broken.glb");
    std::fs::write(&corrupt, b"glTF\x02\x00\x00\x00 this is not a model").unwrap();
    let err = bake(std::slice::from_ref(&corrupt)).unwrap_err();
    let message = err.to_string();
    assert!(message.contains("Broken.glb") && message.contains("not a valid glTF"), "{message}");
    assert!(!dir.path().join("Broken").exists(), "nothing written for a failed model");
    let elsewhere = dir.path().join("other");
    std::fs::create_dir_all(&elsewhere).unwrap();
    let twin = elsewhere.join("Broken.glb");
    std::fs::copy(&corrupt, &twin).unwrap();
    let err = bake(&[corrupt, twin]).unwrap_err();
    assert!(matches!(&err, BakeError::SameName(name) if name == "Broken"), "{err}");
}

#[test]
fn generated_trees_are_baked_by_name_with_no_model_file() {
    // What the demo does on a clone without ../shared: the table names `tree-…` models.
    let out = TempDir::new("bake-generated");
    let nowhere = out.path().join("no-models-here");
    let names = ["tree-bush-s3-h90", "Nothing"];
    let gpu = terramp_testkit::gpu();
    let options = BakeOptions { texels: 256, ..Default::default() };
    let missing =
        terramp::bake::bake_missing(Some(&gpu), &nowhere, &names, out.path(), &options, false).unwrap();
    assert_eq!(missing.baked.iter().map(|r| r.name.as_str()).collect::<Vec<_>>(), ["tree-bush-s3-h90"]);
    assert_eq!(missing.absent, [nowhere.join("Nothing.glb")]);
    let impostor = terramp::impostor::load(out.path(), "tree-bush-s3-h90").unwrap();
    let tree = terramp::tree::generate("bush", 3, 0.9).unwrap();
    assert_eq!(missing.baked[0].triangles, tree.mesh.bark.triangles() + tree.mesh.leaves.triangles());
    assert_eq!(impostor.lods.len(), options.planes.len());
    // Baked once: a second call finds it current and bakes nothing.
    let again =
        terramp::bake::bake_missing(Some(&gpu), &nowhere, &names, out.path(), &options, false).unwrap();
    assert!(again.baked.is_empty());
}

use super::assets;
use super::frame::load_impostors;
use super::{DrawSeedsError, LodChoices};
use crate::gpu::gpu_types::SeedMaterial;
use crate::gpu::layout::{
    MATERIAL_BARK, MATERIAL_LEAVES, MATERIAL_REPEAT, MATERIAL_SLICE, MATERIAL_STEMS, MATERIAL_TEXTURED,
    SEED_DRAWS, SEED_GROUPS, SEED_LODS,
};
use crate::impostor::{
    AlphaMode, BoundingSphere, Detail, Impostor, ImpostorLod, Material, Mesh, MeshVertex, MipChain, Plane,
    Slicing, Submesh,
};

/// A plain atlas of `size`² texels and `mips` levels, every texel `value`.
fn atlas(size: u32, mips: u32, value: u8) -> MipChain {
    let levels = (0..mips).map(|m| vec![value; (4 * (size >> m) * (size >> m)) as usize]).collect();
    MipChain { size: [size; 2], levels }
}

/// LOD 1 drawn with continuous LOD where a mesh has it.
const CONTINUOUS: LodChoices =
    LodChoices { continuous_lod: true, slicing_brightness: None, sliced_species: 0 };

fn impostor(name: &str, planes: [usize; 3], sizes: [u32; 3], with_mesh: bool) -> Impostor {
    let plane = Plane {
        corners_model_m: [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 2.0, 0.0], [0.0, 2.0, 0.0]],
        normal_model: [0.0, 0.0, 1.0],
        uv_min: [0.0, 0.0],
        uv_max: [1.0, 1.0],
    };
    let vertex = |y: f32| MeshVertex {
        position_model_m: [0.0, y, 0.0],
        normal_model: [0.0; 3],
        uv: [0.0; 2],
        pivot_model_m: [0.0, y, 0.0],
    };
    let material = |texture: Option<MipChain>| Material {
        name: "m".into(),
        base_color_factor: [0.5, 0.6, 0.7, 1.0],
        alpha_mode: if texture.is_some() { AlphaMode::Mask } else { AlphaMode::Opaque },
        alpha_cutoff: 0.3,
        double_sided: true,
        texture,
        detail: None,
    };
    // Two submeshes sharing vertex 1: bark (plain) and leaves (textured, 16² with 3 mips).
    let mesh = Mesh {
        vertices: vec![vertex(0.0), vertex(2.0), vertex(1.0), vertex(1.5)],
        indices: vec![0, 1, 2, 1, 2, 3],
        submeshes: vec![
            Submesh { material: 0, first_index: 0, index_count: 3 },
            Submesh { material: 1, first_index: 3, index_count: 3 },
        ],
        materials: vec![material(None), material(Some(atlas(16, 3, 200)))],
    };
    Impostor {
        name: name.into(),
        bounding_sphere: BoundingSphere { centre_model_m: [0.0, 1.0, 0.0], radius_m: 1.2 },
        alpha_cutoff: 0.4,
        lods: (0..3)
            .map(|l| ImpostorLod {
                epsilon_m: 0.1,
                planes: vec![plane; planes[l]],
                atlas: atlas(sizes[l], 2, 10 * l as u8),
            })
            .collect(),
        slicing: None,
        mesh: if with_mesh {
            mesh
        } else {
            Mesh { vertices: vec![vertex(0.0), vertex(2.0)], ..Default::default() }
        },
    }
}

#[test]
fn groups_get_their_index_ranges_materials_and_layers_and_missing_species_draw_nothing() {
    let impostors = [
        Some(impostor("A", [3, 2, 1], [8, 4, 8], true)),
        None,
        Some(impostor("C", [2, 1, 1], [8, 8, 8], false)),
    ];
    let built = assets::gather(&impostors, LodChoices::default()).unwrap();
    // 16² leaves set the size; the atlases' 2 mips the count; 3 atlases + 1 texture + 3 atlases.
    assert_eq!((built.size, built.mips, built.layers.len()), (16, 2, 7));
    let lods = SEED_LODS as usize;
    let groups = SEED_GROUPS as usize;
    let t = &built.templates;
    assert_eq!(t.len(), SEED_DRAWS as usize);
    // Species 0: clouds of 3, 2 and 1 planes (LODs 1-3), then its mesh (LOD 0): 6 vertices, as
    // the shared vertex is repeated for the second material.
    assert_eq!([t[0].index_count, t[1].index_count, t[2].index_count, t[3].index_count], [6, 18, 12, 6]);
    assert_eq!([t[1].first_index, t[2].first_index, t[3].first_index, t[0].first_index], [0, 18, 30, 36]);
    assert_eq!([t[1].base_vertex, t[2].base_vertex, t[3].base_vertex, t[0].base_vertex], [0, 12, 20, 24]);
    assert!(t[lods..2 * lods].iter().all(|a| a.index_count == 0));
    // Species 2 has no mesh: its 2-plane cloud is drawn up close too.
    assert_eq!(t[2 * lods], t[2 * lods + 1]);
    assert_eq!(built.vertices.len(), 24 + 6 + 16);
    // Cross-fades draw the next LOD; the last LOD's draws nothing.
    assert_eq!(&t[groups..groups + 3], &t[1..4]);
    assert_eq!(t[groups + 3].index_count, 0);
    // Materials: clouds (lod 1-3, textured, clamped), then bark (plain, opaque), leaves (repeat).
    let m = &built.materials;
    assert_eq!(m.iter().take(5).map(|m| m.lod).collect::<Vec<_>>(), [1, 2, 3, 0, 0]);
    assert_eq!((m[0].layer, m[0].alpha_cutoff, m[0].flags), (0, 0.4, MATERIAL_TEXTURED));
    assert_eq!((m[3].flags, m[3].alpha_cutoff, m[3].base_colour), (0, -1.0, [0.5, 0.6, 0.7, 1.0]));
    assert_eq!((m[4].layer, m[4].alpha_cutoff, m[4].flags), (3, 0.3, MATERIAL_TEXTURED | MATERIAL_REPEAT));
    let mesh_materials: Vec<u32> = built.vertices[24..30].iter().map(|v| v.material).collect();
    assert_eq!(mesh_materials, [3, 3, 3, 4, 4, 4]);
    assert_eq!(built.inv_model_height_m[..3], [0.5, 0.0, 0.5]);
    // The 4² atlas was resampled to 16², each mip to its own size; the 16² texture copied.
    assert_eq!(built.layers[1][0].len(), 4 * 16 * 16);
    assert_eq!(built.layers[1][1].len(), 4 * 8 * 8);
    assert!(built.layers[1][0].iter().all(|&v| v == 10));
    assert!(built.layers[3][1].iter().all(|&v| v == 200));
    // Nothing is drawn with continuous LOD without materials that say how.
    assert!(built.details.iter().all(Option::is_none));
    assert_eq!(assets::gather(&impostors, CONTINUOUS).unwrap().templates, built.templates);
}

/// A generated tree's mesh in miniature: `leaves` leaf quads (leaves first, 0.1 m), then stems of
/// two levels (0.5 m and 0.01 m across), one triangle each.
fn detailed(leaves: u32) -> Impostor {
    let mut tree = impostor("T", [3, 2, 1], [8, 8, 8], true);
    let vertex = |p: [f32; 3]| MeshVertex {
        position_model_m: p,
        normal_model: [0.0; 3],
        uv: [0.0; 2],
        pivot_model_m: p,
    };
    let mut vertices = Vec::new();
    let mut indices = Vec::new();
    for i in 0..leaves {
        let y = 0.5 + i as f32 * 0.01;
        vertices.extend([[0.0, y, 0.0], [0.1, y, 0.0], [0.1, y + 0.1, 0.0], [0.0, y + 0.1, 0.0]].map(vertex));
        let c = 4 * i;
        indices.extend([c, c + 1, c + 2, c, c + 2, c + 3]);
    }
    for _ in 0..2 {
        let first = vertices.len() as u32;
        // A stem's vertices name its base as their pivot.
        let on_stem = |p: [f32; 3]| MeshVertex { pivot_model_m: [0.0; 3], ..vertex(p) };
        vertices.extend([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 2.0, 0.0]].map(on_stem));
        indices.extend([first, first + 1, first + 2]);
    }
    let material = |detail| Material { detail: Some(detail), ..tree.mesh.materials[0].clone() };
    let leaf_indices = 6 * leaves;
    tree.mesh = Mesh {
        vertices,
        indices,
        submeshes: vec![
            Submesh { material: 0, first_index: 0, index_count: leaf_indices },
            Submesh { material: 1, first_index: leaf_indices, index_count: 3 },
            Submesh { material: 2, first_index: leaf_indices + 3, index_count: 3 },
        ],
        materials: vec![
            Material { texture: Some(atlas(16, 3, 200)), ..material(Detail::Leaves { size_m: 0.1 }) },
            Material { texture: Some(atlas(16, 3, 50)), ..material(Detail::Stems { diameter_m: 0.5 }) },
            Material { texture: Some(atlas(16, 3, 50)), ..material(Detail::Stems { diameter_m: 0.01 }) },
        ],
    };
    tree
}

#[test]
fn a_mesh_with_continuous_lod_stands_for_the_first_cloud_and_keeps_its_pieces() {
    let built = assets::gather(&[Some(detailed(10))], CONTINUOUS).unwrap();
    let t = &built.templates;
    let groups = SEED_GROUPS as usize;
    // Clouds of 2 and 1 planes (LODs 2, 3), then the mesh: 40 leaf vertices and 2 × 3 stems'.
    assert_eq!([t[2].first_index, t[3].first_index, t[0].first_index], [0, 12, 18]);
    assert_eq!(t[0].index_count, 60 + 6);
    assert_eq!(t[1], t[0], "the mesh is LOD 1 too");
    assert_eq!(t[groups].index_count, 0, "the mesh goes on: LOD 0 has no cross-fade");
    assert_eq!(&t[groups + 1..groups + 3], &t[2..4]);
    let m = &built.materials;
    assert_eq!(
        m.iter().map(|m| (m.lod, m.last_lod)).collect::<Vec<_>>(),
        [(2, 2), (3, 3), (0, 1), (0, 1), (0, 1)]
    );
    let leaves = &m[2];
    assert_eq!(leaves.flags & (MATERIAL_LEAVES | MATERIAL_STEMS), MATERIAL_LEAVES);
    assert_eq!(
        (leaves.first_leaf_vertex, leaves.leaf_count, leaves.detail_m),
        (t[0].base_vertex as u32, 10, 0.1)
    );
    assert_eq!((m[3].flags & MATERIAL_STEMS, m[3].detail_m, m[4].detail_m), (MATERIAL_STEMS, 0.5, 0.01));
    // Two clouds' atlases, the leaves' texture, and one layer for the two levels' same bark.
    assert_eq!((m[2].layer, m[3].layer, m[4].layer, built.layers.len()), (2, 3, 3, 4));
    let detail = built.details[0].as_ref().unwrap();
    assert_eq!(detail.leaves.unwrap().first_index, 18);
    assert_eq!(
        detail.stems.iter().map(|(r, d)| (r.clone(), *d)).collect::<Vec<_>>(),
        [(78..81, 0.5), (81..84, 0.01)]
    );
    // Stems whose triangles do not share a pivot cannot be told apart: they are drawn whole.
    let mut unnamed = detailed(10);
    unnamed.mesh.vertices.iter_mut().for_each(|v| v.pivot_model_m = v.position_model_m);
    let unnamed = assets::gather(&[Some(unnamed)], CONTINUOUS).unwrap();
    let detail = unnamed.details[0].as_ref().unwrap();
    assert!(detail.stems.is_empty() && detail.whole_pieces == [78..81, 81..84]);
    assert!(unnamed.materials[3..].iter().all(|m| m.flags & MATERIAL_STEMS == 0));
    // Without continuous LOD the same mesh is drawn as any other.
    let plain = assets::gather(&[Some(detailed(10))], LodChoices::default()).unwrap();
    assert!(plain.details[0].is_none() && plain.templates[1] != plain.templates[0]);
    assert!(plain.materials.iter().all(|m| m.last_lod == m.lod));
}

#[test]
fn each_frame_narrows_lod_1_to_what_its_nearest_seed_keeps() {
    let built = assets::gather(&[Some(detailed(100))], CONTINUOUS).unwrap();
    let mut settings = crate::config::Settings::preset("balanced").unwrap();
    settings.draw_seeds.reach_m = [100.0, 200.0, 300.0, 400.0];
    settings.seeds.reference_height_m = 2.0;
    let at = |focal_px: f32| {
        let t = super::frame::detail_templates(
            &built.templates,
            &built.details,
            &[2.0],
            &built.inv_model_height_m,
            &settings,
            focal_px,
        );
        (t[1].first_index, t[1].index_count, t[0])
    };
    let whole = built.templates[0];
    // The model is 2 m tall: a seed 2 m tall is drawn at scale 1, its leaves 0.1 m, LOD 1 from
    // 98 m on. At a focal length of 10 000 px a leaf is 10 px there: all is kept.
    assert_eq!(at(10_000.0), (whole.first_index, whole.index_count, whole));
    // At 980 px a leaf is 1 px: a quarter of the leaves are kept, the last ones; the stems stay
    // (some seeds draw a twig of 0.1 px widened).
    let (first, count, lod0) = at(980.0);
    assert_eq!(lod0, whole, "LOD 0 is never narrowed");
    let left_out = (first - whole.first_index) / 6;
    assert!((74..=76).contains(&left_out), "{left_out} of 100 leaves left out");
    assert_eq!(first + count, whole.first_index + whole.index_count);
    // At 10 px no leaf is left: only the stems are drawn.
    assert_eq!(at(10.0).0..at(10.0).0 + at(10.0).1, whole.first_index + 600..whole.first_index + 606);
}

#[test]
fn missing_models_are_counted_not_errors() {
    let dir = std::env::temp_dir().join(format!("terramp-draw-seeds-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let table = crate::classes::ClassTable::load("nc").unwrap();
    let loaded = load_impostors(&dir, &table.species).unwrap();
    assert_eq!(loaded.len(), table.species.len());
    assert!(loaded.iter().all(Option::is_none));
    assert!(matches!(load_impostors(&dir.join("absent"), &table.species), Err(DrawSeedsError::NoFolder(_))));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn slicings_take_lod_1_with_the_trunk_for_the_species_that_may_and_others_keep_their_cloud() {
    let sliced = |name: &str| {
        let mut i = impostor(name, [3, 2, 1], [8, 8, 8], true);
        i.mesh.materials[0].name = "Bark".into();
        let lod =
            ImpostorLod { epsilon_m: 0.2, planes: i.lods[0].planes[..2].to_vec(), atlas: atlas(8, 2, 90) };
        i.slicing = Some(Slicing { orientations: 2, slices: 1, lod, crown_triangles: 1, trunk_triangles: 1 });
        i
    };
    let impostors = [Some(sliced("Tree")), Some(sliced("Rock"))];
    let choices = LodChoices { continuous_lod: false, slicing_brightness: Some(0.5), sliced_species: 0b01 };
    let built = assets::gather(&impostors, choices).unwrap();
    let plain = assets::gather(&impostors, LodChoices::default()).unwrap();
    let (t, lods) = (&built.templates, SEED_LODS as usize);
    // Species 0's LOD 1: its bark triangle (3 vertices), then its 2 slices (8 vertices, 12 indices).
    assert_eq!(t[1].index_count, 3 + 12);
    let first = t[1].base_vertex as usize;
    let materials: Vec<&SeedMaterial> =
        built.vertices[first..first + 11].iter().map(|v| &built.materials[v.material as usize]).collect();
    assert!(
        materials[..3].iter().all(|m| (m.lod, m.last_lod, m.flags & MATERIAL_BARK) == (1, 1, MATERIAL_BARK))
    );
    assert!(materials[3..].iter().all(|m| {
        (m.lod, m.flags & MATERIAL_SLICE, m.slicings, m.slicing_brightness) == (1, MATERIAL_SLICE, 2, 0.5)
    }));
    // The rock keeps its 3-plane cloud; the plain build draws both with clouds.
    assert_eq!(t[lods + 1].index_count, 18);
    assert_eq!(plain.templates[1].index_count, 18);
    // A cross-fade from the mesh draws the slicings as LOD 1.
    assert_eq!(t[SEED_GROUPS as usize], t[1]);
}

#[test]
fn the_draws_go_lod_by_lod_each_draw_once_cross_fades_after_their_lod() {
    let order: Vec<usize> = super::gpu::near_to_far_draws().collect();
    let mut sorted = order.clone();
    sorted.sort_unstable();
    assert_eq!(sorted, (0..SEED_DRAWS as usize).collect::<Vec<_>>(), "not every draw once");
    let (groups, lods) = (SEED_GROUPS as usize, SEED_LODS as usize);
    // A draw's place: its group's LOD, then own draws before cross-fades.
    let place = |d: usize| ((d % groups) % lods, d / groups);
    assert!(order.windows(2).all(|w| place(w[0]) <= place(w[1])), "{order:?}");
}

use super::DrawSeedsError;
use super::assets;
use super::frame::load_impostors;
use crate::gpu::layout::{MATERIAL_REPEAT, MATERIAL_TEXTURED, SEED_DRAWS, SEED_GROUPS, SEED_LODS};
use crate::impostor::{
    AlphaMode, BoundingSphere, Impostor, ImpostorLod, Material, Mesh, MeshVertex, MipChain, Plane, Submesh,
};

/// A plain atlas of `size`² texels and `mips` levels, every texel `value`.
fn atlas(size: u32, mips: u32, value: u8) -> MipChain {
    let levels = (0..mips).map(|m| vec![value; (4 * (size >> m) * (size >> m)) as usize]).collect();
    MipChain { size: [size; 2], levels }
}

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
    let built = assets::gather(&impostors).unwrap();
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

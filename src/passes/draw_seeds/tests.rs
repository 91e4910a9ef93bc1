use super::*;
use crate::impostor::{BoundingSphere, ImpostorLod, Mesh, MeshVertex, MipChain, Plane};

/// A plain atlas of `size`² texels and `mips` levels, every texel `value`.
fn atlas(size: u32, mips: u32, value: u8) -> MipChain {
    let levels = (0..mips).map(|m| vec![value; (4 * (size >> m) * (size >> m)) as usize]).collect();
    MipChain { size: [size; 2], levels }
}

fn impostor(name: &str, planes: [usize; 3], sizes: [u32; 3]) -> Impostor {
    let plane = Plane {
        corners_model_m: [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 2.0, 0.0], [0.0, 2.0, 0.0]],
        normal_model: [0.0, 0.0, 1.0],
        uv_min: [0.0, 0.0],
        uv_max: [1.0, 1.0],
    };
    let vertex =
        |y: f32| MeshVertex { position_model_m: [0.0, y, 0.0], normal_model: [0.0; 3], uv: [0.0; 2] };
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
        mesh: Mesh { vertices: vec![vertex(0.0), vertex(2.0)], ..Default::default() },
    }
}

#[test]
fn groups_get_their_index_ranges_and_layers_and_missing_species_draw_nothing() {
    let impostors =
        [Some(impostor("A", [3, 2, 1], [8, 4, 8])), None, Some(impostor("C", [2, 1, 1], [8, 8, 8]))];
    let built = gather(&impostors).unwrap();
    assert_eq!((built.size, built.mips, built.layers.len()), (8, 2, 6));
    let lods = SEED_LODS as usize;
    let t = &built.templates;
    assert_eq!(t.len(), SEED_GROUPS as usize);
    // Species 0: 3, 2 and 1 planes; species 1 nothing; species 2 right after species 0.
    assert_eq!([t[0].index_count, t[1].index_count, t[2].index_count], [18, 12, 6]);
    assert_eq!([t[0].first_index, t[1].first_index, t[2].first_index], [0, 18, 30]);
    assert_eq!([t[0].base_vertex, t[1].base_vertex, t[2].base_vertex], [0, 12, 20]);
    assert!(t[lods..2 * lods].iter().all(|a| a.index_count == 0));
    assert_eq!((t[2 * lods].first_index, t[2 * lods].base_vertex), (36, 24));
    assert_eq!(built.indices.len(), 36 + 24);
    assert_eq!(built.vertices.len(), 24 + 16);
    let g = &built.groups;
    assert_eq!([g[0].layer, g[1].layer, g[2].layer, g[2 * lods].layer], [0, 1, 2, 3]);
    assert_eq!((g[0].alpha_cutoff, g[0].inv_model_height_m), (0.4, 0.5));
    // The 4² atlas was resampled to 8², each mip to its own size.
    assert_eq!(built.layers[1][0].len(), 4 * 8 * 8);
    assert_eq!(built.layers[1][1].len(), 4 * 4 * 4);
    assert!(built.layers[1][0].iter().all(|&v| v == 10));
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

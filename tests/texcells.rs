//! The texcell shader's tiling equals its twin: `forest_uv` run on the GPU (the pass's probe
//! entry point, `passes::texcells::gpu::probe`) gives, bit for bit, the sample coordinates
//! `reference::texcells::forest_uv` gives, at points across cells, halves and both signs, far
//! from the origin, and for two germs.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use terramp::gpu::gpu_types::TexcellUniforms;
use terramp::passes::texcells::gpu::probe::probe_forest_uv;
use terramp::reference::texcells::forest_uv;
use terramp::texcell::tiling::sample_cells_word;
use terramp_testkit::gpu;

#[test]
fn the_shader_tiles_the_ground_as_its_twin_does() {
    let gpu = gpu();
    let cell_m = 32.0f32;
    // A lattice of points, a few per cell, with both halves of each cell and cells of both signs,
    // then the same far away (where f32 positions are coarsest).
    let mut points = Vec::new();
    for j in -40..40 {
        for i in -40..40 {
            let (x, y) = (i as f32 * 9.7 + 0.31, j as f32 * 10.3 - 0.17);
            points.push([x, y]);
            points.push([x + 48_000.0, y + 31_000.0]);
        }
    }
    for seed in [1, 0x5eed] {
        let uniforms = TexcellUniforms {
            inv_cell_m: 1.0 / cell_m,
            seed,
            tile_cells: sample_cells_word(),
            ..Default::default()
        };
        let gpu_uvs = probe_forest_uv(&gpu, &uniforms, &points).unwrap();
        let mismatches: Vec<_> = points
            .iter()
            .zip(&gpu_uvs)
            .filter(|(p, g)| forest_uv(**p, uniforms.inv_cell_m, seed) != **g)
            .take(5)
            .map(|(p, g)| (*p, *g, forest_uv(*p, uniforms.inv_cell_m, seed)))
            .collect();
        assert!(mismatches.is_empty(), "seed {seed}: (point, GPU, twin) {mismatches:?}");
        // Every tile shows up: the four sample cells of each half.
        let cells: std::collections::BTreeSet<[u32; 2]> =
            gpu_uvs.iter().map(|uv| uv.map(|v| (v * 2.0).floor() as u32)).collect();
        assert_eq!(cells.len(), 4, "{cells:?}");
    }
}

//! How it works: a contact sheet of models, to look at what the baker will see: each model drawn
//! from the side (orthographic, looking along −Z, +Y up) into its own cell of a grid, all at one
//! scale (the tallest model fills its cell's height) so sizes compare, through the baker's own
//! pipeline (unlit base colour, alpha-masked leaves cut at their cutoff), then laid over a sky
//! with a ground line under each model.

use glam::{Mat4, Vec4};

use super::RenderError;
use super::render::{Baker, Instances};
use crate::gpu::Gpu;
use crate::impostor::{Mesh, TexelRect};

/// Sky behind the models, and the ground line under them (sRGB).
const SKY: [u8; 3] = [196, 214, 230];
const GROUND: [u8; 3] = [92, 78, 60];

/// Draws `meshes` side by side, `columns` per row, each cell `cell` texels: an RGBA8 sRGB image,
/// top row first, and its size.
pub fn contact_sheet(
    gpu: &Gpu,
    meshes: &[Mesh],
    columns: u32,
    cell: [u32; 2],
) -> Result<(Vec<u8>, [u32; 2]), RenderError> {
    let columns = columns.clamp(1, meshes.len().max(1) as u32);
    let rows = (meshes.len() as u32).div_ceil(columns);
    let size = [columns * cell[0], rows * cell[1]];
    let bounds: Vec<([f32; 3], [f32; 3])> = meshes.iter().map(bounds).collect();
    let tallest_m = bounds.iter().map(|(_, hi)| hi[1]).fold(1e-3, f32::max);
    // The tallest model spans 90 % of a cell's height; widths follow at the same scale.
    let m_per_texel = tallest_m / (0.9 * cell[1] as f32);
    let baker = Baker::new(gpu);
    let uploaded: Vec<_> = meshes.iter().map(|m| baker.upload(gpu, m)).collect();
    let batches: Vec<Instances> = meshes
        .iter()
        .zip(&uploaded)
        .zip(&bounds)
        .enumerate()
        .map(|(i, ((mesh, uploaded), (lo, hi)))| {
            let (col, row) = (i as u32 % columns, i as u32 / columns);
            let rect = TexelRect { x: col * cell[0], y: row * cell[1], width: cell[0], height: cell[1] };
            let half_w_m = 0.5 * cell[0] as f32 * m_per_texel;
            let half_h_m = 0.5 * cell[1] as f32 * m_per_texel;
            let bottom_m = -0.05 * cell[1] as f32 * m_per_texel;
            let depth_m = (hi[2] - lo[2]).max(1e-3);
            // Nearer (larger z) is smaller depth; x and y span the cell.
            let clip_from_model = Mat4::from_cols(
                Vec4::new(1.0 / half_w_m, 0.0, 0.0, 0.0),
                Vec4::new(0.0, 1.0 / half_h_m, 0.0, 0.0),
                Vec4::new(0.0, 0.0, -1.0 / depth_m, 0.0),
                Vec4::new(0.0, -1.0 - bottom_m / half_h_m, hi[2] / depth_m, 1.0),
            );
            Instances { mesh, uploaded, instances: vec![(clip_from_model, rect)] }
        })
        .collect();
    let mut rgba = baker.render_instances(gpu, &batches, size)?;
    let ground_from = (0.95 * cell[1] as f32) as u32;
    for (texel, chunk) in rgba.chunks_exact_mut(4).enumerate() {
        let y_in_cell = (texel as u32 / size[0]) % cell[1];
        let behind = if y_in_cell >= ground_from { GROUND } else { SKY };
        if chunk[3] == 0 {
            chunk.copy_from_slice(&[behind[0], behind[1], behind[2], 255]);
        }
    }
    Ok((rgba, size))
}

fn bounds(mesh: &Mesh) -> ([f32; 3], [f32; 3]) {
    mesh.vertices.iter().fold(([f32::MAX; 3], [f32::MIN; 3]), |(lo, hi), v| {
        let p = v.position_model_m;
        (std::array::from_fn(|i| lo[i].min(p[i])), std::array::from_fn(|i| hi[i].max(p[i])))
    })
}

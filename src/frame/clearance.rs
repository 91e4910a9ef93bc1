//! How it works: the terrain mesh is one-sided (back faces are culled), so a camera under the
//! ground would see the sky through it, and the passes that cull against the ground would judge
//! from inside it. A camera below the ground is therefore lifted, before anything else in the
//! frame sees it, to `GROUND_CLEARANCE_NEAR` near planes above the ground, and the frame reports by
//! how much. The ground is the higher of the two surfaces over the level-0 cell under the camera:
//! the bilinear one seeds stand on and the two triangles the finest mesh draws (the diagonal
//! alternating like a checkerboard, as `passes::terrain::frame::grid_indices` lays it out). On a
//! coarse DEM they part by metres. Only a camera over the dataset can be under it; the height
//! tile's range from the pack index rules out almost every camera without reading a sample.

use glam::DVec3;

use super::Renderer;
use crate::camera::Camera;
use crate::dataset::{PackError, TileId};

/// Clearance of a lifted camera above the ground, in near planes: the ground right below it stays
/// beyond the near plane whatever the pitch.
pub const GROUND_CLEARANCE_NEAR: f64 = 2.0;

impl Renderer {
    /// `camera`, lifted above the ground if it is under it, and the metres it was lifted by.
    pub(super) fn above_ground(&self, camera: &Camera) -> (Camera, f64) {
        let m = &self.dataset.manifest;
        let grid = camera.position_m - DVec3::new(m.origin_m[0], m.origin_m[1], 0.0);
        let pyramid = &self.dataset.height.pyramid;
        let spacing_m = m.height.spacing_m;
        let clearance_m = GROUND_CLEARANCE_NEAR * camera.near_m;
        let span_m = pyramid.size.map(|n| f64::from(n.saturating_sub(1).max(1)) * spacing_m);
        let over = grid.x >= 0.0 && grid.y >= 0.0 && grid.x <= span_m[0] && grid.y <= span_m[1];
        if !over || grid.z >= f64::from(m.height.max_m) + clearance_m {
            return (*camera, 0.0);
        }
        let tile_m = f64::from(pyramid.tile) * spacing_m;
        let [nx, ny] = pyramid.tiles_at(0);
        let tile =
            TileId::new(0, ((grid.x / tile_m) as u32).min(nx - 1), ((grid.y / tile_m) as u32).min(ny - 1));
        let high_m = self.dataset.height_range(tile).map_or(f64::from(m.height.max_m), |r| f64::from(r[1]));
        if grid.z >= high_m + clearance_m {
            return (*camera, 0.0);
        }
        // A tile that cannot be read leaves the camera where it is: the frame reports the tile.
        let Ok(ground_m) = self.ground_m(grid.x, grid.y) else { return (*camera, 0.0) };
        let lift_m = ground_m + clearance_m - grid.z;
        if lift_m <= 0.0 {
            return (*camera, 0.0);
        }
        // Grid z is CRS z: set it, so that rendering the lifted camera lifts it no further.
        let mut lifted = *camera;
        lifted.position_m.z = ground_m + clearance_m;
        (lifted, lift_m)
    }

    /// The higher of the bilinear and the finest mesh's surface at grid position (x, y).
    fn ground_m(&self, x_m: f64, y_m: f64) -> Result<f64, PackError> {
        let size = self.dataset.height.pyramid.size;
        let spacing_m = self.dataset.manifest.height.spacing_m;
        let axis = |v: f64, n: u32| {
            let g = (v / spacing_m).clamp(0.0, f64::from(n.saturating_sub(1)));
            let i = (g.floor() as u32).min(n.saturating_sub(2));
            (i, g - f64::from(i))
        };
        let ((i, u), (j, v)) = (axis(x_m, size[0]), axis(y_m, size[1]));
        let sample = |i: u32, j: u32| self.dataset.height_sample(0, i.min(size[0] - 1), j.min(size[1] - 1));
        let (h00, h10, h01, h11) =
            (sample(i, j)?, sample(i + 1, j)?, sample(i, j + 1)?, sample(i + 1, j + 1)?);
        let bilinear = h00 + (h10 - h00) * u + (h01 - h00) * v + (h11 - h10 - h01 + h00) * u * v;
        let mesh = match ((i + j) % 2 == 0, u >= v, u + v <= 1.0) {
            (true, true, _) => h00 + (h10 - h00) * u + (h11 - h10) * v,
            (true, false, _) => h00 + (h11 - h01) * u + (h01 - h00) * v,
            (false, _, true) => h00 + (h10 - h00) * u + (h01 - h00) * v,
            (false, _, false) => h11 + (h01 - h11) * (1.0 - u) + (h10 - h11) * (1.0 - v),
        };
        Ok(bilinear.max(mesh))
    }
}

//! How it works: the terrain mesh is one-sided (back faces are culled), so a camera under the
//! ground would see the sky through it, and the passes that cull against the ground would judge
//! from inside it. A camera below the ground is therefore lifted, before anything else in the
//! frame sees it, to `GROUND_CLEARANCE_NEAR` near planes above the ground, and the frame reports by
//! how much. The ground is the drawn one over the level-0 cell under the camera
//! (`Dataset::height_at`: the triangles the finest mesh draws, the ground seeds stand on). Only a
//! camera over the dataset can be under it; the height tile's range from the pack index rules out
//! almost every camera without reading a sample.

use glam::DVec3;

use super::Renderer;
use crate::camera::Camera;
use crate::dataset::TileId;

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
        let Ok(ground_m) = self.dataset.height_at(grid.x, grid.y, 0) else { return (*camera, 0.0) };
        let lift_m = ground_m + clearance_m - grid.z;
        if lift_m <= 0.0 {
            return (*camera, 0.0);
        }
        // Grid z is CRS z: set it, so that rendering the lifted camera lifts it no further.
        let mut lifted = *camera;
        lifted.position_m.z = ground_m + clearance_m;
        (lifted, lift_m)
    }
}

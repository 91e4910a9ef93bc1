//! How it works: the terrain pass (pass 0) draws the CDLOD nodes chosen by `select` as instances
//! of one grid mesh, displaced in the vertex shader by the height tiles of the height cache
//! (`shaders/shared/terrain_mesh.wgsl`), into a reversed-Z Depth32Float target only: the depth
//! the Tile Load Map culls against before anything is shaded. The ground pass
//! (`passes::ground`) then draws the same instances again, at depth-equal, to shade them; this
//! module owns what both share: the bind group, the node instances and the mesh draw.
//!
//! The grid's index buffer is laid out quadrant by quadrant, so a node of which the parent draws
//! only some quadrants (CDLOD's partial nodes) costs one instanced draw per quadrant: instances
//! are grouped by quadrant and each group is drawn with that quadrant's index range.
//!
//! `select` (CDLOD node selection) and `frame` (instances, uniforms, wanted tiles) are the CPU
//! half; `gpu` the pipeline, binding table and recorded draw.

pub mod frame;
pub mod gpu;
pub mod select;

// Pass 0, terrain and depth: the mesh of `shared/terrain_mesh.wgsl` drawn into the depth buffer
// only. Every later pass stands on this depth: the Tile Load Map culls against its pyramid, the
// ground pass shades exactly the fragments it kept (depth-equal), the seeds are hidden by it.
// The mesh's vertex stage is the whole program; there is no fragment stage.

//! How it works: pass 2, the ground. It draws the terrain pass's node instances again, with the
//! same vertex code (`shaders/shared/terrain_mesh.wgsl`, positions `@invariant`), at depth-equal
//! without writing depth, so each pixel is shaded once, by the surface the depth pass kept. The
//! shading (`shaders/ground.wgsl`) reads imagery through the imagery cache's page table from the
//! finest resident level at or above the one the pixel's footprint asks for: a tile not loaded
//! yet shows its ancestor, blurry, never a hole. Borders stored with each tile let trilinear and
//! anisotropic filtering run inside one tile; gradients come from continuous coordinates, so tile
//! edges cause no derivative spikes.
//!
//! The pass has no CPU data of its own (it draws the terrain pass's instances): `gpu` is all of it.

pub mod gpu;

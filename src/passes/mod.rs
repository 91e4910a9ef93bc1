//! How it works: one module per GPU pass of the frame after the terrain, each with its shader of
//! the same name in `shaders/` and, for the passes whose output the CPU relies on, a CPU twin of
//! the same name in `reference/`. A pass builds its pipelines once in `new`, writes its per-frame
//! inputs in `prepare`, and only records commands in `encode`; `frame.rs` calls them in order.

pub mod depth_pyramid;
pub mod ground;
pub mod seed_select;
pub mod tile_load_map;

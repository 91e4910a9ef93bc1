//! How it works: pass 3, seed selection (Amara et al. 2007 § 4.4). The CPU hands the GPU the
//! ring-0 cells the latest Tile Load Map found visible within the radial LOD range, each with its
//! pattern and land-cover level; `shaders/seed_select.wgsl` checks every seed of every such cell
//! (one invocation per seed) and appends the survivors to a fixed-capacity record buffer, with
//! counters of what was checked, culled (and why) and what overflowed. Each workgroup writes its
//! survivors in rank order, each with its draw group in a parallel key buffer, and where it put
//! them in its own entry of a block table (`SeedBlock`), which compaction (`passes::compact`)
//! reads in order: the table, not the atomics, fixes the order in which seeds are drawn.
//!
//! `SeedFrame::new` is the CPU half, in f64: it turns each cell's corner into an integer texel and
//! a remainder in every layer's own grid (height samples, level-1 land-cover texels, level-0
//! imagery texels) and pre-divides every length, so the shader (and its twin,
//! `reference/seed_select.rs`) only adds and multiplies small f32 numbers. The patterns and the
//! species tables are uploaded once, in `new`.
//!
//! `frame` is the CPU half (the frame's uniforms and cells, and the output as CPU data), which the
//! twin (`reference::seed_select`) and the analysis read; `gpu` the pipeline, binding table,
//! buffers and recorded dispatch; `march` the tops its occlusion march leaps by.

pub mod frame;
pub mod gpu;
pub mod march;

#[cfg(test)]
mod tests;

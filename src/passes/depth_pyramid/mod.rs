//! How it works: the depth pyramid (Hi-Z) reduces the terrain's reversed-Z depth (1 near, 0 for
//! the sky) into an R32Float mip chain in which each texel holds the *minimum* depth, i.e. the
//! farthest surface, of the pixels it covers. Level 0 is half the target's size; every level
//! halves the one below, rounding down as wgpu's mip sizes do, and the last texel of an odd edge
//! takes three texels below it, so the reduction is conservative at any size. A pixel (x, y)
//! therefore belongs to texel `min(x >> (level + 1), width(level) - 1)` (and likewise in y) at
//! every level: a screen rectangle reads a bounded number of texels and sees every pixel in it.
//!
//! One compute dispatch per level, each reading the level below through a view of that single
//! mip (wgpu tracks usage per mip, so level L can be written while level L − 1 is read).
//!
//! `frame` holds the pyramid as CPU data (`HizMips`, for the Tile Load Map's twin) and its level
//! sizes; `gpu` the pipelines, binding tables and recorded reduction. Its twin is
//! `reference::depth_pyramid`.

pub mod frame;
pub mod gpu;

//! How it works: which tiles a view needs (`wants`), the fixed-size GPU caches that hold them
//! behind page tables (`cache`, with its CPU policy in `residency`), and the loader threads that
//! read and verify tiles off the render thread (`loader`). Each frame the render thread hands each
//! cache its wanted list, sends the resulting requests to the loader, and uploads what arrived
//! within the frame's budget; see `TileCache::set_wanted`.

pub mod analysis;
pub mod cache;
pub mod loader;
mod residency;
pub mod wants;

pub use cache::{CacheStats, TileCache, UploadBudget};
pub use loader::{LayerKind, Loaded, Loader, LoaderError, TileRequest};
pub use wants::{AreaWant, tiles_over};

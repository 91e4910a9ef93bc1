//! How it works: which tiles a view asks for (`wants`: areas to tile lists, pinned levels), the
//! fixed-size GPU caches that hold them behind page tables (`cache`, with its CPU policy in
//! `residency`), and the loader threads that read and verify tiles off the render thread
//! (`loader`). Each frame the render thread hands each cache its wanted list, sends the resulting
//! requests to the loader, and uploads what arrived within the frame's budget; see
//! `TileCache::set_wanted`. Nothing here knows the passes: they tell it what they want.

pub mod cache;
pub mod faults;
mod layer;
pub mod loader;
mod residency;
pub mod wants;

pub use cache::{SlotSummary, TileCache, page_levels};
pub use faults::Faults;
pub use layer::LayerKind;
pub use loader::{Delivery, Loaded, Loader, LoaderError, LoaderOptions, TileRequest};
pub use residency::{CacheStats, UploadBudget};
pub use wants::{AreaWant, tiles_over};

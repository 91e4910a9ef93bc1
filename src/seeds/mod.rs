//! How it works: seeds (paper § 4.4). To be written.

pub mod patterns;

//! How it works: per-pass profiling of a flight (`terramp profile`). To be written.

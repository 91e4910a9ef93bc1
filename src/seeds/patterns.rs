//! How it works: seed patterns. To be written.

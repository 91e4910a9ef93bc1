//! How it works: impostors (billboard clouds baked from glTF models). To be written.

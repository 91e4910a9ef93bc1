//! How it works: `mesh.bin` is a 24-byte header, then the vertices as [`MeshVertex`] structs
//! (44 bytes each), then the `u32` indices, all little-endian (the layout of every target terramp
//! builds for). The header holds the magic `TRMPMESH`, the format version, both counts and a
//! CRC-32 of everything after it, so a truncated or damaged file is an error naming it, never
//! garbage on the GPU.

use std::path::Path;

use super::{FORMAT_VERSION, ImpostorError, MeshVertex};

const MAGIC: &[u8; 8] = b"TRMPMESH";
const HEADER_BYTES: usize = 24;

/// The file's bytes for these vertices and indices.
pub fn encode(vertices: &[MeshVertex], indices: &[u32]) -> Vec<u8> {
    let mut payload = Vec::with_capacity(size_of_val(vertices) + size_of_val(indices));
    payload.extend_from_slice(bytemuck::cast_slice(vertices));
    payload.extend_from_slice(bytemuck::cast_slice(indices));
    let mut bytes = Vec::with_capacity(HEADER_BYTES + payload.len());
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    bytes.extend_from_slice(&(vertices.len() as u32).to_le_bytes());
    bytes.extend_from_slice(&(indices.len() as u32).to_le_bytes());
    bytes.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
    bytes.extend_from_slice(&payload);
    bytes
}

/// The vertices and indices in `bytes` (read from `path`, named in errors).
pub fn decode(path: &Path, bytes: &[u8]) -> Result<(Vec<MeshVertex>, Vec<u32>), ImpostorError> {
    let invalid = |reason: String| ImpostorError::Invalid { path: path.to_owned(), reason };
    if bytes.len() < HEADER_BYTES || &bytes[..8] != MAGIC {
        return Err(invalid("not a terramp mesh file (bad magic)".into()));
    }
    let word = |at: usize| u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let version = word(8);
    if version != FORMAT_VERSION {
        return Err(ImpostorError::Version {
            path: path.to_owned(),
            found: version,
            expected: FORMAT_VERSION,
        });
    }
    let (vertex_count, index_count, crc) = (word(12) as usize, word(16) as usize, word(20));
    let vertex_bytes = vertex_count * size_of::<MeshVertex>();
    let expected = HEADER_BYTES + vertex_bytes + index_count * 4;
    if bytes.len() != expected {
        return Err(invalid(format!("{} bytes, expected {expected} (truncated?)", bytes.len())));
    }
    let payload = &bytes[HEADER_BYTES..];
    if crc32fast::hash(payload) != crc {
        return Err(invalid("checksum mismatch: the file is damaged".into()));
    }
    // Copy out: the payload need not be aligned for `MeshVertex`.
    let vertices: Vec<MeshVertex> = payload[..vertex_bytes]
        .chunks_exact(size_of::<MeshVertex>())
        .map(bytemuck::pod_read_unaligned)
        .collect();
    let indices: Vec<u32> =
        payload[vertex_bytes..].chunks_exact(4).map(bytemuck::pod_read_unaligned).collect();
    if let Some(bad) = indices.iter().find(|&&i| i as usize >= vertex_count) {
        return Err(invalid(format!("index {bad} out of range ({vertex_count} vertices)")));
    }
    Ok((vertices, indices))
}

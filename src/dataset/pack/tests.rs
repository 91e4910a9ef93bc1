use super::*;

const CODECS: [Codec; 2] = [Codec::Raw, Codec::Zstd(Predictor::Planes(4))];

fn temp_path(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("terramp-pack-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join("layer.pack")
}

fn written_pack(name: &str, codec: Codec) -> PathBuf {
    let path = temp_path(name);
    let writer = PackWriter::create(&path, 16, 3, codec).unwrap();
    for i in (0..3).rev() {
        writer.write_tile(i, &[i as u8; 16], Some([i as f32, 10.0 + i as f32])).unwrap();
    }
    assert_eq!(writer.read_tile(1).unwrap(), vec![1u8; 16]);
    writer.finish().unwrap();
    path
}

#[test]
fn round_trip_in_any_order_with_every_codec() {
    for codec in CODECS {
        let path = written_pack(&format!("roundtrip-{}", codec.word()), codec);
        let pack = Pack::open(&path).unwrap();
        assert_eq!((pack.tile_count(), pack.tile_bytes(), pack.codec()), (3, 16, codec));
        for i in 0..3 {
            assert_eq!(&*pack.tile(i).unwrap(), &[i as u8; 16]);
        }
        assert!(matches!(pack.tile(3), Err(PackError::OutOfRange { .. })));
        assert_eq!(pack.tile_range(2).unwrap(), Some([2.0, 12.0]));
    }
}

#[test]
fn flipped_byte_is_reported_for_that_tile_only() {
    for codec in CODECS {
        let path = written_pack(&format!("corrupt-{}", codec.word()), codec);
        let mut bytes = std::fs::read(&path).unwrap();
        // Tiles are stored in the order written: 2, 1, 0; the first stored is tile 2.
        let header = Header::decode(&bytes, &path).unwrap();
        bytes[header.data_offset() as usize + 3] ^= 0x40;
        std::fs::write(&path, &bytes).unwrap();
        let pack = Pack::open(&path).unwrap();
        assert!(pack.tile(0).is_ok());
        assert!(matches!(pack.tile(2), Err(PackError::Corrupt { index: 2, .. })), "{codec:?}");
    }
}

#[test]
fn a_damaged_index_is_refused_at_open() {
    let path = written_pack("index", Codec::Raw);
    let mut bytes = std::fs::read(&path).unwrap();
    bytes[HEADER_BYTES as usize + 9] ^= 0x01;
    std::fs::write(&path, &bytes).unwrap();
    assert!(matches!(Pack::open(&path), Err(PackError::CorruptIndex { .. })));
}

#[test]
fn truncated_and_foreign_files_are_refused() {
    let path = written_pack("truncated", Codec::Zstd(Predictor::None));
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() - 5]).unwrap();
    assert!(matches!(Pack::open(&path), Err(PackError::Truncated { .. })));
    std::fs::write(&path, b"GIF89a, not a pack at all, but long enough to hold a header....").unwrap();
    assert!(matches!(Pack::open(&path), Err(PackError::NotAPack { .. })));
}

#[test]
fn unwritten_tiles_are_missing_not_zero() {
    let path = temp_path("missing");
    let writer = PackWriter::create(&path, 4, 2, Codec::Raw).unwrap();
    writer.write_tile(0, &[7; 4], None).unwrap();
    assert!(matches!(writer.write_tile(0, &[7; 3], None), Err(PackError::PayloadSize { .. })));
    writer.finish().unwrap();
    let pack = Pack::open(&path).unwrap();
    assert!(matches!(pack.tile(1), Err(PackError::Missing { index: 1, .. })));
    assert_eq!(pack.tile_range(0).unwrap(), None);
}

/// A version 2 pack (raw tiles at fixed places, 16-byte entries), byte for byte as that build
/// wrote it.
fn legacy_pack(tiles: &[[u8; 8]]) -> Vec<u8> {
    let count = tiles.len() as u64;
    let mut index = Vec::new();
    for t in tiles {
        index.extend_from_slice(&crc32fast::hash(t).to_le_bytes());
        index.extend_from_slice(&TILE_PRESENT.to_le_bytes());
        index.extend_from_slice(&u64::MAX.to_le_bytes());
    }
    let mut header = [0u8; 64];
    header[0..8].copy_from_slice(MAGIC);
    header[8..12].copy_from_slice(&LEGACY_VERSION.to_le_bytes());
    header[16..24].copy_from_slice(&8u64.to_le_bytes());
    header[24..32].copy_from_slice(&count.to_le_bytes());
    header[32..36].copy_from_slice(&crc32fast::hash(&index).to_le_bytes());
    let crc = crc32fast::hash(&header[0..60]);
    header[60..64].copy_from_slice(&crc.to_le_bytes());
    let mut bytes = header.to_vec();
    bytes.extend(index);
    bytes.resize(DATA_ALIGN as usize, 0);
    bytes.extend(tiles.iter().flatten());
    bytes
}

#[test]
fn version_2_packs_are_still_read_and_other_versions_refused() {
    let path = temp_path("legacy");
    let mut bytes = legacy_pack(&[[1; 8], [2; 8]]);
    std::fs::write(&path, &bytes).unwrap();
    let pack = Pack::open(&path).unwrap();
    assert_eq!((pack.codec(), pack.tile_bytes()), (Codec::Raw, 8));
    assert_eq!(&*pack.tile(1).unwrap(), &[2; 8]);
    assert_eq!(pack.tile_range(0).unwrap(), None);
    bytes[8] = 9;
    let crc = crc32fast::hash(&bytes[0..60]);
    bytes[60..64].copy_from_slice(&crc.to_le_bytes());
    std::fs::write(&path, &bytes).unwrap();
    assert!(matches!(Pack::open(&path), Err(PackError::Version { found: 9, .. })));
}

#[test]
fn a_pack_cut_short_or_rewritten_while_open_fails_its_reads_and_nothing_crashes() {
    // Mapped, the cut read below was a SIGBUS that killed the process.
    let path = written_pack("changed", Codec::Zstd(Predictor::Planes(4)));
    let pack = Pack::open(&path).unwrap();
    assert_eq!(pack.tile(1).unwrap(), [1; 16]);
    let header = Header::decode(&std::fs::read(&path).unwrap(), &path).unwrap();
    // Cut back to the index: every tile's bytes are past the end now.
    std::fs::OpenOptions::new().write(true).open(&path).unwrap().set_len(header.data_offset()).unwrap();
    for i in 0..3 {
        assert!(matches!(pack.tile(i), Err(PackError::Changed { index, .. }) if index == i), "tile {i}");
    }
    let message = pack.tile(0).unwrap_err().to_string();
    assert!(message.contains("changed on disk since it was opened"), "{message}");
    // The index was read at open: what it records still answers.
    assert_eq!(pack.tile_range(2).unwrap(), Some([2.0, 12.0]));

    // Rewritten in place as `cp` does (truncated, then written): a pack of the same layout but
    // other tiles, so every tile read fails the checksum the opened index gives it.
    let pack = Pack::open(&written_pack("changed", Codec::Zstd(Predictor::Planes(4)))).unwrap();
    let other = temp_path("changed-other");
    let writer = PackWriter::create(&other, 16, 3, Codec::Zstd(Predictor::Planes(4))).unwrap();
    for i in (0..3).rev() {
        writer.write_tile(i, &[i as u8 + 100; 16], None).unwrap();
    }
    writer.finish().unwrap();
    std::fs::write(pack.path(), std::fs::read(&other).unwrap()).unwrap();
    for i in 0..3 {
        assert!(matches!(pack.tile(i), Err(PackError::Changed { index, .. }) if index == i), "tile {i}");
    }
    // Opened again, the new file reads whole.
    assert_eq!(Pack::open(pack.path()).unwrap().tile(2).unwrap(), [102; 16]);
}

#[test]
fn damage_before_the_checksum_reaches_the_codec_and_after_it_is_caught() {
    for codec in CODECS {
        let pack = Pack::open(&written_pack(&format!("damage-{}", codec.word()), codec)).unwrap();
        let stored = pack.read_stored(1).unwrap();
        let (mut decoded, mut refused) = (0, 0);
        for at in 0..stored.len() {
            let caught = pack.tile_damaged(1, Damage::Caught { at });
            assert!(matches!(caught, Err(PackError::Corrupt { index: 1, .. })), "{codec:?} byte {at}");
            match pack.tile_damaged(1, Damage::Unseen { at }) {
                Ok(payload) => {
                    decoded += 1;
                    // Raw: the payload is the stored bytes, and the one flipped byte shows.
                    if codec == Codec::Raw {
                        let changed: Vec<usize> = (0..16).filter(|&k| payload[k] != 1).collect();
                        assert_eq!((changed, payload[at]), (vec![at], 1 ^ 0xa5));
                    }
                }
                Err(PackError::Corrupt { index: 1, .. }) => refused += 1,
                Err(error) => panic!("{codec:?} byte {at}: {error}"),
            }
        }
        // Past the checksum every time: a raw tile always decodes, and zstd decodes some damage
        // (into other bytes) and refuses some.
        match codec {
            Codec::Raw => assert_eq!((decoded, refused), (stored.len(), 0)),
            _ => assert!(decoded > 0 && refused > 0, "{codec:?}: {decoded} decoded, {refused} refused"),
        }
        assert_eq!(pack.tile(1).unwrap(), [1; 16], "the damage is to the read, not the file");
    }
}

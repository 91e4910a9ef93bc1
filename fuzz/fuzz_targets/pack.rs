//! A pack file of any bytes (header, index, tiles): opened and every tile read, or refused with a
//! `PackError` naming the file; sizes are checked before anything is allocated from them.
//!
//! The input's first byte says which checksums the target makes right before the pack is read
//! (bit 0: each tile's, of the first 64 entries; bit 1: the index's; bit 2: the header's), the
//! rest is the file. Left wrong, a checksum refuses the file before the fields behind it are used:
//! a mutated size is seen by the arithmetic only when its checksum is made to match. Seeds lead
//! with 7 (`seed_corpora.sh`).
#![no_main]
use libfuzzer_sys::fuzz_target;

mod build_checks;

/// The pack layout `terramp::dataset::pack` reads (its module comment): a 64-byte header, the
/// index of 32-byte entries (16 in version 2) from byte 64, the tiles from the next 4 KiB.
const HEADER_BYTES: usize = 64;
const DATA_ALIGN: usize = 4096;

fn u32_at(bytes: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(bytes.get(at..at + 4)?.try_into().ok()?))
}

fn u64_at(bytes: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_le_bytes(bytes.get(at..at + 8)?.try_into().ok()?))
}

/// Makes the checksums `which` asks for match what they cover, where the file holds it.
fn fix_checksums(pack: &mut [u8], which: u8) {
    let (Some(version), Some(count)) = (u32_at(pack, 8), u64_at(pack, 24)) else { return };
    let entry = if version == 2 { 16 } else { 32 };
    let index_end = usize::try_from(count).ok().and_then(|n| n.checked_mul(entry)?.checked_add(HEADER_BYTES));
    if which & 1 != 0 && version == 3 {
        let data = index_end.and_then(|end| end.checked_next_multiple_of(DATA_ALIGN));
        for k in 0..usize::try_from(count.min(64)).unwrap_or(0) {
            let at = HEADER_BYTES + k * entry;
            let (Some(offset), Some(stored)) = (u64_at(pack, at), u32_at(pack, at + 8)) else { break };
            let start = data.and_then(|d| d.checked_add(usize::try_from(offset).ok()?));
            let span = start.and_then(|s| Some(s..s.checked_add(stored as usize)?));
            let crc = span.and_then(|span| pack.get(span)).map(crc32fast::hash);
            if let (Some(crc), Some(slot)) = (crc, pack.get_mut(at + 12..at + 16)) {
                slot.copy_from_slice(&crc.to_le_bytes());
            }
        }
    }
    if which & 2 != 0
        && let Some(crc) = index_end.and_then(|end| pack.get(HEADER_BYTES..end)).map(crc32fast::hash)
    {
        pack[32..36].copy_from_slice(&crc.to_le_bytes());
    }
    if which & 4 != 0 && pack.len() >= HEADER_BYTES {
        let crc = crc32fast::hash(&pack[0..60]);
        pack[60..64].copy_from_slice(&crc.to_le_bytes());
    }
}

fuzz_target!(init: build_checks::probe(), |bytes: &[u8]| {
    let Some((&which, pack)) = bytes.split_first() else { return };
    let mut pack = pack.to_vec();
    fix_checksums(&mut pack, which);
    let path = std::env::temp_dir().join(format!("terramp-fuzz-pack-{}.pack", std::process::id()));
    if std::fs::write(&path, &pack).is_err() {
        return;
    }
    if let Ok(pack) = terramp::dataset::Pack::open(&path) {
        for index in 0..pack.tile_count().min(64) {
            let _ = pack.tile(index);
            let _ = pack.tile_range(index);
        }
    }
});

//! A pack file of any bytes (header, index, tiles): opened and every tile read, or refused with a
//! `PackError` naming the file; sizes are checked before anything is allocated from them.
#![no_main]
use libfuzzer_sys::fuzz_target;

mod build_checks;

fuzz_target!(init: build_checks::probe(), |bytes: &[u8]| {
    let path = std::env::temp_dir().join(format!("terramp-fuzz-pack-{}.pack", std::process::id()));
    if std::fs::write(&path, bytes).is_err() {
        return;
    }
    if let Ok(pack) = terramp::dataset::Pack::open(&path) {
        for index in 0..pack.tile_count().min(64) {
            let _ = pack.tile(index);
            let _ = pack.tile_range(index);
        }
    }
});

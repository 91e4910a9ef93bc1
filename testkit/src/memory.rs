//! This process's resident memory (Linux `/proc/self/status`), for flights that must not leak.
//! A leak raises the *floor* of the figures over a window of frames (lavapipe holds transient
//! allocations for single frames or short runs), so flights compare window floors.

/// Resident memory of this process, KiB.
#[derive(Debug, Clone, Copy)]
pub struct Memory {
    /// All resident pages.
    pub rss: u64,
    /// Anonymous pages: heap, stacks, and lavapipe's "GPU" memory.
    pub anon: u64,
    /// File-backed pages: mostly the memory-mapped dataset packs, page cache the kernel can
    /// reclaim; reported, not bounded.
    pub file: u64,
}

/// The memory now.
pub fn memory() -> Memory {
    let status = std::fs::read_to_string("/proc/self/status").expect("/proc/self/status (Linux only)");
    let kib = |key: &str| -> u64 {
        let line = status.lines().find(|l| l.starts_with(key)).unwrap_or_else(|| panic!("no {key}"));
        line.split_whitespace().nth(1).and_then(|v| v.parse().ok()).unwrap_or_else(|| panic!("bad {key}"))
    };
    Memory { rss: kib("VmRSS:"), anon: kib("RssAnon:"), file: kib("RssFile:") }
}

/// The minimum of each figure over `samples` (not empty).
pub fn floor(samples: &[Memory]) -> Memory {
    let min = |field: fn(&Memory) -> u64| samples.iter().map(field).min().expect("samples");
    Memory { rss: min(|m| m.rss), anon: min(|m| m.anon), file: min(|m| m.file) }
}

/// Bytes as MiB.
pub fn mib(bytes: u64) -> f64 {
    bytes as f64 / f64::from(1 << 20)
}

//! On `globe/` (the large DEM: 11138 × 6802 samples after the builder's reprojection), a flight of a
//! few hundred frames across it keeps GPU memory fixed and process memory flat.
//!
//! GPU memory: the tile caches are textures allocated once at their configured slot counts, so
//! what must hold is that no frame has more tiles resident than its cache has slots while the
//! flight streams more tiles than that (the slots really are recycled, not merely never filled),
//! and that wgpu's allocator reserves no new device memory after the warm-up. Process memory: the
//! anonymous resident memory (heap, and on a software adapter the GPU's own allocations) is no
//! higher at the end of the flight than after the warm-up, within a small bound. Along the way
//! every frame renders without a GPU error, draws terrain and has no tile that failed to load.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use std::path::Path;
use std::time::Instant;

use terramp::config::Settings;
use terramp::frame::Renderer;
use terramp::path::CameraPath;

use support::build;
use terramp_testkit::memory::{floor, memory, mib};
use terramp_testkit::{TempDir, shared_data};

/// 7,500 km from the Alps to Everest, 5.5–12 km above the datum (see the file's comments).
const PATH: &str = "../config/paths/globe.toml";
/// 25 km per frame along the path: a level-0 height tile (256 samples, 236 km) every ten frames.
const FRAMES: usize = 300;
/// Small frames keep the software rasteriser's share of the wall time low; streaming works on tiles,
/// and the selection still needs about 40 height tiles a frame at this size.
const SIZE: [u32; 2] = [160, 96];
/// Frames before memory is first sampled: by then the shaders are compiled and the staging
/// buffers, readback ring, loader queues and allocator arenas have reached their working sizes.
const WARM_UP: usize = 60;
/// Frames in each process-memory sample. Each figure is the window's floor (its minimum): lavapipe
/// holds transient allocations of up to ~14 MiB for single frames or runs of up to ~15 frames, and
/// what a leak raises is the floor under them.
const WINDOW: usize = 30;
/// The height cache for this flight: a quarter of the default 256 slots, so the ~120 distinct tiles
/// the flight needs cannot all stay resident and the cache must evict and reuse slots, yet well
/// above the ~40 tiles one frame needs, so no node goes without its tile.
const HEIGHT_SLOTS: u32 = 64;
/// Streaming that really turns the cache over: at least as many uploads as slots, and a quarter of
/// the slots evicted (measured: 99–103 uploads, 44–48 evictions).
const MIN_UPLOADS: usize = HEIGHT_SLOTS as usize;
const MIN_EVICTIONS: usize = HEIGHT_SLOTS as usize / 4;
/// Allowed rise of the anonymous-memory floor from the warm-up window to the last one (210 frames
/// later). Measured without a leak: 1–2 MiB. A leak of one height tile a frame (258² × 4 B =
/// 260 KiB) would add 53 MiB; anything above ~80 KiB a frame fails.
const MAX_ANON_GROWTH_KIB: u64 = 16 * 1024;

#[test]
fn globe_flight_keeps_memory_fixed() {
    let Some(data) = shared_data() else { return };
    let dem = data.join("globe/globe_g_30arcsec.tif");
    let dir = TempDir::new("globe-flight");
    let start = Instant::now();
    let (dataset, _) = build(&dir.path().join("globe"), &["--dem", dem.to_str().unwrap()]);
    let build_s = start.elapsed().as_secs_f64();

    let path = CameraPath::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(PATH)).unwrap();
    let mut settings = Settings::default();
    [settings.render.width, settings.render.height] = SIZE;
    settings.cache.height_slots = HEIGHT_SLOTS;
    let slots = settings.cache.clone();
    let (fov, near) = (settings.render.fov_deg, settings.render.near_m);
    let gpu = terramp_testkit::gpu();
    let mut renderer = Renderer::new(gpu, dataset, settings).unwrap();

    let start = Instant::now();
    let mut memory_samples = Vec::with_capacity(FRAMES);
    // Device memory wgpu's allocator has reserved and handed out after each frame (`None` on
    // backends without an allocator report).
    let mut device_samples = Vec::with_capacity(FRAMES);
    let (mut uploads, mut evictions) = (0, 0);
    for i in 0..FRAMES {
        let camera = path.camera_at(i as f64 / (FRAMES - 1) as f64, fov, near);
        let report = renderer.render(&camera).unwrap_or_else(|e| panic!("frame {i} at {camera:?}: {e}"));
        let within = [
            (report.height.resident, slots.height_slots),
            (report.imagery.resident, slots.imagery_slots),
            (report.landcover.resident, slots.landcover_slots),
        ];
        assert!(within.iter().all(|&(resident, cap)| resident <= cap as usize), "frame {i}: {report:?}");
        let failed = report.height.failed + report.imagery.failed + report.landcover.failed;
        assert!(failed == 0 && report.nodes_drawn > 0, "frame {i} at {camera:?}: {report:?}");
        // Every selected node had its own tile or a resident ancestor: the small cache suffices.
        assert_eq!(report.nodes_dropped, 0, "frame {i}: {report:?}");
        uploads += report.height.uploaded;
        evictions += report.height.evicted;
        memory_samples.push(memory());
        device_samples.push(
            renderer
                .gpu
                .device
                .generate_allocator_report()
                .map(|r| (r.total_reserved_bytes, r.total_allocated_bytes)),
        );
    }
    let flight_s = start.elapsed().as_secs_f64();
    let warm = floor(&memory_samples[WARM_UP..WARM_UP + WINDOW]);
    let end = floor(&memory_samples[FRAMES - WINDOW..]);

    println!(
        "globe flight: build {build_s:.1} s, {FRAMES} frames in {flight_s:.1} s ({:.0} ms per frame); \
         {uploads} height tiles uploaded, {evictions} evicted ({HEIGHT_SLOTS} slots)",
        flight_s * 1000.0 / FRAMES as f64
    );
    for (first, m) in [(WARM_UP, warm), (FRAMES - WINDOW, end)] {
        println!(
            "  frames {first:>3}..{:>3}, floor: VmRSS {:6.1} MiB, anonymous {:6.1} MiB, file-backed {:6.1} MiB",
            first + WINDOW,
            mib(m.rss << 10),
            mib(m.anon << 10),
            mib(m.file << 10)
        );
    }

    // The flight streamed: more tiles than the cache holds went through it, so slots were reused.
    assert!(
        uploads >= MIN_UPLOADS && evictions >= MIN_EVICTIONS,
        "too little streaming: {uploads} uploads, {evictions} evictions for {HEIGHT_SLOTS} slots"
    );

    // No device memory reserved after the warm-up beyond what it reached (its allocations vary by
    // a frame's upload staging, inside the reserved blocks).
    let device: Option<Vec<(u64, u64)>> = device_samples.into_iter().collect();
    if let Some(device) = device {
        let (warming, after) = device.split_at(WARM_UP);
        let reserved = |frames: &[(u64, u64)]| frames.iter().map(|&(reserved, _)| reserved).max().unwrap();
        let allocated = after.iter().map(|&(_, allocated)| allocated);
        let (fewest, most) = (allocated.clone().min().unwrap(), allocated.max().unwrap());
        println!(
            "  device memory after the warm-up: {:.1} MiB reserved (at most {:.1} MiB before), \
             {:.1}–{:.1} MiB allocated",
            mib(reserved(after)),
            mib(reserved(warming)),
            mib(fewest),
            mib(most)
        );
        // Real: the allocator reported reserved memory (two zeros would pass the bound).
        assert!(reserved(warming) > 0, "the allocator reports nothing reserved");
        assert!(reserved(after) <= reserved(warming), "device memory reserved after the warm-up grew");
    } else {
        println!("  device memory: no allocator report on this backend");
    }

    // Real: the memory was read (a growth of 0 from two zeros would pass any bound).
    assert!(warm.anon > 0 && end.anon > 0, "no anonymous memory read: {warm:?}, {end:?}");
    let growth = end.anon.saturating_sub(warm.anon);
    assert!(
        growth <= MAX_ANON_GROWTH_KIB,
        "anonymous memory grew {:.1} MiB after the warm-up (bound {:.1} MiB): {warm:?} -> {end:?}",
        mib(growth << 10),
        mib(MAX_ANON_GROWTH_KIB << 10)
    );
}

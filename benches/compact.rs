//! Compaction (pass 4a) alone: records grouped per second for 64 k to 16 M records. The input is
//! synthetic, as pass 3 leaves it: blocks of 0 to 64 records (32 on average) landed in shuffled
//! order, each record in one of the 48 draw groups at random. A sample records `iters` runs in one
//! submission and waits, so submission overhead is spread. Sizes whose keys or permutation exceed
//! the adapter's largest storage binding are skipped with a note. Beside each size, `compact_floor`
//! (`support/floor.rs`): a kernel reading the keys and the block table and writing the permutation
//! and the draws' arguments, as compaction does, timed the same way; and a line with the two medians
//! of single runs and their ratio. Run with `WGPU_BACKEND=vulkan cargo bench --bench compact`.
#![allow(clippy::unwrap_used, reason = "a benchmark that cannot set up has nothing to measure")]

#[path = "support/floor.rs"]
mod floor;

use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use terramp::gpu::counter::Counting;
use terramp::gpu::gpu_types::{SeedBlock, SeedDrawArgs};
use terramp::gpu::layout::{SEED_DRAWS, SEED_GROUPS, SEED_WORKGROUP};
use terramp::gpu::{AdapterChoice, Gpu};
use terramp::passes::compact::frame::CompactLimits;
use terramp::passes::compact::gpu::{CompactInputs, CompactPass};
use terramp::seeds::pcg;
use wgpu::util::DeviceExt;

const SIZES: [u32; 5] = [1 << 16, 1 << 18, 1 << 20, 1 << 22, 1 << 24];

/// `records` records in blocks of 0..=64, landed in shuffled order, with random groups.
fn synthetic(records: u32) -> (Vec<u32>, Vec<SeedBlock>) {
    let mut state = pcg(records);
    let mut next = move || {
        state = pcg(state);
        state
    };
    let mut counts = Vec::new();
    let mut total = 0u32;
    while total < records {
        let count = (next() % (SEED_WORKGROUP + 1)).min(records - total);
        counts.push(count);
        total += count;
    }
    let mut landing: Vec<usize> = (0..counts.len()).collect();
    for i in (1..landing.len()).rev() {
        landing.swap(i, next() as usize % (i + 1));
    }
    let mut blocks = vec![SeedBlock::default(); counts.len()];
    let mut offset = 0;
    for w in landing {
        blocks[w] = SeedBlock { offset, count: counts[w] };
        offset += counts[w];
    }
    let keys = (0..records).map(|_| (next() >> 8) % SEED_GROUPS).collect();
    (keys, blocks)
}

fn compact(c: &mut Criterion) {
    let gpu = Gpu::new(AdapterChoice::Auto).expect("a GPU adapter");
    eprintln!("adapter: {}", gpu.describe());
    let max_binding = gpu.device.limits().max_storage_buffer_binding_size;
    let mut group = c.benchmark_group("compact");
    group.sample_size(10).warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(5));
    for records in SIZES {
        if u64::from(records) * 4 > max_binding {
            eprintln!(
                "compact/{records}: skipped, {} MiB keys exceed this adapter's binding limit",
                records >> 18
            );
            continue;
        }
        let (keys, blocks) = synthetic(records);
        let limits = CompactLimits { blocks: blocks.len() as u32, records };
        let pass = match CompactPass::new(&gpu.device, limits) {
            Ok(pass) => pass,
            Err(e) => {
                eprintln!("compact/{records}: skipped, {e}");
                continue;
            }
        };
        let storage = |label, contents: &[u8]| {
            gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        let keys_buffer = storage("bench keys", bytemuck::cast_slice(&keys));
        let blocks_buffer = storage("bench blocks", bytemuck::cast_slice(&blocks));
        let bind_group =
            pass.bind_group(&gpu.device, &CompactInputs { blocks: &blocks_buffer, keys: &keys_buffer });
        let params = pass.prepare(&gpu.queue, blocks.len() as u32).expect("within the limits");
        if records <= 1 << 18 {
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            pass.encode(&mut encoder, &bind_group, &params, Counting::OFF);
            gpu.queue.submit([encoder.finish()]);
            let gpu_out = pass.read_back(&gpu).expect("read back");
            let twin = terramp::reference::compact::compact(&keys, &blocks, pass.templates()).expect("twin");
            assert_eq!(gpu_out, twin, "compaction differs from its twin at {records} records");
        }
        group.throughput(Throughput::Elements(records.into()));
        group.bench_function(BenchmarkId::from_parameter(records), |b| {
            b.iter_custom(|iters| {
                let mut encoder = gpu.device.create_command_encoder(&Default::default());
                for _ in 0..iters {
                    pass.encode(&mut encoder, &bind_group, &params, Counting::OFF);
                }
                let start = Instant::now();
                gpu.queue.submit([encoder.finish()]);
                gpu.wait().expect("wait");
                start.elapsed()
            })
        });
        let in_bytes = u64::from(records) * 4 + (blocks.len() * size_of::<SeedBlock>()) as u64;
        let out_bytes = u64::from(records) * 4 + u64::from(SEED_DRAWS) * size_of::<SeedDrawArgs>() as u64;
        let floor = floor::Floor::new(&gpu, in_bytes, out_bytes);
        group.bench_function(BenchmarkId::new("floor", records), |b| {
            b.iter_custom(|iters| {
                let mut encoder = gpu.device.create_command_encoder(&Default::default());
                for _ in 0..iters {
                    floor.encode(&mut encoder);
                }
                let start = Instant::now();
                gpu.queue.submit([encoder.finish()]);
                gpu.wait().expect("wait");
                start.elapsed()
            })
        });
        let pass_ms = floor::median_ms(&gpu, 9, |e| pass.encode(e, &bind_group, &params, Counting::OFF));
        let floor_ms = floor::median_ms(&gpu, 9, |e| floor.encode(e));
        eprintln!(
            "compact/{records}: {pass_ms:.3} ms, floor {floor_ms:.3} ms, ÷floor {:.2}",
            pass_ms / floor_ms
        );
        gpu.check().expect("no GPU error");
    }
    group.finish();
}

criterion_group!(benches, compact);
criterion_main!(benches);

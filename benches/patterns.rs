//! Time to generate the seed patterns pass 3 uploads (the corner-tile set: corner patches, edge
//! strips, interiors, each Bridson candidates then a progressive ranking): 16 patterns (2 corner
//! colours, every preset) of 1536, 2048 and 4096 seeds (fast, balanced, accurate), and 81
//! (3 colours) of 2048. Run with `cargo bench --bench patterns`.
#![allow(clippy::unwrap_used, reason = "a benchmark that cannot set up has nothing to measure")]

use criterion::{Criterion, criterion_group, criterion_main};
use terramp::seeds::patterns::SeedPatterns;

fn patterns(c: &mut Criterion) {
    let mut group = c.benchmark_group("seed_patterns");
    group.sample_size(10);
    for (colours, seeds_per_pattern) in [(2, 1536), (2, 2048), (2, 4096), (3, 2048)] {
        group.bench_function(format!("{}x{seeds_per_pattern}", colours * colours * colours * colours), |b| {
            b.iter(|| SeedPatterns::generate(colours, seeds_per_pattern, 1))
        });
    }
    group.finish();
}

criterion_group!(benches, patterns);
criterion_main!(benches);

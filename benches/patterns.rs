//! Time to generate the seed patterns pass 3 uploads (Bridson candidates, then farthest-point
//! ranking): 16 patterns of 2048 seeds (the default) and of 4096 (the accurate preset). Run with
//! `cargo bench --bench patterns`.
#![allow(clippy::unwrap_used, reason = "a benchmark that cannot set up has nothing to measure")]

use criterion::{Criterion, criterion_group, criterion_main};
use terramp::seeds::patterns::SeedPatterns;

fn patterns(c: &mut Criterion) {
    let mut group = c.benchmark_group("seed_patterns");
    group.sample_size(10);
    for seeds_per_pattern in [2048, 4096] {
        group.bench_function(format!("16x{seeds_per_pattern}"), |b| {
            b.iter(|| SeedPatterns::generate(16, seeds_per_pattern, 1))
        });
    }
    group.finish();
}

criterion_group!(benches, patterns);
criterion_main!(benches);

//! Compaction (pass 4a) on synthetic block tables, straight into the pass: the GPU equals its CPU
//! twin bit for bit (random inputs of many sizes, all kept, none kept, one group, every group,
//! keys outside the groups), every record is drawn exactly once, in its group, in block order,
//! and the indirect draws count each group and start where the group starts.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use terramp::gpu::Gpu;
use terramp::gpu::counter::Counting;
use terramp::gpu::gpu_types::{SeedBlock, SeedDrawArgs};
use terramp::gpu::layout::{COMPACT_CHUNK, SEED_DRAWS, SEED_GROUPS, SEED_WORKGROUP};
use terramp::passes::compact::frame::{CompactLimits, Compacted};
use terramp::passes::compact::gpu::{CompactInputs, CompactPass};
use terramp::reference::compact::compact;
use terramp::seeds::pcg;

/// A pass with its own input buffers, sized for one test's inputs.
struct Harness {
    gpu: Gpu,
    pass: CompactPass,
    keys: wgpu::Buffer,
    blocks: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
}

impl Harness {
    fn new(limits: CompactLimits) -> Self {
        let gpu = terramp_testkit::gpu();
        let pass = CompactPass::new(&gpu.device, limits).unwrap();
        let buffer = |label, bytes: u64| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes.max(4),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let keys = buffer("test keys", u64::from(limits.records) * 4);
        let blocks = buffer("test blocks", u64::from(limits.blocks) * 8);
        let bind_group = pass.bind_group(&gpu.device, &CompactInputs { blocks: &blocks, keys: &keys });
        Self { gpu, pass, keys, blocks, bind_group }
    }

    fn run(&self, input: &Input) -> Compacted {
        let queue = &self.gpu.queue;
        if !input.keys.is_empty() {
            queue.write_buffer(&self.keys, 0, bytemuck::cast_slice(&input.keys));
        }
        if !input.blocks.is_empty() {
            queue.write_buffer(&self.blocks, 0, bytemuck::cast_slice(&input.blocks));
        }
        let params = self.pass.prepare(queue, input.blocks.len() as u32).unwrap();
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        self.pass.encode(&mut encoder, &self.bind_group, &params, Counting::OFF);
        queue.submit([encoder.finish()]);
        let out = self.pass.read_back(&self.gpu).unwrap();
        self.gpu.check().unwrap();
        out
    }
}

/// A block table and its keys, as pass 3 leaves them: blocks land in a shuffled order.
struct Input {
    keys: Vec<u32>,
    blocks: Vec<SeedBlock>,
}

/// `blocks` blocks holding `count(rng)` records each, keyed by `key(rng)`.
fn input(blocks: usize, seed: u32, count: impl Fn(u32) -> u32, key: impl Fn(u32) -> u32) -> Input {
    let mut state = pcg(seed);
    let mut next = move || {
        state = pcg(state);
        state
    };
    let counts: Vec<u32> = (0..blocks).map(|_| count(next()).min(SEED_WORKGROUP)).collect();
    // Landing order: a shuffle of the table order (Fisher–Yates).
    let mut landing: Vec<usize> = (0..blocks).collect();
    for i in (1..blocks).rev() {
        landing.swap(i, next() as usize % (i + 1));
    }
    let mut table = vec![SeedBlock::default(); blocks];
    let mut keys = Vec::new();
    for w in landing {
        table[w] = SeedBlock { offset: if counts[w] == 0 { 0 } else { keys.len() as u32 }, count: counts[w] };
        keys.extend((0..counts[w]).map(|_| key(next())));
    }
    Input { keys, blocks: table }
}

fn random(blocks: usize, seed: u32) -> Input {
    input(blocks, seed, |r| r % (SEED_WORKGROUP + 1), |r| (r >> 8) % SEED_GROUPS)
}

fn limits_for(inputs: &[&Input]) -> CompactLimits {
    CompactLimits {
        blocks: inputs.iter().map(|i| i.blocks.len() as u32).max().unwrap_or(0).max(1),
        records: inputs.iter().map(|i| i.keys.len() as u32).max().unwrap_or(0).max(1),
    }
}

/// GPU == twin, and what both must be: every valid record drawn once, in its group, groups in
/// order, block order kept within each group, draws counting and starting each group.
fn check(harness: &Harness, input: &Input, what: &str) -> Compacted {
    let gpu = harness.run(input);
    let twin = compact(&input.keys, &input.blocks, harness.pass.templates()).unwrap();
    assert_eq!(gpu.args, twin.args, "{what}: draw arguments");
    assert_eq!(gpu.order.len(), twin.order.len(), "{what}: drawn");
    if let Some(i) = (0..gpu.order.len()).find(|&i| gpu.order[i] != twin.order[i]) {
        panic!(
            "{what}: slot {i} of {} holds record {} (twin {})",
            gpu.order.len(),
            gpu.order[i],
            twin.order[i]
        );
    }
    // The order the twin must give: table order, stably sorted by group.
    let mut expected: Vec<(u32, u32)> = input
        .blocks
        .iter()
        .flat_map(|b| b.offset..b.offset + b.count)
        .map(|i| (input.keys[i as usize], i))
        .filter(|&(g, _)| g < SEED_GROUPS)
        .collect();
    expected.sort_by_key(|&(g, _)| g);
    assert_eq!(gpu.order, expected.iter().map(|&(_, i)| i).collect::<Vec<_>>(), "{what}");
    let mut first = 0;
    assert_eq!(gpu.args.len(), SEED_DRAWS as usize, "{what}");
    let (own, fades) = gpu.args.split_at(SEED_GROUPS as usize);
    for (g, (args, fade)) in own.iter().zip(fades).enumerate() {
        let total = expected.iter().filter(|&&(k, _)| k == g as u32).count() as u32;
        assert_eq!((args.instance_count, args.first_instance), (total, first), "{what}: group {g}");
        // The cross-fade draw of a group draws the same instances.
        assert_eq!((fade.instance_count, fade.first_instance), (total, first), "{what}: fade {g}");
        first += total;
    }
    gpu
}

#[test]
fn random_inputs_equal_the_twin_at_every_size() {
    // Block counts around the chunk size and the step size, and records around the workgroup size.
    let chunk = COMPACT_CHUNK as usize;
    let sizes = [0, 1, 2, 3, 5, chunk - 1, chunk, chunk + 1, 3 * chunk + 7, 1000, 4097, 20_000];
    let inputs: Vec<Input> = sizes.iter().enumerate().map(|(k, &n)| random(n, k as u32)).collect();
    let harness = Harness::new(limits_for(&inputs.iter().collect::<Vec<_>>()));
    for (input, n) in inputs.iter().zip(sizes) {
        let out = check(&harness, input, &format!("{n} blocks"));
        println!("{n} blocks, {} records: {} drawn", input.keys.len(), out.drawn());
    }
    // Single records, and record counts that are not multiples of a workgroup.
    for (k, records) in [1u32, 63, 65, 129, 1000].into_iter().enumerate() {
        let one = input(records as usize, 100 + k as u32, |_| 1, |r| r % SEED_GROUPS);
        check(&harness, &one, &format!("{records} single-record blocks"));
    }
}

#[test]
fn all_kept_none_kept_one_group_every_group() {
    let blocks = 3 * COMPACT_CHUNK as usize + 5;
    let all = input(blocks, 1, |_| SEED_WORKGROUP, |r| r % SEED_GROUPS);
    let none = input(blocks, 2, |_| 0, |r| r % SEED_GROUPS);
    let one = input(blocks, 3, |r| r % (SEED_WORKGROUP + 1), |_| 17);
    let every = input(blocks, 4, |r| r % (SEED_WORKGROUP + 1), |r| r % SEED_GROUPS);
    let harness = Harness::new(limits_for(&[&all, &none, &one, &every]));

    let out = check(&harness, &all, "all kept");
    assert_eq!(out.drawn(), blocks * SEED_WORKGROUP as usize);
    let mut sorted = out.order.clone();
    sorted.sort_unstable();
    assert!(sorted.iter().enumerate().all(|(i, &r)| i as u32 == r), "all kept: not a permutation");

    let out = check(&harness, &none, "none kept");
    assert_eq!(out.drawn(), 0);
    assert!(out.args.iter().all(|a| a.instance_count == 0 && a.first_instance == 0), "{:?}", out.args);

    let out = check(&harness, &one, "one group");
    let own = &out.args[..SEED_GROUPS as usize];
    assert!(own.iter().enumerate().all(|(g, a)| (a.instance_count != 0) == (g == 17)));
    assert_eq!(out.args[17].first_instance, 0);
    assert_eq!(out.args[18].first_instance, out.drawn() as u32);

    let out = check(&harness, &every, "every group");
    assert!(out.args.iter().all(|a| a.instance_count > 0), "a group is empty: {:?}", out.args);
    assert_eq!(out.args.len(), SEED_DRAWS as usize);
}

#[test]
fn keys_outside_the_groups_are_not_drawn() {
    let input = input(300, 9, |r| r % (SEED_WORKGROUP + 1), |r| (r >> 4) % (SEED_GROUPS + 20));
    let harness = Harness::new(limits_for(&[&input]));
    let out = check(&harness, &input, "keys beyond the groups");
    assert!(out.drawn() < input.keys.len());
}

#[test]
fn draws_take_their_mesh_from_the_templates_and_runs_agree() {
    let input = random(777, 5);
    let mut harness = Harness::new(limits_for(&[&input]));
    let templates: Vec<SeedDrawArgs> = (0..SEED_DRAWS)
        .map(|g| SeedDrawArgs {
            index_count: 3 * (g + 1),
            instance_count: 999,
            first_index: 100 * g,
            base_vertex: -(g as i32),
            first_instance: 999,
        })
        .collect();
    harness.pass.set_templates(&harness.gpu.queue, &templates);
    let first = check(&harness, &input, "with templates");
    for (args, t) in first.args.iter().zip(&templates) {
        assert_eq!(
            (args.index_count, args.first_index, args.base_vertex),
            (t.index_count, t.first_index, t.base_vertex)
        );
    }
    for run in 0..3 {
        assert_eq!(harness.run(&input), first, "run {run} differs");
    }
    // A smaller table after a larger one: nothing of the earlier run leaks into the later one.
    let small = random(10, 6);
    check(&harness, &small, "after a larger run");
}

#[test]
fn a_table_larger_than_the_limits_is_refused() {
    let gpu = terramp_testkit::gpu();
    let pass = CompactPass::new(&gpu.device, CompactLimits { blocks: 100, records: 100 }).unwrap();
    assert!(pass.prepare(&gpu.queue, 101).is_err());
    let limits = CompactLimits { blocks: u32::MAX, records: 1 };
    assert!(CompactPass::new(&gpu.device, limits).is_err());
}

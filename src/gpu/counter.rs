//! How it works: the GPU side of a frame's counts (`gpu::counts` says what they are). A renderer
//! owns one `Counter`; `begin_frame` starts a tally, and each pass records through a `Counting`
//! handle with its label, which issues the pass's draws and dispatches and tallies them, and
//! brackets each wgpu pass (or each part of one) with a pipeline-statistics query where the
//! adapter has them. Queries are numbered from 0 each frame in one query set: the frame's
//! `resolve` (on its last encoder) writes their results into a buffer, copies each indirect
//! draw's first two argument words after them (each distinct buffer and offset once) and copies
//! what it used into a staging ring, tagged with the tally, so nothing waits: `collect` takes
//! the frames that have arrived, a frame or two late, as `FrameCounts`. The next frame's queries
//! reuse the set only after this frame's copies, in queue order.
//!
//! A pass recorded outside a counted frame (tools, the truth) takes `Counting::OFF`, which issues
//! the same commands and counts nothing.

use std::cell::{Cell, RefCell};
use std::ops::Range;

use super::counts::{FrameCounts, FrameTally, INDIRECT_ARGS_BYTES, Part, STATISTICS, STATISTICS_PER_QUERY};
use super::readback_ring::ReadbackRing;
use super::{Gpu, GpuError};

/// Pipeline-statistics queries a frame may run (a frame's passes run about a dozen); a query
/// beyond them is not run and its pass's statistics are absent that frame.
pub const MAX_QUERIES: u32 = 64;

/// Distinct indirect arguments a frame may copy back (pass 4 draws at most `SEED_DRAWS`); an
/// indirect draw beyond them leaves its pass's triangles absent that frame.
pub const MAX_INDIRECT_ARGS: u64 = 1024;

/// Frames whose counts may be in flight at once.
const SLOTS: usize = 4;

/// Bytes of one query's results.
const QUERY_BYTES: u64 = STATISTICS_PER_QUERY as u64 * 8;

/// Where the copied arguments start in the resolved buffer: after every query's results.
const ARGS_OFFSET: u64 =
    (MAX_QUERIES as u64 * QUERY_BYTES).next_multiple_of(wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT);

/// A frame's tally on its way back, with how many queries and arguments it copied.
struct Sent {
    tally: FrameTally,
    queries: usize,
    args: usize,
}

/// Counts each frame's passes (see the module's doc).
pub struct Counter {
    /// `None` without `PIPELINE_STATISTICS_QUERY`.
    queries: Option<wgpu::QuerySet>,
    /// The queries' results, then the copied arguments (from `ARGS_OFFSET`).
    resolved: wgpu::Buffer,
    ring: ReadbackRing<Sent>,
    tally: RefCell<FrameTally>,
    /// Where each copied argument pair comes from, in copy order.
    args: RefCell<Vec<(wgpu::Buffer, u64)>>,
    /// The wgpu pass being recorded began a query: its `end` ends it.
    open: Cell<bool>,
    /// Bytes read back for a frame after its tally was sent (blocking reads): frame, label, bytes.
    late: RefCell<Vec<(u64, &'static str, u64)>>,
}

/// A wgpu pass a pipeline-statistics query can bracket.
pub trait StatisticsPass {
    /// Begins query `index` of `set`.
    fn begin_statistics(&mut self, set: &wgpu::QuerySet, index: u32);
    /// Ends the query begun last.
    fn end_statistics(&mut self);
}

impl StatisticsPass for wgpu::RenderPass<'_> {
    fn begin_statistics(&mut self, set: &wgpu::QuerySet, index: u32) {
        self.begin_pipeline_statistics_query(set, index);
    }
    fn end_statistics(&mut self) {
        self.end_pipeline_statistics_query();
    }
}

impl StatisticsPass for wgpu::ComputePass<'_> {
    fn begin_statistics(&mut self, set: &wgpu::QuerySet, index: u32) {
        self.begin_pipeline_statistics_query(set, index);
    }
    fn end_statistics(&mut self) {
        self.end_pipeline_statistics_query();
    }
}

impl Counter {
    /// A counter on `gpu`, with pipeline statistics when `statistics` and the adapter has them
    /// (`false` counts as an adapter without them would: what a test of that path asks).
    pub fn new(gpu: &Gpu, statistics: bool) -> Self {
        let device = &gpu.device;
        let has = device.features().contains(wgpu::Features::PIPELINE_STATISTICS_QUERY);
        let queries = (statistics && has).then(|| {
            device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass counts"),
                ty: wgpu::QueryType::PipelineStatistics(STATISTICS),
                count: MAX_QUERIES,
            })
        });
        let bytes = ARGS_OFFSET + MAX_INDIRECT_ARGS * INDIRECT_ARGS_BYTES;
        let resolved = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pass counts"),
            size: bytes,
            usage: wgpu::BufferUsages::QUERY_RESOLVE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let statistics = queries.is_some();
        Self {
            queries,
            resolved,
            ring: ReadbackRing::new(device, "pass counts", bytes, SLOTS),
            tally: RefCell::new(FrameTally::new(0, statistics)),
            args: RefCell::default(),
            open: Cell::new(false),
            late: RefCell::default(),
        }
    }

    /// The adapter runs the pipeline-statistics queries.
    pub fn has_statistics(&self) -> bool {
        self.queries.is_some()
    }

    /// Starts frame `frame`'s tally (what the last frame left unresolved is dropped).
    pub fn begin_frame(&self, frame: u64) {
        *self.tally.borrow_mut() = FrameTally::new(frame, self.has_statistics());
        self.args.borrow_mut().clear();
    }

    /// The handle pass `label` records through; the pass has its counts this frame, all zero if
    /// it records nothing.
    pub fn pass(&self, label: &'static str) -> Counting<'_> {
        self.tally.borrow_mut().name(label);
        Counting { counter: Some(self), label }
    }

    /// Runs `step`, counting what it uploads through `queue` as `label`'s.
    pub fn uploads<R>(&self, queue: &super::Queue, label: &'static str, step: impl FnOnce() -> R) -> R {
        let before = queue.uploaded_bytes();
        let result = step();
        self.uploaded(label, queue.uploaded_bytes() - before);
        result
    }

    /// `bytes` uploaded by `label`'s step of the frame being recorded.
    pub fn uploaded(&self, label: &'static str, bytes: u64) {
        self.tally.borrow_mut().uploaded(label, bytes);
    }

    /// `bytes` read back for `label` in the frame being recorded.
    pub fn read_back(&self, label: &'static str, bytes: u64) {
        self.tally.borrow_mut().read_back(label, bytes);
    }

    /// `bytes` read back for `label` in frame `frame`, after its `resolve`: added when it arrives.
    pub fn read_back_late(&self, frame: u64, label: &'static str, bytes: u64) {
        self.late.borrow_mut().push((frame, label, bytes));
    }

    /// Resolves the frame's queries, copies its indirect arguments and sends them back with its
    /// tally: call on the frame's last encoder, after its other readbacks.
    pub fn resolve(&mut self, encoder: &mut wgpu::CommandEncoder) {
        let mut tally = self.tally.take();
        let args = self.args.take();
        let queries = tally.queries();
        if let Some(set) = &self.queries
            && queries > 0
        {
            encoder.resolve_query_set(set, 0..queries as u32, &self.resolved, 0);
        }
        for (i, (buffer, offset)) in args.iter().enumerate() {
            let to = ARGS_OFFSET + i as u64 * INDIRECT_ARGS_BYTES;
            encoder.copy_buffer_to_buffer(buffer, *offset, &self.resolved, to, INDIRECT_ARGS_BYTES);
        }
        let bytes = match args.len() {
            0 => queries as u64 * QUERY_BYTES,
            n => ARGS_OFFSET + n as u64 * INDIRECT_ARGS_BYTES,
        };
        tally.read_back("counts", bytes);
        let sent = Sent { tally, queries, args: args.len() };
        self.ring.encode_copy(encoder, &self.resolved, bytes, sent);
    }

    /// Call after submitting the encoder `resolve` recorded into.
    pub fn submitted(&mut self) {
        self.ring.submitted();
    }

    /// The counts of every frame that has arrived since the last call, oldest first; never waits.
    pub fn collect(&mut self, device: &wgpu::Device) -> Result<Vec<FrameCounts>, GpuError> {
        let mut frames = Vec::new();
        while let Some(readback) = self.ring.try_take(device)? {
            let Sent { mut tally, queries, args } = readback.tag;
            let mut late = self.late.borrow_mut();
            late.retain(|&(frame, label, bytes)| {
                if frame == tally.frame {
                    tally.read_back(label, bytes);
                }
                frame > tally.frame
            });
            let bytes = &readback.bytes;
            let results: Vec<u64> = bytes
                .get(..queries * QUERY_BYTES as usize)
                .map(bytemuck::pod_collect_to_vec)
                .unwrap_or_default();
            let start = ARGS_OFFSET as usize;
            let copied: Vec<u32> = bytes
                .get(start..start + args * INDIRECT_ARGS_BYTES as usize)
                .map(bytemuck::pod_collect_to_vec)
                .unwrap_or_default();
            frames.push(tally.reduce(&results, &copied));
        }
        Ok(frames)
    }

    /// Copies skipped because every staging buffer was in flight: frames whose counts never come.
    pub fn skipped(&self) -> u64 {
        self.ring.skipped()
    }

    /// Which copied arguments `(buffer, offset)` are, copying them this frame if new; `None` when
    /// there is no room left.
    fn note_args(&self, buffer: &wgpu::Buffer, offset: u64) -> Option<usize> {
        let mut args = self.args.borrow_mut();
        if let Some(at) = args.iter().position(|(b, o)| b == buffer && *o == offset) {
            return Some(at);
        }
        if args.len() as u64 >= MAX_INDIRECT_ARGS {
            return None;
        }
        args.push((buffer.clone(), offset));
        Some(args.len() - 1)
    }
}

/// How one pass records its commands: issued through it, they are counted as the pass's (label).
#[derive(Clone, Copy)]
pub struct Counting<'a> {
    counter: Option<&'a Counter>,
    label: &'static str,
}

impl Counting<'static> {
    /// Issues the commands and counts nothing.
    pub const OFF: Self = Self { counter: None, label: "" };
}

impl Counting<'_> {
    /// Starts counting `part` of the pass in `pass` (end it with `end` before the pass ends, and
    /// before another `begin`).
    pub fn begin(self, pass: &mut impl StatisticsPass, part: Part) {
        let Some(counter) = self.counter else { return };
        let Some(set) = &counter.queries else { return };
        let index = counter.tally.borrow_mut().query(self.label, part, MAX_QUERIES as usize);
        if let Some(index) = index {
            pass.begin_statistics(set, index);
        }
        counter.open.set(index.is_some());
    }

    /// Stops counting what `begin` started.
    pub fn end(self, pass: &mut impl StatisticsPass) {
        if self.counter.is_some_and(|c| c.open.replace(false)) {
            pass.end_statistics();
        }
    }

    fn tally(self, count: impl FnOnce(&mut FrameTally, &'static str)) {
        if let Some(counter) = self.counter {
            count(&mut counter.tally.borrow_mut(), self.label);
        }
    }

    /// `wgpu::RenderPass::draw`, counted (a triangle list).
    pub fn draw(self, pass: &mut wgpu::RenderPass, vertices: Range<u32>, instances: Range<u32>) {
        self.tally(|t, label| t.draw(label, span(&vertices), span(&instances)));
        pass.draw(vertices, instances);
    }

    /// `wgpu::RenderPass::draw_indexed`, counted (a triangle list).
    pub fn draw_indexed(
        self,
        pass: &mut wgpu::RenderPass,
        indices: Range<u32>,
        base_vertex: i32,
        instances: Range<u32>,
    ) {
        self.tally(|t, label| t.draw(label, span(&indices), span(&instances)));
        pass.draw_indexed(indices, base_vertex, instances);
    }

    /// `wgpu::RenderPass::draw_indexed_indirect`, counted: its arguments come back with the frame's.
    pub fn draw_indexed_indirect(self, pass: &mut wgpu::RenderPass, args: &wgpu::Buffer, offset: u64) {
        if let Some(counter) = self.counter {
            let copied = counter.note_args(args, offset);
            counter.tally.borrow_mut().draw_indirect(self.label, copied);
        }
        pass.draw_indexed_indirect(args, offset);
    }

    /// `wgpu::ComputePass::dispatch_workgroups`, counted.
    pub fn dispatch(self, pass: &mut wgpu::ComputePass, [x, y, z]: [u32; 3]) {
        self.tally(|t, label| t.dispatch(label, false));
        pass.dispatch_workgroups(x, y, z);
    }

    /// `wgpu::ComputePass::dispatch_workgroups_indirect`, counted.
    pub fn dispatch_indirect(self, pass: &mut wgpu::ComputePass, args: &wgpu::Buffer, offset: u64) {
        self.tally(|t, label| t.dispatch(label, true));
        pass.dispatch_workgroups_indirect(args, offset);
    }
}

fn span(range: &Range<u32>) -> u32 {
    range.end.saturating_sub(range.start)
}

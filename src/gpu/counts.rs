//! How it works: what each pass of a frame asked of the GPU, in counts that are exact and the same
//! on every adapter that has them. While a frame is recorded, its passes go through a
//! `counter::Counting` handle, which issues their draws and dispatches and tallies them here
//! (`FrameTally`): draw calls, indirect draws, dispatches, and the triangles of the direct draws
//! (a triangle list's index or vertex count over 3, times its instances). An indirect draw's
//! triangles are on the GPU: the handle notes where its arguments lie, and the frame's last
//! encoder copies them (the first two words: the index or vertex count and the instance count)
//! beside the queries' results, so they come back together, a frame or two late, through one
//! staging ring. The bytes each step uploads and reads back are tallied by label too (the CPU
//! steps that upload, `streaming`, and the readbacks, are labelled as their work is).
//!
//! Where the adapter has `PIPELINE_STATISTICS_QUERY`, each wgpu pass a frame pass records (and,
//! inside draw_seeds and texcells, each part of one: the depth prepass, the shading draws) runs a
//! pipeline-statistics query: vertex shader invocations, primitives out of the clipper (the
//! triangles rasterised after clipping: "clipped triangles"), fragment shader invocations and
//! compute shader invocations, each the adapter's own figure (`gpu::fragments` says what
//! llvmpipe counts). Without it (WebGPU) those four are absent (`None`), never zero: the counts a
//! frame can derive on the CPU and from the arguments stay.
//!
//! `FrameTally::reduce` turns a frame's tally, its queries' results and its arguments into
//! `FrameCounts`, pure, so it is checked on known inputs.

use serde::Serialize;

/// What each pipeline-statistics query counts: its results come in the flags' bit order.
pub const STATISTICS: wgpu::PipelineStatisticsTypes =
    wgpu::PipelineStatisticsTypes::VERTEX_SHADER_INVOCATIONS
        .union(wgpu::PipelineStatisticsTypes::CLIPPER_PRIMITIVES_OUT)
        .union(wgpu::PipelineStatisticsTypes::FRAGMENT_SHADER_INVOCATIONS)
        .union(wgpu::PipelineStatisticsTypes::COMPUTE_SHADER_INVOCATIONS);

/// Results per pipeline-statistics query: one per flag of `STATISTICS`.
pub const STATISTICS_PER_QUERY: usize = STATISTICS.bits().count_ones() as usize;

/// Bytes of an indirect draw's arguments copied back: its first two words, the index (or vertex)
/// count and the instance count, the same in `DrawIndexedIndirectArgs` and `DrawIndirectArgs`.
pub const INDIRECT_ARGS_BYTES: u64 = 8;

/// One pipeline-statistics query's results: what the adapter ran.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct Statistics {
    /// Vertex shader invocations (an adapter may reuse an indexed vertex, or not).
    pub vertex_invocations: u64,
    /// Primitives out of the clipper: the triangles rasterised, after clipping cut or dropped them.
    pub clipped_triangles: u64,
    /// Fragment shader invocations (llvmpipe: whole 4 × 4 blocks, discarded lanes included).
    pub fragment_invocations: u64,
    /// Compute shader invocations.
    pub compute_invocations: u64,
}

impl Statistics {
    /// One query's results, in `STATISTICS`' order.
    pub fn from_query(results: &[u64]) -> Self {
        let at = |i: usize| results.get(i).copied().unwrap_or(0);
        Self {
            vertex_invocations: at(0),
            clipped_triangles: at(1),
            fragment_invocations: at(2),
            compute_invocations: at(3),
        }
    }

    /// Adds `other`'s counts to these.
    pub fn add(&mut self, other: &Self) {
        self.vertex_invocations += other.vertex_invocations;
        self.clipped_triangles += other.clipped_triangles;
        self.fragment_invocations += other.fragment_invocations;
        self.compute_invocations += other.compute_invocations;
    }
}

/// Which draws of a pass a query holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// All of it, or what is neither below (draw_seeds' multisampled fill).
    Whole,
    /// A depth prepass's draws (`draw_seeds.depth_prepass`).
    Prepass,
    /// The shading draws of a foliage pass: what `gpu::fragments` counts.
    Shading,
}

/// What one pass (or CPU step, by its label) did in one frame.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize)]
pub struct PassCounts {
    /// The pass's label, as the profiler times it (`streaming` for the caches' uploads; `counts`
    /// for this measure's own readback; `fragments` for `gpu.count_fragments`' blocking reads).
    pub label: &'static str,
    /// Draw calls issued with their arguments on the CPU.
    pub draw_calls: u64,
    /// Indirect draws issued (their arguments on the GPU).
    pub indirect_draws: u64,
    /// Compute dispatches issued with their sizes on the CPU.
    pub dispatches: u64,
    /// Indirect dispatches issued.
    pub indirect_dispatches: u64,
    /// Triangles the draws submitted, before any culling or clipping (the indirect draws' from
    /// their arguments); `None` when an indirect draw's arguments could not be copied back.
    pub triangles_submitted: Option<u64>,
    /// What the adapter counted; `None` without pipeline statistics (or a query it had no room for).
    pub statistics: Option<Statistics>,
    /// Bytes uploaded (buffers and textures written through the queue).
    pub bytes_uploaded: u64,
    /// Bytes copied back into mappable memory.
    pub bytes_read_back: u64,
    /// The depth prepass's share of `statistics`, where the pass has one.
    #[serde(skip)]
    pub prepass: Option<Statistics>,
    /// The shading draws' share of `statistics`, where the pass names them.
    #[serde(skip)]
    pub shading: Option<Statistics>,
}

impl PassCounts {
    /// Adds `other`'s counts to these (the label stays); a figure absent in either is absent.
    pub fn add(&mut self, other: &Self) {
        self.draw_calls += other.draw_calls;
        self.indirect_draws += other.indirect_draws;
        self.dispatches += other.dispatches;
        self.indirect_dispatches += other.indirect_dispatches;
        self.triangles_submitted =
            self.triangles_submitted.zip(other.triangles_submitted).map(|(a, b)| a + b);
        self.statistics = self.statistics.zip(other.statistics).map(|(mut a, b)| {
            a.add(&b);
            a
        });
        self.bytes_uploaded += other.bytes_uploaded;
        self.bytes_read_back += other.bytes_read_back;
    }
}

/// Every counted pass of one frame.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize)]
pub struct FrameCounts {
    /// The renderer's frame number.
    pub frame: u64,
    /// The adapter ran the pipeline-statistics queries (false: those figures are absent).
    pub statistics: bool,
    /// Per label, in the order the frame first named them.
    pub passes: Vec<PassCounts>,
}

impl FrameCounts {
    /// The frame's sum over its labels, labelled `frame`.
    pub fn total(&self) -> PassCounts {
        let statistics = self.statistics.then(Statistics::default);
        let start =
            PassCounts { label: "frame", triangles_submitted: Some(0), statistics, ..Default::default() };
        self.passes.iter().fold(start, |mut total, pass| {
            total.add(pass);
            total
        })
    }

    /// The counts of pass `label`, if the frame named it.
    pub fn pass(&self, label: &str) -> Option<&PassCounts> {
        self.passes.iter().find(|p| p.label == label)
    }
}

/// What the CPU tallied of one label while the frame was recorded.
#[derive(Debug, Clone, Default)]
struct PassTally {
    label: &'static str,
    draw_calls: u64,
    indirect_draws: u64,
    dispatches: u64,
    indirect_dispatches: u64,
    direct_triangles: u64,
    bytes_uploaded: u64,
    bytes_read_back: u64,
}

/// One frame's tally while it is recorded, and what its readback is read against.
#[derive(Debug, Clone, Default)]
pub struct FrameTally {
    /// The renderer's frame number.
    pub frame: u64,
    /// The queries ran (the adapter has pipeline statistics).
    pub statistics: bool,
    passes: Vec<PassTally>,
    /// Per query, in query order: the label and part it counted.
    queries: Vec<(&'static str, Part)>,
    /// Labels with a query there was no room for.
    queries_dropped: Vec<&'static str>,
    /// Per indirect draw issued: its label and which copied arguments it read.
    indirect: Vec<(&'static str, Option<usize>)>,
}

impl FrameTally {
    /// An empty tally for frame `frame`.
    pub fn new(frame: u64, statistics: bool) -> Self {
        Self { frame, statistics, ..Default::default() }
    }

    fn pass(&mut self, label: &'static str) -> &mut PassTally {
        match self.passes.iter().position(|p| p.label == label) {
            Some(at) => &mut self.passes[at],
            None => {
                self.passes.push(PassTally { label, ..Default::default() });
                let last = self.passes.len() - 1;
                &mut self.passes[last]
            }
        }
    }

    /// Names pass `label`, so that it has counts even if it does nothing.
    pub fn name(&mut self, label: &'static str) {
        self.pass(label);
    }

    /// A direct draw of `vertices` (indices, or vertices) × `instances` triangles-list vertices.
    pub fn draw(&mut self, label: &'static str, vertices: u32, instances: u32) {
        let pass = self.pass(label);
        pass.draw_calls += 1;
        pass.direct_triangles += u64::from(vertices / 3) * u64::from(instances);
    }

    /// An indirect draw whose arguments are the `args`-th copied (`None`: not copied).
    pub fn draw_indirect(&mut self, label: &'static str, args: Option<usize>) {
        self.pass(label).indirect_draws += 1;
        self.indirect.push((label, args));
    }

    /// A dispatch, direct or indirect.
    pub fn dispatch(&mut self, label: &'static str, indirect: bool) {
        let pass = self.pass(label);
        match indirect {
            true => pass.indirect_dispatches += 1,
            false => pass.dispatches += 1,
        }
    }

    /// A query of `label`'s `part`: its index, or `None` when a frame's `capacity` queries are taken.
    pub fn query(&mut self, label: &'static str, part: Part, capacity: usize) -> Option<u32> {
        self.pass(label);
        if self.queries.len() >= capacity {
            self.queries_dropped.push(label);
            return None;
        }
        self.queries.push((label, part));
        Some(self.queries.len() as u32 - 1)
    }

    /// Queries recorded so far.
    pub fn queries(&self) -> usize {
        self.queries.len()
    }

    /// `bytes` uploaded by `label`'s step.
    pub fn uploaded(&mut self, label: &'static str, bytes: u64) {
        self.pass(label).bytes_uploaded += bytes;
    }

    /// `bytes` read back for `label`.
    pub fn read_back(&mut self, label: &'static str, bytes: u64) {
        self.pass(label).bytes_read_back += bytes;
    }

    /// The frame's counts from its queries' `results` (`STATISTICS_PER_QUERY` per query, in query
    /// order; ignored without statistics) and its copied indirect arguments `args` (two words
    /// each, in copy order).
    pub fn reduce(&self, results: &[u64], args: &[u32]) -> FrameCounts {
        let passes = self
            .passes
            .iter()
            .map(|t| {
                let mut triangles = Some(t.direct_triangles);
                for &(_, copied) in self.indirect.iter().filter(|(label, _)| *label == t.label) {
                    let drawn = copied.and_then(|i| Some((*args.get(2 * i)?, *args.get(2 * i + 1)?)));
                    triangles = triangles
                        .zip(drawn)
                        .map(|(sum, (count, instances))| sum + u64::from(count / 3) * u64::from(instances));
                }
                let part = |wanted: Option<Part>| {
                    let complete = self.statistics && !self.queries_dropped.contains(&t.label);
                    complete.then(|| {
                        let mut sum = Statistics::default();
                        let chunks = results.chunks_exact(STATISTICS_PER_QUERY);
                        for (&(label, part), query) in self.queries.iter().zip(chunks) {
                            if label == t.label && wanted.is_none_or(|w| w == part) {
                                sum.add(&Statistics::from_query(query));
                            }
                        }
                        sum
                    })
                };
                let has = |p: Part| self.queries.iter().any(|&(label, part)| label == t.label && part == p);
                PassCounts {
                    label: t.label,
                    draw_calls: t.draw_calls,
                    indirect_draws: t.indirect_draws,
                    dispatches: t.dispatches,
                    indirect_dispatches: t.indirect_dispatches,
                    triangles_submitted: triangles,
                    statistics: part(None),
                    bytes_uploaded: t.bytes_uploaded,
                    bytes_read_back: t.bytes_read_back,
                    prepass: part(Some(Part::Prepass)).filter(|_| has(Part::Prepass)),
                    shading: part(Some(Part::Shading)).filter(|_| has(Part::Shading)),
                }
            })
            .collect();
        FrameCounts { frame: self.frame, statistics: self.statistics, passes }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn direct_and_indirect_triangles_and_each_parts_statistics() {
        let mut tally = FrameTally::new(7, true);
        tally.draw("terrain", 6 * 64, 10); // 128 triangles × 10 instances
        tally.draw("terrain", 8, 1); // 2 whole triangles of 8 indices
        tally.draw_indirect("draw_seeds", Some(1));
        tally.draw_indirect("draw_seeds", Some(0));
        tally.dispatch("compact", false);
        tally.dispatch("compact", true);
        assert_eq!(tally.query("terrain", Part::Whole, 3), Some(0));
        assert_eq!(tally.query("draw_seeds", Part::Prepass, 3), Some(1));
        assert_eq!(tally.query("draw_seeds", Part::Shading, 3), Some(2));
        tally.uploaded("streaming", 4096);
        tally.read_back("counts", 96);
        let results = [1, 2, 3, 0, 10, 20, 30, 0, 100, 200, 300, 0];
        // Arguments 0: 36 indices × 5 seeds; 1: 3 indices × 2 seeds.
        let counts = tally.reduce(&results, &[36, 5, 3, 2]);
        let terrain = counts.pass("terrain").unwrap();
        assert_eq!((terrain.draw_calls, terrain.triangles_submitted), (2, Some(1282)));
        assert_eq!(terrain.statistics, Some(Statistics::from_query(&[1, 2, 3, 0])));
        let seeds = counts.pass("draw_seeds").unwrap();
        assert_eq!((seeds.indirect_draws, seeds.triangles_submitted), (2, Some(12 * 5 + 2)));
        assert_eq!(seeds.statistics.unwrap().fragment_invocations, 330);
        assert_eq!(seeds.prepass.unwrap().vertex_invocations, 10);
        assert_eq!(seeds.shading.unwrap().clipped_triangles, 200);
        assert_eq!(terrain.prepass, None);
        let compact = counts.pass("compact").unwrap();
        assert_eq!((compact.dispatches, compact.indirect_dispatches), (1, 1));
        let total = counts.total();
        assert_eq!((total.label, total.triangles_submitted), ("frame", Some(1344)));
        assert_eq!((total.bytes_uploaded, total.bytes_read_back), (4096, 96));
        assert_eq!(total.statistics.unwrap().vertex_invocations, 111);
    }

    #[test]
    fn without_statistics_or_room_the_figures_are_absent_not_zero() {
        let mut tally = FrameTally::new(1, false);
        tally.draw("ground", 3, 1);
        tally.name("draw_seeds");
        let counts = tally.reduce(&[], &[]);
        let idle = counts.pass("draw_seeds").unwrap();
        assert_eq!((idle.draw_calls, idle.triangles_submitted, idle.statistics), (0, Some(0), None));
        assert_eq!(counts.pass("ground").unwrap().statistics, None);
        assert_eq!(counts.total().statistics, None);
        assert_eq!(counts.total().triangles_submitted, Some(1));

        let mut tally = FrameTally::new(2, true);
        assert_eq!(tally.query("ground", Part::Whole, 1), Some(0));
        assert_eq!(tally.query("texcells", Part::Shading, 1), None);
        tally.draw_indirect("texcells", None);
        let counts = tally.reduce(&[5, 4, 3, 2], &[]);
        assert!(counts.pass("ground").unwrap().statistics.is_some());
        let texcells = counts.pass("texcells").unwrap();
        assert_eq!((texcells.statistics, texcells.triangles_submitted), (None, None));
        assert_eq!((counts.total().statistics, counts.total().triangles_submitted), (None, None));
    }
}

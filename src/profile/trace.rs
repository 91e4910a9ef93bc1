//! How it works: `--trace` writes the profiled frames in the Trace Event Format (JSON) that
//! chrome://tracing and Perfetto open. wgpu-profiler's own writer covers the GPU scopes of one
//! frame; a flight needs every frame and the CPU work beside it, so the events are written here.
//! Process 1 has two tracks: "CPU" (one complete event, `ph: "X"`, per frame spanning its wall
//! time, with the CPU scopes inside it) and "GPU" (one "X" event per pass per frame), plus a
//! counter track (`ph: "C"`) of seeds checked and selected. Timestamps are microseconds from the
//! first profiled frame's start; CPU work done before it (the TLM analysis that ends the last
//! warm-up frame, counted in the first profiled frame's figures) is left out of the trace. CPU scopes are on the profiler's CPU clock; GPU timestamps are on the GPU's clock,
//! shifted by the smallest offset that starts no frame's GPU work before that frame began on the
//! CPU (the frame where the GPU was quickest to start is aligned exactly; drift between the two
//! clocks over a flight is left as is). Passes timed on the CPU (no timestamp queries) are already
//! on the CPU clock.

use std::path::Path;

use serde_json::{Value, json};

use super::summary::Meta;
use super::{ProfileError, Recording};
use crate::gpu::TimeSource;

const PID: u32 = 1;
const CPU_TRACK: u32 = 1;
const GPU_TRACK: u32 = 2;

/// The trace of `recording`'s profiled frames as a Trace Event Format object.
pub fn chrome_trace(recording: &Recording, meta: &Meta) -> Value {
    let on_gpu_clock = |source: TimeSource| source == TimeSource::GpuTimestamps;
    // GPU clock → CPU clock: the largest (frame start − first GPU timestamp) over the frames.
    let gpu_offset_ms = recording
        .profiled_scopes()
        .filter_map(|(frame, scopes)| {
            let first = scopes
                .iter()
                .filter(|s| on_gpu_clock(s.timing.source))
                .map(|s| s.start_ms)
                .min_by(f64::total_cmp)?;
            Some(frame.start_ms - first)
        })
        .max_by(f64::total_cmp)
        .unwrap_or(0.0);
    let start_of = |start_ms: f64, source: TimeSource| {
        if on_gpu_clock(source) { start_ms + gpu_offset_ms } else { start_ms }
    };
    let origin_ms = recording.frames.first().map_or(0.0, |f| f.start_ms);
    // (Clamped: the GPU event aligned to the first frame may land a rounding error before it.)
    let us = |ms: f64| ((ms - origin_ms) * 1000.0).max(0.0);

    let mut events = vec![
        json!({"ph": "M", "pid": PID, "name": "process_name", "args": {"name": "terramp"}}),
        json!({"ph": "M", "pid": PID, "tid": CPU_TRACK, "name": "thread_name", "args": {"name": "CPU"}}),
        json!({"ph": "M", "pid": PID, "tid": GPU_TRACK, "name": "thread_name", "args": {"name": "GPU"}}),
        json!({"ph": "M", "pid": PID, "tid": CPU_TRACK, "name": "thread_sort_index", "args": {"sort_index": 0}}),
        json!({"ph": "M", "pid": PID, "tid": GPU_TRACK, "name": "thread_sort_index", "args": {"sort_index": 1}}),
    ];
    for frame in &recording.frames {
        events.push(json!({
            "ph": "X", "pid": PID, "tid": CPU_TRACK, "cat": "frame",
            "name": format!("frame {}", frame.frame),
            "ts": us(frame.start_ms), "dur": frame.wall_ms * 1000.0,
            "args": {"frame": frame.frame, "wall_ms": frame.wall_ms},
        }));
        if let Some(seeds) = recording.seeds.get(&frame.frame) {
            events.push(json!({
                "ph": "C", "pid": PID, "name": "seeds", "ts": us(frame.start_ms),
                "args": {"checked": seeds.checked, "selected": seeds.selected},
            }));
        }
    }
    for (frame, scopes) in recording.profiled_scopes() {
        for scope in scopes {
            let t = &scope.timing;
            let start_ms = start_of(scope.start_ms, t.source);
            if start_ms < origin_ms && !on_gpu_clock(t.source) {
                continue;
            }
            let (tid, cat) =
                if t.source == TimeSource::Cpu { (CPU_TRACK, "cpu") } else { (GPU_TRACK, "gpu") };
            events.push(json!({
                "ph": "X", "pid": PID, "tid": tid, "cat": cat, "name": t.label,
                "ts": us(start_ms), "dur": t.ms * 1000.0,
                "args": {"frame": frame.frame, "source": t.source},
            }));
        }
    }
    json!({
        "traceEvents": events,
        "displayTimeUnit": "ms",
        "otherData": {
            "producer": "terramp profile",
            "adapter": meta.adapter,
            "timing": meta.timing,
            "dataset": meta.dataset,
            "path": meta.path,
            "resolution": format!("{}x{}", meta.resolution[0], meta.resolution[1]),
            "preset": meta.preset,
        },
    })
}

/// Writes the trace of `recording` to `path`.
pub fn write(path: &Path, recording: &Recording, meta: &Meta) -> Result<(), ProfileError> {
    let error = |source| ProfileError::Write { path: path.display().to_string(), source };
    let file = std::fs::File::create(path).map_err(error)?;
    let mut writer = std::io::BufWriter::new(file);
    serde_json::to_writer(&mut writer, &chrome_trace(recording, meta)).map_err(|e| error(e.into()))?;
    std::io::Write::flush(&mut writer).map_err(error)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::summary::test_meta;
    use crate::profile::test_data::recording;

    #[test]
    fn one_complete_event_per_scope_per_frame_on_two_tracks() {
        let text = chrome_trace(&recording(), &test_meta()).to_string();
        let trace: Value = serde_json::from_str(&text).expect("the trace is JSON");
        let events = trace["traceEvents"].as_array().expect("traceEvents");
        let complete = |name: &str| -> Vec<&Value> {
            events.iter().filter(|e| e["ph"] == "X" && e["name"] == name).collect()
        };
        assert_eq!(complete("terrain").len(), 4, "the warm-up frame is not in the trace");
        assert_eq!(complete("seed_select").len(), 3);
        assert_eq!(complete("frame 10").len(), 1);
        assert!(complete("terrain").iter().all(|e| e["tid"] == GPU_TRACK && e["cat"] == "gpu"));
        assert!(complete("streaming").iter().all(|e| e["tid"] == CPU_TRACK));
        assert_eq!(events.iter().filter(|e| e["ph"] == "C").count(), 4);
        for e in events.iter().filter(|e| e["ph"] == "X") {
            assert!(e["ts"].as_f64().unwrap() >= 0.0 && e["dur"].as_f64().unwrap() > 0.0, "{e}");
        }
    }

    #[test]
    fn gpu_clock_is_aligned_to_frame_starts() {
        let trace = chrome_trace(&recording(), &test_meta());
        let events = trace["traceEvents"].as_array().unwrap();
        let ts = |name: &str, frame: u64| {
            let e = events.iter().find(|e| e["name"] == name && e["args"]["frame"] == frame).unwrap();
            e["ts"].as_f64().unwrap()
        };
        // Each frame's first pass is 1003 ms ahead of its start on the GPU clock: aligned to it.
        assert_eq!(ts("frame 10", 10), 0.0);
        assert_eq!(ts("terrain", 10), 0.0);
        assert_eq!(ts("terrain", 11), 20_000.0);
        assert_eq!(ts("tile_load_map", 11), 25_000.0);
        assert_eq!(ts("streaming", 11), 21_000.0);
    }

    #[test]
    fn cpu_work_before_the_first_profiled_frame_is_left_out() {
        let mut r = recording();
        let early = crate::profile::test_data::scope("tlm_analysis", TimeSource::Cpu, 95.0, 0.5);
        r.scopes.entry(10).or_default().insert(0, early);
        let trace = chrome_trace(&r, &test_meta());
        assert!(trace["traceEvents"].as_array().unwrap().iter().all(|e| e["name"] != "tlm_analysis"));
    }
}

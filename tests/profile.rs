//! `terramp profile`: the JSON lists every pass the frames timed, with positive times; its seed
//! counts are the log's; every profiled frame's counts are summed, each timed pass's among them; the Chrome trace parses and holds the passes; the CPU-timing fallback says
//! so; the generated orbit stays over the dataset; seeds selected with no impostor to draw them
//! are said.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use serde_json::Value;

const SIZE: u32 = 300;
const WARMUP: u64 = 4;
const FRAMES: u64 = 12;

struct Run {
    json: Value,
    trace: Value,
    log: Vec<Value>,
    stdout: String,
    stderr: String,
}

fn profile(dataset: &Path, name: &str, extra: &[&str]) -> Run {
    let out: PathBuf = std::env::temp_dir().join(format!("terramp-profile-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&out).unwrap();
    let output = terramp_testkit::command(env!("CARGO_BIN_EXE_terramp"))
        .args(["profile", "--width", "160", "--height", "90"])
        .args(["--frames", &FRAMES.to_string(), "--warmup", &WARMUP.to_string()])
        .arg("--dataset")
        .arg(dataset)
        .arg("--json")
        .arg(out.join("profile.json"))
        .arg("--trace")
        .arg(out.join("trace.json"))
        .arg("--log")
        .arg(out.join("log.jsonl"))
        .args(extra)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert!(output.status.success(), "{stdout}\n{stderr}");
    let read = |file: &str| std::fs::read_to_string(out.join(file)).unwrap();
    let run = Run {
        json: serde_json::from_str(&read("profile.json")).expect("the profile is JSON"),
        trace: serde_json::from_str(&read("trace.json")).expect("the trace is JSON"),
        log: read("log.jsonl").lines().map(|l| serde_json::from_str(l).unwrap()).collect(),
        stdout,
        stderr,
    };
    let _ = std::fs::remove_dir_all(&out);
    run
}

fn is_profiled(record: &Value) -> bool {
    record["warmup"] == false
}

#[test]
fn profile_json_trace_and_log_agree() {
    let dataset = terramp_testkit::synth_dataset(SIZE, 7);
    // No --path: the generated orbit, which stays over this small dataset's land cover.
    let run = profile(&dataset, "gpu", &[]);
    let json = &run.json;
    // No impostor folder: the seeds are selected, and the command says none is drawn.
    let undrawn = "seeds of the class table nc are selected but none is drawn";
    assert!(run.stderr.contains(undrawn), "{}", run.stderr);
    assert_eq!(run.log.len() as u64, WARMUP + FRAMES);
    assert_eq!(json["frames"]["profiled"], FRAMES);
    assert_eq!(json["frames"]["first"], WARMUP);
    assert!(json["fps"]["median"].as_f64().unwrap() > 0.0, "{json}");

    // Every pass the frames logged is in the JSON, with positive times.
    let passes = json["passes"].as_array().unwrap();
    let in_json: BTreeMap<&str, &Value> = passes.iter().map(|p| (p["label"].as_str().unwrap(), p)).collect();
    let logged: BTreeSet<&str> = run
        .log
        .iter()
        .filter(|r| is_profiled(r))
        .flat_map(|r| r["passes"].as_array().unwrap())
        .map(|p| p["label"].as_str().unwrap())
        .collect();
    for label in ["terrain", "depth_pyramid", "tile_load_map", "ground", "seed_select"] {
        assert!(logged.contains(label), "the log never timed {label}: {logged:?}");
    }
    for label in &logged {
        let pass = in_json.get(label).unwrap_or_else(|| panic!("{label} is not in {json}"));
        let (median, p95) = (pass["median_ms"].as_f64().unwrap(), pass["p95_ms"].as_f64().unwrap());
        assert!(median > 0.0 && p95 >= median, "{pass}");
        assert!(pass["samples"].as_u64().unwrap() > 0, "{pass}");
    }
    for line in ["median ms", "p95 ms", "Seeds checked", "Seeds selected", "FPS", "seed_select"] {
        assert!(run.stdout.contains(line), "no {line:?} in the table:\n{}", run.stdout);
    }

    // The seed counts are the log's, frame by frame, attributed to the frame they count.
    let mut from_log: BTreeMap<u64, (u64, u64)> = BTreeMap::new();
    for record in &run.log {
        let seeds = &record["report"]["seeds"];
        let Some(frame) = seeds["frame"].as_u64() else { continue };
        if (WARMUP..WARMUP + FRAMES).contains(&frame) {
            from_log.insert(frame, (seeds["checked"].as_u64().unwrap(), seeds["selected"].as_u64().unwrap()));
        }
    }
    let per_frame: BTreeMap<u64, (u64, u64)> = json["seeds"]["per_frame"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            let n = |k: &str| s[k].as_u64().unwrap();
            (n("frame"), (n("checked"), n("selected")))
        })
        .collect();
    assert!(from_log.len() as u64 >= FRAMES / 2, "counters of only {} frames arrived", from_log.len());
    assert_eq!(per_frame, from_log);
    let median = |values: Vec<u64>| {
        let mut v: Vec<f64> = values.into_iter().map(|x| x as f64).collect();
        v.sort_by(f64::total_cmp);
        let n = v.len();
        if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) }
    };
    let checked = median(from_log.values().map(|c| c.0).collect());
    let selected = median(from_log.values().map(|c| c.1).collect());
    assert_eq!(json["seeds"]["checked_median"].as_f64(), Some(checked));
    assert_eq!(json["seeds"]["selected_median"].as_f64(), Some(selected));
    assert!(checked > 0.0, "no seeds checked: the path should fly over land cover");

    // Every profiled frame's counts arrived (the session drains the last ones); each GPU pass
    // timed has its row; the frame's row is the rows' sum, figure by figure.
    let counts = &json["counts"];
    assert_eq!((counts["frames"].as_u64(), counts["statistics"].as_bool()), (Some(FRAMES), Some(true)));
    let rows = counts["passes"].as_array().unwrap();
    for pass in passes.iter().filter(|p| p["source"] != "cpu") {
        assert!(rows.iter().any(|r| r["label"] == pass["label"]), "no counts of {pass} in {counts}");
    }
    let sum = |field: &str| rows.iter().map(|r| r[field].as_u64().unwrap()).sum::<u64>();
    for field in ["draw_calls", "indirect_draws", "dispatches", "triangles_submitted", "bytes_uploaded"] {
        assert_eq!(counts["frame"][field].as_u64(), Some(sum(field)), "{field} in {counts}");
    }
    assert!(sum("triangles_submitted") > 0 && sum("bytes_read_back") > 0, "{counts}");
    assert!(
        run.stdout.contains("Counts per frame (mean of 12 frames, with pipeline statistics)"),
        "{}",
        run.stdout
    );

    // The trace holds one complete event per GPU pass per frame that timed it, on the GPU track.
    let events = run.trace["traceEvents"].as_array().expect("traceEvents");
    let complete = |name: &str| events.iter().filter(|e| e["ph"] == "X" && e["name"] == name).count() as u64;
    for pass in passes.iter().filter(|p| p["source"] != "cpu") {
        let label = pass["label"].as_str().unwrap();
        assert_eq!(complete(label), pass["samples"].as_u64().unwrap(), "{label}");
    }
    let frames = events.iter().filter(|e| e["ph"] == "X" && e["cat"] == "frame").count() as u64;
    assert_eq!(frames, FRAMES);
    assert!(events.iter().filter(|e| e["ph"] == "X").all(|e| e["ts"].as_f64().is_some_and(|t| t >= 0.0)));
}

#[test]
fn without_timestamps_the_table_says_the_passes_were_timed_on_the_cpu() {
    let dataset = terramp_testkit::synth_dataset(SIZE, 7);
    let settings = std::env::temp_dir().join(format!("terramp-profile-cpu-{}.toml", std::process::id()));
    std::fs::write(&settings, "[gpu]\ntimestamps = false\n").unwrap();
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("config/paths/default.toml");
    let args = ["--settings", settings.to_str().unwrap(), "--path", path.to_str().unwrap()];
    let run = profile(&dataset, "cpu", &args);
    assert_eq!(run.json["path"], path.to_str().unwrap());
    let _ = std::fs::remove_file(&settings);
    assert_eq!(run.json["timing"], "cpu_wait");
    assert!(run.stdout.contains("CPU waits"), "{}", run.stdout);
    let passes = run.json["passes"].as_array().unwrap();
    let terrain = passes.iter().find(|p| p["label"] == "terrain").expect("terrain is timed");
    assert_eq!(terrain["source"], "cpu_wait");
    assert!(terrain["median_ms"].as_f64().unwrap() > 0.0);
}

#[test]
fn the_generated_orbit_stays_over_the_dataset() {
    let dataset = terramp::dataset::Dataset::open(&terramp_testkit::synth_dataset(SIZE, 7)).unwrap();
    // The default path's keyframes lie outside a 3 km dataset: the orbit replaces it.
    let (path, name) = terramp::profile::default_path(&dataset).unwrap();
    assert!(name.starts_with("orbit"), "{name}");
    let m = &dataset.manifest;
    let (corner, extent) = (m.corner_m(), m.extent_m());
    for i in 0..=64 {
        let camera = path.camera_at(f64::from(i) / 64.0, 60.0, 0.1);
        let p = camera.position_m;
        assert!((0..2).all(|a| (corner[a]..corner[a] + extent[a]).contains(&p[a])), "{p}");
        let ground = dataset.height_at(p.x - m.origin_m[0], p.y - m.origin_m[1], 0).unwrap();
        assert!(p.z > ground + 10.0, "{p} over ground at {ground}");
        assert!(camera.pitch_deg < 0.0);
    }
}

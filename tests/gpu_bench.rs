//! `scripts/gpu_bench.sh`, the benchmark made for a lent GPU machine, runs as it is on the software
//! adapter: a tiny frame count over a small synthetic dataset, and its one JSON holds the machine,
//! the adapter and driver, the profile's figures for every pass, without and with the seeds'
//! depth prepass, and each criterion bench's mean.
//!
//! The criterion branch runs a tiny bench: this test's own binary (harness = false: `main` is
//! below), which, started by the script with criterion's `--bench`, times the seeds' hash
//! (`terramp::seeds::pcg`) over 1024 values instead of running the test.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::path::Path;

use criterion::Criterion;
use terramp_testkit::data::TempDir;
use terramp_testkit::synth_dataset;

const TEST: &str = "the_gpu_benchmark_runs_on_the_software_adapter_and_writes_its_json";
/// The tiny bench's name under the script's bench folder, and its criterion id.
const BENCH: &str = "tiny";
const BENCH_ID: &str = "tiny/pcg_1024";

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.iter().any(|a| a == "--bench") {
        tiny_bench();
    } else if args.iter().any(|a| a == "--list") {
        println!("{TEST}: test");
    } else {
        the_gpu_benchmark_runs_on_the_software_adapter_and_writes_its_json();
        println!("test {TEST} ... ok");
    }
}

/// What the script's criterion branch runs here: one bench, its arguments the script's.
fn tiny_bench() {
    let mut c = Criterion::default().configure_from_args();
    c.benchmark_group("tiny").bench_function("pcg_1024", |b| {
        b.iter(|| (0..1024u32).fold(0u32, |acc, i| acc ^ terramp::seeds::pcg(std::hint::black_box(i))));
    });
    c.final_summary();
}

fn the_gpu_benchmark_runs_on_the_software_adapter_and_writes_its_json() {
    let Some(impostors) = terramp_testkit::nc_impostors() else { return };
    let dataset = synth_dataset(300, 7);
    let out = TempDir::new("gpu-bench");
    // The bench folder holds this binary under the tiny bench's name.
    let benches = TempDir::new("gpu-bench-benches");
    std::os::unix::fs::symlink(std::env::current_exe().unwrap(), benches.path().join(format!("{BENCH}-0")))
        .unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/gpu_bench.sh");
    let output = terramp_testkit::command("bash")
        .arg(script)
        .env("TERRAMP", env!("CARGO_BIN_EXE_terramp"))
        .env("DATASET", &dataset)
        .env("IMPOSTORS", impostors)
        .env("OUT", out.path())
        // Pass 3's counters arrive a frame or two late: four frames let two of them in.
        .envs([("FRAMES", "4"), ("WARMUP", "2"), ("WIDTH", "160"), ("HEIGHT", "90")])
        .env("BENCH_DIR", benches.path())
        .envs([("BENCHES", BENCH), ("BENCH_SECONDS", "0.5")])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "gpu_bench.sh failed:\n{stderr}");
    let text = std::fs::read_to_string(out.path().join("gpu_bench.json")).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}:\n{text}"));
    assert_eq!(json["schema"], "terramp-gpu-bench/1");
    assert!(json["machine"].as_str().is_some_and(|m| m.contains("cores")), "{text}");
    let (profile, prepass) = (&json["profile"], &json["profile_depth_prepass"]);
    assert!(profile["adapter"].as_str().is_some_and(|a| !a.is_empty()), "{text}");
    assert_eq!(profile["resolution"], serde_json::json!([160, 90]));
    assert_eq!(profile["preset"], "accurate");
    // The same flight with the seeds' depth prepass, for the adapter's verdict on it.
    for (profile, settings) in
        [(profile, "settings-profile.toml"), (prepass, "settings-profile_depth_prepass.toml")]
    {
        for pass in ["terrain", "tile_load_map", "seed_select", "compact", "draw_seeds"] {
            let row = profile["passes"].as_array().unwrap().iter().find(|p| p["label"] == pass);
            assert!(row.is_some_and(|r| r["median_ms"].as_f64().is_some()), "no {pass} timing in {text}");
        }
        assert!(profile["settings"].as_str().is_some_and(|s| s.ends_with(settings)), "{text}");
        let checked = profile["seeds"]["checked_median"].as_f64().unwrap_or(0.0);
        println!("{checked} seeds checked a frame; {}", json["seconds"]);
        assert!(checked > 0.0, "no seed checked: {text}");
        // The frames' counts travel in the summary: the seeds' triangles, drawn indirectly.
        let seeds =
            profile["counts"]["passes"].as_array().unwrap().iter().find(|p| p["label"] == "draw_seeds");
        assert!(seeds.is_some_and(|s| s["triangles_submitted"].as_u64().is_some_and(|t| t > 0)), "{text}");
    }
    let settings = std::fs::read_to_string(out.path().join("settings-profile_depth_prepass.toml")).unwrap();
    assert!(settings.contains("depth_prepass = true"), "{settings}");
    // The tiny bench's mean, as criterion estimated it (a time: only its being one is checked).
    let benches = json["benches"].as_array().unwrap();
    let [bench] = benches.as_slice() else { panic!("not one bench: {text}") };
    assert_eq!(bench["id"], BENCH_ID, "{text}");
    assert!(bench["mean_ns"].as_f64().is_some_and(|ns| ns > 0.0), "{text}");
}

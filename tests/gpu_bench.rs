//! `scripts/gpu_bench.sh`, the benchmark made for a lent GPU machine, runs as it is on the software
//! adapter: a tiny frame count over a small synthetic dataset, and its one JSON holds the machine,
//! the adapter and driver, and the profile's figures for every pass, without and with the seeds'
//! depth prepass.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::path::Path;
use std::process::Command;

use terramp_testkit::data::TempDir;
use terramp_testkit::synth_dataset;

#[test]
fn the_gpu_benchmark_runs_on_the_software_adapter_and_writes_its_json() {
    let Some(impostors) = terramp_testkit::nc_impostors() else { return };
    let dataset = synth_dataset(300, 7);
    let out = TempDir::new("gpu-bench");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/gpu_bench.sh");
    let output = Command::new("bash")
        .arg(script)
        .env("TERRAMP", env!("CARGO_BIN_EXE_terramp"))
        .env("DATASET", &dataset)
        .env("IMPOSTORS", impostors)
        .env("OUT", out.path())
        // Pass 3's counters arrive a frame or two late: four frames let two of them in.
        .envs([("FRAMES", "4"), ("WARMUP", "2"), ("WIDTH", "160"), ("HEIGHT", "90")])
        .env_remove("BENCH_DIR")
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
    }
    let settings = std::fs::read_to_string(out.path().join("settings-profile_depth_prepass.toml")).unwrap();
    assert!(settings.contains("depth_prepass = true"), "{settings}");
}

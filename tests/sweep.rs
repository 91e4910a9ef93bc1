//! `terramp sweep` on a small synthetic dataset, two presets with a knob set, a few frames at
//! 160 × 90, trees drawn (the shared models baked): it writes trade.csv, trade.json and trade.png;
//! the CSV and the JSON hold the same figures; every point has positive times and sensible errors
//! against the ground truth, whole and per distance band; `fast`, which grows half the density,
//! misses about half the truth's visible seeds, `accurate` nearly none; each point's frames differ
//! from their photograph frames (nothing grown) by a finite CIEDE2000. (The product of presets
//! and knob values is `sweep::knobs`' unit test: each point here costs the software adapter a
//! minute.)
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::path::PathBuf;

use serde_json::Value;
use terramp::reference::image_metrics::PSNR_CAP_DB;

#[test]
fn sweep_writes_agreeing_csv_json_and_plot() {
    let Some(impostors) = terramp_testkit::nc_impostors() else { return };
    let dataset = terramp_testkit::synth_dataset(300, 7);
    let out: PathBuf = std::env::temp_dir().join(format!("terramp-sweep-{}", std::process::id()));
    let layer = out.with_extension("toml");
    std::fs::write(&layer, format!("[draw_seeds]\nimpostors = {:?}\n", impostors.display().to_string()))
        .unwrap();
    let output = terramp_testkit::command(env!("CARGO_BIN_EXE_terramp"))
        .args(["sweep", "--presets", "fast,accurate", "--frames", "4", "--warmup", "2", "--samples", "2"])
        .args(["--timing-rounds", "2"])
        .args(["--width", "160", "--height", "90", "--knob", "seeds.frustum_epsilon=0.05"])
        .args(["--truth-supersample", "2", "--truth-reach-m", "1500"])
        .args(["--popping-frames", "4", "--popping-step-m", "3"])
        .arg("--settings")
        .arg(&layer)
        .arg("--dataset")
        .arg(&dataset)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let _ = std::fs::remove_file(&layer);
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(output.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&output.stderr));

    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("trade.json")).unwrap()).unwrap();
    let csv = std::fs::read_to_string(out.join("trade.csv")).unwrap();
    let plot = image::open(out.join("trade.png")).expect("trade.png is an image");
    assert!(plot.width() > 600 && plot.height() > 300);
    let _ = std::fs::remove_dir_all(&out);

    assert_eq!(json["schema"], "terramp-trade/3");
    assert_eq!(json["popping_flight"]["frames"], 4);
    assert_eq!((json["frames"].as_u64(), json["timing_rounds"].as_u64()), (Some(4), Some(2)));
    assert_eq!(json["resolution"], serde_json::json!([160, 90]));
    let points = json["points"].as_array().unwrap();
    let labels: Vec<&str> = points.iter().map(|p| p["label"].as_str().unwrap()).collect();
    assert_eq!(labels, ["fast seeds.frustum_epsilon=0.05", "accurate seeds.frustum_epsilon=0.05"]);
    for label in &labels {
        assert!(stdout.contains(label), "the table lacks {label}:\n{stdout}");
    }

    // The CSV: one row per point, the same figures as the JSON.
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<String>> = lines.map(split_csv).collect();
    assert_eq!(rows.len(), points.len());
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no {name}"));
    for (row, point) in rows.iter().zip(points) {
        assert_eq!(row.len(), header.len());
        assert_eq!(row[column("label")], point["label"].as_str().unwrap());
        let (seeds, any_part) = (&point["seeds"], &point["any_part"]);
        for (name, value) in [
            ("frame_flip", &point["frame_flip"]),
            ("popping", &point["popping"]["popping"]),
            ("block_change_largest", &point["popping"]["largest"]),
            ("truth_block_change_largest", &point["popping"]["truth_largest"]),
            ("any_part_visible", &any_part["visible"]),
            ("any_part_recall_pct", &any_part["recall_pct"]),
            ("pixel_weighted_recall_pct", &any_part["pixel_weighted_recall_pct"]),
            ("missed_reach_pct", &any_part["missed_pct"]["reach"]),
            ("missed_density_pct", &any_part["missed_pct"]["density"]),
            ("missed_selection_pct", &any_part["missed_pct"]["selection"]),
            ("frame_ms", &point["frame_ms"]),
            ("gpu_ms", &point["gpu_ms"]),
            ("ground_psnr_db", &point["ground_psnr_db"]),
            ("frame_psnr_db", &point["frame_psnr_db"]),
            ("frame_ssim", &point["frame_ssim"]),
            ("recall_pct", &seeds["recall_pct"]),
            ("precision_pct", &seeds["precision_pct"]),
            ("height_error_max_m", &seeds["height_error_max_m"]),
            ("visible", &seeds["visible"]),
            ("photo_de2000_mean", &point["photo_de2000"]["mean"]),
            ("photo_de2000_p95", &point["photo_de2000"]["p95"]),
        ] {
            let csv_value: f64 = row[column(name)].parse().unwrap_or_else(|_| panic!("{name}: {row:?}"));
            // serde_json's float parsing may land one ulp away from the shortest form it wrote.
            let json_value = value.as_f64().unwrap();
            assert!((csv_value - json_value).abs() <= 1e-12 * json_value.abs(), "{name} of {}", row[0]);
        }
        for pass in point["passes"].as_array().unwrap() {
            let name = format!("{}_ms", pass["label"].as_str().unwrap());
            let (csv_ms, json_ms) =
                (row[column(&name)].parse::<f64>().unwrap(), pass["median_ms"].as_f64().unwrap());
            assert!((csv_ms - json_ms).abs() <= 1e-12 * json_ms.abs(), "{name} of {}", row[0]);
        }

        // Positive times, sensible errors.
        assert!(
            point["frame_ms"].as_f64().unwrap() > 0.0 && point["gpu_ms"].as_f64().unwrap() > 0.0,
            "{point}"
        );
        let passes: Vec<&str> =
            point["passes"].as_array().unwrap().iter().map(|p| p["label"].as_str().unwrap()).collect();
        for pass in ["terrain", "ground", "tile_load_map", "seed_select"] {
            assert!(passes.contains(&pass), "{} lacks {pass}: {passes:?}", row[0]);
        }
        assert!(point["passes"].as_array().unwrap().iter().all(|p| p["median_ms"].as_f64().unwrap() >= 0.0));
        assert!(seeds["visible"].as_u64().unwrap() > 50, "{seeds}");
        for key in ["recall_pct", "precision_pct"] {
            let pct = seeds[key].as_f64().unwrap();
            assert!((90.0..=100.0).contains(&pct), "{}: {key} {pct}", row[0]);
        }
        assert!(seeds["height_error_max_m"].as_f64().unwrap() < 0.01, "{seeds}");
        let ssim = point["frame_ssim"].as_f64().unwrap();
        assert!(ssim > 0.5 && ssim <= 1.0, "{ssim}");
        for key in ["ground_psnr_db", "frame_psnr_db"] {
            let db = point[key].as_f64().unwrap();
            assert!(db > 20.0 && db <= PSNR_CAP_DB, "{}: {key} {db}", row[0]);
        }
        assert_eq!(point["samples"].as_array().unwrap().len(), 2);
        // The samples missed, by why, add up to all the samples missed.
        let missed: f64 = ["reach", "density", "frustum", "summit_hidden", "selection"]
            .iter()
            .map(|k| any_part["missed_pct"][k].as_f64().unwrap())
            .sum();
        let pw = any_part["pixel_weighted_recall_pct"].as_f64().unwrap();
        assert!((missed - (100.0 - pw)).abs() < 1e-9, "{}: {missed} missed, {pw} recalled", row[0]);
        // Popping: three pairs of frames; block changes are levels of 255, the truth moves too.
        let popping = &point["popping"];
        assert_eq!(popping["pairs"], 3, "{popping}");
        let (largest, truth_largest) =
            (popping["largest"].as_f64().unwrap(), popping["truth_largest"].as_f64().unwrap());
        assert!(
            largest > 0.0 && largest <= 255.0 && truth_largest > 0.0 && truth_largest <= 255.0,
            "{popping}"
        );
        assert!(popping["popping"].as_f64().unwrap() <= largest, "{popping}");
        let flip = point["frame_flip"].as_f64().unwrap();
        assert!(flip > 0.0 && flip < 0.5, "{}: FLIP {flip}", row[0]);
        // Against the photograph (nothing grown): the trees change the forest's blocks, finitely.
        let photo = &point["photo_de2000"];
        let [mean, p95, max] = ["mean", "p95", "max"].map(|k| photo[k].as_f64().unwrap());
        assert!(mean > 0.0 && mean <= max && p95 <= max && max.is_finite(), "{}: {photo}", row[0]);
        // The bands: meshes first, beyond last; their pixels are the frame's bar the sky.
        let error = &point["error"];
        let bands = error["bands"].as_array().unwrap();
        assert_eq!(bands.first().unwrap()["band"]["name"], "meshes");
        assert_eq!(bands.last().unwrap()["band"]["name"], "beyond");
        let banded: u64 = bands.iter().map(|b| b["pixels"].as_u64().unwrap()).sum();
        assert!(banded > 0 && banded <= error["frame"]["pixels"].as_u64().unwrap(), "{error}");
    }
    // `fast` grows half the density (seeds.density_scale 0.5) and reaches 2 km where `accurate`
    // reaches 3 km: it selects far fewer of the truth's visible seeds; `accurate`, judged by any
    // part showing, still misses some (seeds whose summit hides but whose crown shows).
    let recall = |p: &Value| p["any_part"]["recall_pct"].as_f64().unwrap();
    let pixel_recall = |p: &Value| p["any_part"]["pixel_weighted_recall_pct"].as_f64().unwrap();
    let (fast, accurate) = (&points[0], &points[1]);
    println!(
        "recall: fast {:.2} %, accurate {:.2} %; pixel-weighted: fast {:.2} %, accurate {:.2} %",
        recall(fast),
        recall(accurate),
        pixel_recall(fast),
        pixel_recall(accurate)
    );
    assert!(recall(fast) < 70.0 && recall(accurate) > 90.0, "{fast}\n{accurate}");
    assert!(pixel_recall(accurate) > pixel_recall(fast), "{fast}\n{accurate}");
    // `fast` grows half the density: much of what it misses is not grown; `accurate` grows all.
    let not_grown = |p: &Value| p["any_part"]["missed_pct"]["density"].as_f64().unwrap();
    println!("not grown: fast {:.2} %, accurate {:.2} %", not_grown(fast), not_grown(accurate));
    assert!(not_grown(fast) > 10.0 && not_grown(accurate) == 0.0, "{fast}\n{accurate}");
}

/// One CSV line's fields (quoted fields may hold commas and doubled quotes).
fn split_csv(line: &str) -> Vec<String> {
    let (mut fields, mut field, mut quoted) = (Vec::new(), String::new(), false);
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(std::mem::take(&mut field)),
            _ => field.push(c),
        }
    }
    fields.push(field);
    fields
}

//! The examples run as a host would run them: `cargo test` builds them beside the tests
//! (`target/<profile>/examples/`), and these tests run the binaries and read what they print.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::process::Output;

use terramp::dataset::Dataset;
use terramp_testkit::datasets::synth_dataset;
use terramp_testkit::setup::{command, example};

fn run(name: &str, args: &[&str]) -> Output {
    command(example(name)).args(args).output().unwrap()
}

/// Points of the walk asked for.
const POINTS: usize = 12;
/// Plants asked for within this of each point, metres.
const RADIUS_M: f64 = 20.0;

#[test]
fn the_headless_example_prints_the_datasets_ground_and_the_plants_along_its_walk() {
    let dir = synth_dataset(300, 7);
    let dataset = Dataset::open(&dir).unwrap();
    let (points, radius) = (POINTS.to_string(), RADIUS_M.to_string());
    let out = run("queries_along_path", &[dir.to_str().unwrap(), "--points", &points, "--radius", &radius]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "the example failed: {stderr}");
    let stdout = String::from_utf8(out.stdout).unwrap();
    let mut lines = stdout.lines();
    assert_eq!(
        lines.next(),
        Some("distance_m,x_m,y_m,height_m,slope_deg,class,plants,nearest_m,nearest_species")
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), POINTS, "{stdout}");
    let origin = dataset.manifest.origin_m;
    let mut with_plants = 0;
    for row in &rows {
        assert_eq!(row.len(), 9, "{row:?}");
        let number = |i: usize| row[i].parse::<f64>().unwrap();
        // The height printed to a millimetre is the dataset's own finest ground there.
        let (x, y) = (number(1) - origin[0], number(2) - origin[1]);
        let (height_m, _) = dataset.ground_at(x, y, 0).unwrap();
        assert!((number(3) - height_m).abs() <= 0.0005 + 1e-9, "{row:?}: the dataset says {height_m}");
        assert!((0.0..90.0).contains(&number(4)), "{row:?}");
        let plants: usize = row[6].parse().unwrap();
        if plants > 0 {
            with_plants += 1;
            assert!(number(7) <= RADIUS_M, "{row:?}: the nearest plant stands beyond the radius");
            assert!(!row[8].is_empty(), "{row:?}: a plant with no species");
        } else {
            assert!(row[7].is_empty() && row[8].is_empty(), "{row:?}");
        }
    }
    // The synthetic dataset is mostly forest and meadow: a walk across it meets plants.
    assert!(with_plants > 0, "no plants along the walk: {stdout}");
}

#[test]
fn the_headless_example_refuses_bad_arguments_with_the_reason() {
    let out = run("queries_along_path", &["/nonexistent/terramp-dataset", "--points", "3"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/terramp-dataset"));
    let out = run("queries_along_path", &["--points", "1"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("at least 2"));
}

#[test]
fn the_headless_example_without_a_dataset_walks_one_it_synthesises_and_removes() {
    let out = run("queries_along_path", &["--points", "2"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "the example failed: {stderr}");
    let dir = stderr.split("synthesising one into ").nth(1).and_then(|s| s.lines().next()).unwrap();
    assert!(!std::path::Path::new(dir).exists(), "{dir} left behind");
    assert_eq!(String::from_utf8(out.stdout).unwrap().lines().count(), 1 + 2);
}

#[test]
fn the_examples_import_terramp_only_through_the_host_module() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let mut examples = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "rs") {
            continue;
        }
        examples += 1;
        let text = std::fs::read_to_string(&path).unwrap();
        // Every path into the crate, in a `use` or written out in the code.
        for (i, _) in text.match_indices("terramp::") {
            assert!(
                text[i..].starts_with("terramp::host::") || text[i..].starts_with("terramp::host;"),
                "{}: `{}` reaches past terramp::host",
                path.display(),
                text[i..].lines().next().unwrap()
            );
        }
    }
    assert!(examples > 0, "no examples in {}", dir.display());
}

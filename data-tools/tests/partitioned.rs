//! Partitioned builds (`terramp-data plan`, `build --plan --partition`, `merge`) equal the
//! single-process build byte for byte: run as separate jobs, on Dask's `LocalCluster`, and after a
//! job killed with SIGKILL in the middle of its partition; of the synthetic dataset and of GeoTIFF
//! inputs (a DEM as it is, with voids, or reprojected from degrees; imagery and land cover
//! reprojected or not).
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use terramp_testkit::data::{TempDir, shared_data};

const SIZE: &str = "600";
const SEED: &str = "5";

fn terramp_data(args: &[&str]) -> Output {
    let output = terramp_testkit::command(env!("CARGO_BIN_EXE_terramp-data")).args(args).output().unwrap();
    assert!(
        output.status.success(),
        "terramp-data {}: {}{}",
        args.join(" "),
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The single-process build the partitioned ones must equal.
fn single(dir: &Path, size: &str) -> PathBuf {
    let out = dir.join("single");
    terramp_data(&["synth", "--size", size, "--seed", SEED, "--out", path(&out)]);
    out
}

fn plan(dir: &Path, size: &str, partitions: u32) -> PathBuf {
    let plan = dir.join("plan.toml");
    let partitions = partitions.to_string();
    terramp_data(&[
        "plan",
        "--synth-size",
        size,
        "--seed",
        SEED,
        "--partitions",
        &partitions,
        "--out",
        path(&plan),
    ]);
    plan
}

/// Every file of dataset `a` equals `b`'s, byte for byte, and neither has others.
fn assert_same_dataset(a: &Path, b: &Path) {
    let names = |dir: &Path| {
        let mut names: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name()).collect();
        names.sort();
        names
    };
    assert_eq!(names(a), names(b), "{} and {} hold other files", a.display(), b.display());
    for name in names(a) {
        let same = std::fs::read(a.join(&name)).unwrap() == std::fs::read(b.join(&name)).unwrap();
        assert!(same, "{} differs from the single-process build's", b.join(&name).display());
    }
}

#[test]
fn jobs_run_one_by_one_merge_into_the_single_process_build() {
    let dir = TempDir::new("partitioned-jobs");
    let single = single(dir.path(), SIZE);
    let plan = plan(dir.path(), SIZE, 3);
    for part in ["0", "1", "2"] {
        let built = stdout(&terramp_data(&["build", "--plan", path(&plan), "--partition", part]));
        assert!(built.contains("built in"), "{built}");
    }
    let merged = dir.path().join("merged");
    terramp_data(&["merge", "--plan", path(&plan), "--out", path(&merged)]);
    assert_same_dataset(&single, &merged);
    // Idempotent: a partition built for this plan is not built again.
    let again = stdout(&terramp_data(&["build", "--plan", path(&plan), "--partition", "1"]));
    assert!(again.contains("already built"), "{again}");

    // The imagery's format is the merge's alone: a plan for BC7 over the same parts builds nothing
    // again, and merges into the single-process BC7 build.
    let bc7_plan = dir.path().join("plan-bc7.toml");
    let parts = dir.path().join("plan.parts");
    let args = ["--synth-size", SIZE, "--seed", SEED, "--partitions", "3", "--imagery-format", "bc7"];
    terramp_data(&[&["plan"], &args[..], &["--parts", path(&parts), "--out", path(&bc7_plan)]].concat());
    for part in ["0", "1", "2"] {
        let again = stdout(&terramp_data(&["build", "--plan", path(&bc7_plan), "--partition", part]));
        assert!(again.contains("already built"), "{again}");
    }
    let (single_bc7, merged_bc7) = (dir.path().join("single-bc7"), dir.path().join("merged-bc7"));
    let synth =
        ["synth", "--size", SIZE, "--seed", SEED, "--imagery-format", "bc7", "--out", path(&single_bc7)];
    terramp_data(&synth);
    terramp_data(&["merge", "--plan", path(&bc7_plan), "--out", path(&merged_bc7)]);
    assert_same_dataset(&single_bc7, &merged_bc7);
}

#[test]
fn a_merge_names_the_partitions_not_built_and_writes_nothing() {
    let dir = TempDir::new("partitioned-missing");
    let plan = plan(dir.path(), "300", 3);
    terramp_data(&["build", "--plan", path(&plan), "--partition", "1"]);
    let out = dir.path().join("merged");
    let output = terramp_testkit::command(env!("CARGO_BIN_EXE_terramp-data"))
        .args(["merge", "--plan", path(&plan), "--out", path(&out)])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success() && stderr.contains("not built for this plan: 0, 2"), "{stderr}");
    assert!(!out.exists());
    // A plan edited by hand is refused rather than built half one way, half another.
    let text = std::fs::read_to_string(&plan).unwrap().replace("seed = 5", "seed = 6");
    std::fs::write(&plan, text).unwrap();
    let output = terramp_testkit::command(env!("CARGO_BIN_EXE_terramp-data"))
        .args(["build", "--plan", path(&plan), "--partition", "0"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success() && stderr.contains("edited"), "{stderr}");
}

/// The Python of the virtual environment `.ci/run` makes with Dask, if it is there.
fn dask_python() -> Option<PathBuf> {
    let python = Path::new(env!("CARGO_MANIFEST_DIR")).join("../.venv-dask/bin/python");
    if python.is_file() {
        return Some(python);
    }
    assert!(
        std::env::var("CI").is_err(),
        "{} is missing: .ci/run makes it (python3 -m venv .venv-dask; pip install -r scripts/requirements-dask.txt)",
        python.display()
    );
    eprintln!("skipped: no Dask ({} is missing)", python.display());
    None
}

fn dask_build(python: &Path, plan: &Path, out: &Path) -> String {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scripts/dask_build.py");
    let output = Command::new(python)
        .arg(script)
        .args(["--plan", path(plan), "--out", path(out), "--local", "2"])
        .args(["--terramp-data", env!("CARGO_BIN_EXE_terramp-data")])
        .output()
        .unwrap();
    let text = format!("{}{}", stdout(&output), String::from_utf8_lossy(&output.stderr));
    assert!(output.status.success(), "dask_build.py: {text}");
    text
}

#[test]
fn a_dask_local_cluster_builds_the_single_process_dataset() {
    let Some(python) = dask_python() else { return };
    let dir = TempDir::new("partitioned-dask");
    let single = single(dir.path(), SIZE);
    let plan = plan(dir.path(), SIZE, 4);
    let merged = dir.path().join("merged");
    let log = dask_build(&python, &plan, &merged);
    assert!(log.contains("[4/4]") && log.contains("ETA") && log.contains("merged 4 partitions"), "{log}");
    assert_same_dataset(&single, &merged);
}

#[test]
fn a_job_killed_mid_partition_is_rebuilt_and_only_it() {
    let Some(python) = dask_python() else { return };
    let dir = TempDir::new("partitioned-kill");
    let size = "1200";
    let single = single(dir.path(), size);
    let plan = plan(dir.path(), size, 3);
    for part in ["1", "2"] {
        terramp_data(&["build", "--plan", path(&plan), "--partition", part]);
    }
    // Partition 0, killed once its part packs are being written.
    let mut job = terramp_testkit::command(env!("CARGO_BIN_EXE_terramp-data"))
        .args(["build", "--plan", path(&plan), "--partition", "0"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let parts = dir.path().join("plan.parts");
    let started = Instant::now();
    let writing = || {
        std::fs::read_dir(&parts).into_iter().flatten().flatten().any(|e| {
            let partial = e.file_name().to_string_lossy().starts_with(".part-00000.partial-");
            partial && std::fs::read_dir(e.path()).is_ok_and(|mut d| d.next().is_some())
        })
    };
    while !writing() {
        assert!(job.try_wait().unwrap().is_none(), "partition 0 finished before it could be killed");
        assert!(started.elapsed() < Duration::from_secs(300), "partition 0 never started writing");
        std::thread::sleep(Duration::from_millis(20));
    }
    job.kill().unwrap();
    job.wait().unwrap();
    assert!(!parts.join("part-00000").exists(), "a killed partition was taken for a finished one");
    let merged = dir.path().join("merged");
    let log = dask_build(&python, &plan, &merged);
    assert_eq!(log.matches("already built").count(), 2, "{log}");
    assert_eq!(log.matches("built in").count(), 1, "{log}");
    assert_same_dataset(&single, &merged);
}

/// Runs `terramp-data ARGS`, expecting it to fail; returns its stderr.
fn terramp_data_fails(args: &[&str]) -> String {
    let output = terramp_testkit::command(env!("CARGO_BIN_EXE_terramp-data")).args(args).output().unwrap();
    assert!(!output.status.success(), "terramp-data {} succeeded", args.join(" "));
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// Builds `inputs` (`build`'s arguments) in one process and as `partitions` jobs, in `dir`, and
/// checks that they are the same dataset; returns the plan's text.
fn geotiff_both_ways(dir: &Path, inputs: &[&str], partitions: u32) -> String {
    let single = dir.join("single");
    terramp_data(&[&["build"], inputs, &["--out", path(&single)]].concat());
    let plan = dir.join("plan.toml");
    let count = partitions.to_string();
    terramp_data(&[&["plan"], inputs, &["--partitions", &count, "--out", path(&plan)]].concat());
    for part in 0..partitions {
        terramp_data(&["build", "--plan", path(&plan), "--partition", &part.to_string()]);
    }
    let merged = dir.join("merged");
    terramp_data(&["merge", "--plan", path(&plan), "--out", path(&merged)]);
    assert_same_dataset(&single, &merged);
    std::fs::read_to_string(&plan).unwrap()
}

#[test]
fn geotiff_plans_merge_into_the_single_process_build() {
    let shared = std::path::absolute(shared_data().expect("../shared/data")).unwrap();
    let file = |f: &str| shared.join(f).to_str().unwrap().to_owned();
    let (nc_dem, landsat, landuse) =
        (file("nc/elev_ned_30m.tif"), file("nc/landsat_multiband.tif"), file("nc/landuse_r.tif"));
    let (zion_dem, nlcd, srtm) =
        (file("zion/dem_utm12n_30m.tif"), file("zion/nlcd2011.tif"), file("zion/srtm.tif"));

    // nc: all three layers on their own grids, the imagery stretched from 2 % to 98 %.
    let dir = TempDir::new("partitioned-nc");
    let args = [
        "--dem",
        &nc_dem,
        "--imagery",
        &landsat,
        "--bands",
        "3,2,1",
        "--landcover",
        &landuse,
        "--classes",
        "nc",
    ];
    let plan = geotiff_both_ways(dir.path(), &args, 3);
    assert!(plan.contains("kind = \"geotiff\"") && plan.contains("tone = \"stretch\""), "{plan}");

    // Zion: a DEM with 73,270 voids (the fill's coarse surface travels beside the plan, and the
    // validity mask is a fourth layer), the NLCD and a grey SRTM reprojected, imagery in BC7.
    let dir = TempDir::new("partitioned-zion");
    let args = [
        "--dem",
        &zion_dem,
        "--imagery",
        &srtm,
        "--landcover",
        &nlcd,
        "--classes",
        "nlcd",
        "--imagery-format",
        "bc7",
    ];
    let plan = geotiff_both_ways(dir.path(), &args, 4);
    assert!(
        plan.contains("name = \"height_valid\"") && dir.path().join("plan.coarse.bin").is_file(),
        "{plan}"
    );

    // SRTM in degrees: the DEM itself warped onto a local metric frame, voids beyond its edge.
    let dir = TempDir::new("partitioned-srtm");
    let args = ["--dem", &srtm, "--landcover", &nlcd, "--classes", "nlcd"];
    let plan = geotiff_both_ways(dir.path(), &args, 5);
    assert!(plan.contains("beyond_edge = 1111"), "{plan}");
}

#[test]
fn a_geotiff_job_refuses_inputs_changed_since_its_plan() {
    let shared = shared_data().expect("../shared/data");
    let dir = TempDir::new("partitioned-changed");
    let dem = dir.path().join("dem.tif");
    std::fs::copy(shared.join("zion/dem_utm12n_30m.tif"), &dem).unwrap();
    let plan = dir.path().join("plan.toml");
    terramp_data(&["plan", "--dem", path(&dem), "--partitions", "2", "--out", path(&plan)]);

    // The fill's coarse surface replaced: refused, nothing built.
    let coarse = dir.path().join("plan.coarse.bin");
    let good = std::fs::read(&coarse).unwrap();
    let mut bad = good.clone();
    *bad.last_mut().unwrap() ^= 1;
    std::fs::write(&coarse, &bad).unwrap();
    let stderr = terramp_data_fails(&["build", "--plan", path(&plan), "--partition", "0"]);
    assert!(stderr.contains("not the coarse surface the plan was made with"), "{stderr}");
    std::fs::write(&coarse, &good).unwrap();
    terramp_data(&["build", "--plan", path(&plan), "--partition", "0"]);

    // The DEM replaced by another file: the next job refuses it, naming it.
    std::fs::copy(shared.join("zion/srtm.tif"), &dem).unwrap();
    let stderr = terramp_data_fails(&["build", "--plan", path(&plan), "--partition", "1"]);
    assert!(stderr.contains("dem.tif") && stderr.contains("the input changed since"), "{stderr}");
    assert!(!dir.path().join("plan.parts/part-00001").exists());
}

//! Kill -9 anywhere: `terramp-data synth`, `build` and `bake` are killed with SIGKILL at spread
//! points of their run (from the first moments to just before they would finish), over an output
//! folder that already holds a finished result. After each kill the folder must be one whole
//! result, byte for byte the earlier one or the new one, never half of one, and it must load; a
//! later run in the same place must succeed and sweep what the killed ones left hidden beside it.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use terramp::dataset::{Dataset, Pack};
use terramp_testkit::data::{TempDir, shared_data};

/// Where in a run (as a fraction of a whole run's time) each kill lands.
const KILL_AT: [f64; 5] = [0.02, 0.2, 0.45, 0.7, 0.95];

/// Every file under `dir` (hidden ones excluded) and its bytes.
fn files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_owned()];
    while let Some(at) = stack.pop() {
        for entry in std::fs::read_dir(&at).unwrap().map(Result::unwrap) {
            if entry.file_name().to_string_lossy().starts_with('.') {
                continue;
            }
            if entry.file_type().unwrap().is_dir() {
                stack.push(entry.path());
            } else {
                out.insert(
                    entry.path().strip_prefix(dir).unwrap().to_owned(),
                    std::fs::read(entry.path()).unwrap(),
                );
            }
        }
    }
    out
}

fn run(args: &[String]) -> Duration {
    let started = Instant::now();
    let output = Command::new(env!("CARGO_BIN_EXE_terramp-data")).args(args).output().unwrap();
    let says = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "terramp-data {}: {says}", args.join(" "));
    started.elapsed()
}

/// Runs `args` and kills it `after`; whether it had finished by then.
fn run_killed(args: &[String], after: Duration) -> bool {
    let mut child = Command::new(env!("CARGO_BIN_EXE_terramp-data"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(after);
    let finished = child.try_wait().unwrap().is_some();
    child.kill().ok();
    child.wait().unwrap();
    finished
}

/// The two commands `a` and `b` (each given its output folder) write different results. Each is
/// first run whole into a folder of its own; then, over `out` holding `a`'s result, `b` and `a` by
/// turns are killed at every point of `KILL_AT`, and `out` must equal one of the two whole results
/// and pass `loads`; a last whole run must leave nothing hidden beside `out`.
fn kill_anywhere(
    name: &str,
    a: &dyn Fn(&Path) -> Vec<String>,
    b: &dyn Fn(&Path) -> Vec<String>,
    loads: &dyn Fn(&Path),
) {
    let dir = TempDir::new(name);
    let (ref_a, ref_b, out) = (dir.path().join("a"), dir.path().join("b"), dir.path().join("out"));
    let took = [run(&a(&ref_a)), run(&b(&ref_b))];
    let whole = [files(&ref_a), files(&ref_b)];
    assert_ne!(whole[0], whole[1], "{name}: the two commands must write different results");
    run(&a(&out));
    let mut killed_mid_run = 0;
    for (k, at) in KILL_AT.iter().enumerate() {
        let (command, took) = if k % 2 == 0 { (b(&out), took[1]) } else { (a(&out), took[0]) };
        let finished = run_killed(&command, took.mul_f64(*at));
        killed_mid_run += usize::from(!finished);
        let now = files(&out);
        assert!(
            now == whole[0] || now == whole[1],
            "{name}: killed at {:.0} % of a run, {} holds neither whole result: {:?}",
            at * 100.0,
            out.display(),
            now.keys().collect::<Vec<_>>()
        );
        loads(&out);
    }
    eprintln!("{name}: whole runs {took:?}; {killed_mid_run} of {} kills landed mid-run", KILL_AT.len());
    // Runs vary in length with the machine's load, so a late kill may come after the end.
    assert!(killed_mid_run >= 2, "{name}: only {killed_mid_run} of {} kills landed mid-run", KILL_AT.len());
    run(&b(&out));
    assert_eq!(files(&out), whole[1]);
    let hidden: Vec<_> = std::fs::read_dir(out.parent().unwrap())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "{name}: left beside the output after a whole run: {hidden:?}");
}

/// The dataset opens, and every tile of every pack reads back (checksums, sizes, decoding).
fn dataset_loads(dir: &Path) {
    Dataset::open(dir).unwrap();
    for entry in std::fs::read_dir(dir).unwrap().map(Result::unwrap) {
        if entry.path().extension().is_some_and(|e| e == "pack") {
            let pack = Pack::open(&entry.path()).unwrap();
            for i in 0..pack.tile_count() {
                pack.tile(i).unwrap();
            }
        }
    }
}

fn strings(args: &[&str]) -> Vec<String> {
    args.iter().map(|s| (*s).to_owned()).collect()
}

#[test]
fn a_synth_killed_anywhere_leaves_a_whole_dataset() {
    let synth = |seed: &'static str| {
        move |out: &Path| strings(&["synth", "--size", "500", "--seed", seed, "--out", out.to_str().unwrap()])
    };
    kill_anywhere("kill9-synth", &synth("1"), &synth("2"), &dataset_loads);
}

#[test]
fn a_build_killed_anywhere_leaves_a_whole_dataset() {
    let nc = shared_data().expect("../shared/data").join("nc");
    let arg = |f: &str| nc.join(f).to_str().unwrap().to_owned();
    let dem_only = |out: &Path| {
        vec![
            "build".into(),
            "--dem".into(),
            arg("elev_ned_30m.tif"),
            "--out".into(),
            out.to_str().unwrap().into(),
        ]
    };
    let trio = |out: &Path| {
        let mut args = dem_only(out);
        args.extend(["--imagery".into(), arg("landsat_multiband.tif"), "--bands".into(), "3,2,1".into()]);
        args.extend(["--landcover".into(), arg("landuse_r.tif"), "--classes".into(), "nc".into()]);
        args
    };
    kill_anywhere("kill9-build", &dem_only, &trio, &dataset_loads);
}

#[test]
fn a_bake_killed_anywhere_leaves_a_whole_impostor() {
    let models = shared_data().expect("../shared/data").join("models");
    let bake = |texels: &'static str| {
        let model = models.join("Bush_1.glb").to_str().unwrap().to_owned();
        move |out: &Path| {
            let out = out.to_str().unwrap().to_owned();
            strings(&["bake", "--model", &model, "--texels", texels, "--planes", "4,2,1", "--out", &out])
        }
    };
    let loads = |out: &Path| {
        terramp::impostor::load(out, "Bush_1").unwrap();
    };
    kill_anywhere("kill9-bake", &bake("128"), &bake("256"), &loads);
}

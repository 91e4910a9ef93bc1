//! A dataset changed on disk under a running `terramp fly`: its three packs cut short (as `cp`
//! over them does first), or rewritten in place with another dataset's (as `rsync --inplace`
//! does), a few frames into the flight. The flight goes on to its last frame and exits 0; every
//! tile read after the change fails, is named once on stderr, and its ancestor stands in. With
//! the packs memory-mapped, the cut was a SIGBUS: "Bus error", exit status 135.
#![allow(clippy::unwrap_used, reason = "tests")]

use std::io::Read;
use std::os::unix::fs::FileExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const SIZE: u32 = 512;
const FRAMES: u32 = 24;
/// The frame whose PNG, once written, says the flight is under way: the change comes after it.
const CHANGE_AFTER_FRAME: u32 = 2;
const PACKS: [&str; 3] = ["height.pack", "imagery.pack", "landcover.pack"];

/// A private copy of `from`, to change under the flight.
fn copy_dataset(from: &Path, name: &str) -> PathBuf {
    let to =
        Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("pack-changed-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&to);
    std::fs::create_dir_all(&to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        std::fs::copy(entry.path(), to.join(entry.file_name())).unwrap();
    }
    to
}

/// What a flight whose dataset `change` altered after frame `CHANGE_AFTER_FRAME` gave, once it
/// exited 0.
struct Flown {
    stderr: String,
    /// Frames in the flight's log.
    logged: usize,
    /// Tiles its log counts failed, all frames and layers together.
    failed: u64,
}

fn fly_and_change(name: &str, change: impl FnOnce(&Path)) -> Flown {
    let dataset = copy_dataset(&terramp_testkit::synth_dataset(SIZE, 5), name);
    let out = dataset.with_extension("out");
    let _ = std::fs::remove_dir_all(&out);
    // Low across the 5 km dataset, looking ahead: new tiles every frame.
    let path = dataset.with_extension("path.toml");
    std::fs::write(
        &path,
        "[[key]]\nat = [600.0, 600.0, 250.0]\nyaw_deg = 45.0\npitch_deg = -25.0\n\
         [[key]]\nat = [4400.0, 4400.0, 250.0]\nyaw_deg = 45.0\npitch_deg = -25.0\n",
    )
    .unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_terramp"))
        .args([
            "fly",
            "--frames",
            &FRAMES.to_string(),
            "--save-every",
            "1",
            "--width",
            "160",
            "--height",
            "90",
        ])
        .arg("--dataset")
        .arg(&dataset)
        .arg("--path")
        .arg(&path)
        .arg("--out")
        .arg(&out)
        .stderr(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let mut pipe = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut text = String::new();
        pipe.read_to_string(&mut text).unwrap();
        text
    });
    // A guard against a hang, not a measure: the frame's file decides.
    let started = Instant::now();
    let marker = out.join(format!("frame_{CHANGE_AFTER_FRAME:04}.png"));
    while !marker.exists() {
        assert!(child.try_wait().unwrap().is_none(), "the flight ended before frame {CHANGE_AFTER_FRAME}");
        assert!(started.elapsed() < Duration::from_secs(300), "no frame {CHANGE_AFTER_FRAME} after 300 s");
        std::thread::sleep(Duration::from_millis(20));
    }
    change(&dataset);
    let status = child.wait().unwrap();
    let stderr = reader.join().unwrap();
    let tail: Vec<&str> = stderr.lines().rev().take(5).collect();
    assert!(status.success(), "{name}: the flight ended with {status:?}; the end of its stderr: {tail:?}");
    let log = std::fs::read_to_string(out.join("log.jsonl")).unwrap_or_default();
    let mut failed = 0;
    for line in log.lines() {
        let record: serde_json::Value = serde_json::from_str(line).unwrap();
        for layer in ["height", "imagery", "landcover"] {
            failed += record["report"][layer]["failed"].as_u64().unwrap_or(0);
        }
    }
    let logged = log.lines().count();
    let _ = std::fs::remove_dir_all(&out);
    let _ = std::fs::remove_dir_all(&dataset);
    Flown { stderr, logged, failed }
}

/// The flight survived the change: every frame flown and logged, and tiles read after
/// the change failed, each named once with the pack and why.
fn assert_survived(name: &str, flown: &Flown) {
    let Flown { stderr, logged, failed } = flown;
    assert_eq!(*logged, FRAMES as usize, "{name}: frames logged");
    let changed: Vec<&str> =
        stderr.lines().filter(|l| l.contains("changed on disk since it was opened")).collect();
    assert!(!changed.is_empty(), "{name}: no tile read after the change; stderr:\n{stderr}");
    for line in &changed {
        assert!(
            line.starts_with("terramp: ")
                && line.contains("unusable, its ancestor stands in")
                && PACKS.iter().any(|p| line.contains(p)),
            "{name}: {line}"
        );
    }
    let mut unique = changed.clone();
    unique.sort_unstable();
    unique.dedup();
    assert_eq!(unique.len(), changed.len(), "{name}: a tile reported twice");
    // Every failure the log counts is one reported (the flight has no other fault); a read that
    // failed after the last frame is reported and never counted.
    let reported = stderr.lines().filter(|l| l.contains("unusable, its ancestor stands in")).count();
    assert!(
        *failed > 0 && *failed <= reported as u64,
        "{name}: {failed} failures logged, {reported} reported"
    );
    eprintln!("{name}: {} tiles read after the change failed; {failed} counted in the log", changed.len());
}

#[test]
fn a_flight_whose_packs_are_cut_short_goes_on_with_those_tiles_failed() {
    let flown = fly_and_change("cut", |dataset| {
        for pack in PACKS {
            let file = std::fs::OpenOptions::new().write(true).open(dataset.join(pack)).unwrap();
            let bytes = file.metadata().unwrap().len();
            file.set_len(bytes / 3).unwrap();
        }
    });
    assert_survived("cut short", &flown);
}

#[test]
fn a_flight_whose_packs_are_rewritten_in_place_goes_on_with_those_tiles_failed() {
    let other = terramp_testkit::synth_dataset(SIZE, 6);
    let flown = fly_and_change("rewritten", |dataset| {
        for pack in PACKS {
            // As `rsync --inplace`: the new bytes over the old from the start, then the length.
            let bytes = std::fs::read(other.join(pack)).unwrap();
            let file = std::fs::OpenOptions::new().write(true).open(dataset.join(pack)).unwrap();
            file.write_all_at(&bytes, 0).unwrap();
            file.set_len(bytes.len() as u64).unwrap();
        }
    });
    assert_survived("rewritten in place", &flown);
}

//! Kill -9 at each step of publishing. `terramp-data synth`, `build` and `bake` put their result in
//! place through `terramp::publish`; here each is stopped at one `publish::Step` (the test-only
//! `TERRAMP_TEST_PUBLISH_STOP`: the process stops itself there and says so) and killed with
//! SIGKILL, with the exchange (`renameat2`) and with the fallback forced
//! (`TERRAMP_TEST_PUBLISH_NO_EXCHANGE`). The points covered, each one kill:
//! - into an empty place: `written` (all written, nothing published) and `placed` (renamed in);
//! - over a finished result, before either path starts: `begun` (staging folder made, empty) and
//!   `written`;
//! - with the exchange: `placed` (exchanged, old folder not yet removed) and `done` (removed);
//! - with the fallback: `aside` (old folder renamed aside, the name empty), `placed` (new folder
//!   renamed in), `retired` (old folder back under the staging name) and `done`.
//!
//! After each kill the final name must hold exactly what that step leaves, byte for byte: the old
//! whole result before the new one is in place, the new whole one after, nothing only at the
//! fallback's `aside`; the hidden folders beside it must be exactly those the step leaves (the
//! staging folder, empty or whole; the old result, whole); and the output must load. Then a next
//! run, stopped at `begun`, must find a whole result at the name (an old one left aside put back)
//! and nothing hidden but its own empty staging folder. Not killed there: between `begun` and
//! `written` (the command writing into its staging folder; `written` shows the name untouched by
//! then) and during the removal of an old folder (emulated: half of the old folder's files are
//! removed before the next run, which must sweep the rest). A last whole run must succeed and
//! leave nothing hidden.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::collections::BTreeMap;
use std::io::{BufRead as _, BufReader};
use std::path::{Path, PathBuf};
use std::process::Stdio;

use terramp::dataset::{Dataset, Pack};
use terramp::publish::{NO_EXCHANGE_VAR, STOP_VAR, Step};
use terramp_testkit::data::{TempDir, shared_data};

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

fn run(args: &[String]) {
    let output = terramp_testkit::command(env!("CARGO_BIN_EXE_terramp-data")).args(args).output().unwrap();
    let says = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "terramp-data {}: {says}", args.join(" "));
}

/// Runs `args` until it stops itself at `step` (the fallback forced where `fallback`), kills it
/// with SIGKILL there, and returns its process id (which names its staging folder).
fn run_killed_at(args: &[String], step: Step, fallback: bool) -> u32 {
    let mut command = terramp_testkit::command(env!("CARGO_BIN_EXE_terramp-data"));
    command.args(args).env(STOP_VAR, step.name()).stdout(Stdio::null()).stderr(Stdio::piped());
    if fallback {
        command.env(NO_EXCHANGE_VAR, "1");
    }
    let mut child = command.spawn().unwrap();
    let stopped = format!("publish: stopped at {}", step.name());
    let mut said = Vec::new();
    for line in BufReader::new(child.stderr.take().unwrap()).lines() {
        let line = line.unwrap();
        if line == stopped {
            // Past this line the process only raises SIGSTOP: it changes nothing before the kill.
            child.kill().unwrap();
            child.wait().unwrap();
            return child.id();
        }
        said.push(line);
    }
    let status = child.wait().unwrap();
    panic!("terramp-data {} ended ({status}) without reaching `{}`: {said:?}", args.join(" "), step.name());
}

/// What a folder holds: nothing, or one of the two whole results.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Holds {
    Empty,
    Whole(usize),
}

/// One command's two results, what it writes where, and how to check a result loads.
struct Case<'a> {
    name: &'a str,
    /// The arguments that write result `0` or `1` into the folder given.
    args: &'a dyn Fn(usize, &Path) -> Vec<String>,
    /// The name under that folder the result takes.
    out_name: &'a str,
    loads: &'a dyn Fn(&Path),
}

struct Kills<'a> {
    case: Case<'a>,
    whole: [BTreeMap<PathBuf, Vec<u8>>; 2],
    place: PathBuf,
    out: PathBuf,
    /// The whole result the output holds, if any.
    now: Option<usize>,
    /// The steps killed at so far.
    killed: Vec<Step>,
}

impl Kills<'_> {
    /// The hidden entries beside the output, by name.
    fn hidden(&self) -> BTreeMap<String, PathBuf> {
        std::fs::read_dir(&self.place)
            .unwrap()
            .map(|e| e.unwrap())
            .filter(|e| e.file_name().to_string_lossy().starts_with('.'))
            .map(|e| (e.file_name().to_string_lossy().into_owned(), e.path()))
            .collect()
    }

    fn staging_name(&self, pid: u32) -> String {
        format!(".{}.partial-{pid}", self.case.out_name)
    }

    fn check_folder(&self, what: &str, path: &Path, holds: Holds) {
        let found = files(path);
        match holds {
            Holds::Empty => assert!(found.is_empty(), "{what}: expected empty, holds {:?}", found.keys()),
            Holds::Whole(i) => assert!(
                found == self.whole[i],
                "{what}: expected whole result {i}, holds {:?}",
                found.keys().collect::<Vec<_>>()
            ),
        }
    }

    /// The output holds `out` (none: absent) and beside it exactly the hidden folders `hidden`.
    fn check(&self, at: &str, out: Option<usize>, hidden: &[(String, Holds)]) {
        match out {
            None => assert!(!self.out.exists(), "{at}: {} should be absent", self.out.display()),
            Some(i) => {
                assert!(
                    self.out.is_dir(),
                    "{at}: {} is absent, expected whole result {i}",
                    self.out.display()
                );
                self.check_folder(&format!("{at}: {}", self.out.display()), &self.out, Holds::Whole(i));
                (self.case.loads)(&self.out);
            }
        }
        let found = self.hidden();
        let names: Vec<&String> = found.keys().collect();
        let expected: Vec<&String> = hidden.iter().map(|(n, _)| n).collect();
        assert_eq!(names, expected, "{at}: hidden beside {}", self.out.display());
        for (name, holds) in hidden {
            self.check_folder(&format!("{at}: {name}"), &found[name], *holds);
        }
    }

    /// Kills a run of the result the output does not hold at `step`, checks what it left (`out`
    /// and `hidden` from the old result's index, the new one's and the killed run's staging
    /// name), then stops a next run at `begun` and checks it found a whole result and left only its
    /// own staging folder.
    fn kill(
        &mut self,
        step: Step,
        fallback: bool,
        expect: impl Fn(Option<usize>, usize, &str) -> (Option<usize>, Vec<(String, Holds)>),
    ) {
        let new = self.now.map_or(0, |old| 1 - old);
        let at = format!(
            "{}: killed at `{}` ({}), writing {new} over {:?}",
            self.case.name,
            step.name(),
            if fallback { "fallback" } else { "exchange" },
            self.now
        );
        let pid = run_killed_at(&(self.case.args)(new, &self.place), step, fallback);
        self.killed.push(step);
        let (out, hidden) = expect(self.now, new, &self.staging_name(pid));
        self.check(&at, out, &hidden);
        // A kill while the old folder is being removed leaves part of it: emulated by removing
        // half of its files (the old folder is under the staging name at `placed` with the
        // exchange and at `retired`).
        let staging = self.place.join(self.staging_name(pid));
        if out == Some(new) && staging.exists() {
            for (k, file) in files(&staging).keys().enumerate() {
                if k % 2 == 0 {
                    std::fs::remove_file(staging.join(file)).unwrap();
                }
            }
        }
        // The folder a kill at the fallback's `aside` left aside goes back to the name.
        let whole = out.or(self.now);
        let next = run_killed_at(&(self.case.args)(new, &self.place), Step::Begun, false);
        let staging = self.staging_name(next);
        self.check(&format!("{at}; then the next run begun"), whole, &[(staging, Holds::Empty)]);
        self.now = whole;
    }
}

/// Kills runs of `case` at each step of publishing (see the module's comment).
fn kill_at_every_step(case: Case<'_>) {
    let dir = TempDir::new(case.name);
    let refs = [dir.path().join("a"), dir.path().join("b")];
    for (i, place) in refs.iter().enumerate() {
        run(&(case.args)(i, place));
    }
    let whole = refs.clone().map(|place| files(&place.join(case.out_name)));
    assert!(!whole[0].is_empty(), "{}: the result must hold files", case.name);
    assert_ne!(whole[0], whole[1], "{}: the two results must differ", case.name);
    let place = dir.path().join("run");
    let out = place.join(case.out_name);
    let mut kills = Kills { case, whole, place, out, now: None, killed: Vec::new() };
    let keep = |s: &str, h: Holds| (s.to_owned(), h);
    let aside = |s: &str| format!("{s}-old");
    // Into an empty place.
    kills.kill(Step::Written, false, |old, new, s| (old, vec![keep(s, Holds::Whole(new))]));
    kills.kill(Step::Placed, false, |_, new, _| (Some(new), vec![]));
    // Over a whole result, before the exchange or the fallback starts.
    kills.kill(Step::Begun, false, |old, _, s| (old, vec![keep(s, Holds::Empty)]));
    kills.kill(Step::Written, false, |old, new, s| (old, vec![keep(s, Holds::Whole(new))]));
    // The exchange.
    kills.kill(Step::Placed, false, |old, new, s| (Some(new), vec![keep(s, Holds::Whole(old.unwrap()))]));
    kills.kill(Step::Done, false, |_, new, _| (Some(new), vec![]));
    // The fallback.
    kills.kill(Step::Aside, true, |old, new, s| {
        (None, vec![keep(s, Holds::Whole(new)), (aside(s), Holds::Whole(old.unwrap()))])
    });
    kills.kill(Step::Placed, true, |old, new, s| (Some(new), vec![(aside(s), Holds::Whole(old.unwrap()))]));
    kills.kill(Step::Retired, true, |old, new, s| (Some(new), vec![keep(s, Holds::Whole(old.unwrap()))]));
    kills.kill(Step::Done, true, |_, new, _| (Some(new), vec![]));
    let missed: Vec<_> = Step::ALL.iter().filter(|s| !kills.killed.contains(s)).collect();
    assert!(missed.is_empty(), "steps of publishing never killed at: {missed:?}");
    let new = 1 - kills.now.unwrap();
    run(&(kills.case.args)(new, &kills.place));
    kills.check(&format!("{}: a whole run", kills.case.name), Some(new), &[]);
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
fn a_synth_killed_at_each_step_of_publishing_leaves_a_whole_dataset() {
    let args = |i: usize, place: &Path| {
        let out = place.join("out");
        strings(&["synth", "--size", "128", "--seed", ["1", "2"][i], "--out", out.to_str().unwrap()])
    };
    kill_at_every_step(Case { name: "kill9-synth", args: &args, out_name: "out", loads: &dataset_loads });
}

#[test]
fn a_build_killed_at_each_step_of_publishing_leaves_a_whole_dataset() {
    let Some(data) = shared_data() else { return };
    let dem = data.join("nc/elev_ned_30m.tif").to_str().unwrap().to_owned();
    // The DEM alone, its heights stored exactly or quantised: two results of the smallest build.
    let args = |i: usize, place: &Path| {
        let out = place.join("out").to_str().unwrap().to_owned();
        let mut args = strings(&["build", "--dem", &dem, "--out", &out]);
        if i == 1 {
            args.extend(strings(&["--height-step-m", "0.5"]));
        }
        args
    };
    kill_at_every_step(Case { name: "kill9-build", args: &args, out_name: "out", loads: &dataset_loads });
}

#[test]
fn a_bake_killed_at_each_step_of_publishing_leaves_a_whole_impostor() {
    let Some(data) = shared_data() else { return };
    let model = data.join("models/Bush_1.glb").to_str().unwrap().to_owned();
    let args = |i: usize, place: &Path| {
        let out = place.to_str().unwrap();
        strings(&[
            "bake",
            "--model",
            &model,
            "--texels",
            ["128", "256"][i],
            "--planes",
            "4,2,1",
            "--out",
            out,
        ])
    };
    let loads = |out: &Path| {
        terramp::impostor::load(out.parent().unwrap(), "Bush_1").unwrap();
    };
    kill_at_every_step(Case { name: "kill9-bake", args: &args, out_name: "Bush_1", loads: &loads });
}

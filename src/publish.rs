//! How it works: everything the tools publish (a dataset, a partition's part folder, an impostor,
//! a forest sample, a truth) is a folder written under a hidden name beside its final place,
//! `.NAME.partial-PID` (`begin_staging`), then put in place by `publish`. Where a folder already
//! stands there, the two are exchanged by one `renameat2(RENAME_EXCHANGE)`, so the final name
//! holds the old complete folder or the new complete one at every instant; the old one, now under
//! the hidden name, is removed afterwards. Where the exchange is not available (not Linux, or a
//! file system without it) the fallback takes three renames: the old folder aside to
//! `.NAME.partial-PID-old`, the new one into place, the old one back to the hidden staging name to
//! be removed. A kill between the first two leaves the name empty (never half-written), the old
//! whole folder at the aside; the next `begin_staging` there puts it back before anything else.
//! Any other hidden folder beside the name is what a killed run left (a staging folder, whole or
//! not, or an old folder, whole or half-removed) and `begin_staging` sweeps it.
//!
//! Test-only hooks, for `data-tools/tests/kill9.rs` to kill a process at each `Step` of
//! publishing: `TERRAMP_TEST_PUBLISH_STOP=STEP` makes a process that reaches that step print
//! `publish: stopped at STEP` on stderr and stop itself (SIGSTOP), and
//! `TERRAMP_TEST_PUBLISH_NO_EXCHANGE` (any value) makes the exchange report itself unsupported, so
//! the fallback runs. Both are read only while publishing (a few reads of the environment per
//! folder, beside the renames and removals); nothing sets them but those tests.

use std::ffi::OsString;
use std::fs;
use std::io;
use std::path::{Path, PathBuf};

/// Test only: the `Step` (by `Step::name`) at which a publishing process stops itself.
pub const STOP_VAR: &str = "TERRAMP_TEST_PUBLISH_STOP";
/// Test only: when set, the exchange reports itself unsupported and the fallback runs.
pub const NO_EXCHANGE_VAR: &str = "TERRAMP_TEST_PUBLISH_NO_EXCHANGE";

/// The points of publishing a test can stop a process at, in order, with what the file system
/// holds there (`NAME` the final name, `S` the staging folder `.NAME.partial-PID`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// `begin_staging` has put back a whole folder a killed fallback left aside, swept the other
    /// hidden leftovers and made `S`, empty. `NAME` as it was.
    Begun,
    /// `S` is complete; `publish` has not started. `NAME` as it was.
    Written,
    /// Fallback only: the old `NAME` renamed aside to `S-old`; `NAME` is empty.
    Aside,
    /// The new folder holds `NAME`. When an old one stood there, it is whole and hidden: at `S`
    /// after the exchange, at `S-old` in the fallback.
    Placed,
    /// Fallback only: the old folder moved from `S-old` to `S` (where the exchange leaves it).
    Retired,
    /// The old folder removed: nothing hidden is left.
    Done,
}

impl Step {
    /// Every step, in order.
    pub const ALL: [Self; 6] =
        [Self::Begun, Self::Written, Self::Aside, Self::Placed, Self::Retired, Self::Done];

    /// The step's name, as `STOP_VAR` takes it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Begun => "begun",
            Self::Written => "written",
            Self::Aside => "aside",
            Self::Placed => "placed",
            Self::Retired => "retired",
            Self::Done => "done",
        }
    }
}

/// Test only: stops this process at `step` when `STOP_VAR` names it.
fn reached(step: Step) {
    if std::env::var_os(STOP_VAR).is_some_and(|at| at == step.name()) {
        eprintln!("publish: stopped at {}", step.name());
        stop_self();
    }
}

#[cfg(target_os = "linux")]
fn stop_self() {
    // SAFETY: raising a signal has no memory-safety preconditions; SIGSTOP halts every thread
    // until the test kills the process (or continues it).
    unsafe {
        libc::raise(libc::SIGSTOP);
    }
}

#[cfg(not(target_os = "linux"))]
fn stop_self() {
    loop {
        std::thread::park();
    }
}

/// `staging` with `-old` appended: where the fallback puts the old folder aside.
fn aside_of(staging: &Path) -> PathBuf {
    let mut aside = OsString::from(staging.as_os_str());
    aside.push("-old");
    PathBuf::from(aside)
}

/// A new, empty hidden folder beside `out` (`.NAME.partial-PID`) for this process to write what
/// will take `out`'s place. First, where `out` is missing and a killed fallback left the old
/// folder aside, that whole folder goes back to `out`; then every other hidden folder under that
/// prefix is swept (nothing else writes under it: one publisher per `out` at a time). On failure,
/// the path that failed with the error.
pub fn begin_staging(out: &Path) -> Result<PathBuf, (PathBuf, io::Error)> {
    let parent = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_owned(),
        _ => PathBuf::from("."),
    };
    let name = out.file_name().map_or_else(|| "out".into(), |n| n.to_string_lossy().into_owned());
    let at = |path: &Path| {
        let path = path.to_owned();
        move |e| (path, e)
    };
    fs::create_dir_all(&parent).map_err(at(&parent))?;
    let prefix = format!(".{name}.partial-");
    let leftovers = || -> Result<Vec<PathBuf>, (PathBuf, io::Error)> {
        let entries = fs::read_dir(&parent).map_err(at(&parent))?.flatten();
        Ok(entries
            .filter(|e| e.file_name().to_string_lossy().starts_with(&prefix))
            .map(|e| e.path())
            .collect())
    };
    if !out.exists()
        && let Some(aside) = leftovers()?.into_iter().find(|p| p.to_string_lossy().ends_with("-old"))
    {
        fs::rename(&aside, out).map_err(at(&aside))?;
    }
    for leftover in leftovers()? {
        let _ = fs::remove_dir_all(leftover);
    }
    let staging = parent.join(format!("{prefix}{}", std::process::id()));
    fs::create_dir_all(&staging).map_err(at(&staging))?;
    reached(Step::Begun);
    Ok(staging)
}

/// Puts the complete folder `staging` (from `begin_staging`) at `out` and removes the folder `out`
/// held before, if any. On failure, the path that failed with the error. Where the new folder did
/// not take the name, `out` holds the old one (if the fallback's second rename fails, the old one
/// is put back, or failing that, left aside for the next `begin_staging`); where it did, the old
/// one is left hidden for the next `begin_staging` to sweep.
pub fn publish(staging: &Path, out: &Path) -> Result<(), (PathBuf, io::Error)> {
    reached(Step::Written);
    let old = swap_into_place(staging, out).map_err(|e| (out.to_owned(), e))?;
    if let Some(old) = old {
        fs::remove_dir_all(&old).map_err(|e| (old.clone(), e))?;
    }
    reached(Step::Done);
    Ok(())
}

/// Puts the folder `staging` at `out`. Returns where the folder `out` held before now is (the
/// staging name), `None` when `out` was empty.
fn swap_into_place(staging: &Path, out: &Path) -> io::Result<Option<PathBuf>> {
    if !out.exists() {
        fs::rename(staging, out)?;
        reached(Step::Placed);
        return Ok(None);
    }
    let exchanged =
        if std::env::var_os(NO_EXCHANGE_VAR).is_some() { Err(unsupported()) } else { exchange(staging, out) };
    match exchanged {
        Ok(()) => {
            reached(Step::Placed);
            return Ok(Some(staging.to_owned()));
        }
        Err(e) if !matches!(e.raw_os_error(), Some(code) if is_unsupported(code)) => return Err(e),
        Err(_) => {}
    }
    let aside = aside_of(staging);
    fs::rename(out, &aside)?;
    reached(Step::Aside);
    if let Err(e) = fs::rename(staging, out) {
        // Put the old folder back rather than leave the name empty; failing that, the next
        // `begin_staging` does.
        let _ = fs::rename(&aside, out);
        return Err(e);
    }
    reached(Step::Placed);
    // Back to the staging name, so that a folder at `-old` is always whole: `begin_staging` puts
    // one back only where `out` is missing, and an old folder half-removed is never at `-old`.
    fs::rename(&aside, staging)?;
    reached(Step::Retired);
    Ok(Some(staging.to_owned()))
}

#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> io::Result<()> {
    use std::ffi::CString;
    use std::os::unix::ffi::OsStrExt;
    let path = |p: &Path| CString::new(p.as_os_str().as_bytes()).map_err(io::Error::other);
    let (a, b) = (path(a)?, path(b)?);
    // SAFETY: both are valid NUL-terminated paths for the duration of the call; AT_FDCWD
    // resolves them like `rename` does.
    let status = unsafe {
        libc::renameat2(libc::AT_FDCWD, a.as_ptr(), libc::AT_FDCWD, b.as_ptr(), libc::RENAME_EXCHANGE)
    };
    if status == 0 { Ok(()) } else { Err(io::Error::last_os_error()) }
}

#[cfg(target_os = "linux")]
fn unsupported() -> io::Error {
    io::Error::from_raw_os_error(libc::EINVAL)
}

#[cfg(target_os = "linux")]
fn is_unsupported(code: i32) -> bool {
    code == libc::EINVAL || code == libc::ENOSYS || code == libc::EOPNOTSUPP
}

#[cfg(not(target_os = "linux"))]
fn exchange(_: &Path, _: &Path) -> io::Result<()> {
    Err(unsupported())
}

#[cfg(not(target_os = "linux"))]
const UNSUPPORTED: i32 = 38;

#[cfg(not(target_os = "linux"))]
fn unsupported() -> io::Error {
    io::Error::from_raw_os_error(UNSUPPORTED)
}

#[cfg(not(target_os = "linux"))]
fn is_unsupported(code: i32) -> bool {
    code == UNSUPPORTED
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_folder_takes_the_place_of_another_and_the_old_one_is_removed() {
        let dir = std::env::temp_dir().join(format!("terramp-publish-{}", std::process::id()));
        let out = dir.join("out");
        for v in ["1", "2"] {
            let staging = begin_staging(&out).unwrap();
            std::fs::write(staging.join("v"), v).unwrap();
            publish(&staging, &out).unwrap();
            assert_eq!(std::fs::read_to_string(out.join("v")).unwrap(), v);
            assert!(!staging.exists(), "the old folder is removed");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_whole_folder_left_aside_goes_back_and_other_leftovers_are_swept() {
        let dir = std::env::temp_dir().join(format!("terramp-publish-aside-{}", std::process::id()));
        let out = dir.join("out");
        let aside = dir.join(".out.partial-1-old");
        std::fs::create_dir_all(&aside).unwrap();
        std::fs::write(aside.join("v"), "old").unwrap();
        std::fs::create_dir_all(dir.join(".out.partial-1")).unwrap();
        let staging = begin_staging(&out).unwrap();
        assert_eq!(std::fs::read_to_string(out.join("v")).unwrap(), "old");
        let hidden: Vec<_> =
            std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).filter(|p| *p != out).collect();
        assert_eq!(hidden, [staging], "only this run's staging folder is left hidden");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

//! How it works: everything the tools publish (a dataset, an impostor, a forest sample) is a
//! folder written under a hidden name beside its final place (`begin_staging`) and then put in
//! place by `swap_into_place`. Where a folder already stands there, the two are exchanged by one
//! `renameat2(RENAME_EXCHANGE)`: at every instant the final name holds either the old complete
//! folder or the new complete one, so a process killed anywhere (even between the steps of
//! publishing) never leaves the name empty or half-written; the old folder, now under the hidden
//! name, is removed afterwards, or swept by the next build if the process dies first. Where the
//! exchange is not available (not Linux, or a file system without it) the old folder is renamed
//! aside first, and a kill between the two renames leaves the name empty (never half-written).

use std::fs;
use std::io;
use std::path::{Path, PathBuf};

/// A new, empty hidden folder beside `out` (`.NAME.partial-PID`) for this process to write what
/// will take `out`'s place; the ones killed runs left there are swept first (nothing else writes
/// under that name). On failure, the path that failed with the error.
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
    for entry in fs::read_dir(&parent).map_err(at(&parent))?.flatten() {
        if entry.file_name().to_string_lossy().starts_with(&prefix) {
            let _ = fs::remove_dir_all(entry.path());
        }
    }
    let staging = parent.join(format!("{prefix}{}", std::process::id()));
    fs::create_dir_all(&staging).map_err(at(&staging))?;
    Ok(staging)
}

/// Puts the folder `staging` at `out`. Returns where the folder `out` held before now is (to be
/// removed by the caller), `None` when `out` was empty.
pub fn swap_into_place(staging: &Path, out: &Path) -> io::Result<Option<PathBuf>> {
    if !out.exists() {
        fs::rename(staging, out)?;
        return Ok(None);
    }
    match exchange(staging, out) {
        Ok(()) => return Ok(Some(staging.to_owned())),
        Err(e) if !matches!(e.raw_os_error(), Some(code) if is_unsupported(code)) => return Err(e),
        Err(_) => {}
    }
    let mut aside = staging.as_os_str().to_owned();
    aside.push("-old");
    let aside = PathBuf::from(aside);
    fs::rename(out, &aside)?;
    fs::rename(staging, out)?;
    Ok(Some(aside))
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
fn is_unsupported(code: i32) -> bool {
    code == libc::EINVAL || code == libc::ENOSYS || code == libc::EOPNOTSUPP
}

#[cfg(not(target_os = "linux"))]
fn exchange(_: &Path, _: &Path) -> io::Result<()> {
    Err(io::Error::from_raw_os_error(UNSUPPORTED))
}

#[cfg(not(target_os = "linux"))]
const UNSUPPORTED: i32 = 38;

#[cfg(not(target_os = "linux"))]
fn is_unsupported(code: i32) -> bool {
    code == UNSUPPORTED
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_folder_takes_the_place_of_another_and_hands_the_old_one_back() {
        let dir = std::env::temp_dir().join(format!("terramp-publish-{}", std::process::id()));
        let (staging, out) = (dir.join(".out.partial"), dir.join("out"));
        std::fs::create_dir_all(&staging).unwrap();
        std::fs::write(staging.join("v"), "1").unwrap();
        assert_eq!(swap_into_place(&staging, &out).unwrap(), None);
        std::fs::create_dir_all(&staging).unwrap();
        std::fs::write(staging.join("v"), "2").unwrap();
        let old = swap_into_place(&staging, &out).unwrap().unwrap();
        assert_eq!(std::fs::read_to_string(out.join("v")).unwrap(), "2");
        assert_eq!(std::fs::read_to_string(old.join("v")).unwrap(), "1");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

//! `cargo xtask`: README's two commands on a fresh machine (the `xtask` convention: a workspace
//! binary that `.cargo/config.toml` aliases, built from std alone, so it runs before anything that
//! needs a system library is compiled).
//!
//! How it works: each command has a list of what it needs from the system beyond Rust (a C and
//! C++ compiler for the crates that build C, the Vulkan loader and a Vulkan driver, and for the
//! tests GDAL, an X server and the tools that drive it, Python's venv for Dask), each with a check
//! that looks for the thing itself (a program on PATH, a library the dynamic linker knows, a Vulkan
//! driver manifest) rather than for a package. What is missing is installed with apt-get when the
//! machine has it and we may (root, or sudo without a password); otherwise the command stops and
//! prints the exact command to run. Then it runs the real thing: `cargo run --release -- demo`, or
//! the workspace's tests with the environment CI uses.
//!
//!   cargo xtask demo [ARGS...]     the demo (ARGS go to `terramp demo`)
//!   cargo xtask test [ARGS...]     every test (ARGS go to `cargo test --workspace`)
//!   cargo xtask setup [demo|test]  only check and install what that command needs (default: test)
//!   cargo xtask dist               the release binaries to ship, in target/dist: each without its
//!                                  debug info, which goes to a `.debug` file beside it that
//!                                  backtraces read for file and line (GNU debuglink)

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};

/// Something a command needs from the system, how to tell it is there, and the Debian/Ubuntu
/// packages that provide it.
struct Need {
    what: &'static str,
    present: fn() -> bool,
    packages: &'static [&'static str],
}

/// What `cargo run --release -- demo` needs: the crates that build C and C++ (zstd, NVIDIA's FLIP),
/// and a Vulkan adapter (a GPU's driver, or Mesa's software rasteriser, lavapipe).
const DEMO: &[Need] = &[
    Need { what: "a C compiler (cc)", present: || on_path("cc"), packages: &["gcc", "libc6-dev"] },
    Need { what: "a C++ compiler (c++)", present: || on_path("c++"), packages: &["g++"] },
    Need {
        what: "the Vulkan loader (libvulkan.so.1)",
        present: || has_library("libvulkan.so.1"),
        packages: &["libvulkan1"],
    },
    Need {
        what: "a Vulkan driver (an ICD manifest)",
        present: has_vulkan_driver,
        packages: &["mesa-vulkan-drivers"],
    },
];

/// What the tests need beyond the demo: GDAL for the dataset builder's tests, an X server, input and
/// capture for the viewer's test in a real window and the libraries winit loads there, Python's
/// venv for the partitioned builds' Dask driver.
const TEST: &[Need] = &[
    Need {
        what: "GDAL's development files (gdal-config)",
        present: || on_path("gdal-config"),
        packages: &["libgdal-dev"],
    },
    Need { what: "pkg-config", present: || on_path("pkg-config"), packages: &["pkg-config"] },
    Need { what: "an X server without a screen (Xvfb)", present: || on_path("Xvfb"), packages: &["xvfb"] },
    Need { what: "xdotool", present: || on_path("xdotool"), packages: &["xdotool"] },
    Need { what: "xwd", present: || on_path("xwd"), packages: &["x11-apps"] },
    Need {
        what: "the X libraries winit loads (xkbcommon-x11, X11-xcb, Xcursor, Xrandr, Xi)",
        present: || {
            ["libxkbcommon-x11.so.0", "libX11-xcb.so.1", "libXcursor.so.1", "libXrandr.so.2", "libXi.so.6"]
                .iter()
                .all(|l| has_library(l))
        },
        packages: &["libxkbcommon-x11-0", "libx11-xcb1", "libxcursor1", "libxrandr2", "libxi6"],
    },
    Need { what: "Python 3 with venv", present: python_venv, packages: &["python3", "python3-venv"] },
];

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("demo") => ensure(&needs("demo")).and_then(|()| demo(&args[1..])),
        Some("test") => ensure(&needs("test")).and_then(|()| test(&args[1..])),
        Some("dist") => ensure(&needs("demo")).and_then(|()| dist()),
        Some("setup") => match args.get(1).map(String::as_str).unwrap_or("test") {
            "demo" => ensure(&needs("demo")),
            "test" => ensure(&needs("test")).and_then(|()| dask_env()),
            other => Err(format!("setup {other}: give demo or test")),
        },
        _ => Err("usage: cargo xtask demo [ARGS...] | test [ARGS...] | setup [demo|test] | dist".to_owned()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("xtask: {message}");
            ExitCode::FAILURE
        }
    }
}

fn needs(command: &str) -> Vec<&'static Need> {
    let mut needs: Vec<&Need> = DEMO.iter().collect();
    if command == "test" {
        needs.extend(TEST);
    }
    needs
}

/// Installs what is missing where it may, or says what to run.
fn ensure(needs: &[&Need]) -> Result<(), String> {
    let missing: Vec<&&Need> = needs.iter().filter(|n| !(n.present)()).collect();
    if missing.is_empty() {
        return Ok(());
    }
    let mut packages: Vec<&str> = missing.iter().flat_map(|n| n.packages.iter().copied()).collect();
    packages.dedup();
    for need in &missing {
        eprintln!("xtask: missing {} (Debian/Ubuntu: {})", need.what, need.packages.join(" "));
    }
    let install = format!("apt-get update && apt-get install -y {}", packages.join(" "));
    if !on_path("apt-get") {
        return Err(format!(
            "this machine has no apt-get: install the above with its package manager (on Debian/Ubuntu: {install})"
        ));
    }
    let sudo = if is_root() {
        ""
    } else if on_path("sudo") && succeeds(Command::new("sudo").args(["-n", "true"])) {
        "sudo "
    } else {
        return Err(format!("run this, then the same command again:\n  sudo sh -c '{install}'"));
    };
    eprintln!("xtask: installing: {sudo}{install}");
    let apt = |args: &[&str]| {
        let mut command = if sudo.is_empty() { Command::new("apt-get") } else { Command::new("sudo") };
        if !sudo.is_empty() {
            command.arg("apt-get");
        }
        command.args(args).env("DEBIAN_FRONTEND", "noninteractive");
        succeeds(&mut command)
    };
    if !apt(&["update", "-qq"]) || !apt(&[&["install", "-y", "-qq"][..], &packages].concat()) {
        return Err(format!("apt-get failed; run it yourself: {sudo}sh -c '{install}'"));
    }
    let still: Vec<&str> = missing.iter().filter(|n| !(n.present)()).map(|n| n.what).collect();
    if still.is_empty() {
        Ok(())
    } else {
        Err(format!("still missing after installing: {}", still.join("; ")))
    }
}

fn demo(args: &[String]) -> Result<(), String> {
    let mut command = cargo();
    command.args(["run", "--release", "--", "demo"]).args(args);
    run(command.env("WGPU_BACKEND", backend()))
}

fn test(args: &[String]) -> Result<(), String> {
    dask_env()?;
    let shared = workspace().join("../shared/data");
    if !shared.is_dir() && std::env::var_os("TERRAMP_SKIP_SHARED").is_none() {
        eprintln!(
            "xtask: {} is missing: the real-data tests will fail naming it (TERRAMP_SKIP_SHARED=1 skips them)",
            shared.display()
        );
    }
    let mut command = cargo();
    command.args(["test", "--workspace"]).args(args);
    // Vulkan, not a silent fallback to GL with fewer features; Mesa's device-select layer would
    // probe Wayland and X11 at every adapter the tests open.
    run(command.env("WGPU_BACKEND", backend()).env("NODEVICE_SELECT", "1"))
}

/// The binaries to ship: `target/dist/NAME` without debug info, and `NAME.debug` beside it with the
/// release profile's line tables, which the binary names (`.gnu_debuglink`): Rust's backtraces
/// read it for file and line, and without it still name the functions.
fn dist() -> Result<(), String> {
    const BINARIES: [&str; 2] = ["terramp", "terramp-data"];
    if !on_path("objcopy") {
        return Err("missing objcopy (Debian/Ubuntu: binutils)".to_owned());
    }
    run(cargo().args(["build", "--release", "--workspace", "--bins"]))?;
    let target =
        std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| workspace().join("target"), PathBuf::from);
    let dist = target.join("dist");
    std::fs::create_dir_all(&dist).map_err(|e| format!("{}: {e}", dist.display()))?;
    for name in BINARIES {
        let (built, shipped) = (target.join("release").join(name), dist.join(name));
        let debug = dist.join(format!("{name}.debug"));
        std::fs::copy(&built, &shipped).map_err(|e| format!("copying {}: {e}", built.display()))?;
        run(Command::new("objcopy").arg("--only-keep-debug").arg(&shipped).arg(&debug))?;
        // The link names the file alone: it is looked for beside the binary, wherever that goes.
        let link = format!("--add-gnu-debuglink={name}.debug");
        run(Command::new("objcopy").args(["--strip-debug", &link]).arg(&shipped).current_dir(&dist))?;
        let size = |p: &Path| std::fs::metadata(p).map_or(0, |m| m.len()) as f64 / (1 << 20) as f64;
        println!(
            "{}: {:.1} MiB (built: {:.1} MiB); its debug info {:.1} MiB in {}",
            shipped.display(),
            size(&shipped),
            size(&built),
            size(&debug),
            debug.display()
        );
    }
    Ok(())
}

/// The Dask environment `data-tools/tests/partitioned.rs` drives (`.venv-dask`), made when missing
/// and kept to `scripts/requirements-dask.txt`.
fn dask_env() -> Result<(), String> {
    let root = workspace();
    let venv = root.join(".venv-dask");
    if !venv.join("bin/python").is_file() {
        run(Command::new("python3").args(["-m", "venv"]).arg(&venv))?;
    }
    let requirements = root.join("scripts/requirements-dask.txt");
    run(Command::new(venv.join("bin/pip")).args(["install", "-q", "-r"]).arg(requirements))
}

fn backend() -> String {
    std::env::var("WGPU_BACKEND").unwrap_or_else(|_| "vulkan".to_owned())
}

fn cargo() -> Command {
    let mut command = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()));
    command.current_dir(workspace());
    command
}

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().map_or_else(|| PathBuf::from("."), Path::to_owned)
}

fn run(command: &mut Command) -> Result<(), String> {
    let shown = format!("{command:?}");
    match command.status() {
        Ok(status) if status.success() => Ok(()),
        Ok(status) => Err(format!("{shown} failed ({status})")),
        Err(e) => Err(format!("{shown}: {e}")),
    }
}

fn succeeds(command: &mut Command) -> bool {
    command.stdout(Stdio::null()).stderr(Stdio::null()).status().is_ok_and(|s| s.success())
}

fn on_path(program: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|dir| dir.join(program).is_file()))
}

/// Whether the dynamic linker finds `name` (its cache, `ldconfig -p`).
fn has_library(name: &str) -> bool {
    let listed = ["/sbin/ldconfig", "/usr/sbin/ldconfig", "ldconfig"]
        .iter()
        .find_map(|ldconfig| Command::new(ldconfig).arg("-p").output().ok().filter(|o| o.status.success()));
    listed
        .is_some_and(|o| String::from_utf8_lossy(&o.stdout).lines().any(|l| l.trim_start().starts_with(name)))
}

/// A Vulkan driver: a manifest where the loader looks (or the variables that point it elsewhere).
fn has_vulkan_driver() -> bool {
    if ["VK_DRIVER_FILES", "VK_ICD_FILENAMES"].iter().any(|v| std::env::var_os(v).is_some()) {
        return true;
    }
    ["/usr/share/vulkan/icd.d", "/etc/vulkan/icd.d", "/usr/local/share/vulkan/icd.d"].iter().any(|dir| {
        std::fs::read_dir(dir)
            .is_ok_and(|entries| entries.flatten().any(|e| e.path().extension().is_some_and(|x| x == "json")))
    })
}

/// Python 3 that can make a venv: Debian keeps `ensurepip`, which `venv` needs, in python3-venv.
fn python_venv() -> bool {
    on_path("python3") && succeeds(Command::new("python3").args(["-c", "import ensurepip, venv"]))
}

fn is_root() -> bool {
    Command::new("id").arg("-u").output().is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
}

//! An X server of a test's own (Xvfb) for programs that open a window: the lowest free display
//! above 90, killed when dropped, so a failing test leaves no server behind.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

/// A running Xvfb; `display` is what `DISPLAY` names it.
pub struct Xvfb {
    pub display: String,
    server: Child,
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.server.kill();
        let _ = self.server.wait();
    }
}

/// Whether `tool` is on the `PATH`.
pub fn have(tool: &str) -> bool {
    Command::new("sh").args(["-c", &format!("command -v {tool}")]).output().is_ok_and(|o| o.status.success())
}

impl Xvfb {
    /// Starts one, once `tools` (Xvfb and whatever else the test drives X with) are all there;
    /// without them `None`, after failing under `CI` (`.ci/run` installs them) or saying the test
    /// is skipped elsewhere.
    pub fn start(tools: &[&str]) -> Option<Self> {
        if !tools.iter().all(|t| have(t)) {
            assert!(std::env::var("CI").is_err(), "CI needs {tools:?} (.ci/run installs them)");
            eprintln!("SKIPPED: one of {tools:?} is missing (apt-get install xvfb xdotool x11-apps)");
            return None;
        }
        let n = (90..200).find(|n| !Path::new(&format!("/tmp/.X11-unix/X{n}")).exists()).unwrap();
        let display = format!(":{n}");
        let server = Command::new("Xvfb")
            .args([display.as_str(), "-screen", "0", "800x600x24", "-nolisten", "tcp"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let socket = format!("/tmp/.X11-unix/X{n}");
        for _ in 0..100 {
            if Path::new(&socket).exists() {
                break;
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        Some(Self { display, server })
    }
}

//! The binary run from a folder, and a small valid capture for the fit tests (include with
//! `#[path = "common/capture.rs"]`).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the `xylem` binary with `args` in `dir` (no backtraces in its errors).
#[allow(dead_code)]
pub fn xylem(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_xylem"))
        .args(args)
        .current_dir(dir)
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap()
}

#[allow(dead_code)]
/// Renders the built-in fit scene as 3 frames an arc at 1 spp into `dir/cap` (512² EXR frames,
/// 9 in all, under a second) and returns that folder.
pub fn small_capture(dir: &Path) -> PathBuf {
    let o = Command::new(env!("CARGO_BIN_EXE_xylem"))
        .args(["sweep", "fit_maple_sweep", "--frames", "3", "--spp", "1"])
        .args(["--quiet", "--out", "cap"])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    dir.join("cap")
}

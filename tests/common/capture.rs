//! A small valid capture for the fit tests (include with `#[path = "common/capture.rs"]`).

use std::path::{Path, PathBuf};
use std::process::Command;

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

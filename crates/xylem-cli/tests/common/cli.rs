//! The `xylem` binary as the CLI tests drive it (included with `#[path]` by the tests that use it).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn xylem() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_xylem"));
    c.env("RUST_BACKTRACE", "0");
    c
}

pub fn run(args: &[&str]) -> Output {
    xylem().args(args).output().expect("xylem runs")
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub fn repo() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// The built-in board scene at `w × h`, 1 spp, with a `frames`-frame sweep, written into `dir`.
pub fn tiny_board(dir: &Path, w: u32, h: u32, frames: usize) -> PathBuf {
    let text = std::fs::read_to_string(repo().join("scenes/sweep_board.toml")).unwrap();
    let text = text
        .replace("width = 512", &format!("width = {w}"))
        .replace("height = 384", &format!("height = {h}"))
        .replace("spp = 16", "spp = 1")
        .replace("frames = 48", &format!("frames = {frames}"));
    assert!(text.contains(&format!("width = {w}")) && text.contains("spp = 1"));
    // The named regions are in pixels of the full-size image.
    let text = &text[..text.find("[[sweep.regions]]").unwrap_or(text.len())];
    let p = dir.join("board.toml");
    std::fs::write(&p, text).unwrap();
    p
}

pub fn assert_clean_error(o: &Output, needle: &str) {
    let e = stderr(o);
    assert!(!o.status.success(), "expected an error, got success: {e}");
    assert!(!e.contains("panicked"), "panic: {e}");
    assert!(e.contains(needle), "error does not name `{needle}`: {e}");
}

//! `xylem tradeoff` refuses a reference under 4× the highest measured spp (issue 28: with a
//! 16-spp reference its 16-spp row scored SSIM 1.0000 and it recommended "final = 16 spp").

use std::process::Command;
use xylem_lab::tradeoff::{settings, weak_reference, MIN_REFERENCE_FACTOR};

#[test]
fn a_reference_under_four_times_the_highest_spp_is_weak() {
    let max = settings().iter().map(|(_, _, k)| k.spp).max().unwrap();
    assert_eq!(max, 64);
    assert_eq!(MIN_REFERENCE_FACTOR, 4);
    let why = weak_reference(16, max).expect("16 spp against rows of 64 is weak");
    assert!(why.contains("--reference-spp 256"), "{why}");
    // The boundary: 4 × 64 passes, one sample less does not.
    assert!(weak_reference(256, max).is_none());
    assert!(weak_reference(255, max).is_some());
}

#[test]
fn tradeoff_refuses_a_weak_reference_before_rendering() {
    let tmp = tempfile::tempdir().unwrap();
    let report = tmp.path().join("T.md");
    let o = Command::new(env!("CARGO_BIN_EXE_xylem"))
        .args([
            "tradeoff",
            "sweep_board",
            "--reference-spp",
            "16",
            "--width",
            "8",
            "--out",
        ])
        .arg(&report)
        .current_dir(tmp.path())
        .output()
        .unwrap();
    assert!(!o.status.success(), "a 16-spp reference was accepted");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("--reference-spp 256") && err.contains("--allow-weak-reference"),
        "{err}"
    );
    assert!(!report.exists(), "a report was written");
}

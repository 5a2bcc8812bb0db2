//! `xylem fit` refuses captures it cannot fit, naming the cause, and no NaN reaches an output
//! (issue 26, item 7). Before: `clip = 0`, a camera behind the board, tiny intensities and a
//! camera whose axes are parallel (a 1×23 map) each exited 0 with every texel unfitted and
//! black maps; one frame of 3e38 made the residual map NaN and `fit.json` write `null`.

#[path = "common/capture.rs"]
mod common_capture;

use common_capture::{small_capture as capture, xylem};
use std::path::Path;
use xylem::picture::exr::{write_exr_layers, ExrLayer};

fn edit(cap: &Path, f: impl Fn(&mut serde_json::Value)) {
    let m = cap.join("manifest.json");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&m).unwrap()).unwrap();
    f(&mut v);
    std::fs::write(&m, v.to_string()).unwrap();
}

const FIT: [&str; 7] = ["fit", "cap", "--out", "fitted", "--quiet", "--texels", "8"];

/// Exit 1 (not 0, not a panic), naming every needle, and no maps written.
fn refused(dir: &Path, needles: &[&str]) {
    let o = xylem(&FIT, dir);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(!e.contains("panicked"), "{e}");
    for n in needles {
        assert!(e.contains(n), "the error does not name `{n}`: {e}");
    }
    assert!(!dir.join("fitted/diffuse.png").exists(), "{e}");
}

#[test]
fn unfittable_captures_are_refused_with_their_cause() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let cap = capture(dir);
    let original = std::fs::read(cap.join("manifest.json")).unwrap();
    let reset = || std::fs::write(cap.join("manifest.json"), &original).unwrap();
    // Negative control: the capture as rendered fits.
    let o = xylem(&FIT, dir);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::remove_dir_all(dir.join("fitted")).unwrap();

    edit(&cap, |m| m["clip"] = 0.0.into());
    refused(
        dir,
        &["manifest.json", "field `clip`", "allowed finite and > 0"],
    );
    edit(&cap, |m| m["clip"] = (-1.0).into());
    refused(dir, &["field `clip`"]);
    // A clip level under every pixel: clipped everywhere, the cause named.
    edit(&cap, |m| m["clip"] = 1e-30.into());
    refused(dir, &["no texel", "clipped", "field `clip` = 1e-30"]);
    reset();

    // The camera under the board looking up at its back.
    edit(&cap, |m| {
        m["camera"]["eye"] = serde_json::json!([0.0, 0.0, -500.0]);
        m["camera"]["forward"] = serde_json::json!([0.0, 0.0, 1.0]);
        m["camera"]["right"] = serde_json::json!([-1.0, 0.0, 0.0]);
    });
    refused(dir, &["no texel", "edge-on or from behind", "180.0°"]);
    reset();

    // Intensities 10⁻³⁰ of those the frames were rendered with.
    edit(&cap, |m| {
        for f in m["frames"].as_array_mut().unwrap() {
            f["intensity"] = serde_json::json!([2.5e-25, 2.5e-25, 2.5e-25]);
        }
    });
    refused(dir, &["no texel", "frames[].intensity"]);
    reset();

    // A degenerate camera: `up` along `right`.
    edit(&cap, |m| {
        m["camera"]["up"] = serde_json::json!([1.0, 0.0, 0.0])
    });
    refused(dir, &["field `camera.up`", "perpendicular"]);
    reset();
}

#[test]
fn a_frame_of_huge_values_leaves_no_nan_in_any_output() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let cap = capture(dir);
    let (w, h) = (512u32, 512u32);
    let layer = ExrLayer {
        name: "",
        channels: &["R", "G", "B"],
        data: vec![3e38; (w * h * 3) as usize],
    };
    let frame0 = cap.join("frame_0000.exr");
    std::fs::remove_file(&frame0).unwrap();
    write_exr_layers(&frame0, w, h, &[layer]).unwrap();
    let o = xylem(&FIT, dir);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{e}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("fitted/fit.json")).unwrap())
            .unwrap();
    let median = &report["median_relative_residual"];
    assert!(median.as_f64().is_some_and(f64::is_finite), "{report}");
    // The frame's samples were rejected as brighter than any surface reflects, and counted.
    let too_bright = report["samples"]["too_bright"].as_u64().unwrap();
    assert!(too_bright >= 64, "{report}");
    let text = std::fs::read_to_string(dir.join("fitted/fit.json")).unwrap();
    assert!(!text.contains("null"), "{text}");
    for (name, data) in
        xylem::picture::exr::read_exr_channels(&dir.join("fitted/maps.exr")).unwrap()
    {
        assert!(
            data.iter().all(|v| v.is_finite()),
            "maps.exr {name} holds a NaN"
        );
    }
}

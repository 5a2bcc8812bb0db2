//! Mutations of a valid small capture (issue 26): its manifest's values replaced by hostile
//! ones or its bytes cut and flipped, its frames truncated or flipped; and of the measured maps.
//! Reading and fitting never panic, and every error names the manifest, frame or map at fault.
//! Fixed seeds.

use std::panic::{catch_unwind, AssertUnwindSafe};
#[path = "common/capture.rs"]
mod common_capture;

use common_capture::small_capture as capture;
use std::path::Path;
use xylem::fit::{fit, Capture, FitOptions};
use xylem::math::Pcg32;

/// Opens and fits (4×4 texels) the capture in `dir`: Ok, or the error's message.
fn open_and_fit(dir: &Path) -> Result<(), String> {
    let opts = FitOptions {
        texels: Some((4, 4)),
        ..Default::default()
    };
    let c = Capture::open(dir).map_err(|e| e.to_string())?;
    fit(&c, &opts).map(drop).map_err(|e| e.to_string())
}

/// Runs `open_and_fit`, failing the test on a panic or an error naming no file.
fn check(dir: &Path, what: &str) {
    match catch_unwind(AssertUnwindSafe(|| open_and_fit(dir))) {
        Err(_) => panic!("{what}: panicked"),
        Ok(Err(e)) => assert!(
            e.contains("manifest.json") || e.contains("frame_"),
            "{what}: the error names no file: {e}"
        ),
        Ok(Ok(())) => {}
    }
}

/// Hostile JSON values for a manifest field.
fn hostile(k: u32) -> serde_json::Value {
    use serde_json::json;
    match k % 10 {
        0 => json!(1e300),
        1 => json!(-1),
        2 => json!(0),
        3 => json!(u64::MAX),
        4 => json!(null),
        5 => json!(""),
        6 => json!([]),
        7 => json!({}),
        8 => json!("/dev/zero"),
        _ => json!(1e-39),
    }
}

/// Every leaf of `v` as a JSON pointer.
fn leaves(v: &serde_json::Value, at: String, out: &mut Vec<String>) {
    match v {
        serde_json::Value::Object(m) => m
            .iter()
            .for_each(|(k, x)| leaves(x, format!("{at}/{k}"), out)),
        serde_json::Value::Array(a) => a
            .iter()
            .enumerate()
            .for_each(|(i, x)| leaves(x, format!("{at}/{i}"), out)),
        _ => out.push(at),
    }
}

/// A JSON pointer (`/frames/3/intensity/0`) as the field path errors name
/// (`frames[3].intensity[0]`).
fn dotted(pointer: &str) -> String {
    let mut out = String::new();
    for part in pointer.split('/').skip(1) {
        if part.parse::<usize>().is_ok() {
            out += &format!("[{part}]");
        } else {
            if !out.is_empty() {
                out.push('.');
            }
            out += part;
        }
    }
    out
}

#[test]
fn mutated_captures_give_errors_naming_the_file_never_panics() {
    let tmp = tempfile::tempdir().unwrap();
    capture(tmp.path());
    let dir = tmp.path().join("cap");
    check(&dir, "the capture as written");
    let manifest = dir.join("manifest.json");
    let good = std::fs::read(&manifest).unwrap();
    let value: serde_json::Value = serde_json::from_slice(&good).unwrap();
    let mut paths = Vec::new();
    leaves(&value, String::new(), &mut paths);
    let mut rng = Pcg32::new(26, 1);
    // Values: a random leaf replaced by a hostile value.
    let mut typed = 0;
    for t in 0..60 {
        let mut v = value.clone();
        let p = &paths[rng.next_u32() as usize % paths.len()];
        *v.pointer_mut(p).unwrap() = hostile(rng.next_u32());
        std::fs::write(&manifest, v.to_string()).unwrap();
        check(&dir, &format!("value {t}: {p}"));
        // A type error names the field (`frames[3].intensity[0]`), not only line and column.
        if let Err(e) = open_and_fit(&dir) {
            if e.contains("invalid type") || e.contains("invalid length") {
                let field = dotted(p);
                assert!(
                    e.contains(&format!("field `{field}")),
                    "value {t}: {p}: {e}"
                );
                typed += 1;
            }
        }
    }
    assert!(typed >= 10, "only {typed} type errors among 60 mutations");
    // Bytes: cut, or flipped.
    for t in 0..30 {
        let mut b = good.clone();
        let at = rng.next_u32() as usize % b.len();
        if t % 2 == 0 {
            b.truncate(at);
        } else {
            b[at] ^= 1 << (rng.next_u32() % 8);
        }
        std::fs::write(&manifest, &b).unwrap();
        check(&dir, &format!("manifest bytes {t} at {at}"));
    }
    std::fs::write(&manifest, &good).unwrap();
    // Frames: cut, or a byte flipped (in the header for half of them).
    for t in 0..30 {
        let frame = dir.join(format!("frame_{:04}.exr", rng.next_u32() % 9));
        let original = std::fs::read(&frame).unwrap();
        let mut b = original.clone();
        let span = if t % 4 < 2 { 400.min(b.len()) } else { b.len() };
        let at = rng.next_u32() as usize % span;
        if t % 2 == 0 {
            b.truncate(at);
        } else {
            b[at] ^= 1 << (rng.next_u32() % 8);
        }
        std::fs::write(&frame, &b).unwrap();
        check(
            &dir,
            &format!("frame bytes {t} at {at} of {}", frame.display()),
        );
        std::fs::write(&frame, &original).unwrap();
    }
}

#[test]
fn mutated_measured_maps_give_errors_naming_the_map_never_panics() {
    use xylem::material::{ColorSpace, MeasuredBoard, MeasuredFiles};
    let tmp = tempfile::tempdir().unwrap();
    let repo = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
    let files = MeasuredFiles::in_dir(tmp.path());
    for name in ["diffuse", "fiber_color", "fiber_axis"] {
        let from = repo.join(format!("data/marschner2005/maple/{name}.png"));
        std::fs::copy(from, tmp.path().join(format!("{name}.png"))).unwrap();
    }
    let mut rng = Pcg32::new(26, 2);
    for t in 0..30 {
        let map = [&files.diffuse, &files.fiber_color, &files.fiber_axis][t % 3];
        let original = std::fs::read(map).unwrap();
        let mut b = original.clone();
        // The header (signature, IHDR, the start of IDAT) for half of them.
        let span = if t % 4 < 2 { 64 } else { b.len() };
        let at = rng.next_u32() as usize % span;
        if t % 2 == 0 {
            b.truncate(at);
        } else {
            b[at] ^= 1 << (rng.next_u32() % 8);
        }
        std::fs::write(map, &b).unwrap();
        let what = format!("{} bytes {t} at {at}", map.display());
        let r = catch_unwind(|| MeasuredBoard::from_files(&files, ColorSpace::Srgb).map(drop));
        match r {
            Err(_) => panic!("{what}: panicked"),
            Ok(Err(e)) => {
                let e = e.to_string();
                assert!(e.contains(&*map.to_string_lossy()), "{what}: {e}");
            }
            Ok(Ok(())) => {}
        }
        std::fs::write(map, &original).unwrap();
    }
}

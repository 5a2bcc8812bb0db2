//! Species presets (issue 4): every preset parses and validates; malformed presets (unknown field,
//! out-of-range value, wrong type, unknown name) are rejected with messages naming the file, the
//! field and the allowed range.

use xylem::wood::{self, WoodError, WoodParams, PRESET_NAMES};

#[test]
fn every_preset_parses_and_validates() {
    for name in PRESET_NAMES {
        let p = wood::preset(name).unwrap_or_else(|e| panic!("{e}"));
        assert!(p.rings.width > 0.0, "{name}");
        // The file on disk is the one embedded.
        let path = format!(
            "{}/scenes/presets/{name}.toml",
            concat!(env!("CARGO_MANIFEST_DIR"), "/../..")
        );
        assert_eq!(WoodParams::from_toml_file(&path).unwrap(), p);
    }
    assert_eq!(
        std::fs::read_dir(format!(
            "{}/scenes/presets",
            concat!(env!("CARGO_MANIFEST_DIR"), "/../..")
        ))
        .unwrap()
        .count(),
        PRESET_NAMES.len()
    );
}

fn base() -> String {
    wood::preset_text("red_oak").unwrap().to_string()
}

fn err_of(text: &str) -> String {
    WoodParams::from_toml_str(text, "bad.toml")
        .unwrap_err()
        .to_string()
}

#[test]
fn unknown_field_is_rejected_naming_file_and_field() {
    let text = base().replace("[pores]", "[pores]\nradiuss = 3.0");
    let msg = err_of(&text);
    assert!(msg.contains("bad.toml") && msg.contains("radiuss"), "{msg}");
    let msg = err_of(&format!("{}\n[lighting]\nx = 1\n", base()));
    assert!(msg.contains("lighting"), "{msg}");
}

#[test]
fn out_of_range_value_is_rejected_with_the_range() {
    let text = base().replace("ring_porosity = 1.0", "ring_porosity = 1.5");
    let msg = err_of(&text);
    assert!(
        msg.contains("bad.toml") && msg.contains("pores.ring_porosity") && msg.contains("[0, 1]"),
        "{msg}"
    );
    let text = base().replace("width = 4.0", "width = -4.0");
    assert!(err_of(&text).contains("rings.width"));
    // A growth wave so steep that time would run backwards.
    let text = base().replace("amplitude = 1.0", "amplitude = 9.0");
    let msg = err_of(&text);
    assert!(
        msg.contains("growth.amplitude") && msg.contains("backwards"),
        "{msg}"
    );
    // Growth noise beyond the monotonicity bound.
    let text = base().replace("noise_amplitude = 0.42", "noise_amplitude = 1.5");
    assert!(err_of(&text).contains("growth.noise_amplitude"));
}

#[test]
fn wrong_type_is_rejected() {
    let text = base().replace("density = 0.5", "density = \"lots\"");
    let msg = err_of(&text);
    assert!(msg.contains("bad.toml") && msg.contains("density"), "{msg}");
    let text = base().replace("earlywood = [0.55, 0.32, 0.19]", "earlywood = [0.55, 0.32]");
    assert!(err_of(&text).contains("bad.toml"));
}

#[test]
fn unknown_preset_lists_the_valid_ones() {
    let e = wood::preset("oak").unwrap_err();
    assert!(matches!(e, WoodError::UnknownPreset { .. }));
    let msg = e.to_string();
    for name in PRESET_NAMES {
        assert!(msg.contains(name), "{msg}");
    }
    let e = WoodParams::from_toml_file("/nonexistent/x.toml").unwrap_err();
    assert!(e.to_string().contains("/nonexistent/x.toml"));
    // A device is refused at once, not read forever (issue 26; before, it read /dev/zero until
    // memory ran out).
    let e = WoodParams::from_toml_file("/dev/zero").unwrap_err();
    let cause = std::error::Error::source(&e).map(|c| c.to_string());
    assert!(
        cause
            .as_deref()
            .unwrap_or("")
            .contains("not a regular file"),
        "{e}: {cause:?}"
    );
}

#[test]
fn xylem_texture_renders_every_preset_in_three_cuts() {
    let dir = std::env::temp_dir().join(format!("xylem_wood_cuts_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for name in PRESET_NAMES {
        for plane in ["xy", "xz", "yz"] {
            let out = dir.join(format!("{name}_{plane}.png"));
            let status = std::process::Command::new(env!("CARGO_BIN_EXE_xylem"))
                .args([
                    "texture", "--preset", name, "--plane", plane, "--offset", "60",
                ])
                .args(["--res", "24", "--out"])
                .arg(&out)
                .output()
                .unwrap();
            assert!(
                status.status.success(),
                "{name} {plane}: {}",
                String::from_utf8_lossy(&status.stderr)
            );
            assert!(std::fs::metadata(&out).unwrap().len() > 100);
        }
    }
    // A user's file with a mistake is refused, naming the file and the field.
    let bad = dir.join("bad.toml");
    std::fs::write(
        &bad,
        base().replace("ring_porosity = 1.0", "ring_porosity = 2.0"),
    )
    .unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_xylem"))
        .args(["texture", "--preset-file"])
        .arg(&bad)
        .args(["--res", "8", "--out"])
        .arg(dir.join("bad.png"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("bad.toml") && err.contains("pores.ring_porosity"),
        "{err}"
    );
    assert!(!dir.join("bad.png").exists());
    std::fs::remove_dir_all(&dir).ok();
}

/// `color.fiber_saturation` is one scale or one per channel (notes/wood.md §8); each in [0, 2].
#[test]
fn fiber_saturation_is_a_number_or_one_per_channel() {
    let with = |v: &str| {
        let text = base().replace("fiber_saturation = 0.5", &format!("fiber_saturation = {v}"));
        WoodParams::from_toml_str(&text, "bad.toml")
    };
    assert_eq!(with("0.7").unwrap().color.fiber_saturation, [0.7; 3]);
    assert_eq!(
        with("[0.7, 0.8, 1.1]").unwrap().color.fiber_saturation,
        [0.7, 0.8, 1.1]
    );
    let msg = with("[0.7, 0.8]").unwrap_err().to_string();
    assert!(
        msg.contains("bad.toml") && msg.contains("three numbers"),
        "{msg}"
    );
    let msg = with("[0.7, 0.8, 2.5]").unwrap_err().to_string();
    assert!(msg.contains("color.fiber_saturation[2]"), "{msg}");
}

/// `xylem preset gallery` renders a preset on the README board into a PNG row of three frames,
/// and refuses a light angle out of range naming the option.
#[test]
fn preset_gallery_renders_a_row_per_preset() {
    let out = tempfile::tempdir().unwrap();
    let run = |extra: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_xylem"))
            .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .args([
                "preset", "gallery", "--only", "walnut", "--res", "40x20", "--spp", "1",
            ])
            .arg("--out")
            .arg(out.path())
            .args(extra)
            .output()
            .unwrap()
    };
    let o = run(&[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let img = xylem::picture::png::read_png_rgb8(&out.path().join("walnut.png")).unwrap();
    let (w, h) = (img.width, img.height);
    assert!(w >= 3 * 40 && h >= 20, "{w}x{h}");
    let o = run(&["--angles", "95"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--angles"));
}

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
        let path = format!("{}/scenes/presets/{name}.toml", env!("CARGO_MANIFEST_DIR"));
        assert_eq!(WoodParams::from_toml_file(&path).unwrap(), p);
    }
    assert_eq!(
        std::fs::read_dir(format!("{}/scenes/presets", env!("CARGO_MANIFEST_DIR")))
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
    let text = base().replace("noise_amplitude = 0.4", "noise_amplitude = 1.5");
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
}

//! A scene's `[quality]` table: the `--quality` presets and wood-model knobs written in the
//! scene file (scenes/README.md), applied when it loads.

use std::path::PathBuf;
use xylem::field::JacobianModel;
use xylem::material::Material;
use xylem::scene::{load, LoadedScene};

/// scenes/sweep_board.toml with `[render] spp` as given (None: the line removed) and `extra`
/// appended, loaded from a temporary file.
fn board(spp: Option<u32>, extra: &str) -> Result<LoadedScene, String> {
    let root = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
    let text = std::fs::read_to_string(root.join("scenes/sweep_board.toml")).unwrap();
    let spp_line = spp.map_or(String::new(), |n| format!("spp = {n}"));
    let text = text.replacen("spp = 16", &spp_line, 1) + "\n" + extra;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("board.toml");
    std::fs::write(&path, text).unwrap();
    load(&path).map_err(|e| e.to_string())
}

/// The board's wood: (its distortion Jacobian, whether it has pores).
fn wood(s: &LoadedScene) -> (JacobianModel, bool) {
    s.scene
        .materials
        .iter()
        .find_map(|m| match m {
            Material::Wood(w) => {
                Some((w.volume.jacobian_model(), w.volume.params().pores.is_some()))
            }
            _ => None,
        })
        .expect("the board is wood")
}

#[test]
fn quality_presets_set_spp_and_knobs_unless_the_scene_says_otherwise() {
    // Control: no table, the full model (simplified Jacobian, pores) at the default 16 spp.
    let plain = board(None, "").unwrap();
    assert_eq!(plain.settings.spp, 16);
    assert_eq!(wood(&plain), (JacobianModel::Simplified, true));
    for (preset, spp) in [("draft", 4), ("default", 16), ("final", 64)] {
        let s = board(None, &format!("[quality]\npreset = \"{preset}\"\n")).unwrap();
        assert_eq!(s.settings.spp, spp, "{preset}");
        assert_eq!(wood(&s), (JacobianModel::Exact, true), "{preset}");
    }
    // `[render] spp` overrides the preset's; the knobs override the preset's knobs.
    let s = board(Some(7), "[quality]\npreset = \"draft\"\n").unwrap();
    assert_eq!(s.settings.spp, 7);
    let s = board(
        None,
        "[quality]\npreset = \"final\"\njacobian = \"simplified\"\npores_and_rays = false\n",
    )
    .unwrap();
    assert_eq!(
        (s.settings.spp, wood(&s)),
        (64, (JacobianModel::Simplified, false))
    );
}

/// The error of a scene that must not load.
fn refused(extra: &str) -> String {
    match board(None, extra) {
        Ok(_) => panic!("loaded: {extra}"),
        Err(e) => e,
    }
}

#[test]
fn bad_quality_tables_name_the_field_and_the_allowed_values() {
    let e = refused("[quality]\npreset = \"best\"\n");
    assert!(e.contains("best") && e.contains("draft"), "{e}");
    let e = refused("[quality]\nmax_noise_bands = 0\n");
    assert!(
        e.contains("quality.max_noise_bands") && e.contains("allowed 1"),
        "{e}"
    );
    let e = refused("[quality]\nspeed = 3\n");
    assert!(e.contains("speed"), "{e}");
}

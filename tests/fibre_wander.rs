//! Walnut against the measured flat-sawn board walnut1 (issue 25): the preset's fibres must dip
//! and wander as much as the board's, and its rendered highlight must spread over the board
//! instead of flashing at one light angle. The statistics are those of `xylem validate
//! appearance` (src/validate/appearance.rs, notes/appearance.md); the preset is sampled flat-sawn
//! 120 mm from the pith, as walnut1 was cut.

use glam::Vec3;
use std::path::Path;
use xylem::material::Placement;
use xylem::validate::appearance::{
    chatoyance_statistics, compare_boards, quantile, sweep_luminance, BoardMaps, Comparison,
    Subject, SweepSettings, BOARD_MM, PRESET_TREE,
};
use xylem::wood::{preset, WoodVolume};

/// The tree placement of a flat-sawn board: object z = 9 (the face) lies 120 mm from the pith,
/// fibres along object x.
const FLAT_TREE: &str =
    "{ origin = [-111.0, 0.0, 0.0], axis = [1.0, 0.0, 0.0], rotation_deg = 0.0 }";

fn walnut1() -> Subject {
    Subject::Measured {
        dir: "data/marschner2005/walnut1".into(),
        grain_along_x: false,
    }
}

/// Walnut's fibres on a flat-sawn face against walnut1: fibre dip std and in-plane p10–p90 inside
/// the board's 10–90 % band over 8 strips or within 25 % (measured 1.82°, band 1.66–1.96°; 5.84°,
/// band 5.27–6.29°). Fails on the walnut of main before issue 25: dip std 0.79°, in-plane 0.42°.
/// The other map statistics (colour, dip quantiles) are held to the same criterion.
#[test]
fn walnut_fibres_dip_and_wander_like_walnut1() {
    let base = Path::new(env!("CARGO_MANIFEST_DIR"));
    let volume = WoodVolume::new(preset("walnut").unwrap(), 7).unwrap();
    let placement = Placement {
        origin: Vec3::new(-111.0, 0.0, 0.0),
        axis: Vec3::X,
        ..Placement::default()
    };
    let n = 390;
    let maps = BoardMaps::from_preset(&volume, &placement, (n, n), BOARD_MM / n as f32, 9.0);
    let rows = compare_boards(&maps, &walnut1().maps(base).unwrap());
    let mut failed = Vec::new();
    for c in rows.iter().filter(|c| !c.name.starts_with("dip profile")) {
        println!(
            "{}: preset {:.4}, walnut1 {:.4}, band {:.4} … {:.4}",
            c.name, c.preset, c.measured, c.band.0, c.band.1
        );
        if !c.passes() {
            failed.push(c.name.clone());
        }
    }
    for name in ["fibre dip std (deg)", "in-plane angle p10-p90 width (deg)"] {
        assert!(rows.iter().any(|c| c.name == name));
    }
    assert!(failed.is_empty(), "walnut against walnut1: {failed:?}");
}

/// The rendered chatoyance (per-pixel max/min luminance over a ±60° sweep of a distant light along
/// the grain, `validate appearance`'s settings) of walnut flat-sawn against walnut1's: median 6.86
/// (band 6.56–7.18) and p90/p10 1.55 (band 1.46–1.57). Main before issue 25: 10.5 and 1.08 (the
/// whole board flashed at one light angle).
#[test]
fn walnut_highlight_spreads_like_walnut1() {
    let base = Path::new(env!("CARGO_MANIFEST_DIR"));
    let s = SweepSettings::FULL;
    let subject = Subject::Preset {
        name: "walnut".into(),
        seed: 7,
        dir: None,
    };
    let text = subject
        .sweep_scene(s.frames, 60.0, s.res, s.spp)
        .replace(PRESET_TREE, FLAT_TREE);
    assert!(text.contains(FLAT_TREE));
    let preset_sweep = sweep_luminance(&text, base).unwrap();
    let measured_sweep = walnut1().sweep(base, s.frames, s.res, s.spp).unwrap();
    let (p, _) = chatoyance_statistics(&preset_sweep, true);
    let (m, strips) = chatoyance_statistics(&measured_sweep, false);
    for (k, name) in ["chatoyance median (max/min)", "chatoyance p90/p10"]
        .iter()
        .enumerate()
    {
        let v: Vec<f64> = strips.iter().map(|s| s[k]).collect();
        let c = Comparison {
            name: name.to_string(),
            preset: p[k],
            measured: m[k],
            band: (quantile(&v, 0.1), quantile(&v, 0.9)),
        };
        println!("{c:?}");
        assert!(c.passes(), "{c:?}");
    }
}

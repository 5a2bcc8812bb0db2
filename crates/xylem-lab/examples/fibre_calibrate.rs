//! Calibration of a preset's fibre statistics against a measured board (issue 25): the board
//! statistics of `xylem validate appearance`, the rendered chatoyance, and the along/across-grain
//! autocorrelation of the fibre dip and in-plane angle, for a quartersawn or flat-sawn cut.
//!
//! `cargo run --release --example fibre_calibrate -- PRESET_OR_FILE MEASURED_DIR (x|y)
//! RING_ANGLE_DEG [--diffuse OUT.png]`
//!
//! The comparison is `validate appearance`'s (`compare_pair`: the preset cut as the gallery's
//! showcase board at that angle to the rings, 0 flat-sawn, 90 quartersawn); this adds the
//! autocorrelations, and with `--diffuse` the preset's diffuse map as 8-bit codes (as the
//! measured diffuse.png stores its linear values), grain along the rows.

use std::path::Path;
use xylem_lab::appearance::{compare_pair, BoardMaps, Pair, SweepSettings};

/// Autocorrelation of `angle` (per texel) at `lag` texels along (true) or across the grain.
fn autocorr(maps: &BoardMaps, angle: &dyn Fn(usize) -> f64, lag: usize, along: bool) -> f64 {
    let (w, h) = (maps.board.width as usize, maps.board.height as usize);
    let v: Vec<f64> = (0..w * h).map(angle).collect();
    let m = v.iter().sum::<f64>() / v.len() as f64;
    let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / v.len() as f64;
    let step_x = along == maps.grain_along_x;
    let mut s = 0.0;
    let mut n = 0usize;
    for y in 0..h {
        for x in 0..w {
            let (x2, y2) = if step_x { (x + lag, y) } else { (x, y + lag) };
            if x2 < w && y2 < h {
                s += (v[y * w + x] - m) * (v[y2 * w + x2] - m);
                n += 1;
            }
        }
    }
    s / n as f64 / var
}

fn print_autocorr(label: &str, maps: &BoardMaps) {
    let lags = [1usize, 2, 4, 8, 16, 32, 64, 128];
    for (name, f) in [
        ("dip", &(|i| maps.dip_deg(i)) as &dyn Fn(usize) -> f64),
        (
            "in-plane",
            &(|i| maps.in_plane_deg(i)) as &dyn Fn(usize) -> f64,
        ),
    ] {
        for along in [true, false] {
            let c: Vec<String> = lags
                .iter()
                .map(|&l| format!("{:.2}", autocorr(maps, f, l, along)))
                .collect();
            println!(
                "autocorr {label} {name:8} {:6} lags {:?} texels: {}",
                if along { "along" } else { "across" },
                lags,
                c.join(" ")
            );
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let pair = Pair {
        preset: args[0].clone(),
        measured_dir: args[1].clone(),
        grain_along_x: args[2] == "x",
        ring_angle_deg: args[3].parse().expect("ring angle in degrees"),
    };
    let base = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
    let report = compare_pair(&pair, base, None, SweepSettings::FULL).unwrap();
    println!(
        "{} (ring angle {}°) against {}",
        pair.preset, pair.ring_angle_deg, pair.measured_dir
    );
    for r in report.rows.iter().chain(&report.pattern_rows) {
        println!(
            "{:45} preset {:8.4}  measured {:8.4}  band {:8.4} … {:8.4}  {}",
            r.name,
            r.preset,
            r.measured,
            r.band.0,
            r.band.1,
            r.verdict()
        );
    }
    let passed = report.pattern_rows.iter().filter(|r| r.passes()).count();
    println!(
        "pattern rows passing: {passed} of {}",
        report.pattern_rows.len()
    );
    let pm = &report.preset_maps;
    if let Some(i) = args.iter().position(|a| a == "--diffuse") {
        let (w, h) = (pm.board.width as usize, pm.board.height as usize);
        let mut rgb = Vec::with_capacity(w * h * 3);
        for row in 0..w {
            for col in 0..h {
                let c = pm.board.diffuse[col * w + row];
                rgb.extend(
                    c.to_array()
                        .map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8),
                );
            }
        }
        xylem::picture::png::write_png_data8(Path::new(&args[i + 1]), h as u32, w as u32, &rgb)
            .unwrap();
    }
    print_autocorr("preset  ", pm);
    print_autocorr("measured", &report.measured_maps);
}

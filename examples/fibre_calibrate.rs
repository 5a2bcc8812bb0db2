//! Calibration of a preset's fibre statistics against a measured board (issue 25): the board
//! statistics of `xylem validate appearance`, the rendered chatoyance, and the along/across-grain
//! autocorrelation of the fibre dip and in-plane angle, for a quartersawn or flat-sawn cut.
//!
//! `cargo run --release --example fibre_calibrate -- PRESET MEASURED_DIR (x|y) (quarter|flat)
//! [PRESET_DIR] [--no-sweep] [--png OUT.png]`
//!
//! Flat-sawn: the face at object z = 9 lies 120 mm from the pith (origin (−111, 0, 0), fibres
//! along object x), quartersawn as `validate appearance` (origin (0, 120, 0)).

use glam::Vec3;
use std::path::{Path, PathBuf};
use xylem::material::Placement;
use xylem::validate::appearance::{
    chatoyance_statistics as chat_stats, compare_boards, quantile, sweep_luminance, BoardMaps,
    Subject, BOARD_MM, PRESET_TREE,
};
use xylem::wood::{WoodParams, WoodVolume};

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
    let name = args[0].clone();
    let measured_dir = args[1].clone();
    let grain_along_x = args[2] == "x";
    let flat = args[3] == "flat";
    let dir = args
        .get(4)
        .filter(|a| !a.starts_with("--"))
        .map(PathBuf::from);
    let no_sweep = args.iter().any(|a| a == "--no-sweep");
    let base = Path::new(env!("CARGO_MANIFEST_DIR"));
    let params = match &dir {
        Some(d) => WoodParams::from_toml_file(d.join(format!("{name}.toml"))).unwrap(),
        None => xylem::wood::preset(&name).unwrap(),
    };
    let volume = WoodVolume::new(params, 7).unwrap();
    let origin = if flat {
        Vec3::new(-111.0, 0.0, 0.0)
    } else {
        Vec3::new(0.0, 120.0, 0.0)
    };
    let placement = Placement {
        origin,
        axis: Vec3::X,
        ..Placement::default()
    };
    let n = 390;
    let pm = BoardMaps::from_preset(&volume, &placement, (n, n), BOARD_MM / n as f32, 9.0);
    let measured = Subject::Measured {
        dir: measured_dir.clone(),
        grain_along_x,
    };
    let mm = measured.maps(base).unwrap();
    println!(
        "{name} ({}) against {measured_dir}",
        if flat { "flat-sawn" } else { "quartersawn" }
    );
    let rows = compare_boards(&pm, &mm);
    for r in &rows {
        println!(
            "{:45} preset {:8.4}  measured {:8.4}  band {:8.4} … {:8.4}  {}",
            r.name,
            r.preset,
            r.measured,
            r.band.0,
            r.band.1,
            if r.passes() { "pass" } else { "FAIL" }
        );
    }
    if let Some(i) = args.iter().position(|a| a == "--diffuse") {
        // The preset's diffuse map as 8-bit codes (as the measured diffuse.png stores its linear
        // values), transposed so the grain runs along the rows as on walnut1.
        let mut rgb = Vec::with_capacity(n * n * 3);
        for row in 0..n {
            for col in 0..n {
                let c = pm.board.diffuse[col * n + row];
                rgb.extend(
                    c.to_array()
                        .map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8),
                );
            }
        }
        xylem::picture::png::write_png_data8(Path::new(&args[i + 1]), n as u32, n as u32, &rgb)
            .unwrap();
    }
    print_autocorr("preset  ", &pm);
    print_autocorr("measured", &mm);
    if no_sweep {
        return;
    }
    let preset = Subject::Preset {
        name: name.clone(),
        seed: 7,
        dir: dir.clone(),
    };
    let flat_tree = "{ origin = [-111.0, 0.0, 0.0], axis = [1.0, 0.0, 0.0], rotation_deg = 0.0 }";
    let mut text = preset.sweep_scene(25, 60.0, 130, 4);
    if flat {
        text = text.replace(PRESET_TREE, flat_tree);
    }
    let ps = sweep_luminance(&text, base).unwrap();
    let ms = measured.sweep(base, 25, 130, 4).unwrap();
    let (pc, _) = chat_stats(&ps, true);
    let (mc, strips) = chat_stats(&ms, grain_along_x);
    for (k, label) in ["chatoyance median (max/min)", "chatoyance p90/p10"]
        .iter()
        .enumerate()
    {
        let v: Vec<f64> = strips.iter().map(|s| s[k]).collect();
        let (lo, hi) = (quantile(&v, 0.1), quantile(&v, 0.9));
        let ok = (pc[k] >= lo && pc[k] <= hi) || (pc[k] - mc[k]).abs() <= 0.25 * mc[k];
        println!(
            "{label:45} preset {:8.4}  measured {:8.4}  band {lo:8.4} … {hi:8.4}  {}",
            pc[k],
            mc[k],
            if ok { "pass" } else { "FAIL" }
        );
    }
    if let Some(i) = args.iter().position(|a| a == "--png") {
        // The middle frame (light at the zenith) of the preset's sweep.
        let f = &ps.frames[ps.frames.len() / 2];
        xylem::picture::png::write_png_linear(Path::new(&args[i + 1]), ps.width, ps.height, f, 0.0)
            .unwrap();
    }
}

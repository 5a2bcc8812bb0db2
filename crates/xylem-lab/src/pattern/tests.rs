//! Pattern statistics of synthetic boards whose answers are known.

use super::*;
use glam::Vec3;
use xylem::material::MeasuredBoard;
use xylem::math::Pcg32;

const PITCH: f64 = 0.25;
/// The relative bias of the correlation length on lines of N = 1024 texels with L ≈ 8–10:
/// removing each line's mean lowers the autocorrelation by ≈ 2L/N and the biased estimator
/// scales lag k by 1 − k/N, which moves the 1/e crossing ≈ (2(e − 1) + 1) L/N ≈ 4.4 L/N
/// short: 3–4 % here, ≈ 8 % on the 390-texel boards at L ≈ 7 (the same for preset and
/// measured board).
const BIAS: f64 = 0.04;

/// A board `w` × `h` with grain along x (columns = along, rows = across), grey diffuse of
/// luminance `lum(a, c)` and fibres dipping `dip(a, c)` degrees out of the face.
fn board(
    (w, h): (usize, usize),
    lum: impl Fn(usize, usize) -> f64,
    dip: impl Fn(usize, usize) -> f64,
) -> BoardMaps {
    let cells = (0..h).flat_map(|c| (0..w).map(move |a| (a, c)));
    let diffuse = cells.clone().map(|(a, c)| Vec3::splat(lum(a, c) as f32));
    let axis = cells.map(|(a, c)| {
        let d = dip(a, c).to_radians() as f32;
        Vec3::new(d.cos(), 0.0, d.sin())
    });
    BoardMaps {
        board: MeasuredBoard {
            width: w as u32,
            height: h as u32,
            diffuse: diffuse.collect(),
            fiber_color: vec![Vec3::splat(0.2); w * h],
            fiber_axis: axis.collect(),
            highlight_width: None,
        },
        grain_along_x: true,
    }
}

fn gauss(rng: &mut Pcg32) -> f64 {
    let (u, v): (f64, f64) = (rng.next_f64().max(1e-300), rng.next_f64());
    (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
}

/// `rows` independent unit-variance AR(1) series of `n` samples with correlation exp(−k/l).
fn ar1(rows: usize, n: usize, l: f64, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = Pcg32::new(seed, 1);
    let rho = (-1.0 / l).exp();
    (0..rows)
        .map(|_| {
            let mut x = gauss(&mut rng);
            (0..n)
                .map(|_| {
                    let out = x;
                    x = rho * x + (1.0 - rho * rho).sqrt() * gauss(&mut rng);
                    out
                })
                .collect()
        })
        .collect()
}

fn stat(maps: &BoardMaps, name: &str) -> Option<f64> {
    let n = maps.board.height as usize;
    pattern_statistics(maps, PITCH, 0..n)
        .into_iter()
        .find(|s| s.0 == name)
        .unwrap()
        .1
}

fn close(x: Option<f64>, want: f64, tol: f64) {
    let x = x.expect("statistic applies");
    assert!((x - want).abs() <= tol, "{x} against {want} ± {tol}");
}

/// Rows of an exponentially correlated (AR(1)) field with L = 8 texels: 2 mm along (less the
/// estimator's bias, [`BIAS`]); rows
/// independent, so across the autocorrelation falls from 1 to ≈ 0 at lag 1 and the linear
/// interpolation puts the 1/e crossing at 1 − 1/e = 0.63 texels (0.16 mm).
#[test]
fn exponential_field_has_its_correlation_length() {
    let rows = ar1(64, 1024, 8.0, 1);
    let maps = board((1024, 64), |a, c| 0.5 + 0.05 * rows[c][a], |_, _| 0.0);
    close(stat(&maps, PATTERN_STATISTICS[0]), 2.0 * (1.0 - BIAS), 0.1);
    close(stat(&maps, PATTERN_STATISTICS[1]), 0.632 * PITCH, 0.03);
}

/// Rows synthesised with power ∝ f^−2 (random phases): slope −2 along; the rows' phases are
/// independent, so across the grain the field is white (slope 0).
#[test]
fn power_law_field_has_its_spectrum_slope() {
    let mut rng = Pcg32::new(2, 1);
    let n = 256;
    let rows: Vec<Vec<f64>> = (0..128)
        .map(|_| {
            let phases: Vec<f64> = (0..=n / 2)
                .map(|_| std::f64::consts::TAU * rng.next_f64())
                .collect();
            (0..n)
                .map(|i| {
                    (1..=n / 2)
                        .map(|k| {
                            let t = std::f64::consts::TAU * (k * i) as f64 / n as f64;
                            (k as f64).powf(-1.0) * (t + phases[k]).cos()
                        })
                        .sum::<f64>()
                })
                .collect()
        })
        .collect();
    let maps = board((n, 128), |a, c| 0.5 + 0.1 * rows[c][a], |_, _| 0.0);
    close(stat(&maps, PATTERN_STATISTICS[2]), -2.0, 0.15);
    close(stat(&maps, PATTERN_STATISTICS[3]), 0.0, 0.2);
}

/// Straight stripes along the grain: coherence 1, orientation 0°; stripes at 30° to the grain:
/// coherence ≈ 1, orientation 30°. Isotropic white noise: coherence is the bias of a
/// Wishart-distributed tensor of n_eff independent gradients, ≈ √(π / (2 n_eff)), n_eff ≈
/// 4πσ² = 201 for σ = 4 texels gives 0.088 (central differences correlate neighbouring
/// gradients, so somewhat more).
#[test]
fn stripes_are_coherent_and_white_noise_is_not() {
    let stripes = board(
        (128, 128),
        |_, c| 0.5 + 0.2 * (std::f64::consts::TAU * c as f64 / 10.0).sin(),
        |_, _| 0.0,
    );
    close(stat(&stripes, PATTERN_STATISTICS[4]), 1.0, 0.01);
    close(stat(&stripes, PATTERN_STATISTICS[5]), 0.0, 0.5);
    let (s, c) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
    let oblique = board(
        (128, 128),
        |a, k| 0.5 + 0.2 * (std::f64::consts::TAU * (k as f64 * c - a as f64 * s) / 10.0).sin(),
        |_, _| 0.0,
    );
    close(stat(&oblique, PATTERN_STATISTICS[4]), 1.0, 0.05);
    close(stat(&oblique, PATTERN_STATISTICS[5]), 30.0, 1.0);
    let mut rng = Pcg32::new(3, 1);
    let noise: Vec<f64> = (0..128 * 128).map(|_| gauss(&mut rng)).collect();
    let white = board(
        (128, 128),
        |a, c| 0.5 + 0.05 * noise[c * 128 + a],
        |_, _| 0.0,
    );
    let coherence = stat(&white, PATTERN_STATISTICS[4]).unwrap();
    println!("white-noise coherence {coherence:.4}");
    assert!((0.07..0.16).contains(&coherence), "{coherence}");
}

/// A photographed board turned against its fibres: the oblique stripes of
/// [`stripes_are_coherent_and_white_noise_is_not`] with fibres running along them (in-plane
/// −30°: stored y points up, the rows run down) are at 0° to the grain; the negative control,
/// fibres along the image axis, reads 30°.
#[test]
fn orientation_is_measured_from_the_fibres_not_the_image_axes() {
    let (s, c) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
    let mut turned = board(
        (128, 128),
        |a, k| 0.5 + 0.2 * (std::f64::consts::TAU * (k as f64 * c - a as f64 * s) / 10.0).sin(),
        |_, _| 0.0,
    );
    close(stat(&turned, PATTERN_STATISTICS[5]), 30.0, 1.0);
    let fibre = Vec3::new(c as f32, -s as f32, 0.0);
    turned.board.fiber_axis.iter_mut().for_each(|u| *u = fibre);
    close(stat(&turned, PATTERN_STATISTICS[5]), 0.0, 1.0);
}

/// Dark ellipses of semi-axes 12 texels along and 3 across on a pale ground: elongation 4, and
/// the area fraction is exactly the ellipses' texels; round discs give 1.
#[test]
fn ellipses_have_their_aspect_ratio_and_area() {
    for (ra, rc, want) in [(12.0, 3.0, 4.0), (5.0, 5.0, 1.0)] {
        let inside = |a: usize, c: usize| {
            let (x, y) = ((a % 40) as f64 - 19.5, (c % 20) as f64 - 9.5);
            (x / ra).powi(2) + (y / rc).powi(2) <= 1.0
        };
        let maps = board(
            (200, 100),
            |a, c| if inside(a, c) { 0.4 } else { 1.0 },
            |_, _| 0.0,
        );
        let count = (0..100)
            .flat_map(|c| (0..200).map(move |a| (a, c)))
            .filter(|&(a, c)| inside(a, c))
            .count();
        close(stat(&maps, PATTERN_STATISTICS[6]), want, 0.08 * want);
        close(
            stat(&maps, PATTERN_STATISTICS[7]),
            count as f64 / 20000.0,
            1e-12,
        );
    }
}

/// Rings 12, 16, 20, 12, … texels wide, each pale, then a linear 4-texel ramp to a 5-texel dark
/// band and an abrupt boundary: width CV √(32/3)/16 = 0.204, transition 4 texels = 1 mm.
/// A white-noise field has no rings (not applicable).
#[test]
fn rings_of_known_widths() {
    let mut profile = Vec::new();
    for k in 0..24 {
        let w = [12, 16, 20][k % 3];
        for t in 0..w {
            let ramp_end = w - 5;
            let ramp_start = ramp_end - 4;
            profile.push(if t < ramp_start {
                1.0
            } else if t < ramp_end {
                1.0 - 0.5 * (t - ramp_start) as f64 / 4.0
            } else {
                0.5
            });
        }
    }
    let maps = board((64, profile.len()), |_, c| profile[c], |_, _| 0.0);
    close(
        stat(&maps, PATTERN_STATISTICS[8]),
        (32.0f64 / 3.0).sqrt() / 16.0,
        0.02,
    );
    close(stat(&maps, PATTERN_STATISTICS[9]), 1.0, 0.1);
    let mut rng = Pcg32::new(4, 1);
    let noise: Vec<f64> = (0..64 * 64).map(|_| gauss(&mut rng)).collect();
    let white = board((64, 64), |a, c| 0.5 + 0.05 * noise[c * 64 + a], |_, _| 0.0);
    assert_eq!(stat(&white, PATTERN_STATISTICS[8]), None);
    assert_eq!(stat(&white, PATTERN_STATISTICS[9]), None);
}

/// Fibres dipping by an AR(1) field of std 3° and L = 10 texels along each row: spread 3°,
/// correlation length 2.5 mm along and 0.16 mm across; no in-plane angle: spread 0, no length.
#[test]
fn fibre_field_of_known_spread_and_correlation() {
    let rows = ar1(64, 1024, 10.0, 5);
    let maps = board((1024, 64), |_, _| 0.5, |a, c| 3.0 * rows[c][a]);
    close(stat(&maps, PATTERN_STATISTICS[10]), 3.0, 0.2);
    close(stat(&maps, PATTERN_STATISTICS[11]), 0.0, 1e-3);
    close(
        stat(&maps, PATTERN_STATISTICS[12]),
        2.5 * (1.0 - BIAS),
        0.12,
    );
    close(stat(&maps, PATTERN_STATISTICS[13]), 0.632 * PITCH, 0.03);
    assert_eq!(stat(&maps, PATTERN_STATISTICS[14]), None);
}

/// Degenerate input: constant boards, a single texel, empty and out-of-range regions give
/// None or a documented value (spreads 0, area fraction 0), never NaN or a panic.
#[test]
fn degenerate_input_gives_none_not_nan() {
    for (w, h) in [(1, 1), (2, 2), (3, 1), (40, 40)] {
        let maps = board((w, h), |_, _| 0.3, |_, _| 0.0);
        let reversed = Range { start: 5, end: 2 };
        for across in [0..h, 0..0, reversed, h + 3..h + 9] {
            for (name, v) in pattern_statistics(&maps, PITCH, across.clone()) {
                assert!(v.is_none_or(f64::is_finite), "{name}: {v:?}");
                if name.contains("correlation") || name.contains("slope") {
                    assert_eq!(v, None, "{name} of a constant field");
                }
            }
        }
        let rows = compare_patterns(&maps, &maps, PITCH);
        assert!(rows.iter().all(Comparison::passes));
    }
    let black = board((30, 30), |_, _| 0.0, |_, _| 0.0);
    for (name, v) in pattern_statistics(&black, PITCH, 0..30) {
        assert!(v.is_none_or(f64::is_finite), "{name}: {v:?}");
    }
}

//! Pattern statistics of a board face (issue 25): what the colour and fibre-angle statistics of
//! [`super::appearance`] miss — how the figure is laid out. Each is a pure function of a
//! [`BoardMaps`], the texel pitch (mm) and a range of texels across the grain, computed alike on a
//! measured board and on a preset's; derivations and sources: notes/appearance.md, "Pattern
//! statistics (issue 25)".
//!
//! Fields are read in grain coordinates: `a` along the grain, `c` across it. Luminance is Rec. 709
//! ([`luminance`]) of the diffuse colour.

use super::appearance::{quantile, strip_comparison, BoardMaps, Comparison, STRIPS};
use std::ops::Range;
use xylem::math::luminance;

/// The names of [`pattern_statistics`], in its order.
pub const PATTERN_STATISTICS: [&str; 16] = [
    "luminance correlation length along (mm)",
    "luminance correlation length across (mm)",
    "luminance spectrum slope along",
    "luminance spectrum slope across",
    "orientation coherence",
    "mean orientation from grain (deg)",
    "dark feature elongation (along/across)",
    "dark feature area fraction",
    "ring width CV",
    "latewood transition width (mm)",
    "fibre dip spread (deg)",
    "in-plane angle spread (deg)",
    "dip correlation length along (mm)",
    "dip correlation length across (mm)",
    "in-plane correlation length along (mm)",
    "in-plane correlation length across (mm)",
];

/// Frequency band of the spectrum slopes, cycles/mm: from figure a few mm across (0.2 c/mm,
/// 5 mm) to the Nyquist frequency of the 0.25 mm pitch (2 c/mm).
pub const SPECTRUM_BAND: (f64, f64) = (0.2, 2.0);
/// Integration scale σ of the structure tensor, mm: a few texels, so that one estimate spans a
/// pore line's width and its neighbours but not a ring.
pub const TENSOR_SIGMA_MM: f64 = 1.0;
/// σ of the smooth trend that dark features are measured against, mm: wider than a pore or
/// streak (0.1–0.3 mm) so they stand out, narrow enough to follow rings and colour blotches.
pub const TREND_SIGMA_MM: f64 = 2.0;
/// A texel is dark when its luminance is at most this fraction of the local trend (10 % darker).
pub const DARK_RATIO: f64 = 0.9;
/// Smallest dark feature counted, texels (0.5 mm² at 0.25 mm): smaller ones are texel noise.
pub const MIN_FEATURE_TEXELS: usize = 8;
/// Rings are visible when the mean profile across the grain carries at least this share of the
/// region's luminance variance, pores smoothed away ([`RING_SMOOTH_MM`]): quartersawn rings run
/// along the grain, so each line along it is nearly uniform (the ringed presets: 0.60; the
/// measured boards, whose bands are irregular or cathedrals: 0.22–0.45).
pub const RING_VARIANCE_SHARE: f64 = 0.5;
/// σ of the smoothing before the ring share is taken, mm (a few pores across).
pub const RING_SMOOTH_MM: f64 = 0.5;
/// σ of the trend removed from the ring profile, mm (wider than a ring).
pub const RING_TREND_SIGMA_MM: f64 = 5.0;

/// A scalar field over a region of a board in grain coordinates: `v[c * na + a]`.
struct Grid {
    na: usize,
    nc: usize,
    v: Vec<f64>,
}

impl Grid {
    /// `f(texel index)` over the texels `along` and `across` the grain (clamped to the board).
    fn new(
        maps: &BoardMaps,
        (along, across): (Range<usize>, Range<usize>),
        f: impl Fn(usize) -> f64,
    ) -> Grid {
        let (w, h) = (maps.board.width as usize, maps.board.height as usize);
        let (n_along, n_across) = if maps.grain_along_x { (w, h) } else { (h, w) };
        let clamp = |r: Range<usize>, n: usize| r.start.min(n)..r.end.min(n).max(r.start.min(n));
        let (along, across) = (clamp(along, n_along), clamp(across, n_across));
        let (na, nc) = (along.len(), across.len());
        let mut v = Vec::with_capacity(na * nc);
        for c in across {
            for a in along.clone() {
                v.push(f(if maps.grain_along_x {
                    c * w + a
                } else {
                    a * w + c
                }));
            }
        }
        Grid { na, nc, v }
    }

    fn at(&self, a: usize, c: usize) -> f64 {
        self.v[c * self.na + a]
    }

    /// The lines along the grain (one per `c`) or across it (one per `a`).
    fn lines(&self, along: bool) -> Vec<Vec<f64>> {
        if along {
            self.v.chunks(self.na.max(1)).map(<[f64]>::to_vec).collect()
        } else {
            (0..self.na)
                .map(|a| (0..self.nc).map(|c| self.at(a, c)).collect())
                .collect()
        }
    }

    /// Separable Gaussian blur of σ texels, the kernel truncated at 3σ and renormalised over the
    /// texels inside the region (so edges are not darkened).
    fn blur(&self, sigma: f64) -> Grid {
        let r = (3.0 * sigma).ceil().max(0.0) as isize;
        let k: Vec<f64> = (-r..=r)
            .map(|i| (-0.5 * (i as f64 / sigma.max(1e-9)).powi(2)).exp())
            .collect();
        let pass = |src: &[f64], n: usize, stride: usize, count: usize, step: usize| {
            let mut out = vec![0.0; src.len()];
            for line in 0..count {
                for i in 0..n as isize {
                    let (mut s, mut ws) = (0.0, 0.0);
                    for j in (i - r).max(0)..(i + r + 1).min(n as isize) {
                        let w = k[(j - i + r) as usize];
                        s += w * src[line * step + j as usize * stride];
                        ws += w;
                    }
                    out[line * step + i as usize * stride] = s / ws;
                }
            }
            out
        };
        let along = pass(&self.v, self.na, 1, self.nc, self.na);
        let v = pass(&along, self.nc, self.na, self.na, 1);
        Grid { v, ..*self }
    }
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// Mean squared deviation from the mean.
fn variance(v: &[f64]) -> f64 {
    let m = mean(v);
    v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / v.len().max(1) as f64
}

/// True when the lines vary about their own means beyond rounding (a constant line's
/// mean-removed values are rounding residue, ~1e-17 of its level).
fn lines_vary(lines: &[Vec<f64>]) -> bool {
    let (var, level): (f64, f64) = lines
        .iter()
        .map(|l| (variance(l), mean(l).powi(2)))
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
    var > 0.0 && var > 1e-20 * level
}

/// Correlation length, in samples: the lag where the normalised autocorrelation of the
/// mean-removed lines, pooled over the lines, first drops below 1/e (linear between lags), the
/// e-folding length of an exponential correlation exp(−k/L) (e.g. Vanmarcke, "Random Fields").
/// The biased estimator (divide by the zero-lag sum) sums to zero over all lags once the mean is
/// removed, so it always crosses; None for lines shorter than 2 or without variance.
fn correlation_length(lines: &[Vec<f64>]) -> Option<f64> {
    let centred: Vec<Vec<f64>> = lines
        .iter()
        .filter(|l| l.len() >= 2)
        .map(|l| {
            let m = mean(l);
            l.iter().map(|x| x - m).collect()
        })
        .collect();
    let lag = |k: usize| -> f64 {
        centred
            .iter()
            .map(|l| {
                l.iter()
                    .zip(&l[k.min(l.len())..])
                    .map(|(x, y)| x * y)
                    .sum::<f64>()
            })
            .sum()
    };
    let n = centred.iter().map(Vec::len).max()?;
    if !lines_vary(lines) {
        return None;
    }
    let r0 = lag(0);
    let target = (-1.0f64).exp();
    let mut prev = 1.0;
    for k in 1..n {
        let r = lag(k) / r0;
        if r < target {
            return Some(k as f64 - 1.0 + (prev - target) / (prev - r));
        }
        prev = r;
    }
    None
}

/// Log-log slope of the mean periodogram of the lines (mean removed, Hann window) against
/// frequency over `band` (cycles/mm), by least squares weighted 1/f so each octave counts alike.
/// A power-law spectrum P ∝ f^−β gives −β (white noise 0, a random walk −2). None with fewer
/// than 3 frequencies in the band or no power.
fn spectrum_slope(lines: &[Vec<f64>], pitch: f64, band: (f64, f64)) -> Option<f64> {
    let n = lines.iter().map(Vec::len).max()?;
    if !lines_vary(lines) {
        return None;
    }
    let lines: Vec<&Vec<f64>> = lines.iter().filter(|l| l.len() == n).collect();
    let df = 1.0 / (n as f64 * pitch);
    let bins: Vec<usize> = (1..=n / 2)
        .filter(|&k| (band.0..=band.1 + 1e-9).contains(&(k as f64 * df)))
        .collect();
    if bins.len() < 3 {
        return None;
    }
    let tau = 2.0 * std::f64::consts::PI;
    let (cos, sin): (Vec<f64>, Vec<f64>) = (0..n)
        .map(|m| {
            (
                (tau * m as f64 / n as f64).cos(),
                (tau * m as f64 / n as f64).sin(),
            )
        })
        .unzip();
    let window: Vec<f64> = (0..n)
        .map(|i| {
            (std::f64::consts::PI * (i as f64 + 0.5) / n as f64)
                .sin()
                .powi(2)
        })
        .collect();
    let mut power = vec![0.0; bins.len()];
    for l in &lines {
        let m = mean(l);
        let x: Vec<f64> = l.iter().zip(&window).map(|(v, w)| (v - m) * w).collect();
        for (p, &k) in power.iter_mut().zip(&bins) {
            let (mut re, mut im) = (0.0, 0.0);
            for (i, xi) in x.iter().enumerate() {
                re += xi * cos[(k * i) % n];
                im += xi * sin[(k * i) % n];
            }
            *p += re * re + im * im;
        }
    }
    let pts: Vec<(f64, f64, f64)> = bins
        .iter()
        .zip(&power)
        .filter(|(_, &p)| p > 0.0)
        .map(|(&k, &p)| {
            let f = k as f64 * df;
            (f.ln(), p.ln(), 1.0 / f)
        })
        .collect();
    if pts.len() < 3 {
        return None;
    }
    let sw: f64 = pts.iter().map(|p| p.2).sum();
    let mx = pts.iter().map(|p| p.2 * p.0).sum::<f64>() / sw;
    let my = pts.iter().map(|p| p.2 * p.1).sum::<f64>() / sw;
    let sxx: f64 = pts.iter().map(|p| p.2 * (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| p.2 * (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// Structure tensor (Bigün & Granlund 1987; Jähne, "Digital Image Processing", ch. 13): the
/// outer product of the luminance gradient (central differences) smoothed by a Gaussian of
/// [`TENSOR_SIGMA_MM`]. Returns (mean coherence (λ1−λ2)/(λ1+λ2) over the texels with any
/// gradient, |angle| in degrees between the grain and the mean orientation of the structure,
/// i.e. the direction across the dominant gradient of the region's summed tensor). The grain is
/// the direction `grain_deg` from the grid's along axis (towards +c): the fibres', not the
/// image's, since a photographed board is rarely square to its fibres.
fn structure_tensor(g: &Grid, pitch: f64, grain_deg: f64) -> (Option<f64>, Option<f64>) {
    if g.na < 3 || g.nc < 3 {
        return (None, None);
    }
    let d = |i: usize, n: usize, f: &dyn Fn(usize) -> f64| {
        let (lo, hi) = (i.saturating_sub(1), (i + 1).min(n - 1));
        (f(hi) - f(lo)) / (hi - lo) as f64
    };
    let mut ga = Vec::with_capacity(g.v.len());
    let mut gc = Vec::with_capacity(g.v.len());
    for c in 0..g.nc {
        for a in 0..g.na {
            ga.push(d(a, g.na, &|x| g.at(x, c)));
            gc.push(d(c, g.nc, &|y| g.at(a, y)));
        }
    }
    let product = |f: &dyn Fn(usize) -> f64| Grid {
        v: (0..g.v.len()).map(f).collect(),
        ..*g
    };
    let sigma = TENSOR_SIGMA_MM / pitch;
    let jaa = product(&|i| ga[i] * ga[i]).blur(sigma).v;
    let jcc = product(&|i| gc[i] * gc[i]).blur(sigma).v;
    let jac = product(&|i| ga[i] * gc[i]).blur(sigma).v;
    let scale = jaa.iter().zip(&jcc).map(|(x, y)| x + y).fold(0.0, f64::max);
    let coherences: Vec<f64> = (0..jaa.len())
        .filter(|&i| jaa[i] + jcc[i] > 1e-9 * scale && scale > 0.0)
        .map(|i| ((jaa[i] - jcc[i]).powi(2) + 4.0 * jac[i].powi(2)).sqrt() / (jaa[i] + jcc[i]))
        .collect();
    let coherence = (!coherences.is_empty()).then(|| mean(&coherences));
    let (saa, scc, sac) = (
        ga.iter().map(|x| x * x).sum::<f64>(),
        gc.iter().map(|x| x * x).sum::<f64>(),
        ga.iter().zip(&gc).map(|(x, y)| x * y).sum::<f64>(),
    );
    let angle = (saa + scc > 0.0)
        .then(|| {
            // The dominant gradient's angle from the grain; the structure runs at right angles to it.
            let gradient = 0.5 * (2.0 * sac).atan2(saa - scc).to_degrees();
            (gradient + 90.0 - grain_deg + 90.0).rem_euclid(180.0) - 90.0
        })
        .map(f64::abs);
    (coherence, angle)
}

/// Dark features: 4-connected sets of texels at most [`DARK_RATIO`] of their local luminance
/// trend (Gaussian, [`TREND_SIGMA_MM`]), at least [`MIN_FEATURE_TEXELS`] large. Returns (median
/// elongation, area fraction of the region they cover). Elongation = √((C_aa + 1/12)/(C_cc + 1/12))
/// from the second moments of the feature's texel positions (1/12: a texel's own extent), i.e.
/// along-grain over across-grain extent: an ellipse of semi-axes A along and B across gives A/B.
/// Vessels cut lengthwise show as streaks along the grain (Hoadley, "Understanding Wood"); a
/// blotchy figure gives round features. Elongation is None without features; the fraction is 0.
fn dark_features(g: &Grid, pitch: f64) -> (Option<f64>, Option<f64>) {
    if g.v.is_empty() {
        return (None, None);
    }
    let trend = g.blur(TREND_SIGMA_MM / pitch);
    let dark: Vec<bool> =
        g.v.iter()
            .zip(&trend.v)
            .map(|(&x, &t)| t > 0.0 && x <= DARK_RATIO * t)
            .collect();
    let mut seen = vec![false; dark.len()];
    let (mut aspects, mut covered) = (Vec::new(), 0usize);
    for start in 0..dark.len() {
        if !dark[start] || seen[start] {
            continue;
        }
        seen[start] = true;
        let (mut stack, mut cells) = (vec![start], Vec::new());
        while let Some(i) = stack.pop() {
            let (a, c) = ((i % g.na) as isize, (i / g.na) as isize);
            cells.push((a as f64, c as f64));
            for (da, dc) in [(0, -1), (-1, 0), (1, 0), (0, 1)] {
                let (x, y) = (a + da, c + dc);
                if x >= 0 && y >= 0 && (x as usize) < g.na && (y as usize) < g.nc {
                    let j = y as usize * g.na + x as usize;
                    if dark[j] && !seen[j] {
                        seen[j] = true;
                        stack.push(j);
                    }
                }
            }
        }
        if cells.len() < MIN_FEATURE_TEXELS {
            continue;
        }
        covered += cells.len();
        let n = cells.len() as f64;
        let (ma, mc) = (
            cells.iter().map(|p| p.0).sum::<f64>() / n,
            cells.iter().map(|p| p.1).sum::<f64>() / n,
        );
        let caa = cells.iter().map(|p| (p.0 - ma).powi(2)).sum::<f64>() / n;
        let ccc = cells.iter().map(|p| (p.1 - mc).powi(2)).sum::<f64>() / n;
        aspects.push(((caa + 1.0 / 12.0) / (ccc + 1.0 / 12.0)).sqrt());
    }
    let elongation = (!aspects.is_empty()).then(|| quantile(&aspects, 0.5));
    (elongation, Some(covered as f64 / g.v.len() as f64))
}

/// Rings seen as lines along the grain (a quartersawn face): the mean luminance profile across
/// the grain, its trend ([`RING_TREND_SIGMA_MM`]) removed, cut at its zero crossings (with
/// hysteresis of a quarter of its std, so texel noise does not cross). Ring widths = distances
/// between successive pale-to-dark crossings; returns (their coefficient of variation, median
/// over rings of the wider of a ring's two edges, mm). An edge's width is its step over its
/// steepest slope (a linear ramp of width W gives W); the wider edge is the gradual
/// earlywood-to-latewood transition, the ring boundary (latewood to the next earlywood) being
/// abrupt (Panshin & de Zeeuw, "Textbook of Wood Technology"). Not applicable (None, None) when
/// the profile carries under [`RING_VARIANCE_SHARE`] of the variance (flat-sawn cathedrals,
/// ringless wood) or fewer than 3 rings fit (the edge width needs 1 ring).
fn rings(g: &Grid, pitch: f64) -> (Option<f64>, Option<f64>) {
    if g.nc < 3 || g.na == 0 || !lines_vary(std::slice::from_ref(&g.v)) {
        return (None, None);
    }
    let profile = |g: &Grid| -> Vec<f64> {
        (0..g.nc)
            .map(|c| mean(&g.v[c * g.na..(c + 1) * g.na]))
            .collect()
    };
    let smooth = g.blur(RING_SMOOTH_MM / pitch);
    let share = variance(&profile(&smooth)) / variance(&smooth.v);
    if share.is_nan() || share < RING_VARIANCE_SHARE {
        return (None, None);
    }
    let p = Grid {
        na: 1,
        nc: g.nc,
        v: profile(g),
    };
    let trend = p.blur(RING_TREND_SIGMA_MM / pitch);
    let d: Vec<f64> = p.v.iter().zip(&trend.v).map(|(x, t)| x - t).collect();
    let h = 0.25 * (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt();
    // Crossings (position, pale-to-dark?), each after the profile has passed ±h on its far side.
    let mut crossings: Vec<(f64, bool)> = Vec::new();
    let mut state = 0i8;
    let mut last_zero = 0.0;
    for i in 0..d.len() {
        if i > 0 && (d[i - 1] >= 0.0) != (d[i] >= 0.0) {
            last_zero = i as f64 - 1.0 + d[i - 1] / (d[i - 1] - d[i]);
        }
        let s = if d[i] > h {
            1
        } else if d[i] < -h {
            -1
        } else {
            0
        };
        if s != 0 && s != state {
            if state != 0 {
                crossings.push((last_zero, s < 0));
            }
            state = s;
        }
    }
    let downs: Vec<f64> = crossings.iter().filter(|c| c.1).map(|c| c.0).collect();
    let widths: Vec<f64> = downs.windows(2).map(|w| w[1] - w[0]).collect();
    let cv = (widths.len() >= 3).then(|| {
        let m = mean(&widths);
        (widths.iter().map(|w| (w - m).powi(2)).sum::<f64>() / widths.len() as f64).sqrt() / m
    });
    // Edge k: its step is between the extremes of the half-rings on either side (from crossing
    // k − 1 to k + 1); its slope the steepest one-texel difference between them.
    let edge = |k: usize| -> Option<f64> {
        let (lo, hi) = (crossings.get(k.checked_sub(1)?)?.0, crossings.get(k + 1)?.0);
        let range = lo.ceil() as usize..(hi.floor() as usize + 1).min(d.len());
        let pick = |sign: f64| {
            range
                .clone()
                .reduce(|i, j| if sign * (d[j] - d[i]) > 0.0 { j } else { i })
        };
        let (imax, imin) = (pick(1.0)?, pick(-1.0)?);
        let slope = (imax.min(imin)..imax.max(imin))
            .map(|i| (d[i + 1] - d[i]).abs())
            .fold(0.0, f64::max);
        (slope > 0.0).then(|| (d[imax] - d[imin]) / slope * pitch)
    };
    let transitions: Vec<f64> = (0..crossings.len())
        .filter(|&k| crossings[k].1)
        .filter_map(|k| {
            let up = edge(k + 1).filter(|_| crossings.get(k + 1).is_some_and(|c| !c.1));
            match (edge(k), up) {
                (Some(a), Some(b)) => Some(a.max(b)),
                _ => None,
            }
        })
        .collect();
    let transition = (!transitions.is_empty()).then(|| quantile(&transitions, 0.5));
    (cv, transition)
}

/// Spread about the median, √(mean (x − median)²): the median is the board's runout or slope of
/// grain (how it was sawn), not its figure. None when empty.
fn spread(v: &[f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let m = quantile(v, 0.5);
    Some((v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / v.len() as f64).sqrt())
}

/// Every [`PATTERN_STATISTICS`] of the texels `across` the grain (every texel along it), at
/// `pitch` mm per texel: mm-valued or scale-free; None where not applicable (see each).
pub fn pattern_statistics(
    maps: &BoardMaps,
    pitch: f64,
    across: Range<usize>,
) -> Vec<(&'static str, Option<f64>)> {
    region_statistics(maps, pitch, (0..usize::MAX, across))
}

/// [`PATTERN_STATISTICS`] of the texels in (`along`, `across`) the grain.
fn region_statistics(
    maps: &BoardMaps,
    pitch: f64,
    region: (Range<usize>, Range<usize>),
) -> Vec<(&'static str, Option<f64>)> {
    let lum = Grid::new(maps, region.clone(), |i| {
        luminance(maps.board.diffuse[i]) as f64
    });
    let dip = Grid::new(maps, region.clone(), |i| maps.dip_deg(i));
    let inplane = Grid::new(maps, region, |i| maps.in_plane_deg(i));
    let length = |g: &Grid, along: bool| correlation_length(&g.lines(along)).map(|k| k * pitch);
    let slope = |along: bool| spectrum_slope(&lum.lines(along), pitch, SPECTRUM_BAND);
    // The region's grain: its median fibre direction in the face, in the grid's frame (rows run
    // down, the stored in-plane angle counts towards image up, so the sign flips).
    let grain_deg = if inplane.v.is_empty() {
        0.0
    } else {
        -quantile(&inplane.v, 0.5)
    };
    let (coherence, orientation) = structure_tensor(&lum, pitch, grain_deg);
    let (elongation, fraction) = dark_features(&lum, pitch);
    let (ring_cv, transition) = rings(&lum, pitch);
    let values = [
        length(&lum, true),
        length(&lum, false),
        slope(true),
        slope(false),
        coherence,
        orientation,
        elongation,
        fraction,
        ring_cv,
        transition,
        spread(&dip.v),
        spread(&inplane.v),
        length(&dip, true),
        length(&dip, false),
        length(&inplane, true),
        length(&inplane, false),
    ];
    PATTERN_STATISTICS
        .iter()
        .zip(values)
        .map(|(&n, v)| (n, v.filter(|x| x.is_finite())))
        .collect()
}

/// Which [`PATTERN_STATISTICS`] look across the grain (along lines across it, or at variation
/// across it: the rings, the fibre-angle spreads of ribbon figure): they are compared over pieces
/// along the grain that keep the board's whole width, since a strip 12 mm wide truncates what they
/// see (maple's dip correlation across: 8.1 mm on the whole board, 0.3–1.1 mm on strips).
pub const ACROSS_GRAIN: [bool; 16] = [
    false, true, false, true, false, false, false, false, true, true, true, true, false, true,
    false, true,
];

/// Every [`PATTERN_STATISTICS`] of `preset` against `measured`, as
/// [`super::appearance::compare_boards`] does it ([`strip_comparison`]): the preset's median over
/// [`STRIPS`] pieces against the measured pieces' median and 10–90 % band, criterion
/// [`Comparison::passes`]. The pieces are strips across the grain (each the board's length), as in
/// `compare_boards`, except for the [`ACROSS_GRAIN`] statistics, whose pieces are [`STRIPS`]
/// lengths along the grain (each the board's width). Whether a statistic applies is decided on the
/// whole board (a 12 mm piece of irregular bands can pass for rings): one not applicable on the
/// whole measured board is left out, one the whole measured board has and the whole preset board
/// lacks is a row whose preset value is +∞, which fails; pieces where it does not apply are
/// skipped.
pub fn compare_patterns(preset: &BoardMaps, measured: &BoardMaps, pitch: f64) -> Vec<Comparison> {
    let pieces = |m: &BoardMaps, along: bool| -> Vec<Vec<(&'static str, Option<f64>)>> {
        let (w, h) = (m.board.width as usize, m.board.height as usize);
        let (na, nc) = if m.grain_along_x { (w, h) } else { (h, w) };
        let piece = |s: usize, n: usize| s * n / STRIPS..(s + 1) * n / STRIPS;
        (0..STRIPS)
            .map(|s| {
                let region = if along {
                    (piece(s, na), 0..nc)
                } else {
                    (0..na, piece(s, nc))
                };
                region_statistics(m, pitch, region)
            })
            .collect()
    };
    let both = |along: bool| (pieces(preset, along), pieces(measured, along));
    let (strips, lengths) = (both(false), both(true));
    let whole = |m: &BoardMaps| region_statistics(m, pitch, (0..usize::MAX, 0..usize::MAX));
    let (pw, mw) = (whole(preset), whole(measured));
    (0..PATTERN_STATISTICS.len())
        .filter_map(|k| {
            mw[k].1?;
            let (p, m) = if ACROSS_GRAIN[k] { &lengths } else { &strips };
            let column = |s: &[Vec<(&str, Option<f64>)>]| -> Vec<f64> {
                s.iter().filter_map(|s| s[k].1).collect()
            };
            let (p, m) = (column(p), column(m));
            if m.is_empty() {
                return None;
            }
            let mut row = strip_comparison(PATTERN_STATISTICS[k], &p, &m);
            if p.is_empty() || pw[k].1.is_none() {
                row.preset = f64::INFINITY;
            }
            Some(row)
        })
        .collect()
}

#[cfg(test)]
mod tests {
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
}

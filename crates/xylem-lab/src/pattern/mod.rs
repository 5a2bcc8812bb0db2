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
mod tests;

//! The aliasing estimator's statistics: the energy terms of renders against reference parts,
//! the delete-one jackknife, Student's t and Fieller's interval for a ratio (derivation:
//! notes/render.md, "The aliasing estimator").

pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The mean of equally long vectors.
pub(super) fn mean_of(v: &[&[f64]]) -> Vec<f64> {
    let mut m = vec![0.0; v[0].len()];
    for x in v {
        for (a, b) in m.iter_mut().zip(x.iter()) {
            *a += b;
        }
    }
    let k = v.len() as f64;
    m.iter_mut().for_each(|a| *a /= k);
    m
}

/// Σ_i ‖v_i − v̄‖² / (k − 1): the sample variance of `k` vectors, summed over their entries.
pub(super) fn spread(v: &[&[f64]], mean: &[f64]) -> f64 {
    let s: f64 = v
        .iter()
        .map(|x| {
            x.iter()
                .zip(mean)
                .map(|(a, m)| (a - m).powi(2))
                .sum::<f64>()
        })
        .sum();
    s / (v.len() as f64 - 1.0)
}

/// The three energies of one setting from the high-passed reference parts `g` (R ≥ 2) and
/// renders `h` (K ≥ 2), all independent: [total, bias, noise], with
/// total = mean_i ‖h_i − ḡ‖² − s_g/R, noise = s_h, bias = total − noise, where s is the
/// sample variance summed over pixels. Unbiased: E total = ‖Hβ‖² + E‖Hn‖², E noise = E‖Hn‖²
/// (notes/render.md).
pub fn energy_terms(g: &[&[f64]], h: &[&[f64]]) -> [f64; 3] {
    let (gm, hm) = (mean_of(g), mean_of(h));
    let reference_noise = spread(g, &gm) / g.len() as f64;
    let total = h
        .iter()
        .map(|x| x.iter().zip(&gm).map(|(a, m)| (a - m).powi(2)).sum::<f64>())
        .sum::<f64>()
        / h.len() as f64
        - reference_noise;
    let noise = spread(h, &hm);
    [total, total - noise, noise]
}

/// A statistic and the jackknife covariance of its outputs.
#[derive(Clone, Debug)]
pub struct Jackknifed {
    /// The statistic on all units.
    pub value: Vec<f64>,
    /// Covariance of the outputs (row-major, n × n).
    pub cov: Vec<Vec<f64>>,
    /// The smallest group's size less one: the degrees of freedom the intervals use.
    pub dof: usize,
}

/// Groups of units, each unit a vector ([`jackknife`]).
pub type Groups<'a> = [Vec<&'a [f64]>];

/// Delete-one jackknife over several independent groups of units (Efron & Stein 1981; for
/// several samples Arvesen 1969): the statistic recomputed with each unit left out in turn, and
/// cov = Σ_groups (n − 1)/n Σ_i (θ₋ᵢ − θ̄)(θ₋ᵢ − θ̄)ᵀ. Every group needs ≥ 3 units (the
/// statistic's spreads need 2 after one is left out).
pub fn jackknife(groups: &Groups, stat: &dyn Fn(&Groups) -> Vec<f64>) -> Jackknifed {
    let value = stat(groups);
    let m = value.len();
    let mut cov = vec![vec![0.0; m]; m];
    for (gi, group) in groups.iter().enumerate() {
        let n = group.len();
        let replicates: Vec<Vec<f64>> = (0..n)
            .map(|leave| {
                let mut g = groups.to_vec();
                g[gi] = (group.iter().enumerate())
                    .filter(|(i, _)| *i != leave)
                    .map(|(_, v)| *v)
                    .collect();
                stat(&g)
            })
            .collect();
        let mean: Vec<f64> = (0..m)
            .map(|j| replicates.iter().map(|r| r[j]).sum::<f64>() / n as f64)
            .collect();
        let f = (n as f64 - 1.0) / n as f64;
        for r in &replicates {
            for a in 0..m {
                for b in 0..m {
                    cov[a][b] += f * (r[a] - mean[a]) * (r[b] - mean[b]);
                }
            }
        }
    }
    let dof = groups.iter().map(|g| g.len()).min().unwrap_or(1) - 1;
    Jackknifed { value, cov, dof }
}

/// Student's t quantile for a two-sided 95 % interval with `dof` degrees of freedom.
pub fn t95(dof: usize) -> f64 {
    use statrs::distribution::{ContinuousCDF, StudentsT};
    StudentsT::new(0.0, 1.0, dof.max(1) as f64)
        .map(|t| t.inverse_cdf(0.975))
        .unwrap_or(1.96)
}

/// A figure and its standard error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    pub value: f64,
    pub se: f64,
}

impl Estimate {
    /// The 95 % interval, value ± t · se.
    pub fn interval(&self, t: f64) -> (f64, f64) {
        (self.value - t * self.se, self.value + t * self.se)
    }
}

/// One setting's high-frequency error energy ([`energy_terms`]), each part with its standard
/// error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Energy {
    /// Of one render: bias + noise (the "aliasing energy").
    pub total: Estimate,
    /// What every render shares: the filter's departure from the pixel average, a fixed
    /// sampling pattern's aliasing, a model difference.
    pub bias: Estimate,
    /// What changes with the seed: Monte Carlo noise, including the sub-pixel texture's
    /// aliasing that random point samples turn into noise.
    pub noise: Estimate,
}

/// A ratio of two energies' totals with its 95 % interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ratio {
    pub value: f64,
    /// Fieller's interval; None when the denominator is not significantly above 0 (the
    /// interval is then unbounded).
    pub interval: Option<(f64, f64)>,
}

/// The energies of several settings against one reference, from the high-passed reference parts
/// and, per setting, its renders (all independent of one another), with their jackknife
/// covariance; `totals_cov[a][b]` is the covariance of setting a's and b's totals (they share
/// the reference). Returns (energies, totals' covariance, degrees of freedom).
pub fn energies(
    reference: &[Vec<f64>],
    settings: &[Vec<Vec<f64>>],
) -> (Vec<Energy>, Vec<Vec<f64>>, usize) {
    let mut groups: Vec<Vec<&[f64]>> = vec![reference.iter().map(|v| v.as_slice()).collect()];
    groups.extend(
        settings
            .iter()
            .map(|s| s.iter().map(|v| v.as_slice()).collect()),
    );
    let stat = |g: &[Vec<&[f64]>]| -> Vec<f64> {
        (1..g.len())
            .flat_map(|s| energy_terms(&g[0], &g[s]))
            .collect()
    };
    let jk = jackknife(&groups, &stat);
    let est = |j: usize| Estimate {
        value: jk.value[j],
        se: jk.cov[j][j].max(0.0).sqrt(),
    };
    let out = (0..settings.len())
        .map(|s| Energy {
            total: est(3 * s),
            bias: est(3 * s + 1),
            noise: est(3 * s + 2),
        })
        .collect();
    let totals_cov = (0..settings.len())
        .map(|a| (0..settings.len()).map(|b| jk.cov[3 * a][3 * b]).collect())
        .collect();
    (out, totals_cov, jk.dof)
}

/// Fieller's interval (Fieller 1954) for the ratio ρ = n/d of two estimates with variances
/// `vn`, `vd` and covariance `c`, at quantile `t`: the ρ with (n − ρd)² ≤ t²(vn − 2ρc + ρ²vd),
/// bounded when d is significant (d² > t² vd). Unlike the delta method it stays right when d's
/// relative error is large.
pub fn ratio_interval(n: f64, d: f64, vn: f64, vd: f64, c: f64, t: f64) -> Ratio {
    let t2 = t * t;
    let a = d * d - t2 * vd;
    let b = n * d - t2 * c;
    let cc = n * n - t2 * vn;
    let disc = b * b - a * cc;
    let interval = (a > 0.0 && disc >= 0.0).then(|| {
        let r = disc.sqrt();
        ((b - r) / a, (b + r) / a)
    });
    Ratio {
        value: n / d,
        interval,
    }
}

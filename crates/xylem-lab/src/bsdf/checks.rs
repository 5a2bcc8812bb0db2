//! The suite's verdicts: each case's numbers summarised into checks (white furnace, sampling,
//! rough finish), each a [`Check`]: criterion, worst value and case.

use super::*;

/// The whole run: per-check summary, per-case results and the settings used.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BsdfValidation {
    /// One summary line per check.
    pub checks: Vec<Check>,
    /// Per-case results.
    pub cases: Vec<CaseResult>,
    /// Each extremes case with its count of NaN / Inf / negative values (0 when clean).
    pub extreme_violations: Vec<(String, u64)>,
    /// The settings used.
    pub settings: Settings,
    /// Largest albedo of the published (unnormalised) lobe cases, for notes/bsdf.md.
    pub published_max_albedo: Option<(f64, String)>,
    /// The rough-finish rows against the layered reference.
    #[serde(default)]
    pub rough_rows: Vec<RoughRow>,
    /// The rough-finish settings used.
    #[serde(default)]
    pub rough_settings: Option<RoughSettings>,
}

impl BsdfValidation {
    /// True when every check passed ("reported" figures cannot fail).
    pub fn passed(&self) -> bool {
        all_passed(&self.checks)
    }
}

/// Runs the suite over all cases in parallel (rayon); `progress` is called once per finished case.
pub fn run_suite(suite: &Suite, progress: &(dyn Fn() + Sync)) -> BsdfValidation {
    let s = &suite.settings;
    let cases: Vec<CaseResult> = suite
        .cases
        .par_iter()
        .enumerate()
        .map(|(i, c)| {
            let r = run_case(c, i, s);
            progress();
            r
        })
        .collect();
    let extreme_violations = suite
        .extremes
        .par_iter()
        .enumerate()
        .map(|(i, c)| {
            let b = c.bsdf().expect("cases are checked when loaded");
            let mut rng = Pcg32::new(s.seed ^ 0xE5, i as u64);
            (
                c.name.clone(),
                extreme_violations(&b, s.extreme_samples, &mut rng),
            )
        })
        .collect();
    let rough_rows = suite.rough.as_ref().map(run_rough).unwrap_or_default();
    summarise(
        cases,
        extreme_violations,
        s.clone(),
        rough_rows,
        suite.rough.clone(),
    )
}

fn summarise(
    cases: Vec<CaseResult>,
    extreme_violations: Vec<(String, u64)>,
    s: Settings,
    rough_rows: Vec<RoughRow>,
    rough: Option<RoughSettings>,
) -> BsdfValidation {
    let mut checks = Vec::new();
    furnace_checks(&mut checks, &cases, &s);
    sampling_checks(&mut checks, &cases, &s);
    push_worst(
        &mut checks,
        "extremes: NaN / Inf / negative values",
        "0".into(),
        extreme_violations
            .iter()
            .map(|(n, v)| (*v as f64, n.clone(), *v == 0))
            .collect(),
        true,
    );
    if let Some(r) = &rough {
        rough_checks(&mut checks, &rough_rows, r);
    }
    let published_max_albedo = published_max_albedo(&cases);
    BsdfValidation {
        checks,
        cases,
        extreme_violations,
        settings: s,
        published_max_albedo,
        rough_rows,
        rough_settings: rough,
    }
}

/// The largest quadrature albedo of the cases with the published (unbounded) normalisation,
/// and where it occurs.
fn published_max_albedo(cases: &[CaseResult]) -> Option<(f64, String)> {
    cases
        .iter()
        .filter(|c| !c.spec.bounded)
        .flat_map(|c| {
            c.furnace.iter().map(move |f| {
                (
                    f.quadrature,
                    format!("{} θo {}°", c.spec.name, f.theta_o_deg),
                )
            })
        })
        .max_by(|a, b| a.0.total_cmp(&b.0))
}

/// Adds to `checks` the check `check` over `items` (figure, case, pass): passed when every item
/// passes, its worst figure the largest (`larger_is_worse`) or the smallest, with its case.
fn push_worst(
    checks: &mut Vec<Check>,
    check: &str,
    criterion: String,
    items: Vec<(f64, String, bool)>,
    larger_is_worse: bool,
) {
    let passed = items.iter().all(|x| x.2);
    let pick = items.iter().max_by(|a, b| {
        let o = a.0.total_cmp(&b.0);
        if larger_is_worse {
            o
        } else {
            o.reverse()
        }
    });
    let (w, case) = pick
        .map(|x| (x.0, x.1.clone()))
        .unwrap_or((0.0, "-".into()));
    checks.push(Check::new(check, criterion, w, case, passed));
}

/// `"{case} {extra}"`, the case column of a per-case row.
fn label(c: &CaseResult, extra: String) -> String {
    format!("{} {}", c.spec.name, extra)
}

/// The white-furnace checks: bounded albedo, the smallest albedo, Monte Carlo against
/// quadrature, and the white substrate under a smooth finish.
fn furnace_checks(checks: &mut Vec<Check>, cases: &[CaseResult], s: &Settings) {
    let bounded: Vec<&CaseResult> = cases.iter().filter(|c| c.spec.bounded).collect();
    push_worst(
        checks,
        "furnace: albedo ≤ 1 + 3σ (max channel)",
        "MC ≤ 1 + 3σ and quadrature ≤ 1.001".into(),
        bounded
            .iter()
            .flat_map(|c| {
                c.furnace.iter().map(|f| {
                    (
                        f.mc.max(f.quadrature),
                        label(c, format!("θo {}°", f.theta_o_deg)),
                        f.mc <= 1.0 + 3.0 * f.sigma && f.quadrature <= 1.001,
                    )
                })
            })
            .collect(),
        true,
    );
    push_worst(
        checks,
        "furnace: min albedo (max channel)",
        "reported".into(),
        cases
            .iter()
            .flat_map(|c| {
                c.furnace.iter().map(|f| {
                    (
                        f.quadrature,
                        label(c, format!("θo {}°", f.theta_o_deg)),
                        true,
                    )
                })
            })
            .collect(),
        false,
    );
    push_worst(
        checks,
        "furnace: MC agrees with quadrature (max abs Δ)",
        format!(
            "abs Δ ≤ {}σ + {} per channel",
            s.furnace_sigmas, s.furnace_abs_tol
        ),
        cases
            .iter()
            .flat_map(|c| {
                c.furnace.iter().map(|f| {
                    (
                        f.worst_diff,
                        label(c, format!("θo {}° ({:.1}σ)", f.theta_o_deg, f.worst_z)),
                        f.agrees,
                    )
                })
            })
            .collect(),
        true,
    );
    push_worst(
        checks,
        "white substrate under smooth finish: min albedo",
        format!(
            "≥ {} for θo ≤ {}°",
            s.white_min_albedo, s.white_max_theta_deg
        ),
        cases
            .iter()
            .filter(|c| c.spec.white && c.spec.roughness < 1e-3)
            .flat_map(|c| {
                c.furnace
                    .iter()
                    .filter(|f| f.theta_o_deg <= s.white_max_theta_deg)
                    .map(|f| {
                        let ok = f.quadrature >= s.white_min_albedo
                            && f.mc + 3.0 * f.sigma >= s.white_min_albedo;
                        (
                            f.quadrature,
                            label(
                                c,
                                format!("θo {}° (MC {:.4} ± {:.4})", f.theta_o_deg, f.mc, f.sigma),
                            ),
                            ok,
                        )
                    })
            })
            .collect(),
        false,
    );
}

/// Reciprocity, and the sampling checks over the χ² runs: p-values (Šidák-corrected), pdf
/// normalisation, sample weights.
fn sampling_checks(checks: &mut Vec<Check>, cases: &[CaseResult], s: &Settings) {
    push_worst(
        checks,
        "reciprocity: max relative error",
        format!("≤ {}", s.reciprocity_tolerance),
        cases
            .iter()
            .map(|c| {
                (
                    c.reciprocity,
                    c.spec.name.clone(),
                    c.reciprocity <= s.reciprocity_tolerance,
                )
            })
            .collect(),
        true,
    );
    let tests = cases.iter().map(|c| c.chi2.len()).sum::<usize>().max(1);
    // Šidák correction: per-test level 1 − (1 − α)^(1/m) keeps the family-wise level at α.
    let alpha = 1.0 - (1.0 - s.significance).powf(1.0 / tests as f64);
    push_worst(
        checks,
        "chi-square: min p-value",
        format!(
            "p ≥ {alpha:.3e} (α = {} Šidák-corrected over {tests} tests)",
            s.significance
        ),
        cases
            .iter()
            .flat_map(|c| {
                c.chi2.iter().map(move |(t, o)| {
                    (
                        o.p_value,
                        format!("{} θo {}°", c.spec.name, t),
                        o.p_value >= alpha && o.impossible == 0,
                    )
                })
            })
            .collect(),
        false,
    );
    push_worst(
        checks,
        "pdf normalisation: max abs(∫pdf − accepted fraction)",
        format!(
            "≤ {} × accepted fraction, or ≤ 5σ (binomial)",
            s.pdf_tolerance
        ),
        cases
            .iter()
            .flat_map(|c| {
                c.chi2.iter().map(move |(t, o)| {
                    let d = (o.pdf_integral - o.accepted).abs();
                    // Binomial standard error of the accepted fraction, at the pdf's own prediction.
                    let q = o.pdf_integral.clamp(0.0, 1.0);
                    let sigma = (q * (1.0 - q) / s.chi2_samples as f64).sqrt()
                        + 1.0 / s.chi2_samples as f64;
                    let ok = d <= s.pdf_tolerance * o.accepted || d <= 5.0 * sigma;
                    (
                        d,
                        format!("{} θo {}° (∫pdf {:.4})", c.spec.name, t, o.pdf_integral),
                        ok,
                    )
                })
            })
            .collect(),
        true,
    );
    push_worst(
        checks,
        "sample weights: max relative error of f and pdf",
        format!("≤ {}", s.weight_tolerance),
        cases
            .iter()
            .flat_map(|c| {
                c.chi2.iter().map(move |(t, o)| {
                    (
                        o.weight_error,
                        format!("{} θo {}°", c.spec.name, t),
                        o.weight_error <= s.weight_tolerance,
                    )
                })
            })
            .collect(),
        true,
    );
}

/// The rough finish against the layered random walk: white substrate, albedo (Lambertian and
/// fibre substrates), interface reflection, BSDF shape, the analytic albedo's bound.
fn rough_checks(checks: &mut Vec<Check>, rough_rows: &[RoughRow], r: &RoughSettings) {
    push_worst(
        checks,
        "white substrate under rough finish: min albedo",
        format!(
            "≥ {} for θo ≤ {}°, α ≤ {} (≥ {} where the reference is)",
            r.white_min_albedo, r.white_max_theta_deg, r.white_max_roughness, r.white_strict_albedo
        ),
        rough_rows
            .iter()
            .filter(|x| white_row_checked(x, r))
            .map(|x| (x.model, x.label(), white_row_ok(x, r)))
            .collect(),
        false,
    );
    push_worst(
        checks,
        "rough finish, Lambertian: albedo against the layered reference (max rel Δ)",
        format!("|Δ| ≤ {} · reference + 3σ", r.tolerance),
        rough_rows
            .iter()
            .filter(|x| !x.is_fiber())
            .map(|x| (x.rel_diff(), x.label(), x.agrees(r)))
            .collect(),
        true,
    );
    // Interface plus the single pass (the model drops fibre light the finish reflects back
    // down, notes/bsdf.md §4.6).
    push_worst(
        checks,
        "rough finish, fibre: albedo against the layered reference (max rel Δ)",
        format!("|Δ| ≤ {} · reference + 3σ (single pass)", r.tolerance),
        rough_rows
            .iter()
            .filter(|x| x.is_fiber())
            .map(|x| (x.rel_diff(), x.label(), x.agrees(r)))
            .collect(),
        true,
    );
    push_worst(
        checks,
        "rough finish: interface reflection against the reference (max abs Δ)",
        "reported".into(),
        rough_rows
            .iter()
            .map(|x| {
                let d = (x.model_interface - x.reference_interface).abs();
                (d, x.label(), true)
            })
            .collect(),
        true,
    );
    push_worst(
        checks,
        "rough finish: BSDF shape, max |Δ| over direction bins",
        "reported (fraction of incident light, 16 bins)".into(),
        rough_rows
            .iter()
            .map(|x| (x.max_bin_diff, x.label(), true))
            .collect(),
        true,
    );
    push_worst(
        checks,
        "rough finish: analytic albedo ≤ 1",
        "quadrature ≤ 1.001, reference paths cut = 0".into(),
        rough_rows
            .iter()
            .map(|x| (x.model, x.label(), x.model <= 1.001 && x.truncated == 0))
            .collect(),
        true,
    );
}

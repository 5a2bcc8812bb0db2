//! The suite's Markdown (validation/REPORT.md's BSDF section), its polar plots and the pdf
//! normalisation table.

use super::*;

/// The rough-finish table of the report: model against reference per row.
fn rough_markdown(rows: &[RoughRow], s: &RoughSettings) -> String {
    let mut md = format!(
        "\nRough finish against the layered random-walk reference (crates/xylem/src/bsdf/layered_reference.rs; \
         {} paths per row, seed {}; analytic albedo by a {}-point two-grid quadrature of `eval`). \
         For the fibre the reference's light after internal reflections (`dropped`) is not in the \
         model and not compared (notes/bsdf.md §4):\n\n",
        s.paths, s.seed, s.quadrature_n
    );
    let table: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            vec![
                r.substrate.clone(),
                format!("{}", r.roughness),
                format!("{}", r.eta),
                format!("{}", r.theta_o_deg),
                format!("{:.4}", r.model),
                format!("{:.4} ± {:.4}", r.reference, r.sigma),
                format!(
                    "{:+.2} %",
                    100.0 * (r.model - r.reference) / r.reference.max(1e-3)
                ),
                format!("{:.4} / {:.4}", r.model_interface, r.reference_interface),
                format!("{:.4}", r.reference_dropped),
                format!("{:.4}", r.max_bin_diff),
            ]
        })
        .collect();
    md += &markdown_table(
        &[
            "substrate",
            "α",
            "η",
            "θo",
            "model",
            "reference",
            "Δ",
            "interface model / ref",
            "dropped",
            "max bin Δ",
        ],
        &table,
    );
    md
}

/// Points (x, y) of the curve f·cos θi in the incidence plane of `wo` (x = sin θi, y = cos θi,
/// scaled by the value; negative x on the side of ωo), `n` points from −90° to 90°.
pub fn incidence_plane_curve(b: &(impl Bsdf + ?Sized), theta_o: f32, n: usize) -> Vec<(f64, f64)> {
    let wo = spherical(theta_o, 0.0);
    (0..n)
        .map(|k| {
            let t = -0.5 * PI + PI * (k as f32 + 0.5) / n as f32;
            // Positive t: the mirror side (φ = π); negative: the side of ωo (φ = 0).
            let wi = spherical(t.abs(), if t > 0.0 { PI } else { 0.0 });
            let v = b.eval(wo, wi).max_element() * wi.z;
            ((v * t.sin()) as f64, (v * t.cos()) as f64)
        })
        .collect()
}

/// Markdown of the bsdf section of REPORT.md; `plots` are (case name, path relative to the report).
pub fn to_markdown(v: &BsdfValidation, plots: &[(String, String)]) -> String {
    let s = &v.settings;
    let mut md = String::from("## BSDF (`xylem validate bsdf`)\n\n");
    md += &format!(
        "{} cases from `validation/bsdf_cases.toml`; furnace at θo ∈ {:?}° with {} samples each and a \
         quadrature step ≤ min({}°, β/2); chi-square at θo ∈ {:?}° with {} samples on {}×{} bins; \
         {} reciprocity pairs per case; seed {}. Overall: **{}**.\n\n",
        v.cases.len(),
        s.theta_o_deg,
        s.furnace_samples,
        s.quadrature_step_deg,
        s.chi2_theta_o_deg,
        s.chi2_samples,
        s.chi2_theta_bins,
        s.chi2_phi_bins,
        s.reciprocity_pairs,
        s.seed,
        if v.passed() { "PASS" } else { "FAIL" }
    );
    md += &checks_table(&v.checks);
    if let Some(r) = &v.rough_settings {
        md += &rough_markdown(&v.rough_rows, r);
    }
    if let Some((a, case)) = &v.published_max_albedo {
        md += &format!(
            "\nFor comparison, the published (unnormalised) fibre lobe reaches an albedo of {a:.3} ({case}); \
             it is not checked against 1 (notes/bsdf.md §2).\n"
        );
    }
    md += "\nFibre lobe alone (k_f = 1, β = 8°, no finish, ωo in the vertical plane of the fibre on the \
           side it points to), directional albedo by quadrature: the published lobe reflects ≈ 2 k_f for \
           fibres in the surface plane and up to ≈ 2π k_f cos(dip) at grazing for dipping fibres; the \
           energy-bounded default never exceeds 1 (notes/bsdf.md §2):\n\n";
    md += &normalisation_markdown(&normalisation_table(
        &[0.0, 10.0, 30.0, 60.0],
        &[0.0, 30.0, 60.0, 80.0, 85.0, 89.0],
    ));
    let mut chi: Vec<(f64, String, u32)> = v
        .cases
        .iter()
        .flat_map(|c| {
            c.chi2
                .iter()
                .map(move |(t, o)| (o.p_value, format!("{} θo {}°", c.spec.name, t), o.dof))
        })
        .collect();
    chi.sort_by(|a, b| a.0.total_cmp(&b.0));
    md += "\nLowest chi-square p-values:\n\n";
    let rows: Vec<Vec<String>> = chi
        .iter()
        .take(5)
        .map(|(p, c, d)| vec![c.clone(), format!("{p:.4}"), d.to_string()])
        .collect();
    md += &markdown_table(&["case", "p-value", "dof"], &rows);
    if !plots.is_empty() {
        md += "\nPolar plots of f·cos θi in the incidence plane (x = sin θi, y = cos θi, radius = value \
                normalised per curve; ωo on the left at θo = 0°, 30°, 60°, 80° in blue, red, green, orange; \
                grey: unit circle; the delta reflection of a smooth finish is not drawn):\n\n";
        for (name, path) in plots {
            md += &format!("- {name}\n\n  ![{name}]({path})\n");
        }
    }
    md
}

/// Why a polar plot could not be written.
#[derive(Debug, thiserror::Error)]
pub enum PolarPlotError {
    /// The case's parameters are out of range for [`WoodBsdf`].
    #[error(transparent)]
    Params(#[from] BsdfError),
    /// The plot's folder could not be made.
    #[error("cannot create folder {path}: {source}")]
    Dir {
        /// The folder.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The PNG could not be written.
    #[error(transparent)]
    Png(#[from] xylem::picture::ImageError),
}

/// Writes the polar plot of `spec` (f·cos θi in the incidence plane at θo = 0°, 30°, 60°, 80°,
/// each curve normalised to its own maximum, so lobe shapes compare across angles) as a PNG.
pub fn write_polar_plot(spec: &CaseSpec, path: &Path) -> Result<(), PolarPlotError> {
    use xylem::picture::plot::{line_plot, PlotOptions, Series, PALETTE};
    let b = spec.bsdf()?;
    let curves: Vec<Vec<(f64, f64)>> = [0.0f32, 30.0, 60.0, 80.0]
        .iter()
        .map(|t| incidence_plane_curve(&b, t.to_radians(), 721))
        .collect();
    let mut series: Vec<Series> = vec![Series {
        points: (0..=180)
            .map(|k| {
                let t = (k as f64 - 90.0).to_radians();
                (t.sin(), t.cos())
            })
            .collect(),
        color: [190, 190, 190],
        markers: false,
        label: String::new(),
    }];
    for (k, c) in curves.iter().enumerate() {
        let max = c
            .iter()
            .map(|(x, y)| x.hypot(*y))
            .fold(0.0f64, f64::max)
            .max(1e-30);
        series.push(Series {
            points: c.iter().map(|(x, y)| (x / max, y / max)).collect(),
            color: PALETTE[k % PALETTE.len()],
            markers: false,
            label: format!("{}°", [0, 30, 60, 80][k]),
        });
    }
    let img = line_plot(
        &series,
        &PlotOptions {
            width: 420,
            height: 230,
            ..PlotOptions::default()
        },
    );
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|source| PolarPlotError::Dir {
            path: dir.to_path_buf(),
            source,
        })?;
    }
    img.write_png(path)?;
    Ok(())
}

/// Directional albedo of the fibre lobe alone (k_f = 1, no diffuse, no finish, β = 8°) by
/// quadrature, published against energy-bounded normalisation, for fibres dipping `dips_deg`
/// and views at `thetas_deg` in the vertical plane of the fibre, on the side it points to
/// (ψr = θo − dip, largest at grazing): rows of (dip, θo, published, energy-bounded). The
/// numbers of notes/bsdf.md §2.
pub fn normalisation_table(dips_deg: &[f32], thetas_deg: &[f32]) -> Vec<(f32, f32, f64, f64)> {
    let mut rows = Vec::new();
    for &dip in dips_deg {
        for &t in thetas_deg {
            let spec = |normalization| CaseSpec {
                diffuse: [0.0; 3],
                fiber_color: [1.0; 3],
                eta: 1.0,
                fiber_dip_deg: dip,
                normalization,
                ..CaseSpec::default()
            };
            let wo = spherical(t.to_radians(), 0.0);
            let a = |n| {
                let b = spec(n).bsdf().expect("valid case");
                albedo_quadrature(&b, wo, 0.25f32.to_radians()).x as f64
            };
            rows.push((
                dip,
                t,
                a(Normalization::Published),
                a(Normalization::EnergyBounded),
            ));
        }
    }
    rows
}

/// Markdown of [`normalisation_table`].
pub fn normalisation_markdown(rows: &[(f32, f32, f64, f64)]) -> String {
    let body: Vec<Vec<String>> = rows
        .iter()
        .map(|(d, t, p, e)| {
            vec![
                format!("{d}"),
                format!("{t}"),
                format!("{p:.3}"),
                format!("{e:.3}"),
            ]
        })
        .collect();
    markdown_table(
        &[
            "fibre dip °",
            "θo °",
            "published albedo",
            "energy-bounded albedo",
        ],
        &body,
    )
}

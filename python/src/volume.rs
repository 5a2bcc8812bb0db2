//! `WoodVolume`: the procedural solid wood of a preset, evaluated at arrays of tree points.

use crate::*;

/// Where a volume's parameters came from: a built-in preset or a preset file.
#[derive(Clone)]
pub(crate) enum Source {
    Preset(String),
    File(PathBuf),
}

impl Source {
    /// `'red_oak'` or `preset_file='woods/oak.toml'`, as the constructors take them.
    pub(crate) fn repr(&self) -> String {
        match self {
            Source::Preset(n) => format!("{n:?}").replace('"', "'"),
            Source::File(f) => {
                format!("preset_file={:?}", f.display().to_string()).replace('"', "'")
            }
        }
    }
}

/// Exactly one of a built-in preset name or a preset file.
pub(crate) fn wood_params(
    preset: Option<String>,
    preset_file: Option<PathBuf>,
) -> PyResult<(xylem::wood::WoodParams, Source)> {
    match (preset, preset_file) {
        (Some(name), None) => {
            let p = xylem::wood::preset(&name).map_err(wood_error)?;
            Ok((p, Source::Preset(name)))
        }
        (None, Some(file)) => {
            let p = xylem::scene::read_preset_file(&file).map_err(|e| match e {
                e @ xylem::scene::PresetFileError::Read(_) => PyOSError::new_err(e.to_string()),
                xylem::scene::PresetFileError::Wood(w) => wood_error(w),
            })?;
            Ok((p, Source::File(file)))
        }
        _ => Err(value_error(format!(
            "give exactly one of `preset` (one of: {}) or `preset_file`",
            xylem::wood::PRESET_NAMES.join(", ")
        ))),
    }
}

pub(crate) fn parse_needs(needs: &Bound<'_, PyAny>) -> PyResult<Needs> {
    let names: Vec<String> = if let Ok(s) = needs.extract::<String>() {
        s.split(',').map(|x| x.trim().to_string()).collect()
    } else {
        needs.extract()?
    };
    let mut out = Needs {
        color: false,
        fibers: false,
        bump: false,
    };
    for n in names {
        match n.as_str() {
            "color" => out.color = true,
            "fibers" => out.fibers = true,
            "bump" => out.bump = true,
            "all" => out = Needs::ALL,
            other => {
                return Err(value_error(format!(
                    "needs: unknown `{other}`; allowed: color, fibers, bump, all"
                )))
            }
        }
    }
    Ok(out)
}

/// The named arrays of texels that `needs` asked for (and the growth time, always computed),
/// over the points' leading shape.
pub(crate) fn texel_dict<'py>(
    py: Python<'py>,
    t: &[WoodTexel],
    needs: Needs,
    shape: &[usize],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let v3 = |f: fn(&WoodTexel) -> Vec3| -> Vec<Vec3> { t.iter().map(f).collect() };
    let v1 = |f: fn(&WoodTexel) -> f32| -> Vec<f32> { t.iter().map(f).collect() };
    d.set_item("growth_time", out(py, v1(|x| x.growth_time), shape)?)?;
    if needs.color {
        d.set_item("diffuse", vec3_out(py, &v3(|x| x.diffuse), shape)?)?;
        d.set_item("fiber_color", vec3_out(py, &v3(|x| x.fiber_color), shape)?)?;
    }
    if needs.color || needs.bump {
        d.set_item("pore_mask", out(py, v1(|x| x.pore_mask), shape)?)?;
    }
    if needs.fibers {
        d.set_item("fiber_dir", vec3_out(py, &v3(|x| x.fiber_dir), shape)?)?;
        d.set_item("ray_dir", vec3_out(py, &v3(|x| x.ray_dir), shape)?)?;
        d.set_item("ray_mask", out(py, v1(|x| x.ray_mask), shape)?)?;
        d.set_item(
            "highlight_width",
            out(py, v1(|x| x.highlight_width), shape)?,
        )?;
    }
    if needs.bump {
        d.set_item("bump", out(py, v1(|x| x.bump), shape)?)?;
        d.set_item("bump_grad", vec3_out(py, &v3(|x| x.bump_grad), shape)?)?;
    }
    Ok(d)
}

/// The procedural solid wood of a species preset (Liu et al. 2016) in tree space (mm, pith
/// along +z).
///
/// Constructor fields:
///
/// - `preset`: a built-in preset name (`xylem.PRESETS`), or
/// - `preset_file`: a preset TOML file (keyword; give exactly one of the two)
/// - `seed`: the tree (keyword, a whole number >= 0; default 0)
///
/// `eval(points, needs="all")` takes tree-space points in mm of shape (..., 3).
#[pyclass(module = "xylem", name = "WoodVolume", frozen)]
pub(crate) struct PyWoodVolume {
    volume: Arc<xylem::wood::WoodVolume>,
    source: Source,
}

#[pymethods]
impl PyWoodVolume {
    #[new]
    #[pyo3(signature = (preset=None, *, preset_file=None, seed=0))]
    fn new(preset: Option<String>, preset_file: Option<PathBuf>, seed: u64) -> PyResult<Self> {
        let (params, source) = wood_params(preset, preset_file)?;
        let volume = xylem::wood::WoodVolume::new(params, seed).map_err(wood_error)?;
        Ok(PyWoodVolume {
            volume: Arc::new(volume),
            source,
        })
    }

    /// The seed that selects the tree.
    #[getter]
    fn seed(&self) -> u64 {
        self.volume.seed()
    }

    fn __repr__(&self) -> String {
        format!(
            "WoodVolume({}, seed={})",
            self.source.repr(),
            self.volume.seed()
        )
    }

    /// Texels at `points` (..., 3), tree-space mm; `needs` is "color", "fibers", "bump", "all" (the
    /// default) or a list / comma-separated string of them. Returns a dict of arrays over the
    /// points' leading shape: always `growth_time`; with color `diffuse`, `fiber_color`,
    /// `pore_mask`; with fibers `fiber_dir`, `ray_dir`, `ray_mask`, `highlight_width` (radians);
    /// with bump `pore_mask`, `bump`, `bump_grad`.
    #[pyo3(signature = (points, needs=None))]
    fn eval<'py>(
        &self,
        py: Python<'py>,
        points: ArrayIn<'py>,
        needs: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let points = batch::vec3("points", &points)?;
        let needs = needs.map_or(Ok(Needs::ALL), parse_needs)?;
        let v = &self.volume;
        let p = &points.data;
        let texels = py.allow_threads(|| {
            let chunk = 1024;
            let mut out = vec![WoodTexel::default(); p.len()];
            out.par_chunks_mut(chunk)
                .zip(p.par_chunks(chunk))
                .for_each(|(o, p)| v.eval_many(p, needs, o));
            out
        });
        texel_dict(py, &texels, needs, &points.lead)
    }
}

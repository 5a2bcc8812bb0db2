//! `WoodBsdf`: the finished-wood BSDF over arrays of shading points, and the field and sample
//! dicts it shares with `WoodHits`.

use crate::*;

/// The fields of `WoodBsdfParams`, in the order the constructor documents them: the names of
/// the engine's parameter table `xylem::bsdf::WOOD_BSDF_PARAMS`.
pub(crate) const BSDF_FIELDS: [&str; 8] = {
    let mut names = [""; 8];
    let mut i = 0;
    while i < names.len() {
        names[i] = xylem::bsdf::WOOD_BSDF_PARAMS[i].name;
        i += 1;
    }
    names
};

/// Per-shading-point BSDF parameters from a dict of fields, each a scalar / 3-vector or an array
/// of them over any leading shape (broadcast together); missing fields take
/// `WoodBsdfParams::default()`. Returns the parameters, flat, and their leading shape.
pub(crate) fn bsdf_params(
    fields: &Bound<'_, PyDict>,
) -> PyResult<(Vec<WoodBsdfParams>, Vec<usize>)> {
    for key in fields.keys() {
        let k: String = key.extract()?;
        if !BSDF_FIELDS.contains(&k.as_str()) {
            return Err(value_error(format!(
                "WoodBsdf: unknown field `{k}`; fields: {}",
                BSDF_FIELDS.join(", ")
            )));
        }
    }
    let d = WoodBsdfParams::default();
    let get3 = |name: &str, default: Vec3| -> PyResult<Arg<Vec3>> {
        let field = format!("WoodBsdfParams.{name}");
        match fields.get_item(name)? {
            Some(v) => batch::vec3(&field, &v),
            None => Ok(Arg::one(default)),
        }
    };
    let get1 = |name: &str, default: f32| -> PyResult<Arg<f32>> {
        let field = format!("WoodBsdfParams.{name}");
        match fields.get_item(name)? {
            Some(v) => batch::scalar(&field, &v),
            None => Ok(Arg::one(default)),
        }
    };
    let (diffuse, fiber_color) = (
        get3("diffuse", d.diffuse)?,
        get3("fiber_color", d.fiber_color)?,
    );
    let (fiber_dir, ray_dir) = (get3("fiber_dir", d.fiber_dir)?, get3("ray_dir", d.ray_dir)?);
    let (ray_mask, width) = (
        get1("ray_mask", d.ray_mask)?,
        get1("highlight_width", d.highlight_width)?,
    );
    let (eta, roughness) = (get1("eta", d.eta)?, get1("roughness", d.roughness)?);
    let b = Broadcast::new(&[
        ("diffuse", &diffuse.lead),
        ("fiber_color", &fiber_color.lead),
        ("fiber_dir", &fiber_dir.lead),
        ("ray_dir", &ray_dir.lead),
        ("ray_mask", &ray_mask.lead),
        ("highlight_width", &width.lead),
        ("eta", &eta.lead),
        ("roughness", &roughness.lead),
    ])?;
    let m = &b.maps;
    let params = (0..b.len)
        .map(|i| WoodBsdfParams {
            diffuse: diffuse.data[m[0].get(i)],
            fiber_color: fiber_color.data[m[1].get(i)],
            fiber_dir: fiber_dir.data[m[2].get(i)],
            ray_dir: ray_dir.data[m[3].get(i)],
            ray_mask: ray_mask.data[m[4].get(i)],
            highlight_width: width.data[m[5].get(i)],
            eta: eta.data[m[6].get(i)],
            roughness: roughness.data[m[7].get(i)],
        })
        .collect();
    Ok((params, b.shape))
}

/// Sample results as a dict of arrays over the leading shape `shape`: `wi` (..., 3), `f` (...,
/// 3), `pdf`, `is_delta`, `valid` (...); where sampling failed `valid` is false and the rest zero.
pub(crate) fn sample_dict<'py>(
    py: Python<'py>,
    s: &[Option<BsdfSample>],
    shape: &[usize],
) -> PyResult<Bound<'py, PyDict>> {
    let get = |f: &dyn Fn(&BsdfSample) -> Vec3| -> Vec<Vec3> {
        s.iter().map(|x| x.as_ref().map_or(Vec3::ZERO, f)).collect()
    };
    let d = PyDict::new(py);
    d.set_item("wi", vec3_out(py, &get(&|x| x.wi), shape)?)?;
    d.set_item("f", vec3_out(py, &get(&|x| x.f), shape)?)?;
    let pdf: Vec<f32> = s.iter().map(|x| x.map_or(0.0, |x| x.pdf)).collect();
    d.set_item("pdf", out(py, pdf, shape)?)?;
    let delta: Vec<bool> = s.iter().map(|x| x.is_some_and(|x| x.is_delta)).collect();
    d.set_item("is_delta", out(py, delta, shape)?)?;
    let valid: Vec<bool> = s.iter().map(|x| x.is_some()).collect();
    d.set_item("valid", out(py, valid, shape)?)?;
    Ok(d)
}

/// The inputs of a `sample` call: directions `wo`, lobe numbers `uc` and 2D numbers `u`.
pub(crate) fn sample_args(wo: &ArrayIn, uc: &ArrayIn, u: &ArrayIn) -> PyResult<SampleArgs> {
    Ok((
        batch::vec3("wo", wo)?,
        batch::scalar("uc", uc)?,
        batch::vec2("u", u)?,
    ))
}

pub(crate) type SampleArgs = (Arg<Vec3>, Arg<f32>, Arg<Vec2>);

/// xylem's finished-wood BSDF (Marschner et al. 2005) at one shading point or an array of them,
/// in the local shading frame (z = normal, unit directions pointing away from the surface).
///
/// Fields (a dict `params` and keywords merge, keywords winning; each missing field takes the
/// default of Rust's `WoodBsdfParams::default()`):
///
/// - `diffuse`: Lambertian substrate albedo, linear RGB in [0, 1] (3-vector or (..., 3))
/// - `fiber_color`: fibre highlight colour k_f, linear RGB >= 0 (3-vector or (..., 3))
/// - `fiber_dir`: fibre axis, unit vector in the local frame (3-vector or (..., 3))
/// - `ray_dir`: ray-cell axis, unit vector in the local frame (3-vector or (..., 3))
/// - `ray_mask`: blend towards the ray fibres, [0, 1] (scalar or (...))
/// - `highlight_width`: the fibre lobe's width beta in radians (scalar or (...))
/// - `eta`: refractive index of the finish, [1, 4]; 1 is unfinished (scalar or (...))
/// - `roughness`: GGX roughness of the finish, [0, 1]; 0 is a smooth finish (scalar or (...))
///
/// Arrays broadcast over their leading dimensions as numpy does; the result's `shape` is their
/// broadcast. `eval(wo, wi)` is f without the cosine, `pdf(wo, wi)` per unit solid angle,
/// `sample(wo, uc, u)` importance-samples wi; directions broadcast against the shading points.
/// Non-finite values raise ValueError naming the field and the element.
#[pyclass(module = "xylem", name = "WoodBsdf", frozen)]
pub(crate) struct PyWoodBsdf {
    bsdfs: Vec<xylem::bsdf::WoodBsdf>,
    shape: Vec<usize>,
}

impl PyWoodBsdf {
    /// `f(bsdf, wo, wi)` at every element of the broadcast (bsdf, wo, wi), GIL released.
    fn at_pairs<T: Send>(
        &self,
        py: Python<'_>,
        wo: &ArrayIn,
        wi: &ArrayIn,
        f: impl Fn(&xylem::bsdf::WoodBsdf, Vec3, Vec3) -> T + Sync + Send,
    ) -> PyResult<(Vec<T>, Vec<usize>)> {
        let (wo, wi) = (batch::vec3("wo", wo)?, batch::vec3("wi", wi)?);
        let b = Broadcast::new(&[("bsdf", &self.shape), ("wo", &wo.lead), ("wi", &wi.lead)])?;
        let (bs, m) = (&self.bsdfs, &b.maps);
        let v = py.allow_threads(|| {
            map_indices(b.len, |i| {
                f(&bs[m[0].get(i)], wo.data[m[1].get(i)], wi.data[m[2].get(i)])
            })
        });
        Ok((v, b.shape))
    }
}

#[pymethods]
impl PyWoodBsdf {
    /// The fields of the constructor, in order.
    #[classattr]
    const FIELDS: [&'static str; 8] = BSDF_FIELDS;

    #[new]
    #[pyo3(signature = (params=None, **fields))]
    fn new(
        py: Python<'_>,
        params: Option<&Bound<'_, PyDict>>,
        fields: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let all = PyDict::new(py);
        if let Some(p) = params {
            all.update(p.as_mapping())?;
        }
        if let Some(f) = fields {
            all.update(f.as_mapping())?;
        }
        let (params, shape) = bsdf_params(&all)?;
        let bsdfs = params
            .iter()
            .enumerate()
            .map(|(i, p)| {
                xylem::bsdf::WoodBsdf::new(*p).map_err(|e| {
                    if shape.is_empty() {
                        value_error(e)
                    } else {
                        value_error(format!(
                            "{e} (shading point {})",
                            batch::index_str(&shape, i)
                        ))
                    }
                })
            })
            .collect::<PyResult<Vec<_>>>()?;
        Ok(PyWoodBsdf { bsdfs, shape })
    }

    /// Number of shading points (the product of `shape`).
    fn __len__(&self) -> usize {
        self.bsdfs.len()
    }

    /// The shading points' shape: () for one, else the fields' broadcast leading shape.
    #[getter]
    fn shape<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        pyo3::types::PyTuple::new(py, &self.shape)
    }

    /// The fields as a dict of arrays of this BSDF's shape (3-vectors with a trailing axis 3).
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let p: Vec<WoodBsdfParams> = self.bsdfs.iter().map(|b| *b.params()).collect();
        params_dict(py, &p, &self.shape)
    }

    fn __repr__(&self) -> String {
        let p = self.bsdfs.first().map(|b| *b.params());
        match (self.shape.is_empty(), p) {
            (true, Some(p)) => format!(
                "WoodBsdf(diffuse={}, fiber_color={}, fiber_dir={}, ray_dir={}, ray_mask={:?}, \
                 highlight_width={:?}, eta={:?}, roughness={:?})",
                tuple3(p.diffuse),
                tuple3(p.fiber_color),
                tuple3(p.fiber_dir),
                tuple3(p.ray_dir),
                p.ray_mask,
                p.highlight_width,
                p.eta,
                p.roughness
            ),
            _ => format!(
                "<WoodBsdf of shape {}: {} shading points>",
                batch::shape_str(&self.shape),
                self.bsdfs.len()
            ),
        }
    }

    /// True where the BSDF has a delta lobe (a smooth finish), of this BSDF's shape.
    fn has_delta<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let v = self.bsdfs.iter().map(|b| b.has_delta()).collect();
        out(py, v, &self.shape)
    }

    /// f(wo, wi) without the cosine, shape (..., 3): wo, wi (..., 3) broadcast with the BSDF.
    fn eval<'py>(
        &self,
        py: Python<'py>,
        wo: ArrayIn<'py>,
        wi: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (f, shape) = self.at_pairs(py, &wo, &wi, |b, o, i| b.eval(o, i))?;
        vec3_out(py, &f, &shape)
    }

    /// The sampling density of `sample` per unit solid angle, shape (...).
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        wo: ArrayIn<'py>,
        wi: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (p, shape) = self.at_pairs(py, &wo, &wi, |b, o, i| b.pdf(o, i))?;
        out(py, p, &shape)
    }

    /// Importance-samples wi given wo (..., 3) and uniform numbers `uc` (...) (lobe choice) and
    /// `u` (..., 2); returns a dict `wi`, `f`, `pdf`, `is_delta`, `valid` over the broadcast.
    fn sample<'py>(
        &self,
        py: Python<'py>,
        wo: ArrayIn<'py>,
        uc: ArrayIn<'py>,
        u: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (wo, uc, u) = sample_args(&wo, &uc, &u)?;
        let b = Broadcast::new(&[
            ("bsdf", &self.shape),
            ("wo", &wo.lead),
            ("uc", &uc.lead),
            ("u", &u.lead),
        ])?;
        let (bs, m) = (&self.bsdfs, &b.maps);
        let s = py.allow_threads(|| {
            map_indices(b.len, |i| {
                bs[m[0].get(i)].sample(
                    wo.data[m[1].get(i)],
                    uc.data[m[2].get(i)],
                    u.data[m[3].get(i)],
                )
            })
        });
        sample_dict(py, &s, &b.shape)
    }
}

/// The `WoodBsdf` fields of `p` as a dict of arrays over the leading shape `shape`.
pub(crate) fn params_dict<'py>(
    py: Python<'py>,
    p: &[WoodBsdfParams],
    shape: &[usize],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let col = |f: fn(&WoodBsdfParams) -> Vec3| -> Vec<Vec3> { p.iter().map(f).collect() };
    let one = |f: fn(&WoodBsdfParams) -> f32| -> Vec<f32> { p.iter().map(f).collect() };
    d.set_item("diffuse", vec3_out(py, &col(|p| p.diffuse), shape)?)?;
    d.set_item("fiber_color", vec3_out(py, &col(|p| p.fiber_color), shape)?)?;
    d.set_item("fiber_dir", vec3_out(py, &col(|p| p.fiber_dir), shape)?)?;
    d.set_item("ray_dir", vec3_out(py, &col(|p| p.ray_dir), shape)?)?;
    d.set_item("ray_mask", out(py, one(|p| p.ray_mask), shape)?)?;
    d.set_item(
        "highlight_width",
        out(py, one(|p| p.highlight_width), shape)?,
    )?;
    d.set_item("eta", out(py, one(|p| p.eta), shape)?)?;
    d.set_item("roughness", out(py, one(|p| p.roughness), shape)?)?;
    Ok(d)
}

/// `max_lobe_albedo(beta, dip)`: the bound on the energy-bounded fibre lobe's directional
/// albedo at any view for highlight width `beta` and fibre dip `dip` = asin|u·n| (radians), as
/// `WoodBsdf` bounds its diffuse with it (bilinear in xylem's table, plus its margin). The baked
/// Mitsuba plugin tabulates it into a Dr.Jit texture.
#[pyfunction]
pub(crate) fn max_lobe_albedo(beta: f32, dip: f32) -> f32 {
    xylem::bsdf::fiber_albedo::max_lobe_albedo(beta, dip)
}

/// `rough_finish_nodes(alpha, eta)`: xylem's rough-finish tables for one finish (GGX roughness
/// `alpha` in [0.001, 1], index `eta` in [1, 4]) on the μ nodes μᵢ = (i/(N−1))², to be
/// interpolated linearly in √μ (`xylem::bsdf::rough_finish::finish_nodes`): a dict of
/// `reflectance` R(μᵢ) and `multiple` R_ms(μᵢ) (N,), `transmission` (N, 11) (the share of
/// single scattering, then mean x, mean z as offsets from the smooth refraction, cov xx, yy, xz
/// of the single- and of the multiple-scattering part), `ms_norm` 1/(π R̄_ms) and
/// `avg_reflectance` R̄. The baked Mitsuba plugin reads them into a Dr.Jit texture.
#[pyfunction]
pub(crate) fn rough_finish_nodes(
    py: Python<'_>,
    alpha: f32,
    eta: f32,
) -> PyResult<Bound<'_, PyDict>> {
    if !(alpha.is_finite() && (1e-3..=1.0).contains(&alpha)) {
        return Err(PyValueError::new_err(format!(
            "rough_finish_nodes: alpha = {alpha}: expected a roughness in [0.001, 1]"
        )));
    }
    if !(eta.is_finite() && (1.0..=4.0).contains(&eta)) {
        return Err(PyValueError::new_err(format!(
            "rough_finish_nodes: eta = {eta}: expected an index in [1, 4]"
        )));
    }
    let n = xylem::bsdf::rough_finish::finish_nodes(alpha, eta);
    let d = PyDict::new(py);
    let rows = n.transmission.len();
    let flat: Vec<f32> = n.transmission.iter().flatten().copied().collect();
    d.set_item("reflectance", out(py, n.reflectance, &[rows])?)?;
    d.set_item("multiple", out(py, n.multiple, &[rows])?)?;
    let cols = xylem::bsdf::rough_transmission::PER_NODE;
    d.set_item("transmission", out(py, flat, &[rows, cols])?)?;
    d.set_item("ms_norm", n.ms_norm)?;
    d.set_item("avg_reflectance", n.avg_reflectance)?;
    Ok(d)
}

//! Python bindings of xylem (PyO3 + numpy), the native module `xylem._xylem` behind the `xylem`
//! package (distributed as `xylem-wood`): the finished-wood BSDF, the wood volume, a wood surface
//! (volume + finish + tree placement, shaded in world space as the renderer shades a hit), and
//! scenes (from files or Python dicts) rendered and light-swept into numpy arrays. Every number
//! comes from the xylem library; these functions only move arrays in and out (broadcasting over
//! leading dimensions as numpy does, `batch`), release the GIL while computing, and turn the
//! library's typed errors into Python exceptions (`ValueError` for values out of range or not
//! finite, `OSError` for files).

mod batch;

use batch::{Arg, Broadcast};
use glam::{Mat3, Vec2, Vec3};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use xylem::bsdf::{Bsdf, BsdfSample, WoodBsdfParams};
use xylem::material::{Cutting, Material, MaterialHit, Placement, ShadingSwitches, WoodMaterial};
use xylem::scene::Overrides;
use xylem::wood::{Needs, WoodError, WoodTexel};

/// Below this many items a call runs on the calling thread (rayon's start-up is not worth it).
const PARALLEL_FROM: usize = 4096;

/// An array argument: anything `numpy.asarray` turns into numbers (`batch`).
type ArrayIn<'py> = Bound<'py, PyAny>;

fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

fn wood_error(e: WoodError) -> PyErr {
    match e {
        WoodError::Io { .. } => PyOSError::new_err(format!("{e}: {}", io_source(&e))),
        other => value_error(other),
    }
}

fn io_source(e: &WoodError) -> String {
    std::error::Error::source(e).map_or(String::new(), |s| s.to_string())
}

/// `f(i)` for i in 0..n, in parallel for large n; the results are in index order either way.
fn map_indices<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
    if n >= PARALLEL_FROM {
        (0..n).into_par_iter().map(f).collect()
    } else {
        (0..n).map(f).collect()
    }
}

/// An array of 3-vectors with leading shape `shape`, as shape (*shape, 3).
fn vec3_out<'py>(py: Python<'py>, v: &[Vec3], shape: &[usize]) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f32> = v.iter().flat_map(|c| c.to_array()).collect();
    let mut s = shape.to_vec();
    s.push(3);
    Ok(PyArray1::from_vec(py, flat).reshape(s)?.into_any())
}

/// An array of scalars (f32 or bool) with shape `shape`.
fn out<'py, T: numpy::Element>(
    py: Python<'py>,
    v: Vec<T>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    Ok(PyArray1::from_vec(py, v)
        .reshape(shape.to_vec())?
        .into_any())
}

/// `(a, b, c)` with each number as Python reads it back exactly (f32's shortest round trip).
fn tuple3(v: Vec3) -> String {
    format!("({:?}, {:?}, {:?})", v.x, v.y, v.z)
}

/// The fields of `WoodBsdfParams`, in the order the constructor documents them.
const BSDF_FIELDS: [&str; 8] = [
    "diffuse",
    "fiber_color",
    "fiber_dir",
    "ray_dir",
    "ray_mask",
    "highlight_width",
    "eta",
    "roughness",
];

/// Per-shading-point BSDF parameters from a dict of fields, each a scalar / 3-vector or an array
/// of them over any leading shape (broadcast together); missing fields take
/// `WoodBsdfParams::default()`. Returns the parameters, flat, and their leading shape.
fn bsdf_params(fields: &Bound<'_, PyDict>) -> PyResult<(Vec<WoodBsdfParams>, Vec<usize>)> {
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
fn sample_dict<'py>(
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
fn sample_args(wo: &ArrayIn, uc: &ArrayIn, u: &ArrayIn) -> PyResult<SampleArgs> {
    Ok((
        batch::vec3("wo", wo)?,
        batch::scalar("uc", uc)?,
        batch::vec2("u", u)?,
    ))
}

type SampleArgs = (Arg<Vec3>, Arg<f32>, Arg<Vec2>);

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
struct PyWoodBsdf {
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
fn params_dict<'py>(
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
/// Where a volume's parameters came from: a built-in preset or a preset file.
#[derive(Clone)]
enum Source {
    Preset(String),
    File(PathBuf),
}

impl Source {
    /// `'red_oak'` or `preset_file='woods/oak.toml'`, as the constructors take them.
    fn repr(&self) -> String {
        match self {
            Source::Preset(n) => format!("{n:?}").replace('"', "'"),
            Source::File(f) => {
                format!("preset_file={:?}", f.display().to_string()).replace('"', "'")
            }
        }
    }
}

/// Exactly one of a built-in preset name or a preset file.
fn wood_params(
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

fn parse_needs(needs: &Bound<'_, PyAny>) -> PyResult<Needs> {
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
fn texel_dict<'py>(
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
struct PyWoodVolume {
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

/// A wood surface as the renderer shades it: the volume under a finish, placed in the tree by a
/// solid cutting in world space (`p_tree = origin + scale * Rz(rotation) * A * p`, A turning
/// `axis` onto the pith). Methods take world-space points `p`, shading normals `n` and
/// directions, each of shape (..., 3) (broadcast as numpy does), and the sample numbers `uc`
/// (...) and `u` (..., 2).
///
/// Constructor fields:
///
/// - `preset`: a built-in preset name (`xylem.PRESETS`), or
/// - `preset_file`: a preset TOML file (keyword; give exactly one of the two)
/// - `seed`: the tree (whole number >= 0; default 0)
/// - `eta`: refractive index of the finish, [1, 4] (default 1.5; 1 is unfinished)
/// - `roughness`: GGX roughness of the finish, [0, 1] (default 0, a smooth finish)
/// - `origin`: the tree point (mm) at the world origin, 3 finite numbers (default (0, 0, 0))
/// - `axis`: the world direction of the pith, non-zero (default (0, 0, 1))
/// - `rotation_deg`: rotation about the pith, degrees (default 0)
/// - `scale`: tree mm per world unit, [1e-6, 1e6] (default 1: a scene in mm)
#[pyclass(module = "xylem", name = "WoodSurface", frozen)]
struct PyWoodSurface {
    material: Material,
    placement: Placement,
    source: Source,
    seed: u64,
    finish: (f32, f32),
    axis: Vec3,
    rotation_deg: f32,
    /// Shading points evaluated so far, by every method (`shade_count`, a debug counter).
    shaded: AtomicU64,
}

impl PyWoodSurface {
    /// Shades world point `p` with shading normal `n` (normalised unless it is unit already).
    fn shade_one(&self, p: Vec3, n: Vec3) -> xylem::material::Shading {
        let n = if (n.length_squared() - 1.0).abs() <= 1e-6 {
            n
        } else {
            n.normalize_or(Vec3::Z)
        };
        let hit = MaterialHit {
            p_object: p,
            p_world: p,
            n_object: n,
            ng: n,
            ns: n,
            tangent: n.any_orthonormal_vector(),
            object_to_world: Mat3::IDENTITY,
            normal_to_world: Mat3::IDENTITY,
            placement: self.placement,
            footprint: 0.0,
        };
        self.shaded.fetch_add(1, Ordering::Relaxed);
        self.material.shade(&hit)
    }

    /// `f(bsdf, wo, wi)` in xylem's local frame at every element of the broadcast (p, n, wo,
    /// wi), world inputs.
    fn at_pairs<T: Send>(
        &self,
        py: Python<'_>,
        [p, n, wo, wi]: [&ArrayIn; 4],
        f: impl Fn(&xylem::material::SurfaceBsdf, Vec3, Vec3) -> T + Sync + Send,
    ) -> PyResult<(Vec<T>, Vec<usize>)> {
        let (p, nn) = (batch::vec3("p", p)?, batch::vec3("n", n)?);
        let (wo, wi) = (batch::vec3("wo", wo)?, batch::vec3("wi", wi)?);
        let b = Broadcast::new(&[
            ("p", &p.lead),
            ("n", &nn.lead),
            ("wo", &wo.lead),
            ("wi", &wi.lead),
        ])?;
        let m = &b.maps;
        let v = py.allow_threads(|| {
            map_indices(b.len, |i| {
                let s = self.shade_one(p.data[m[0].get(i)], nn.data[m[1].get(i)]);
                let to_local = |d: Vec3| s.frame.to_local(d);
                f(
                    &s.bsdf,
                    to_local(wo.data[m[2].get(i)]),
                    to_local(wi.data[m[3].get(i)]),
                )
            })
        });
        Ok((v, b.shape))
    }
}

#[pymethods]
impl PyWoodSurface {
    #[new]
    #[pyo3(signature = (preset=None, *, preset_file=None, seed=0, eta=1.5, roughness=0.0,
        origin=[0.0, 0.0, 0.0], axis=[0.0, 0.0, 1.0], rotation_deg=0.0, scale=1.0),
        text_signature = "(preset=None, *, preset_file=None, seed=0, eta=1.5, roughness=0.0, \
            origin=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0), rotation_deg=0.0, scale=1.0)")]
    #[allow(clippy::too_many_arguments)]
    fn new(
        preset: Option<String>,
        preset_file: Option<PathBuf>,
        seed: u64,
        eta: f32,
        roughness: f32,
        origin: [f32; 3],
        axis: [f32; 3],
        rotation_deg: f32,
        scale: f32,
    ) -> PyResult<Self> {
        // The finish is checked by the BSDF itself, so the message names its field and range.
        xylem::bsdf::WoodBsdf::new(WoodBsdfParams {
            eta,
            roughness,
            ..Default::default()
        })
        .map_err(value_error)?;
        let axis = Vec3::from(axis);
        if !(axis.is_finite() && axis.length() > 1e-6) {
            return Err(value_error(format!(
                "axis = {axis}: must be a finite non-zero direction"
            )));
        }
        if !(scale.is_finite() && (1e-6..=1e6).contains(&scale)) {
            return Err(value_error(format!(
                "scale = {scale}: must be tree mm per unit in [0.000001, 1e6]"
            )));
        }
        let origin = Vec3::from(origin);
        if !origin.is_finite() || !rotation_deg.is_finite() {
            return Err(value_error("origin and rotation_deg must be finite"));
        }
        let (params, source) = wood_params(preset, preset_file)?;
        let volume = xylem::wood::WoodVolume::new(params, seed).map_err(wood_error)?;
        Ok(PyWoodSurface {
            material: Material::Wood(Box::new(WoodMaterial {
                volume: Arc::new(volume),
                eta,
                roughness,
                bump: 0.0,
                switches: ShadingSwitches::default(),
            })),
            placement: Placement {
                origin,
                axis,
                rotation: rotation_deg.to_radians(),
                scale,
                cutting: Cutting::Solid,
                world_space: true,
                tilt: Default::default(),
            },
            source,
            seed,
            finish: (eta, roughness),
            axis,
            rotation_deg,
            shaded: AtomicU64::new(0),
        })
    }

    fn __repr__(&self) -> String {
        let p = &self.placement;
        format!(
            "WoodSurface({}, seed={}, eta={:?}, roughness={:?}, origin={}, axis={}, \
             rotation_deg={:?}, scale={:?})",
            self.source.repr(),
            self.seed,
            self.finish.0,
            self.finish.1,
            tuple3(p.origin),
            tuple3(self.axis),
            self.rotation_deg,
            p.scale
        )
    }

    /// How many shading points (evaluations of the wood: the tree point, the texel and the
    /// BSDF built there) this surface has computed so far, by every method: `shade`, `eval`,
    /// `pdf` and `sample` count one per element of their broadcast, `prepare` one per point. A
    /// debug counter: the Mitsuba plugin's tests read it to prove the wood is evaluated once
    /// per interaction.
    #[getter]
    fn shade_count(&self) -> u64 {
        self.shaded.load(Ordering::Relaxed)
    }

    /// The wood shaded once at world points `p` (..., 3) in the caller's shading frames `frame`
    /// (..., 3, 3; rows s, t, n in world space, orthonormal, n the shading normal): a
    /// `WoodHits` whose `eval`, `pdf`, `eval_pdf` and `sample` take and return directions in
    /// the caller's frames and evaluate only the BSDF, never the wood again. The values are
    /// those of `eval` / `pdf` / `sample` here with the directions mapped to world space by
    /// `frame` (to float rounding).
    fn prepare(&self, py: Python<'_>, p: ArrayIn<'_>, frame: ArrayIn<'_>) -> PyResult<PyWoodHits> {
        let (p, fr) = (batch::vec3("p", &p)?, batch::mat3("frame", &frame)?);
        let b = Broadcast::new(&[("p", &p.lead), ("frame", &fr.lead)])?;
        // Refused before any shading: a frame that is not orthonormal would rotate the
        // directions wrongly (its transpose would not be its inverse).
        if let Some(i) = fr.data.iter().position(|m| !orthonormal(m)) {
            return Err(value_error(format!(
                "frame: element {} is not orthonormal (rows s, t, n must be unit and \
                 perpendicular to 1e-3)",
                batch::index_str(&fr.lead, i)
            )));
        }
        let m = &b.maps;
        let hits = py.allow_threads(|| {
            map_indices(b.len, |i| {
                let [cs, ct, cn] = fr.data[m[1].get(i)];
                let s = self.shade_one(p.data[m[0].get(i)], cn);
                // Caller-local -> world is C^T (C the rows s, t, n), world -> xylem-local is
                // F (xylem's frame rows): column c of F C^T is axis c of C in xylem's frame.
                let f = s.frame;
                let to_xylem = Mat3::from_cols(f.to_local(cs), f.to_local(ct), f.to_local(cn));
                (s.bsdf, to_xylem)
            })
        });
        Ok(PyWoodHits {
            hits,
            shape: b.shape,
        })
    }

    /// The BSDF parameters at world points `p` (..., 3) with shading normals `n` (..., 3), in the
    /// shading frame xylem builds there (z = n, x along the fibre's surface projection): a dict
    /// of the `WoodBsdf` fields and `frame` (..., 3, 3), rows s, t, n in world space.
    fn shade<'py>(
        &self,
        py: Python<'py>,
        p: ArrayIn<'py>,
        n: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (p, nn) = (batch::vec3("p", &p)?, batch::vec3("n", &n)?);
        let b = Broadcast::new(&[("p", &p.lead), ("n", &nn.lead)])?;
        let m = &b.maps;
        let shaded = py.allow_threads(|| {
            map_indices(b.len, |i| {
                let s = self.shade_one(p.data[m[0].get(i)], nn.data[m[1].get(i)]);
                let params = match s.bsdf {
                    xylem::material::SurfaceBsdf::Wood(b) => *b.params(),
                    // A texel the BSDF rejected falls back to a Lambertian of its colour.
                    _ => WoodBsdfParams {
                        diffuse: s.aov.albedo,
                        fiber_color: Vec3::ZERO,
                        ..Default::default()
                    },
                };
                (params, s.frame)
            })
        });
        let params: Vec<WoodBsdfParams> = shaded.iter().map(|x| x.0).collect();
        let d = params_dict(py, &params, &b.shape)?;
        let frames: Vec<f32> = shaded
            .iter()
            .flat_map(|(_, f)| [f.s.to_array(), f.t.to_array(), f.n.to_array()])
            .flatten()
            .collect();
        d.set_item("frame", out(py, frames, &b.with(&[3, 3]))?)?;
        Ok(d)
    }

    /// f(wo, wi) without the cosine at world points `p` with shading normals `n`; `wo`, `wi` are
    /// world-space unit directions away from the surface. Shape (..., 3).
    fn eval<'py>(
        &self,
        py: Python<'py>,
        p: ArrayIn<'py>,
        n: ArrayIn<'py>,
        wo: ArrayIn<'py>,
        wi: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (f, shape) = self.at_pairs(py, [&p, &n, &wo, &wi], |b, o, i| b.eval(o, i))?;
        vec3_out(py, &f, &shape)
    }

    /// The sampling density per unit solid angle of world direction `wi`, shape (...).
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        p: ArrayIn<'py>,
        n: ArrayIn<'py>,
        wo: ArrayIn<'py>,
        wi: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (pdf, shape) = self.at_pairs(py, [&p, &n, &wo, &wi], |b, o, i| b.pdf(o, i))?;
        out(py, pdf, &shape)
    }

    /// Samples a world direction `wi` given `wo`; as `WoodBsdf.sample`, with `wi` in world space.
    fn sample<'py>(
        &self,
        py: Python<'py>,
        p: ArrayIn<'py>,
        n: ArrayIn<'py>,
        wo: ArrayIn<'py>,
        uc: ArrayIn<'py>,
        u: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (p, nn) = (batch::vec3("p", &p)?, batch::vec3("n", &n)?);
        let (wo, uc, u) = sample_args(&wo, &uc, &u)?;
        let b = Broadcast::new(&[
            ("p", &p.lead),
            ("n", &nn.lead),
            ("wo", &wo.lead),
            ("uc", &uc.lead),
            ("u", &u.lead),
        ])?;
        let m = &b.maps;
        let s = py.allow_threads(|| {
            map_indices(b.len, |i| {
                let s = self.shade_one(p.data[m[0].get(i)], nn.data[m[1].get(i)]);
                let frame = s.frame;
                s.bsdf
                    .sample(
                        frame.to_local(wo.data[m[2].get(i)]),
                        uc.data[m[3].get(i)],
                        u.data[m[4].get(i)],
                    )
                    .map(|x| BsdfSample {
                        wi: frame.to_world(x.wi),
                        ..x
                    })
            })
        });
        sample_dict(py, &s, &b.shape)
    }
}
/// True when the rows of `m` are unit and perpendicular (to 1e-3).
fn orthonormal(m: &[Vec3; 3]) -> bool {
    let ok = |x: f32, want: f32| (x - want).abs() <= 1e-3;
    ok(m[0].length_squared(), 1.0)
        && ok(m[1].length_squared(), 1.0)
        && ok(m[2].length_squared(), 1.0)
        && ok(m[0].dot(m[1]), 0.0)
        && ok(m[0].dot(m[2]), 0.0)
        && ok(m[1].dot(m[2]), 0.0)
}

/// A `WoodSurface` shaded once at a batch of hit points (`WoodSurface.prepare(p, frame)`): the
/// BSDF built from the wood at each point and the rotation from the caller's shading frame to
/// xylem's. `eval(wo, wi)`, `pdf(wo, wi)`, `eval_pdf(wo, wi)` and `sample(wo, uc, u)` take and
/// return unit directions in the caller's frame (z = the shading normal), broadcast against the
/// points as `WoodBsdf`'s do, and evaluate only the BSDF (the wood is not evaluated again:
/// `WoodSurface.shade_count` does not move). `eval` is f without the cosine.
#[pyclass(module = "xylem", name = "WoodHits", frozen)]
struct PyWoodHits {
    /// The BSDF at each point and the caller-local -> xylem-local rotation there (its
    /// transpose is the inverse); one vector, as `prepare` collects them.
    hits: Vec<(xylem::material::SurfaceBsdf, Mat3)>,
    shape: Vec<usize>,
}

impl PyWoodHits {
    /// `f(bsdf, wo, wi)` in xylem's frame at every element of the broadcast (hits, wo, wi).
    fn at_pairs<T: Send>(
        &self,
        py: Python<'_>,
        wo: &ArrayIn,
        wi: &ArrayIn,
        f: impl Fn(&xylem::material::SurfaceBsdf, Vec3, Vec3) -> T + Sync + Send,
    ) -> PyResult<(Vec<T>, Vec<usize>)> {
        let (wo, wi) = (batch::vec3("wo", wo)?, batch::vec3("wi", wi)?);
        let b = Broadcast::new(&[("hits", &self.shape), ("wo", &wo.lead), ("wi", &wi.lead)])?;
        let m = &b.maps;
        let v = py.allow_threads(|| {
            map_indices(b.len, |i| {
                let (bsdf, r) = &self.hits[m[0].get(i)];
                f(bsdf, *r * wo.data[m[1].get(i)], *r * wi.data[m[2].get(i)])
            })
        });
        Ok((v, b.shape))
    }
}

#[pymethods]
impl PyWoodHits {
    /// Number of hit points (the product of `shape`).
    fn __len__(&self) -> usize {
        self.hits.len()
    }

    /// The hit points' shape (the broadcast of `prepare`'s `p` and `frame`).
    #[getter]
    fn shape<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        pyo3::types::PyTuple::new(py, &self.shape)
    }

    fn __repr__(&self) -> String {
        format!(
            "<WoodHits of shape {}: {} hit points>",
            batch::shape_str(&self.shape),
            self.hits.len()
        )
    }

    /// f(wo, wi) without the cosine, shape (..., 3); directions in the caller's frame.
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

    /// `(eval(wo, wi), pdf(wo, wi))` in one pass over the points (the same numbers).
    fn eval_pdf<'py>(
        &self,
        py: Python<'py>,
        wo: ArrayIn<'py>,
        wi: ArrayIn<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let (v, shape) = self.at_pairs(py, &wo, &wi, |b, o, i| (b.eval(o, i), b.pdf(o, i)))?;
        let (f, pdf): (Vec<Vec3>, Vec<f32>) = v.into_iter().unzip();
        Ok((vec3_out(py, &f, &shape)?, out(py, pdf, &shape)?))
    }

    /// Importance-samples wi given wo (..., 3), `uc` (...) and `u` (..., 2); as
    /// `WoodBsdf.sample`, with `wi` in the caller's frame.
    fn sample<'py>(
        &self,
        py: Python<'py>,
        wo: ArrayIn<'py>,
        uc: ArrayIn<'py>,
        u: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (wo, uc, u) = sample_args(&wo, &uc, &u)?;
        let b = Broadcast::new(&[
            ("hits", &self.shape),
            ("wo", &wo.lead),
            ("uc", &uc.lead),
            ("u", &u.lead),
        ])?;
        let m = &b.maps;
        let s = py.allow_threads(|| {
            map_indices(b.len, |i| {
                let (bsdf, r) = &self.hits[m[0].get(i)];
                bsdf.sample(
                    *r * wo.data[m[1].get(i)],
                    uc.data[m[2].get(i)],
                    u.data[m[3].get(i)],
                )
                .map(|x| BsdfSample {
                    wi: r.transpose() * x.wi,
                    ..x
                })
            })
        });
        sample_dict(py, &s, &b.shape)
    }
}

/// `threads`: 0 (all cores) up to 16 per core, as `--threads`.
/// A `quality=` keyword (`draft`, `default` or `final`, as `--quality`).
fn parse_quality(quality: Option<&str>) -> PyResult<Option<xylem::scene::quality::Quality>> {
    quality
        .map(|q| q.parse().map_err(|e| value_error(format!("quality: {e}"))))
        .transpose()
}

fn check_threads(threads: usize) -> PyResult<()> {
    use xylem::render::resources::{check_threads, ResourceError};
    check_threads(threads).map_err(|e| match e {
        ResourceError::Threads { max, .. } => value_error(format!(
            "threads = {threads}: out of range (allowed 0 = all cores, up to {max})"
        )),
        other => value_error(other),
    })
}

fn scene_error(e: xylem::scene::SceneError) -> PyErr {
    match e {
        xylem::scene::SceneError::Io { .. } | xylem::scene::SceneError::Input(_) => {
            PyOSError::new_err(e.to_string())
        }
        other => value_error(other),
    }
}

/// A Python value as a TOML value: dict → table, list / tuple / numpy array → array, bool, int,
/// float, str, numpy scalars and `os.PathLike` (a path string); `at` names the key for errors.
fn toml_value(v: &Bound<'_, PyAny>, at: &str) -> PyResult<toml::Value> {
    use pyo3::types::{PyBool, PyFloat, PyInt, PyList, PyString, PyTuple};
    if let Ok(d) = v.downcast::<PyDict>() {
        let mut t = toml::Table::new();
        for (k, x) in d.iter() {
            let key: String = k.extract().map_err(|_| {
                value_error(format!("scene dict: a key in `{at}` is not a string: {k}"))
            })?;
            let here = if at.is_empty() {
                key.clone()
            } else {
                format!("{at}.{key}")
            };
            t.insert(key, toml_value(&x, &here)?);
        }
        return Ok(toml::Value::Table(t));
    }
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        return Ok(toml::Value::Integer(v.extract().map_err(|_| {
            value_error(format!("scene dict: `{at}` = {v}: out of the 64-bit range"))
        })?));
    }
    if v.is_instance_of::<PyFloat>() {
        let x: f64 = v.extract()?;
        if !x.is_finite() {
            return Err(value_error(format!(
                "scene dict: `{at}` = {x}: must be finite"
            )));
        }
        return Ok(toml::Value::Float(x));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items = v
            .try_iter()?
            .enumerate()
            .map(|(i, x)| toml_value(&x?, &format!("{at}[{i}]")))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(items));
    }
    if v.hasattr("__fspath__")? {
        let p: PathBuf = v.extract()?;
        return Ok(toml::Value::String(p.display().to_string()));
    }
    // numpy arrays and scalars: their Python equivalents.
    if v.hasattr("tolist")? {
        return toml_value(&v.call_method0("tolist")?, at);
    }
    Err(value_error(format!(
        "scene dict: `{at}` = {}: a {} is not a scene value (use dicts, lists, numbers, \
         strings and booleans, as in a scene file)",
        v.repr()?,
        v.get_type().name()?
    )))
}

/// A loaded scene, ready to render many times (as `mitsuba.load_dict` gives). Made by
/// `xylem.load_file(path)` or `xylem.load_dict(dict)`; `render` and `sweep` take it in place
/// of a file. Renders of one Scene from several threads run one after the other.
#[pyclass(module = "xylem", name = "Scene", frozen)]
struct PyScene {
    loaded: Mutex<xylem::scene::LoadedScene>,
    /// The file, or `<dict>`.
    origin: String,
}

impl PyScene {
    fn new(loaded: xylem::scene::LoadedScene, origin: String) -> Self {
        PyScene {
            loaded: Mutex::new(loaded),
            origin,
        }
    }

    /// The scene locked for this thread; other threads' renders of it are waited for with the
    /// GIL released.
    fn lock(
        &self,
        py: Python<'_>,
    ) -> PyResult<std::sync::MutexGuard<'_, xylem::scene::LoadedScene>> {
        loop {
            match self.loaded.try_lock() {
                Ok(g) => return Ok(g),
                Err(std::sync::TryLockError::WouldBlock) => {
                    py.allow_threads(|| std::thread::sleep(std::time::Duration::from_millis(5)));
                    py.check_signals()?;
                }
                Err(std::sync::TryLockError::Poisoned(p)) => return Ok(p.into_inner()),
            }
        }
    }
}

#[pymethods]
impl PyScene {
    /// The scene's name (the file stem, or `name` of `load_dict`).
    #[getter]
    fn name(&self, py: Python<'_>) -> PyResult<String> {
        Ok(self.lock(py)?.name.clone())
    }

    /// (width, height) of the camera's image.
    #[getter]
    fn res(&self, py: Python<'_>) -> PyResult<(u32, u32)> {
        let s = self.lock(py)?;
        Ok((s.scene.camera.width, s.scene.camera.height))
    }

    /// Samples per pixel of the scene's `[render]` table.
    #[getter]
    fn spp(&self, py: Python<'_>) -> PyResult<u32> {
        Ok(self.lock(py)?.settings.spp)
    }

    /// Non-fatal problems found while loading (e.g. degenerate triangles dropped).
    #[getter]
    fn warnings(&self, py: Python<'_>) -> PyResult<Vec<String>> {
        Ok(self.lock(py)?.warnings.clone())
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let s = self.lock(py)?;
        Ok(format!(
            "<xylem.Scene '{}' from {}: {}x{}, {} spp, {} lights, {} materials{}>",
            s.name,
            self.origin,
            s.scene.camera.width,
            s.scene.camera.height,
            s.settings.spp,
            s.scene.lights.len(),
            s.scene.materials.len(),
            if s.sweep.is_some() { ", [sweep]" } else { "" }
        ))
    }
}

/// `load_file(path)`: reads and builds a scene file (or a built-in scene by name) once, for
/// many renders.
#[pyfunction]
fn load_file(scene: PathBuf) -> PyResult<PyScene> {
    let loaded = xylem::scene::load(&scene).map_err(scene_error)?;
    Ok(PyScene::new(loaded, scene.display().to_string()))
}

/// `load_dict(scene, *, name="scene", base=None)`: builds a scene from a dict with the keys and
/// values of a scene file (scenes/README.md: `camera`, `render`, `materials`, `objects`,
/// `lights`, `sweep`, ...); relative files (meshes, maps) resolve against `base` (default: the
/// current folder). Errors name
/// the field as for a file, with `<dict>` as the file.
#[pyfunction]
#[pyo3(signature = (scene, *, name="scene", base=None))]
fn load_dict(scene: &Bound<'_, PyDict>, name: &str, base: Option<PathBuf>) -> PyResult<PyScene> {
    let base = base.unwrap_or_else(|| PathBuf::from("."));
    let value = toml_value(scene.as_any(), "")?;
    let text = toml::to_string(&value).map_err(|e| value_error(format!("scene dict: {e}")))?;
    let loaded = xylem::scene::from_str(&text, "<dict>", &base, name).map_err(scene_error)?;
    Ok(PyScene::new(loaded, "<dict>".into()))
}

/// Runs `f` on the scene `scene` (a `Scene`, a dict or a file path) with the overrides
/// applied; a `Scene`'s own settings are restored afterwards.
fn with_scene<T>(
    py: Python<'_>,
    scene: &Bound<'_, PyAny>,
    o: &Overrides,
    f: impl FnOnce(&xylem::scene::LoadedScene) -> PyResult<T>,
) -> PyResult<T> {
    o.check().map_err(value_error)?;
    let apply = |loaded: &mut xylem::scene::LoadedScene| -> PyResult<T> {
        // Overrides change the settings and camera, and a quality preset or footprint switch
        // the materials (wood volumes rebuilt with the knobs): all three are restored after.
        let (settings, camera) = (loaded.settings, loaded.scene.camera);
        let materials = (o.quality.is_some() || o.footprint_filter.is_some())
            .then(|| loaded.scene.materials.clone());
        let r = o
            .apply(loaded)
            .map_err(value_error)
            .and_then(|()| f(loaded));
        (loaded.settings, loaded.scene.camera) = (settings, camera);
        if let Some(m) = materials {
            loaded.scene.materials = m;
        }
        r
    };
    if let Ok(s) = scene.downcast::<PyScene>() {
        let mut guard = s.get().lock(py)?;
        return apply(&mut guard);
    }
    let mut loaded = if let Ok(d) = scene.downcast::<PyDict>() {
        load_dict(d, "scene", None)?
            .loaded
            .into_inner()
            .map_err(|_| value_error("scene dict: unusable"))?
    } else {
        let path: PathBuf = scene.extract().map_err(|_| {
            pyo3::exceptions::PyTypeError::new_err(format!(
                "scene: expected a file path, a built-in scene name, a dict or an xylem.Scene, not {}",
                scene.get_type().name().map_or("?".into(), |n| n.to_string())
            ))
        })?;
        xylem::scene::load(&path).map_err(scene_error)?
    };
    apply(&mut loaded)
}

/// Reshapes a row-major image of 3-vectors to (H, W, 3).
fn image3<'py>(py: Python<'py>, w: u32, h: u32, v: &[Vec3]) -> PyResult<Bound<'py, PyAny>> {
    vec3_out(py, v, &[h as usize, w as usize])
}

fn image1<'py>(py: Python<'py>, w: u32, h: u32, v: Vec<f32>) -> PyResult<Bound<'py, PyAny>> {
    out(py, v, &[h as usize, w as usize])
}

/// A render's [`xylem::progress::Progress`] that asks it to stop once `flag` is set.
struct StopFlag<'a>(&'a std::sync::atomic::AtomicBool);

impl xylem::progress::Progress for StopFlag<'_> {
    fn update(&self, _done: u64, _total: u64, _message: &str) {}
    fn stop(&self) -> bool {
        self.0.load(std::sync::atomic::Ordering::Relaxed)
    }
}

/// Runs `f` with the GIL released on a helper thread while this (the main) thread checks
/// Python's signals every 50 ms, since only the main thread can raise KeyboardInterrupt: on
/// Ctrl-C the run is asked to stop ([`StopFlag`]), ends at its next tile, and the signal's
/// exception is raised. A panic in the run becomes a RuntimeError, never a PanicException.
fn interruptible<T: Send>(py: Python<'_>, f: impl FnOnce(&StopFlag) -> T + Send) -> PyResult<T> {
    let flag = std::sync::atomic::AtomicBool::new(false);
    let stop = StopFlag(&flag);
    std::thread::scope(|scope| {
        let run = scope.spawn(|| f(&stop));
        let mut interrupted = None;
        while !run.is_finished() {
            py.allow_threads(|| std::thread::sleep(std::time::Duration::from_millis(50)));
            if let Err(e) = py.check_signals() {
                flag.store(true, std::sync::atomic::Ordering::Relaxed);
                interrupted = Some(e);
                break;
            }
        }
        let out = py.allow_threads(|| run.join());
        match (interrupted, out) {
            (Some(e), _) => Err(e),
            (None, Ok(v)) => Ok(v),
            (None, Err(_)) => Err(pyo3::exceptions::PyRuntimeError::new_err(
                "the render panicked (a bug: please report it with the scene)",
            )),
        }
    })
}

/// `render(scene, spp=None, res=None, seed=None, threads=0, quality=None, footprint_filter=None)`:
/// renders a scene (a file path, a built-in scene name, a dict as `load_dict` takes, or a
/// `Scene`) as `xylem render` does — `quality` is `--quality` (`draft`, `default`, `final`: spp
/// and wood-model knobs, validation/TRADEOFF.md), `spp` and `footprint_filter` override it —
/// and returns a dict of (H, W[, 3]) float32 arrays, top row first: `beauty`
/// (linear RGB), `std_error` (of each pixel's luminance), and the first-hit AOVs `albedo`,
/// `normal`, `depth`, `fiber`, `ray_mask`, `growth_time`; plus `nonfinite` (samples dropped) and
/// `seconds`. The GIL is released while rendering; Ctrl-C stops it within a tile and raises
/// KeyboardInterrupt.
#[pyfunction]
#[pyo3(signature = (scene, spp=None, res=None, seed=None, threads=0, quality=None, footprint_filter=None))]
#[allow(clippy::too_many_arguments)]
fn render<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    spp: Option<u32>,
    res: Option<(u32, u32)>,
    seed: Option<u64>,
    threads: usize,
    quality: Option<&str>,
    footprint_filter: Option<bool>,
) -> PyResult<Bound<'py, PyDict>> {
    check_threads(threads)?;
    let o = Overrides {
        quality: parse_quality(quality)?,
        spp,
        res,
        seed,
        footprint_filter,
    };
    let out = with_scene(py, scene, &o, |loaded| {
        interruptible(py, |stop| {
            let run = xylem::render::RunOptions {
                threads,
                progress: stop,
            };
            xylem::render::render(&loaded.scene, &loaded.settings, &run)
        })
    })?
    .map_err(value_error)?;
    let img = &out.image;
    let (w, h) = (img.width, img.height);
    let d = PyDict::new(py);
    d.set_item("beauty", image3(py, w, h, &img.beauty)?)?;
    d.set_item("std_error", image1(py, w, h, img.std_error.clone())?)?;
    let aov3 =
        |f: fn(&xylem::render::Aov) -> Vec3| -> Vec<Vec3> { img.aov.iter().map(f).collect() };
    let aov1 = |f: fn(&xylem::render::Aov) -> f32| -> Vec<f32> { img.aov.iter().map(f).collect() };
    d.set_item("albedo", image3(py, w, h, &aov3(|a| a.albedo))?)?;
    d.set_item("normal", image3(py, w, h, &aov3(|a| a.normal))?)?;
    d.set_item("fiber", image3(py, w, h, &aov3(|a| a.fiber))?)?;
    d.set_item("depth", image1(py, w, h, aov1(|a| a.depth))?)?;
    d.set_item("ray_mask", image1(py, w, h, aov1(|a| a.ray_mask))?)?;
    d.set_item("growth_time", image1(py, w, h, aov1(|a| a.growth_time))?)?;
    d.set_item("nonfinite", img.nonfinite)?;
    d.set_item("seconds", out.elapsed.as_secs_f64())?;
    Ok(d)
}

/// `sweep(scene, frames=None, arc=None, spp=None, res=None, seed=None, threads=0, quality=None,
/// footprint_filter=None)`: renders the
/// light sweep of a scene's (a path, a name, a dict or a `Scene`, as `render` takes) `[sweep]` table (with the per-sweep cache, as `xylem sweep` does)
/// without writing files; `arc` = (from_deg, to_deg). Returns a dict: `frames` (F, H, W, 3),
/// `std_error` (F, H, W), `light_deg` (F,), `seconds`. The GIL is released while rendering;
/// Ctrl-C stops it within a tile and raises KeyboardInterrupt.
#[pyfunction]
#[pyo3(signature = (scene, frames=None, arc=None, spp=None, res=None, seed=None, threads=0, quality=None, footprint_filter=None))]
#[allow(clippy::too_many_arguments)]
fn sweep<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    frames: Option<usize>,
    arc: Option<(f32, f32)>,
    spp: Option<u32>,
    res: Option<(u32, u32)>,
    seed: Option<u64>,
    threads: usize,
    quality: Option<&str>,
    footprint_filter: Option<bool>,
) -> PyResult<Bound<'py, PyDict>> {
    check_threads(threads)?;
    let o = Overrides {
        quality: parse_quality(quality)?,
        spp,
        res,
        seed,
        footprint_filter,
    };
    let (r, deg) = with_scene(py, scene, &o, |loaded| {
        let (path, moving) =
            xylem::sweep::SweepPath::from_scene(loaded, frames, arc).map_err(value_error)?;
        let total = path.arc.frames;
        let r = interruptible(py, |stop| {
            let run = xylem::render::RunOptions {
                threads,
                progress: stop,
            };
            xylem::sweep::render_sweep(
                &loaded.scene,
                &loaded.settings,
                &path,
                moving,
                0..total,
                &run,
            )
        })?
        .map_err(value_error)?;
        let deg: Vec<f32> = (0..r.frames.len()).map(|k| path.light_deg(k)).collect();
        Ok((r, deg))
    })?;
    let (w, h, f) = (r.width as usize, r.height as usize, r.frames.len());
    let beauty: Vec<f32> = r
        .frames
        .iter()
        .flat_map(|fr| fr.beauty.iter().flat_map(|c| c.to_array()))
        .collect();
    let err: Vec<f32> = r
        .frames
        .iter()
        .flat_map(|fr| fr.std_error.clone())
        .collect();
    let d = PyDict::new(py);
    d.set_item(
        "frames",
        PyArray1::from_vec(py, beauty).reshape([f, h, w, 3])?,
    )?;
    d.set_item("std_error", PyArray1::from_vec(py, err).reshape([f, h, w])?)?;
    d.set_item("light_deg", PyArray1::from_vec(py, deg))?;
    d.set_item("seconds", r.elapsed.as_secs_f64())?;
    Ok(d)
}

/// Fits the capture in the folder `capture` (a sweep's `manifest.json` and frames) and writes
/// its maps and report into `out`, as `xylem fit` does; returns the report as JSON text
/// (`xylem.fit` parses it). One board per call, the GIL released, so a Ray or Dask pool of
/// processes can fit many boards at once.
#[pyfunction]
#[pyo3(signature = (capture, out, texels=None, threads=0))]
fn fit(
    py: Python<'_>,
    capture: PathBuf,
    out: PathBuf,
    texels: Option<(usize, usize)>,
    threads: usize,
) -> PyResult<String> {
    check_threads(threads)?;
    let report = py
        .allow_threads(|| {
            let opts = xylem::fit::FitOptions {
                texels,
                threads,
                ..Default::default()
            };
            xylem::fit::fit_folder(&capture, &out, &opts)
        })
        .map_err(|e| match e {
            xylem::fit::FolderError::Fit(f) => value_error(f),
            other => PyOSError::new_err(other.to_string()),
        })?;
    Ok(report.to_string())
}

/// `max_lobe_albedo(beta, dip)`: the bound on the energy-bounded fibre lobe's directional
/// albedo at any view for highlight width `beta` and fibre dip `dip` = asin|u·n| (radians), as
/// `WoodBsdf` bounds its diffuse with it (bilinear in xylem's table, plus its margin). The baked
/// Mitsuba plugin tabulates it into a Dr.Jit texture.
#[pyfunction]
fn max_lobe_albedo(beta: f32, dip: f32) -> f32 {
    xylem::bsdf::fiber_albedo::max_lobe_albedo(beta, dip)
}

#[pymodule]
fn _xylem(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyWoodBsdf>()?;
    m.add_class::<PyWoodVolume>()?;
    m.add_class::<PyWoodSurface>()?;
    m.add_class::<PyWoodHits>()?;
    m.add_class::<PyScene>()?;
    m.add_function(wrap_pyfunction!(load_file, m)?)?;
    m.add_function(wrap_pyfunction!(load_dict, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(fit, m)?)?;
    m.add_function(wrap_pyfunction!(max_lobe_albedo, m)?)?;
    m.add("PRESETS", xylem::wood::PRESET_NAMES.to_vec())?;
    Ok(())
}

//! Python bindings of xylem (PyO3 + numpy), the native module `xylem._xylem` behind the `xylem`
//! package: the finished-wood BSDF, the wood volume, a wood surface (volume + finish + tree
//! placement, shaded in world space as the renderer shades a hit), and renders and light sweeps
//! of scene files as numpy arrays. Every number comes from the xylem library; these functions
//! only move arrays in and out, release the GIL while computing, and turn the library's typed
//! errors into Python exceptions (`ValueError` for values out of range, `OSError` for files).

use glam::{Mat3, Vec2, Vec3};
use numpy::{AllowTypeChange, PyArray1, PyArray2, PyArrayLikeDyn, PyArrayMethods};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use std::path::PathBuf;
use std::sync::Arc;
use xylem::bsdf::{Bsdf, BsdfSample, WoodBsdfParams};
use xylem::material::{Cutting, Material, MaterialHit, Placement, ShadingSwitches, WoodMaterial};
use xylem::wood::{Needs, WoodError, WoodTexel};

/// Below this many items a call runs on the calling thread (rayon's start-up is not worth it).
const PARALLEL_FROM: usize = 4096;

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

/// An array-like of 3-vectors: shape (3,) (one vector) or (N, 3).
fn vec3_rows(name: &str, a: &PyArrayLikeDyn<'_, f32, AllowTypeChange>) -> PyResult<Vec<Vec3>> {
    let v = a.as_array();
    let shape = v.shape().to_vec();
    let ok = match shape.as_slice() {
        [3] | [_, 3] => true,
        _ => false,
    };
    if !ok {
        return Err(value_error(format!(
            "{name}: shape {shape:?}, expected (3,) or (N, 3)"
        )));
    }
    let flat: Vec<f32> = v.iter().copied().collect();
    Ok(flat
        .chunks_exact(3)
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect())
}

/// An array-like of scalars: shape () (one value) or (N,).
fn scalars(name: &str, a: &PyArrayLikeDyn<'_, f32, AllowTypeChange>) -> PyResult<Vec<f32>> {
    let v = a.as_array();
    if v.ndim() > 1 {
        return Err(value_error(format!(
            "{name}: shape {:?}, expected () or (N,)",
            v.shape()
        )));
    }
    Ok(v.iter().copied().collect())
}

/// An array-like of 2-vectors: shape (2,) or (N, 2).
fn vec2_rows(name: &str, a: &PyArrayLikeDyn<'_, f32, AllowTypeChange>) -> PyResult<Vec<Vec2>> {
    let v = a.as_array();
    let shape = v.shape().to_vec();
    if !matches!(shape.as_slice(), [2] | [_, 2]) {
        return Err(value_error(format!(
            "{name}: shape {shape:?}, expected (2,) or (N, 2)"
        )));
    }
    let flat: Vec<f32> = v.iter().copied().collect();
    Ok(flat
        .chunks_exact(2)
        .map(|c| Vec2::new(c[0], c[1]))
        .collect())
}

/// The arguments of a `sample` call: directions `wo`, lobe numbers `uc` and 2D numbers `u`.
type SampleInputs = (Vec<Vec3>, Vec<f32>, Vec<Vec2>);

fn sample_inputs(
    wo: &PyArrayLikeDyn<'_, f32, AllowTypeChange>,
    uc: &PyArrayLikeDyn<'_, f32, AllowTypeChange>,
    u: &PyArrayLikeDyn<'_, f32, AllowTypeChange>,
) -> PyResult<SampleInputs> {
    Ok((vec3_rows("wo", wo)?, scalars("uc", uc)?, vec2_rows("u", u)?))
}

/// The common length of arrays that broadcast: each has length 1 or N.
fn broadcast(lens: &[(&str, usize)]) -> PyResult<usize> {
    let n = lens.iter().map(|l| l.1).max().unwrap_or(1);
    for (name, len) in lens {
        if *len != 1 && *len != n {
            let all: Vec<String> = lens.iter().map(|(k, l)| format!("{k}: {l}")).collect();
            return Err(value_error(format!(
                "{name} has {len} rows; every argument needs 1 or {n} rows ({})",
                all.join(", ")
            )));
        }
        if *len == 0 {
            return Err(value_error(format!("{name} is empty")));
        }
    }
    Ok(n)
}

/// Element i of a broadcast array.
#[inline]
fn at<T: Copy>(v: &[T], i: usize) -> T {
    if v.len() == 1 {
        v[0]
    } else {
        v[i]
    }
}

fn vec3_array<'py>(py: Python<'py>, v: &[Vec3]) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let flat: Vec<f32> = v.iter().flat_map(|c| c.to_array()).collect();
    PyArray1::from_vec(py, flat).reshape([v.len(), 3])
}

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
/// with one row per shading point; missing fields take `WoodBsdfParams::default()`.
fn bsdf_params(fields: &Bound<'_, PyDict>) -> PyResult<Vec<WoodBsdfParams>> {
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
    let get3 = |name: &str, default: Vec3| -> PyResult<Vec<Vec3>> {
        match fields.get_item(name)? {
            Some(v) => vec3_rows(
                &format!("WoodBsdfParams.{name}"),
                &v.extract::<PyArrayLikeDyn<f32, AllowTypeChange>>()?,
            ),
            None => Ok(vec![default]),
        }
    };
    let get1 = |name: &str, default: f32| -> PyResult<Vec<f32>> {
        match fields.get_item(name)? {
            Some(v) => scalars(
                &format!("WoodBsdfParams.{name}"),
                &v.extract::<PyArrayLikeDyn<f32, AllowTypeChange>>()?,
            ),
            None => Ok(vec![default]),
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
    let n = broadcast(&[
        ("diffuse", diffuse.len()),
        ("fiber_color", fiber_color.len()),
        ("fiber_dir", fiber_dir.len()),
        ("ray_dir", ray_dir.len()),
        ("ray_mask", ray_mask.len()),
        ("highlight_width", width.len()),
        ("eta", eta.len()),
        ("roughness", roughness.len()),
    ])?;
    Ok((0..n)
        .map(|i| WoodBsdfParams {
            diffuse: at(&diffuse, i),
            fiber_color: at(&fiber_color, i),
            fiber_dir: at(&fiber_dir, i),
            ray_dir: at(&ray_dir, i),
            ray_mask: at(&ray_mask, i),
            highlight_width: at(&width, i),
            eta: at(&eta, i),
            roughness: at(&roughness, i),
        })
        .collect())
}

/// Sample results as a dict of arrays: `wi` (N, 3), `f` (N, 3), `pdf` (N,), `is_delta` (N,),
/// `valid` (N,); rows where sampling failed have `valid` false and zeros elsewhere.
fn sample_dict<'py>(py: Python<'py>, s: &[Option<BsdfSample>]) -> PyResult<Bound<'py, PyDict>> {
    let get = |f: &dyn Fn(&BsdfSample) -> Vec3| -> Vec<Vec3> {
        s.iter().map(|x| x.as_ref().map_or(Vec3::ZERO, f)).collect()
    };
    let d = PyDict::new(py);
    d.set_item("wi", vec3_array(py, &get(&|x| x.wi))?)?;
    d.set_item("f", vec3_array(py, &get(&|x| x.f))?)?;
    let pdf: Vec<f32> = s.iter().map(|x| x.map_or(0.0, |x| x.pdf)).collect();
    d.set_item("pdf", PyArray1::from_vec(py, pdf))?;
    let delta: Vec<bool> = s.iter().map(|x| x.is_some_and(|x| x.is_delta)).collect();
    d.set_item("is_delta", PyArray1::from_vec(py, delta))?;
    let valid: Vec<bool> = s.iter().map(|x| x.is_some()).collect();
    d.set_item("valid", PyArray1::from_vec(py, valid))?;
    Ok(d)
}

/// xylem's finished-wood BSDF (Marschner et al. 2005) for one or N shading points, in the local
/// shading frame (z = normal, unit directions pointing away from the surface). `eval` is f
/// without the cosine; `pdf` is per unit solid angle.
#[pyclass(module = "xylem", name = "WoodBsdf", frozen)]
struct PyWoodBsdf {
    bsdfs: Vec<xylem::bsdf::WoodBsdf>,
}

impl PyWoodBsdf {
    /// `f(bsdf, wo, wi)` at every row of the broadcast (bsdf, wo, wi), GIL released.
    fn at_pairs<T: Send>(
        &self,
        py: Python<'_>,
        wo: &PyArrayLikeDyn<'_, f32, AllowTypeChange>,
        wi: &PyArrayLikeDyn<'_, f32, AllowTypeChange>,
        f: impl Fn(&xylem::bsdf::WoodBsdf, Vec3, Vec3) -> T + Sync + Send,
    ) -> PyResult<Vec<T>> {
        let (wo, wi) = (vec3_rows("wo", wo)?, vec3_rows("wi", wi)?);
        let b = &self.bsdfs;
        let n = broadcast(&[("bsdf", b.len()), ("wo", wo.len()), ("wi", wi.len())])?;
        Ok(py.allow_threads(|| map_indices(n, |i| f(&at(b, i), at(&wo, i), at(&wi, i)))))
    }
}

#[pymethods]
impl PyWoodBsdf {
    /// `WoodBsdf(params=None, **fields)`: fields `diffuse`, `fiber_color`, `fiber_dir`,
    /// `ray_dir` (3-vectors or (N, 3)), `ray_mask`, `highlight_width` (radians), `eta`,
    /// `roughness` (scalars or (N,)); a dict and keywords merge, keywords winning.
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
        let params = bsdf_params(&all)?;
        let bsdfs = params
            .iter()
            .enumerate()
            .map(|(i, p)| {
                xylem::bsdf::WoodBsdf::new(*p).map_err(|e| {
                    if params.len() > 1 {
                        value_error(format!("{e} (shading point {i})"))
                    } else {
                        value_error(e)
                    }
                })
            })
            .collect::<PyResult<Vec<_>>>()?;
        Ok(PyWoodBsdf { bsdfs })
    }

    /// Number of shading points.
    fn __len__(&self) -> usize {
        self.bsdfs.len()
    }

    /// True where the BSDF has a delta lobe (a smooth finish), shape (N,).
    fn has_delta<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        PyArray1::from_vec(py, self.bsdfs.iter().map(|b| b.has_delta()).collect())
    }

    /// f(wo, wi) without the cosine, shape (N, 3).
    fn eval<'py>(
        &self,
        py: Python<'py>,
        wo: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
        wi: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let f = self.at_pairs(py, &wo, &wi, |b, o, i| b.eval(o, i))?;
        vec3_array(py, &f)
    }

    /// The sampling density of `sample` per unit solid angle, shape (N,).
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        wo: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
        wi: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyArray1<f32>>> {
        let p = self.at_pairs(py, &wo, &wi, |b, o, i| b.pdf(o, i))?;
        Ok(PyArray1::from_vec(py, p))
    }

    /// Importance-samples wi given wo and uniform numbers `uc` (N,) (lobe choice) and `u`
    /// (N, 2); returns a dict `wi`, `f`, `pdf`, `is_delta`, `valid`.
    fn sample<'py>(
        &self,
        py: Python<'py>,
        wo: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
        uc: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
        u: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (wo, uc, u) = sample_inputs(&wo, &uc, &u)?;
        let n = broadcast(&[
            ("bsdf", self.bsdfs.len()),
            ("wo", wo.len()),
            ("uc", uc.len()),
            ("u", u.len()),
        ])?;
        let b = &self.bsdfs;
        let s = py.allow_threads(|| {
            map_indices(n, |i| at(b, i).sample(at(&wo, i), at(&uc, i), at(&u, i)))
        });
        sample_dict(py, &s)
    }
}

/// Exactly one of a built-in preset name or a preset file.
fn wood_params(
    preset: Option<String>,
    preset_file: Option<PathBuf>,
) -> PyResult<xylem::wood::WoodParams> {
    match (preset, preset_file) {
        (Some(name), None) => xylem::wood::preset(&name).map_err(wood_error),
        (None, Some(file)) => xylem::scene::read_preset_file(&file).map_err(|e| match e {
            e @ xylem::scene::PresetFileError::Read(_) => PyOSError::new_err(e.to_string()),
            xylem::scene::PresetFileError::Wood(w) => wood_error(w),
        }),
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

/// The named arrays of texels that `needs` asked for (and the growth time, always computed).
fn texel_dict<'py>(py: Python<'py>, t: &[WoodTexel], needs: Needs) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let v3 = |f: fn(&WoodTexel) -> Vec3| -> Vec<Vec3> { t.iter().map(f).collect() };
    let v1 = |f: fn(&WoodTexel) -> f32| -> Vec<f32> { t.iter().map(f).collect() };
    d.set_item("growth_time", PyArray1::from_vec(py, v1(|x| x.growth_time)))?;
    if needs.color {
        d.set_item("diffuse", vec3_array(py, &v3(|x| x.diffuse))?)?;
        d.set_item("fiber_color", vec3_array(py, &v3(|x| x.fiber_color))?)?;
    }
    if needs.color || needs.bump {
        d.set_item("pore_mask", PyArray1::from_vec(py, v1(|x| x.pore_mask)))?;
    }
    if needs.fibers {
        d.set_item("fiber_dir", vec3_array(py, &v3(|x| x.fiber_dir))?)?;
        d.set_item("ray_dir", vec3_array(py, &v3(|x| x.ray_dir))?)?;
        d.set_item("ray_mask", PyArray1::from_vec(py, v1(|x| x.ray_mask)))?;
        d.set_item(
            "highlight_width",
            PyArray1::from_vec(py, v1(|x| x.highlight_width)),
        )?;
    }
    if needs.bump {
        d.set_item("bump", PyArray1::from_vec(py, v1(|x| x.bump)))?;
        d.set_item("bump_grad", vec3_array(py, &v3(|x| x.bump_grad))?)?;
    }
    Ok(d)
}

/// The procedural solid wood of a species preset (Liu et al. 2016) in tree space (mm, pith
/// along +z).
#[pyclass(module = "xylem", name = "WoodVolume", frozen)]
struct PyWoodVolume {
    volume: Arc<xylem::wood::WoodVolume>,
}

#[pymethods]
impl PyWoodVolume {
    /// `WoodVolume(preset=None, *, preset_file=None, seed=0)`: a built-in preset by name or a
    /// preset TOML file, and the seed that selects the tree.
    #[new]
    #[pyo3(signature = (preset=None, *, preset_file=None, seed=0))]
    fn new(preset: Option<String>, preset_file: Option<PathBuf>, seed: u64) -> PyResult<Self> {
        let params = wood_params(preset, preset_file)?;
        let volume = xylem::wood::WoodVolume::new(params, seed).map_err(wood_error)?;
        Ok(PyWoodVolume {
            volume: Arc::new(volume),
        })
    }

    #[getter]
    fn seed(&self) -> u64 {
        self.volume.seed()
    }

    /// Texels at `points` (N, 3) tree-space mm; `needs` is "color", "fibers", "bump", "all" (the
    /// default) or a list / comma-separated string of them. Returns a dict of arrays: always `growth_time`;
    /// with color `diffuse`, `fiber_color`, `pore_mask`; with fibers `fiber_dir`, `ray_dir`,
    /// `ray_mask`, `highlight_width` (radians); with bump `pore_mask`, `bump`, `bump_grad`.
    #[pyo3(signature = (points, needs=None))]
    fn eval<'py>(
        &self,
        py: Python<'py>,
        points: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
        needs: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let points = vec3_rows("points", &points)?;
        let needs = needs.map_or(Ok(Needs::ALL), parse_needs)?;
        let v = &self.volume;
        let texels = py.allow_threads(|| {
            let chunk = 1024;
            let mut out = vec![WoodTexel::default(); points.len()];
            out.par_chunks_mut(chunk)
                .zip(points.par_chunks(chunk))
                .for_each(|(o, p)| v.eval_many(p, needs, o));
            out
        });
        texel_dict(py, &texels, needs)
    }
}

/// A wood surface as the renderer shades it: the volume under a finish, placed in the tree by a
/// solid cutting in world space (`p_tree = origin + scale · Rz(rotation) · A · p`, A turning
/// `axis` onto the pith). Methods take world-space points, shading normals and directions.
#[pyclass(module = "xylem", name = "WoodSurface", frozen)]
struct PyWoodSurface {
    material: Material,
    placement: Placement,
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
        self.material.shade(&hit)
    }

    /// `f(bsdf, wo, wi)` in xylem's local frame at every row of (p, n, wo, wi), world inputs.
    fn at_pairs<T: Send>(
        &self,
        py: Python<'_>,
        [p, n, wo, wi]: [&PyArrayLikeDyn<'_, f32, AllowTypeChange>; 4],
        f: impl Fn(&xylem::material::SurfaceBsdf, Vec3, Vec3) -> T + Sync + Send,
    ) -> PyResult<Vec<T>> {
        let (p, nn) = (vec3_rows("p", p)?, vec3_rows("n", n)?);
        let (wo, wi) = (vec3_rows("wo", wo)?, vec3_rows("wi", wi)?);
        let count = broadcast(&[
            ("p", p.len()),
            ("n", nn.len()),
            ("wo", wo.len()),
            ("wi", wi.len()),
        ])?;
        Ok(py.allow_threads(|| {
            map_indices(count, |i| {
                let s = self.shade_one(at(&p, i), at(&nn, i));
                let to_local = |d: Vec3| s.frame.to_local(d);
                f(&s.bsdf, to_local(at(&wo, i)), to_local(at(&wi, i)))
            })
        }))
    }
}

#[pymethods]
impl PyWoodSurface {
    /// `WoodSurface(preset=None, *, preset_file=None, seed=0, eta=1.5, roughness=0.0,
    /// origin=(0, 0, 0), axis=(0, 0, 1), rotation_deg=0.0, scale=1.0)`.
    #[new]
    #[pyo3(signature = (preset=None, *, preset_file=None, seed=0, eta=1.5, roughness=0.0,
        origin=[0.0, 0.0, 0.0], axis=[0.0, 0.0, 1.0], rotation_deg=0.0, scale=1.0))]
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
        let params = wood_params(preset, preset_file)?;
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
        })
    }

    /// The BSDF parameters at world points `p` (N, 3) with shading normals `n` (N, 3), in the
    /// shading frame xylem builds there (z = n, x along the fibre's surface projection): a dict
    /// of the `WoodBsdf` fields and `frame` (N, 3, 3), rows s, t, n in world space.
    fn shade<'py>(
        &self,
        py: Python<'py>,
        p: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
        n: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (p, nn) = (vec3_rows("p", &p)?, vec3_rows("n", &n)?);
        let count = broadcast(&[("p", p.len()), ("n", nn.len())])?;
        let shaded = py.allow_threads(|| {
            map_indices(count, |i| {
                let s = self.shade_one(at(&p, i), at(&nn, i));
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
        let d = PyDict::new(py);
        let col = |f: fn(&WoodBsdfParams) -> Vec3| -> Vec<Vec3> {
            shaded.iter().map(|(p, _)| f(p)).collect()
        };
        let one = |f: fn(&WoodBsdfParams) -> f32| -> Vec<f32> {
            shaded.iter().map(|(p, _)| f(p)).collect()
        };
        d.set_item("diffuse", vec3_array(py, &col(|p| p.diffuse))?)?;
        d.set_item("fiber_color", vec3_array(py, &col(|p| p.fiber_color))?)?;
        d.set_item("fiber_dir", vec3_array(py, &col(|p| p.fiber_dir))?)?;
        d.set_item("ray_dir", vec3_array(py, &col(|p| p.ray_dir))?)?;
        d.set_item("ray_mask", PyArray1::from_vec(py, one(|p| p.ray_mask)))?;
        d.set_item(
            "highlight_width",
            PyArray1::from_vec(py, one(|p| p.highlight_width)),
        )?;
        d.set_item("eta", PyArray1::from_vec(py, one(|p| p.eta)))?;
        d.set_item("roughness", PyArray1::from_vec(py, one(|p| p.roughness)))?;
        let frames: Vec<f32> = shaded
            .iter()
            .flat_map(|(_, f)| [f.s.to_array(), f.t.to_array(), f.n.to_array()])
            .flatten()
            .collect();
        d.set_item(
            "frame",
            PyArray1::from_vec(py, frames).reshape([count, 3, 3])?,
        )?;
        Ok(d)
    }

    /// f(wo, wi) without the cosine at world points `p` with shading normals `n`; `wo`, `wi` are
    /// world-space unit directions away from the surface. Shape (N, 3).
    fn eval<'py>(
        &self,
        py: Python<'py>,
        p: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
        n: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
        wo: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
        wi: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let f = self.at_pairs(py, [&p, &n, &wo, &wi], |b, o, i| b.eval(o, i))?;
        vec3_array(py, &f)
    }

    /// The sampling density per unit solid angle of world direction `wi`, shape (N,).
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        p: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
        n: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
        wo: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
        wi: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyArray1<f32>>> {
        let pdf = self.at_pairs(py, [&p, &n, &wo, &wi], |b, o, i| b.pdf(o, i))?;
        Ok(PyArray1::from_vec(py, pdf))
    }

    /// Samples a world direction `wi` given `wo`; as `WoodBsdf.sample`, with `wi` in world space.
    fn sample<'py>(
        &self,
        py: Python<'py>,
        p: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
        n: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
        wo: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
        uc: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
        u: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (p, nn) = (vec3_rows("p", &p)?, vec3_rows("n", &n)?);
        let (wo, uc, u) = sample_inputs(&wo, &uc, &u)?;
        let count = broadcast(&[
            ("p", p.len()),
            ("n", nn.len()),
            ("wo", wo.len()),
            ("uc", uc.len()),
            ("u", u.len()),
        ])?;
        let s = py.allow_threads(|| {
            map_indices(count, |i| {
                let s = self.shade_one(at(&p, i), at(&nn, i));
                let frame = s.frame;
                s.bsdf
                    .sample(frame.to_local(at(&wo, i)), at(&uc, i), at(&u, i))
                    .map(|x| BsdfSample {
                        wi: frame.to_world(x.wi),
                        ..x
                    })
            })
        });
        sample_dict(py, &s)
    }
}

/// `threads`: 0 (all cores) up to 16 per core, as `--threads`.
fn check_threads(threads: usize) -> PyResult<()> {
    use xylem::render::resources::{check_threads, ResourceError};
    check_threads(threads).map_err(|e| match e {
        ResourceError::Threads { max, .. } => value_error(format!(
            "threads = {threads}: out of range (allowed 0 = all cores, up to {max})"
        )),
        other => value_error(other),
    })
}

/// A scene file loaded with the overrides of `xylem render` (`spp`, `res` = (width, height),
/// `seed`).
fn load_scene(
    scene: PathBuf,
    spp: Option<u32>,
    res: Option<(u32, u32)>,
    seed: Option<u64>,
) -> PyResult<xylem::scene::LoadedScene> {
    let mut loaded = xylem::scene::load(&scene).map_err(|e| match e {
        xylem::scene::SceneError::Io { .. } | xylem::scene::SceneError::Input(_) => {
            PyOSError::new_err(e.to_string())
        }
        other => value_error(other),
    })?;
    if let Some(spp) = spp {
        if !(1..=1_000_000).contains(&spp) {
            return Err(value_error(format!(
                "spp = {spp}: out of range (allowed 1 to 1000000 samples per pixel)"
            )));
        }
        loaded.settings.spp = spp;
    }
    if let Some(seed) = seed {
        loaded.settings.seed = seed;
    }
    if let Some((w, h)) = res {
        for (name, v) in [("width", w), ("height", h)] {
            if !(1..=16384).contains(&v) {
                return Err(value_error(format!(
                    "res {name} = {v}: must be a whole number in 1..=16384"
                )));
            }
        }
        loaded.scene.camera = loaded.scene.camera.with_resolution(w, h);
    }
    Ok(loaded)
}

/// Reshapes a row-major image of 3-vectors to (H, W, 3).
fn image3<'py>(py: Python<'py>, w: u32, h: u32, v: &[Vec3]) -> PyResult<Bound<'py, PyAny>> {
    Ok(vec3_array(py, v)?
        .reshape([h as usize, w as usize, 3])?
        .into_any())
}

fn image1<'py>(py: Python<'py>, w: u32, h: u32, v: Vec<f32>) -> PyResult<Bound<'py, PyAny>> {
    Ok(PyArray1::from_vec(py, v)
        .reshape([h as usize, w as usize])?
        .into_any())
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

/// `render(scene, spp=None, res=None, seed=None, threads=0)`: renders a scene file as
/// `xylem render` does and returns a dict of (H, W[, 3]) float32 arrays, top row first: `beauty`
/// (linear RGB), `std_error` (of each pixel's luminance), and the first-hit AOVs `albedo`,
/// `normal`, `depth`, `fiber`, `ray_mask`, `growth_time`; plus `nonfinite` (samples dropped) and
/// `seconds`. The GIL is released while rendering; Ctrl-C stops it within a tile and raises
/// KeyboardInterrupt.
#[pyfunction]
#[pyo3(signature = (scene, spp=None, res=None, seed=None, threads=0))]
fn render<'py>(
    py: Python<'py>,
    scene: PathBuf,
    spp: Option<u32>,
    res: Option<(u32, u32)>,
    seed: Option<u64>,
    threads: usize,
) -> PyResult<Bound<'py, PyDict>> {
    check_threads(threads)?;
    let loaded = load_scene(scene, spp, res, seed)?;
    let out = interruptible(py, |stop| {
        let run = xylem::render::RunOptions {
            threads,
            progress: stop,
            ..Default::default()
        };
        xylem::render::render(&loaded.scene, &loaded.settings, &run)
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

/// `sweep(scene, frames=None, arc=None, spp=None, res=None, seed=None, threads=0)`: renders the
/// light sweep of a scene's `[sweep]` table (with the per-sweep cache, as `xylem sweep` does)
/// without writing files; `arc` = (from_deg, to_deg). Returns a dict: `frames` (F, H, W, 3),
/// `std_error` (F, H, W), `light_deg` (F,), `seconds`. The GIL is released while rendering;
/// Ctrl-C stops it within a tile and raises KeyboardInterrupt.
#[pyfunction]
#[pyo3(signature = (scene, frames=None, arc=None, spp=None, res=None, seed=None, threads=0))]
#[allow(clippy::too_many_arguments)]
fn sweep<'py>(
    py: Python<'py>,
    scene: PathBuf,
    frames: Option<usize>,
    arc: Option<(f32, f32)>,
    spp: Option<u32>,
    res: Option<(u32, u32)>,
    seed: Option<u64>,
    threads: usize,
) -> PyResult<Bound<'py, PyDict>> {
    check_threads(threads)?;
    let loaded = load_scene(scene, spp, res, seed)?;
    let (path, moving) =
        xylem::sweep::SweepPath::from_scene(&loaded, frames, arc).map_err(value_error)?;
    let total = path.arc.frames;
    let r = interruptible(py, |stop| {
        let run = xylem::render::RunOptions {
            threads,
            progress: stop,
            ..Default::default()
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
    let deg: Vec<f32> = (0..f).map(|k| path.light_deg(k)).collect();
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

#[pymodule]
fn _xylem(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyWoodBsdf>()?;
    m.add_class::<PyWoodVolume>()?;
    m.add_class::<PyWoodSurface>()?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(fit, m)?)?;
    m.add("PRESETS", xylem::wood::PRESET_NAMES.to_vec())?;
    Ok(())
}

//! `WoodSurface` (the wood under a finish, placed in world space) and `WoodHits` (one shading
//! of it at a batch of hit points, shared by eval, pdf and sample).

use crate::*;

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
pub(crate) struct PyWoodSurface {
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
                finish: xylem::bsdf::Finish::new(eta, roughness),
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
pub(crate) fn orthonormal(m: &[Vec3; 3]) -> bool {
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
pub(crate) struct PyWoodHits {
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

    /// The probability that `sample` takes a smooth finish's mirror at `wo` (..., 3), shape
    /// (...); 0 under a rough finish. `sample` picks the mirror for `uc` below it.
    fn mirror_probability<'py>(
        &self,
        py: Python<'py>,
        wo: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (p, shape) = self.at_pairs(py, &wo, &wo, |b, o, _| b.delta_probability(o))?;
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

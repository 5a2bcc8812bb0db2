//! The TOML scene format, built-in procedural shapes, mesh loading and preset lookup.
//!
//! [`load`] reads a scene file (format in scenes/README.md) and builds a [`render::Scene`] with
//! its render settings. Every error names the file, the field and what is allowed.

pub mod format;
pub mod mesh_io;
pub mod overrides;
pub mod quality;
pub mod shapes;
pub mod teapot;

pub use format::{SceneFile, SweepBoard, SweepRegion, SweepTable, MAX_ARCS};
pub use overrides::{OverrideError, Overrides, MAX_RESOLUTION, MAX_SPP};

/// Samples per pixel of a scene whose file gives neither `[render] spp` nor a quality preset.
pub const DEFAULT_SPP: u32 = 16;

use crate::bsdf::{WoodBsdf, WoodBsdfParams};
use crate::field::JacobianModel;
use crate::material::{
    BoardFace, ColorSpace, Cutting, Material, MeasuredBoard, MeasuredFiles, MeasuredMaterial,
    Placement, TextureMaterial, WoodMaterial,
};
use crate::render::{
    self, Accel, Camera, DistantLight, EnvMap, Environment, Filter, Instance, Integrator, Light,
    PointLight, Projection, RectLight, RenderSettings, SphereLight, SpotLight, Transform, TriMesh,
};
use crate::wood::BoardLayout;
use format::*;
use glam::{Affine3A, EulerRot, Quat, Vec2, Vec3};
use quality::Knobs;
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Why a scene could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The scene file could not be read.
    #[error("cannot read scene {path}: {source}")]
    Io {
        /// The scene file.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file is not UTF-8 or not valid TOML for the format (unknown field, wrong type...).
    #[error("scene {path}: {message}")]
    Parse {
        /// The scene file.
        path: String,
        /// toml's or serde's message.
        message: String,
    },
    /// The scene file itself is missing, not a regular file or larger than
    /// [`MAX_SCENE_BYTES`](crate::render::resources::MAX_SCENE_BYTES).
    #[error("cannot read scene {0}")]
    Input(crate::render::resources::ResourceError),
    /// The geometry's BVH build would need more memory than the machine has (estimated before
    /// it starts; `--ignore-limits` skips the check).
    #[error("scene {path}: {source}")]
    Resources {
        /// The scene file.
        path: String,
        /// The estimate and what is available.
        source: crate::render::resources::ResourceError,
    },
    /// A field's value is out of range or inconsistent with the rest of the scene.
    #[error("scene {path}: field `{field}`: {message}")]
    Invalid {
        /// The scene file.
        path: String,
        /// The field at fault (e.g. `objects[2].radius`).
        field: String,
        /// What is allowed.
        message: String,
    },
    /// An object's mesh file could not be loaded.
    #[error("scene {path}: field `{field}`: {source}")]
    Mesh {
        /// The scene file.
        path: String,
        /// The field naming the mesh (e.g. `objects[0].file`).
        field: String,
        /// Why the mesh could not be loaded.
        source: mesh_io::MeshError,
    },
}

/// How far from the origin (mm) any object may reach: 1 km, so that f32 coordinates keep a
/// resolution of 0.06 mm or better (2⁻²⁴ relative) where a scene has geometry.
pub(crate) const MAX_EXTENT_MM: f32 = 1e6;

/// A loaded scene: what to render and how.
pub struct LoadedScene {
    /// The file stem (`sweep_board` for scenes/sweep_board.toml).
    pub name: String,
    /// The built geometry, materials, lights and camera.
    pub scene: render::Scene,
    /// Image size, sampling, integrator and filter from `[render]`, before command-line overrides.
    pub settings: RenderSettings,
    /// PNG exposure in stops.
    pub exposure: f32,
    /// Name of each light in `scene.lights` (None where the file gave none).
    pub light_names: Vec<Option<String>>,
    /// The `[sweep]` table, if the scene has one.
    pub sweep: Option<SweepTable>,
    /// Non-fatal problems (e.g. degenerate triangles dropped), for the CLI to print.
    pub warnings: Vec<String>,
}

/// Reads and builds a scene file, refusing geometry whose BVH build would not fit in memory.
pub fn load(path: &Path) -> Result<LoadedScene, SceneError> {
    load_with(path, false)
}

/// [`load`], with the geometry memory check skipped when `ignore_limits` (`--ignore-limits`).
pub fn load_with(path: &Path, ignore_limits: bool) -> Result<LoadedScene, SceneError> {
    let (text, base) = source_text(path)?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    let file = parse(&text, &path.display().to_string())?;
    Builder {
        path: &path.display().to_string(),
        base: &base,
        warnings: Vec::new(),
        ignore_limits,
    }
    .build(file, &name)
}

/// A scene file's bytes and the folder its relative files (meshes, maps) resolve against: the
/// file's own folder, or `scenes/` for a built-in scene named by a path that does not exist
/// here (an installed binary run from another folder; `crate::builtin`), whose meshes and maps
/// then come from the embedded copies too. Bounded by
/// [`MAX_SCENE_BYTES`](crate::render::resources::MAX_SCENE_BYTES).
pub fn source(path: &Path) -> Result<(std::borrow::Cow<'static, [u8]>, PathBuf), SceneError> {
    use crate::render::resources::MAX_SCENE_BYTES;
    let bytes = crate::builtin::read(path, MAX_SCENE_BYTES).map_err(SceneError::Input)?;
    let base = match crate::builtin::stand_in(path) {
        Some((repo_path, _)) => Path::new(repo_path).parent().unwrap().to_path_buf(),
        None => path.parent().unwrap_or(Path::new(".")).to_path_buf(),
    };
    Ok((bytes, base))
}

/// [`source`] as text (a scene is a UTF-8 TOML file).
pub fn source_text(path: &Path) -> Result<(String, PathBuf), SceneError> {
    let (bytes, base) = source(path)?;
    let text = String::from_utf8(bytes.into_owned()).map_err(|_| SceneError::Parse {
        path: path.display().to_string(),
        message: "not UTF-8 text (a scene is a TOML file)".into(),
    })?;
    Ok((text, base))
}

/// Why a species preset file could not be used.
#[derive(Debug, thiserror::Error)]
pub enum PresetFileError {
    /// Missing, not a regular file (a FIFO, a device) or larger than
    /// [`MAX_SCENE_BYTES`](crate::render::resources::MAX_SCENE_BYTES).
    #[error("preset file {0}")]
    Read(crate::render::resources::ResourceError),
    /// Not a valid preset (the error names the file, the field and the range).
    #[error(transparent)]
    Wood(#[from] crate::wood::WoodError),
}

/// Reads a species preset file (`preset_file` of a wood material, `--preset-file`): regular
/// TOML text of at most [`MAX_SCENE_BYTES`](crate::render::resources::MAX_SCENE_BYTES), so a
/// FIFO or a device is refused instead of blocking or reading forever.
pub fn read_preset_file(path: &Path) -> Result<crate::wood::WoodParams, PresetFileError> {
    use crate::render::resources::{read_text_bounded, MAX_SCENE_BYTES};
    let text =
        read_text_bounded(path, MAX_SCENE_BYTES, "TOML text").map_err(PresetFileError::Read)?;
    Ok(crate::wood::WoodParams::from_toml_str(
        &text,
        &path.display().to_string(),
    )?)
}

/// Parses the scene text only (no meshes built), for checks and the sweep setup.
pub fn parse(text: &str, path: &str) -> Result<SceneFile, SceneError> {
    toml::from_str(text).map_err(|e| match tagged_field_error(text) {
        Some((field, message)) => SceneError::Invalid {
            path: path.to_string(),
            field,
            message,
        },
        None => SceneError::Parse {
            path: path.to_string(),
            message: e.to_string().trim_end().replace('\n', "\n  "),
        },
    })
}

/// The field at fault in a `type`-tagged table (`[[lights]]`, `[materials.NAME]`) and serde's
/// message. serde buffers such a table before choosing the variant, so toml's error points at
/// the table's header, not the field. Each table is deserialized alone; in the failing one the
/// key whose removal changes the error is the one at fault (serde reports the first bad value,
/// and missing fields only after all values). None when no tagged table fails on its own.
fn tagged_field_error(text: &str) -> Option<(String, String)> {
    use serde::de::DeserializeOwned;
    fn error<T: DeserializeOwned>(t: &toml::Table) -> Option<String> {
        let e = toml::Value::Table(t.clone()).try_into::<T>().err()?;
        Some(e.message().to_string())
    }
    fn culprit<T: DeserializeOwned>(name: String, t: &toml::Table) -> Option<(String, String)> {
        let e = error::<T>(t)?;
        // A missing field names itself (and removing any other key would change nothing).
        if let Some(k) = e
            .strip_prefix("missing field `")
            .and_then(|r| r.split('`').next())
        {
            return Some((format!("{name}.{k}"), "required".into()));
        }
        if e.starts_with("unknown variant") {
            return Some((format!("{name}.type"), e));
        }
        let key = t.keys().filter(|k| *k != "type").find(|k| {
            let mut less = t.clone();
            less.remove(*k);
            error::<T>(&less).as_ref() != Some(&e)
        });
        Some((key.map_or(name.clone(), |k| format!("{name}.{k}")), e))
    }
    let doc: toml::Table = toml::from_str(text).ok()?;
    let lights = doc.get("lights").and_then(toml::Value::as_array);
    let from_lights = lights
        .into_iter()
        .flatten()
        .enumerate()
        .find_map(|(i, l)| culprit::<LightTable>(format!("lights[{i}]"), l.as_table()?));
    let materials = doc.get("materials").and_then(toml::Value::as_table);
    from_lights.or_else(|| {
        materials.into_iter().flatten().find_map(|(name, m)| {
            culprit::<MaterialTable>(format!("materials.{name}"), m.as_table()?)
        })
    })
}

/// Builds a scene from TOML text; `path` names it in errors and `base` resolves relative files.
pub fn from_str(
    text: &str,
    path: &str,
    base: &Path,
    name: &str,
) -> Result<LoadedScene, SceneError> {
    let file = parse(text, path)?;
    Builder {
        path,
        base,
        warnings: Vec::new(),
        ignore_limits: false,
    }
    .build(file, name)
}

struct Builder<'a> {
    path: &'a str,
    base: &'a Path,
    warnings: Vec<String>,
    /// Skip the geometry memory check.
    ignore_limits: bool,
}

fn v3(a: [f32; 3]) -> Vec3 {
    Vec3::from_array(a)
}

impl Builder<'_> {
    fn invalid(&self, field: impl Into<String>, message: impl Into<String>) -> SceneError {
        SceneError::Invalid {
            path: self.path.to_string(),
            field: field.into(),
            message: message.into(),
        }
    }

    /// Checks `lo <= x <= hi` (and finite), naming the field and the range.
    fn range(&self, field: &str, x: f32, lo: f32, hi: f32) -> Result<f32, SceneError> {
        if x.is_finite() && x >= lo && x <= hi {
            Ok(x)
        } else {
            Err(self.invalid(field, format!("{x} is out of range (allowed {lo} to {hi})")))
        }
    }

    fn finite3(&self, field: &str, a: [f32; 3]) -> Result<Vec3, SceneError> {
        if a.iter().all(|x| x.is_finite()) {
            Ok(v3(a))
        } else {
            Err(self.invalid(field, "every component must be finite"))
        }
    }

    /// A finite point with every coordinate within `±max` mm.
    fn point(&self, field: &str, a: [f32; 3], max: f32) -> Result<Vec3, SceneError> {
        let p = self.finite3(field, a)?;
        if p.abs().max_element() > max {
            return Err(self.invalid(
                field,
                format!("{p} is out of range (every coordinate within ±{max:e} mm)"),
            ));
        }
        Ok(p)
    }

    fn unit3(&self, field: &str, a: [f32; 3]) -> Result<Vec3, SceneError> {
        let v = self.finite3(field, a)?;
        // Divided by the largest component first: the squares of components ≥ ~2e19 overflow
        // f32, which turned such a direction into a zero vector.
        let m = v.abs().max_element();
        if m > 1e-6 {
            Ok((v / m).normalize())
        } else {
            Err(self.invalid(field, "must be a non-zero direction"))
        }
    }

    fn color(&self, field: &str, a: [f32; 3], hi: f32) -> Result<Vec3, SceneError> {
        for x in a {
            self.range(field, x, 0.0, hi)?;
        }
        Ok(v3(a))
    }

    fn build(mut self, file: SceneFile, name: &str) -> Result<LoadedScene, SceneError> {
        let r = &file.render;
        let width = self.range("render.width", r.width as f32, 1.0, MAX_RESOLUTION as f32)? as u32;
        let height =
            self.range("render.height", r.height as f32, 1.0, MAX_RESOLUTION as f32)? as u32;
        if let Some(spp) = r.spp {
            self.range("render.spp", spp as f32, 1.0, MAX_SPP as f32)?;
        }
        let knobs = match &file.quality {
            Some(q) => Some(self.quality_knobs(q, r)?),
            None => None,
        };
        self.range("render.max_depth", r.max_depth as f32, 1.0, 1000.0)?;
        self.range("render.exposure", r.exposure, -30.0, 30.0)?;
        let integrator = match r.integrator {
            IntegratorName::Direct => Integrator::Direct,
            IntegratorName::Path => Integrator::Path {
                max_depth: r.max_depth,
            },
        };
        let filter = match r.filter {
            FilterName::Box => Filter::Box {
                radius: self.range(
                    "render.filter_radius",
                    r.filter_radius.unwrap_or(0.5),
                    0.0,
                    8.0,
                )?,
            },
            FilterName::Tent => Filter::Tent {
                radius: self.range(
                    "render.filter_radius",
                    r.filter_radius.unwrap_or(1.0),
                    0.0,
                    8.0,
                )?,
            },
            FilterName::Gaussian => {
                let radius = self.range(
                    "render.filter_radius",
                    r.filter_radius.unwrap_or(1.5),
                    0.01,
                    8.0,
                )?;
                Filter::Gaussian {
                    sigma: radius / 3.0,
                    radius,
                }
            }
        };
        let camera = self.camera(&file.camera, width, height)?;
        let (lights, light_names) = self.lights(&file.lights)?;
        let (mut materials, material_index) = self.materials(&file.materials)?;
        for m in &mut materials {
            m.set_footprint_filter(r.footprint_filter);
        }
        let instances = self.objects(&file.objects, &material_index, &materials)?;
        if let Some(s) = &file.sweep {
            self.check_sweep(s, &light_names, width, height)?;
        }
        // Checked before the BVHs are built (the largest allocation a scene makes).
        crate::render::resources::Resources::geometry(&instances)
            .check(self.base, self.ignore_limits)
            .map_err(|source| SceneError::Resources {
                path: self.path.to_string(),
                source,
            })?;
        let scene = render::Scene {
            accel: Accel::new(instances),
            materials,
            lights,
            camera,
            filter,
        };
        let mut loaded = LoadedScene {
            name: name.to_string(),
            scene,
            settings: RenderSettings {
                spp: r.spp.unwrap_or(DEFAULT_SPP),
                integrator,
                seed: r.seed,
            },
            exposure: r.exposure,
            light_names,
            sweep: file.sweep,
            warnings: self.warnings,
        };
        if let Some(k) = knobs {
            quality::apply(&mut loaded, &k).map_err(|e| SceneError::Invalid {
                path: self.path.to_string(),
                field: "quality".into(),
                message: e.to_string(),
            })?;
        }
        Ok(loaded)
    }

    /// The knobs of a `[quality]` table: its preset's (or the full model's), its own knobs
    /// over them, then `[render] spp` and `footprint_filter`.
    fn quality_knobs(&self, q: &QualityTable, r: &RenderTable) -> Result<Knobs, SceneError> {
        let mut k = q
            .preset
            .map_or(Knobs::full(DEFAULT_SPP), |preset| preset.knobs());
        if let Some(j) = q.jacobian {
            k.jacobian = match j {
                JacobianName::Simplified => JacobianModel::Simplified,
                JacobianName::Exact => JacobianModel::Exact,
            };
        }
        if let Some(keep) = q.pores_and_rays {
            k.pores_and_rays = keep;
        }
        if let Some(bands) = q.max_noise_bands {
            self.range("quality.max_noise_bands", bands as f32, 1.0, 16.0)?;
            k.max_bands = Some(bands);
        }
        if let Some(spp) = r.spp {
            k.spp = spp;
        }
        k.footprint_filter = r.footprint_filter;
        Ok(k)
    }

    fn camera(&self, c: &CameraTable, width: u32, height: u32) -> Result<Camera, SceneError> {
        // Bounded so that `target − eye` and its square stay finite (a far eye was blamed on `up`).
        let eye = self.point("camera.eye", c.eye, 1e9)?;
        let target = self.point("camera.target", c.target, 1e9)?;
        let up = self.unit3("camera.up", c.up)?;
        let dir = target - eye;
        if dir.length_squared() < 1e-12 {
            return Err(self.invalid("camera.target", "must differ from camera.eye"));
        }
        if dir.normalize().cross(up).length_squared() < 1e-8 {
            return Err(self.invalid("camera.up", "must not be parallel to the view direction"));
        }
        let projection = match c.projection {
            ProjectionName::Perspective => {
                if c.width.is_some() {
                    return Err(
                        self.invalid("camera.width", "only for projection = \"orthographic\"")
                    );
                }
                Projection::Perspective {
                    fov_y: self
                        .range(
                            "camera.fov_deg",
                            c.fov_deg.unwrap_or(DEFAULT_FOV_DEG),
                            0.01,
                            179.0,
                        )?
                        .to_radians(),
                    lens_radius: self.range("camera.lens_radius", c.lens_radius, 0.0, 1e6)?,
                    focus_distance: self.range(
                        "camera.focus_distance",
                        c.focus_distance.unwrap_or(dir.length()),
                        1e-3,
                        1e9,
                    )?,
                }
            }
            ProjectionName::Orthographic => {
                if c.fov_deg.is_some() {
                    return Err(self.invalid(
                        "camera.fov_deg",
                        "only for projection = \"perspective\" (an orthographic camera's view is `width` mm wide)",
                    ));
                }
                if c.lens_radius != 0.0 {
                    return Err(self.invalid(
                        "camera.lens_radius",
                        "only for projection = \"perspective\" (an orthographic camera has no lens)",
                    ));
                }
                if c.focus_distance.is_some() {
                    return Err(self.invalid(
                        "camera.focus_distance",
                        "only for projection = \"perspective\"",
                    ));
                }
                let w = c.width.ok_or_else(|| {
                    self.invalid(
                        "camera.width",
                        "required for projection = \"orthographic\" (film width in mm)",
                    )
                })?;
                Projection::Orthographic {
                    width: self.range("camera.width", w, 1e-3, 1e9)?,
                }
            }
        };
        Ok(Camera::look_at(eye, target, up, projection, width, height))
    }

    fn lights(
        &self,
        tables: &[LightTable],
    ) -> Result<(Vec<Light>, Vec<Option<String>>), SceneError> {
        let mut lights = Vec::new();
        let mut names = Vec::new();
        for (i, t) in tables.iter().enumerate() {
            let f = |s: &str| format!("lights[{i}].{s}");
            let light = match t {
                LightTable::Point {
                    position,
                    intensity,
                    color,
                    ..
                } => Light::Point(PointLight {
                    position: self.finite3(&f("position"), *position)?,
                    intensity: self.color(&f("color"), *color, 1e3)?
                        * self.range(&f("intensity"), *intensity, 0.0, 1e12)?,
                }),
                LightTable::Spot {
                    position,
                    target,
                    intensity,
                    color,
                    cone_deg,
                    falloff_deg,
                    ..
                } => {
                    let p = self.finite3(&f("position"), *position)?;
                    let d = self.finite3(&f("target"), *target)? - p;
                    if d.length_squared() < 1e-12 {
                        return Err(self.invalid(f("target"), "must differ from position"));
                    }
                    let outer = self.range(&f("cone_deg"), *cone_deg, 0.01, 180.0)?;
                    let falloff = self.range(&f("falloff_deg"), *falloff_deg, 0.0, outer)?;
                    Light::Spot(SpotLight {
                        position: p,
                        direction: d.normalize(),
                        intensity: self.color(&f("color"), *color, 1e3)?
                            * self.range(&f("intensity"), *intensity, 0.0, 1e12)?,
                        cos_inner: (outer - falloff).to_radians().cos(),
                        cos_outer: outer.to_radians().cos(),
                    })
                }
                LightTable::Distant {
                    direction,
                    irradiance,
                    color,
                    ..
                } => Light::Distant(DistantLight {
                    direction: self.unit3(&f("direction"), *direction)?,
                    irradiance: self.color(&f("color"), *color, 1e3)?
                        * self.range(&f("irradiance"), *irradiance, 0.0, 1e12)?,
                }),
                LightTable::Rect {
                    corner,
                    edge_u,
                    edge_v,
                    radiance,
                    color,
                    ..
                } => {
                    let (u, v) = (
                        self.finite3(&f("edge_u"), *edge_u)?,
                        self.finite3(&f("edge_v"), *edge_v)?,
                    );
                    if u.cross(v).length_squared() < 1e-12 {
                        return Err(self.invalid(f("edge_v"), "edges must span a non-zero area"));
                    }
                    Light::Rect(RectLight::new(
                        self.finite3(&f("corner"), *corner)?,
                        u,
                        v,
                        self.color(&f("color"), *color, 1e3)?
                            * self.range(&f("radiance"), *radiance, 0.0, 1e12)?,
                    ))
                }
                LightTable::Sphere {
                    center,
                    radius,
                    radiance,
                    color,
                    ..
                } => Light::Sphere(SphereLight {
                    center: self.finite3(&f("center"), *center)?,
                    radius: self.range(&f("radius"), *radius, 1e-4, 1e9)?,
                    radiance: self.color(&f("color"), *color, 1e3)?
                        * self.range(&f("radiance"), *radiance, 0.0, 1e12)?,
                }),
                LightTable::Environment {
                    radiance,
                    color,
                    map,
                    rotate_deg,
                    ..
                } => {
                    let scale = self.color(&f("color"), *color, 1e3)?
                        * self.range(&f("radiance"), *radiance, 0.0, 1e12)?;
                    let rot = self.range(&f("rotate_deg"), *rotate_deg, -360.0, 360.0)?;
                    let map = match map {
                        None => None,
                        Some(m) => Some(Arc::new(self.env_map(&f("map"), m, rot)?)),
                    };
                    Light::Environment(Environment { scale, map })
                }
            };
            if let Some(n) = t.name() {
                if names
                    .iter()
                    .any(|o: &Option<String>| o.as_deref() == Some(n))
                {
                    return Err(self.invalid(f("name"), format!("light name `{n}` is used twice")));
                }
            }
            lights.push(light);
            names.push(t.name().map(str::to_string));
        }
        Ok((lights, names))
    }

    fn env_map(&self, field: &str, file: &str, rotate_deg: f32) -> Result<EnvMap, SceneError> {
        let p = self.base.join(file);
        let img = crate::picture::exr::read_exr_rgb(&p)
            .map_err(|e| self.invalid(field, e.to_string()))?;
        let (w, h, texels) = (img.width as usize, img.height as usize, img.pixels);
        if w < 2 || h < 1 {
            return Err(self.invalid(field, format!("{} is too small ({w}x{h})", p.display())));
        }
        if texels
            .iter()
            .any(|t| !t.is_finite() || t.min_element() < 0.0)
        {
            return Err(self.invalid(
                field,
                format!("{} holds negative or non-finite texels", p.display()),
            ));
        }
        Ok(EnvMap::new(w, h, texels).rotated(rotate_deg))
    }

    fn materials(
        &mut self,
        tables: &BTreeMap<String, MaterialTable>,
    ) -> Result<(Vec<Material>, HashMap<String, u32>), SceneError> {
        let mut out = Vec::new();
        let mut index = HashMap::new();
        for (name, t) in tables {
            let f = |s: &str| format!("materials.{name}.{s}");
            let m = match t {
                MaterialTable::Lambertian { albedo } => Material::Lambertian {
                    albedo: self.color(&f("albedo"), *albedo, 1.0)?,
                },
                MaterialTable::Fiber {
                    diffuse,
                    fiber_color,
                    fiber_dir,
                    ray_dir,
                    ray_mask,
                    highlight_width_deg,
                    eta,
                    roughness,
                } => {
                    let params = WoodBsdfParams {
                        diffuse: self.color(&f("diffuse"), *diffuse, 1.0)?,
                        fiber_color: self.color(&f("fiber_color"), *fiber_color, 1.0)?,
                        fiber_dir: self.unit3(&f("fiber_dir"), *fiber_dir)?,
                        ray_dir: self.unit3(&f("ray_dir"), *ray_dir)?,
                        ray_mask: self.range(&f("ray_mask"), *ray_mask, 0.0, 1.0)?,
                        highlight_width: self
                            .range(&f("highlight_width_deg"), *highlight_width_deg, 0.06, 90.0)?
                            .to_radians(),
                        eta: self.range(&f("eta"), *eta, 1.0, 4.0)?,
                        roughness: self.range(&f("roughness"), *roughness, 0.0, 1.0)?,
                    };
                    // Let the BSDF itself check the combination once, here, with a clear message.
                    WoodBsdf::new(params).map_err(|e| self.invalid(f("type"), e.to_string()))?;
                    Material::Fiber { params }
                }
                MaterialTable::Wood {
                    preset,
                    preset_file,
                    seed,
                    eta,
                    roughness,
                    bump,
                } => {
                    let params = match (preset, preset_file) {
                        (Some(name), None) => crate::wood::preset(name)
                            .map_err(|e| self.invalid(f("preset"), e.to_string()))?,
                        (None, Some(file)) => read_preset_file(&self.base.join(file))
                            .map_err(|e| self.invalid(f("preset_file"), e.to_string()))?,
                        _ => {
                            return Err(self.invalid(
                                f("preset"),
                                format!(
                                    "give exactly one of `preset` (one of: {}) or `preset_file`",
                                    crate::wood::PRESET_NAMES.join(", ")
                                ),
                            ))
                        }
                    };
                    let bump = match bump {
                        Some(b) => self.range(&f("bump"), *b, 0.0, 100.0)?,
                        None => params.default_bump(),
                    };
                    let volume = crate::wood::WoodVolume::new(params, *seed)
                        .map_err(|e| self.invalid(f("preset"), e.to_string()))?;
                    Material::Wood(Box::new(WoodMaterial {
                        volume: Arc::new(volume),
                        eta: self.range(&f("eta"), *eta, 1.0, 4.0)?,
                        roughness: self.range(&f("roughness"), *roughness, 0.0, 1.0)?,
                        bump,
                        switches: Default::default(),
                    }))
                }
                MaterialTable::Measured { .. } => self.measured(t, name)?,
                MaterialTable::Texture { texture, params } => {
                    let t = crate::texture::by_name(texture, params)
                        .map_err(|e| self.invalid(f("texture"), e.to_string()))?;
                    Material::Texture(TextureMaterial {
                        name: texture.clone(),
                        texture: Arc::from(t),
                    })
                }
                MaterialTable::Mirror { reflectance } => Material::Mirror {
                    reflectance: self.color(&f("reflectance"), *reflectance, 1.0)?,
                },
                MaterialTable::Glass { eta, tint } => Material::Glass {
                    eta: self.range(&f("eta"), *eta, 1.0, 4.0)?,
                    tint: self.color(&f("tint"), *tint, 1.0)?,
                },
            };
            index.insert(name.clone(), out.len() as u32);
            out.push(m);
        }
        Ok((out, index))
    }

    /// A `measured` material: reads and checks the maps (errors name the field and the range) and
    /// warns when fibre colours had to be clamped into the BSDF's range (notes/measured.md).
    fn measured(&mut self, t: &MaterialTable, name: &str) -> Result<Material, SceneError> {
        let MaterialTable::Measured {
            diffuse,
            fiber_color,
            fiber_axis,
            highlight_width,
            highlight_width_deg,
            fiber_color_scale,
            color_space,
            size_mm,
            face,
            eta,
            roughness,
        } = t
        else {
            unreachable!("called for measured materials only")
        };
        let f = |s: &str| format!("materials.{name}.{s}");
        if highlight_width.is_some() && highlight_width_deg.is_some() {
            return Err(self.invalid(
                f("highlight_width_deg"),
                "give either a β map `highlight_width` or a constant `highlight_width_deg`, not both",
            ));
        }
        let beta = self.range(
            &f("highlight_width_deg"),
            highlight_width_deg.unwrap_or(crate::material::DEFAULT_HIGHLIGHT_WIDTH_DEG),
            0.06,
            90.0,
        )?;
        let scale = self.range(&f("fiber_color_scale"), *fiber_color_scale, 0.0, 1000.0)?;
        let size = Vec2::new(
            self.range(&f("size_mm"), size_mm[0], 1e-3, 1e6)?,
            self.range(&f("size_mm"), size_mm[1], 1e-3, 1e6)?,
        );
        let face = match face
            .as_deref()
            .map_or(Some(BoardFace::PosZ), BoardFace::from_name)
        {
            Some(face) => face,
            None => {
                return Err(self.invalid(
                    f("face"),
                    "allowed \"+z\", \"-z\", \"+x\", \"-x\", \"+y\", \"-y\"",
                ))
            }
        };
        let colors = match color_space.as_deref() {
            None | Some("linear") => ColorSpace::Linear,
            Some("srgb") => ColorSpace::Srgb,
            Some(other) => {
                return Err(self.invalid(
                    f("color_space"),
                    format!("`{other}` (allowed \"linear\" or \"srgb\")"),
                ))
            }
        };
        let files = MeasuredFiles {
            diffuse: self.base.join(diffuse),
            fiber_color: self.base.join(fiber_color),
            fiber_axis: self.base.join(fiber_axis),
            highlight_width: highlight_width.as_ref().map(|p| self.base.join(p)),
        };
        let board = MeasuredBoard::from_files(&files, colors)
            .map_err(|e| self.invalid(f(e.field()), e.to_string()))?;
        let m = MeasuredMaterial::new(
            Arc::new(board),
            face.rect(size),
            scale,
            beta.to_radians(),
            self.range(&f("eta"), *eta, 1.0, 4.0)?,
            self.range(&f("roughness"), *roughness, 0.0, 1.0)?,
        );
        if m.clamped > 0 {
            self.warnings.push(format!(
                "{}: {}: {} of {} texels have 2π · fiber_color_scale · fiber_color above 1 and were scaled down to 1 (hue kept)",
                self.path,
                f("fiber_color_scale"),
                m.clamped,
                m.board.fiber_color.len()
            ));
        }
        Ok(Material::Measured(Box::new(m)))
    }

    fn objects(
        &mut self,
        tables: &[ObjectTable],
        materials: &HashMap<String, u32>,
        _mats: &[Material],
    ) -> Result<Vec<Instance>, SceneError> {
        if tables.is_empty() {
            return Err(self.invalid(
                "objects",
                "the scene has no objects (give at least one [[objects]] table)",
            ));
        }
        let mut cache: HashMap<(PathBuf, bool), Arc<TriMesh>> = HashMap::new();
        let mut out = Vec::new();
        for (i, o) in tables.iter().enumerate() {
            let f = |s: &str| format!("objects[{i}].{s}");
            let material = *materials.get(&o.material).ok_or_else(|| {
                let mut names: Vec<&String> = materials.keys().collect();
                names.sort();
                self.invalid(
                    f("material"),
                    format!("no material named `{}` (defined: {names:?})", o.material),
                )
            })?;
            let mesh = self.shape(o, i, &mut cache)?;
            let scale = match o.scale {
                Scale::Uniform(s) => Vec3::splat(s),
                Scale::Axes(a) => v3(a),
            };
            for s in scale.to_array() {
                if !(s.is_finite() && s.abs() > 1e-9) {
                    return Err(self.invalid(f("scale"), "must be finite and non-zero"));
                }
            }
            let r = self.finite3(&f("rotate_deg"), o.rotate_deg)?;
            let rot = Quat::from_euler(
                EulerRot::ZYX,
                r.z.to_radians(),
                r.y.to_radians(),
                r.x.to_radians(),
            );
            let transform = Transform::new(Affine3A::from_scale_rotation_translation(
                scale,
                rot,
                self.finite3(&f("translate"), o.translate)?,
            ));
            if !transform.is_valid() {
                return Err(self.invalid(f("scale"), "the transform is not invertible"));
            }
            let reach = mesh
                .positions
                .iter()
                .map(|&v| transform.point_to_world(v).abs().max_element())
                .fold(
                    0.0f32,
                    |a, b| if b.is_nan() { f32::INFINITY } else { a.max(b) },
                );
            if reach > MAX_EXTENT_MM {
                return Err(self.invalid(
                    f("translate"),
                    format!(
                        "with its scale and translation the object reaches {reach:e} mm from the origin (allowed within {MAX_EXTENT_MM:e} mm)"
                    ),
                ));
            }
            let placement = match &o.tree {
                None => Placement::default(),
                Some(t) => self.placement(t, i)?,
            };
            out.push(Instance {
                mesh,
                transform,
                material,
                placement,
            });
        }
        Ok(out)
    }

    fn placement(&self, t: &TreeTable, i: usize) -> Result<Placement, SceneError> {
        let f = |s: &str| format!("objects[{i}].tree.{s}");
        let region = t.region.unwrap_or_default();
        if t.region.is_some() {
            self.range(&f("region.r_min"), region.r_min, 0.0, 1e6)?;
            self.range(&f("region.r_max"), region.r_max, region.r_min, 1e6)?;
            self.range(&f("region.z_span"), region.z_span, 0.0, 1e7)?;
        }
        let cutting = match t.cut {
            CutName::Solid => {
                if t.layout.is_some() || t.region.is_some() {
                    return Err(self.invalid(
                        f("layout"),
                        "`layout` and `region` are for cut = \"boards\" / \"veneer\"",
                    ));
                }
                Cutting::Solid
            }
            CutName::Veneer => Cutting::Veneer {
                region,
                seed: t.seed,
            },
            CutName::Boards => {
                let layout = t.layout.ok_or_else(|| {
                    self.invalid(f("layout"), "required for cut = \"boards\", e.g. { kind = \"planks\", width = 90.0, length = 900.0, stagger = 0.3 } or { kind = \"parquet\", tile = 400.0, strip = 50.0 }")
                })?;
                match layout {
                    BoardLayout::Planks {
                        width,
                        length,
                        stagger,
                    } => {
                        self.range(&f("layout.width"), width, 1e-3, 1e6)?;
                        self.range(&f("layout.length"), length, 1e-3, 1e6)?;
                        self.range(&f("layout.stagger"), stagger, 0.0, 1.0)?;
                    }
                    BoardLayout::Parquet { tile, strip } => {
                        self.range(&f("layout.tile"), tile, 1e-3, 1e6)?;
                        self.range(&f("layout.strip"), strip, 1e-3, tile / 2.0)?;
                    }
                }
                Cutting::Boards {
                    layout,
                    region,
                    seed: t.seed,
                }
            }
        };
        let axis = self.unit3(&f("axis"), t.axis)?;
        let scale = self.range(&f("scale"), t.scale, 1e-6, 1e6)?;
        if let Some(sawn) = &t.sawn {
            if t.cut != CutName::Solid || t.origin != [0.0; 3] || t.rotation_deg != 0.0 {
                return Err(self.invalid(
                    f("sawn"),
                    "`sawn` places a solid cut by itself: give it or `origin`/`rotation_deg`, not both",
                ));
            }
            let mut p =
                Placement::sawn(axis, scale, sawn).map_err(|e| self.invalid(f("sawn"), e))?;
            p.world_space = t.space == SpaceName::World;
            return Ok(p);
        }
        Ok(Placement {
            // Beyond the scene's extent the growth time loses all precision (NaN at 1e12).
            origin: self.point(&f("origin"), t.origin, MAX_EXTENT_MM)?,
            axis,
            rotation: self
                .range(&f("rotation_deg"), t.rotation_deg, -360.0, 360.0)?
                .to_radians(),
            scale,
            cutting,
            world_space: t.space == SpaceName::World,
            tilt: glam::Mat3::IDENTITY,
        })
    }

    /// Builds (or loads) the mesh of one object, rejecting fields its shape does not use.
    fn shape(
        &mut self,
        o: &ObjectTable,
        i: usize,
        cache: &mut HashMap<(PathBuf, bool), Arc<TriMesh>>,
    ) -> Result<Arc<TriMesh>, SceneError> {
        let f = |s: &str| format!("objects[{i}].{s}");
        let (kind, used): (&str, &[&str]) = match o.shape {
            ShapeKind::Box => ("box", &["size"]),
            ShapeKind::Quad => ("quad", &["size"]),
            ShapeKind::Sphere => ("sphere", &["radius", "segments"]),
            ShapeKind::Cylinder => ("cylinder", &["radius", "height", "segments"]),
            ShapeKind::Lathe => ("lathe", &["profile", "segments"]),
            ShapeKind::Teapot => ("teapot", &["size", "resolution"]),
            ShapeKind::Mesh => ("mesh", &["file"]),
        };
        let present = [
            ("size", o.size.is_some()),
            ("radius", o.radius.is_some()),
            ("height", o.height.is_some()),
            ("segments", o.segments.is_some()),
            ("profile", o.profile.is_some()),
            ("resolution", o.resolution.is_some()),
            ("file", o.file.is_some()),
        ];
        for (name, is) in present {
            if is && !used.contains(&name) {
                return Err(self.invalid(
                    f(name),
                    format!("not used by shape `{kind}` (it takes: {})", used.join(", ")),
                ));
            }
        }
        let need = |name: &str| self.invalid(f(name), format!("required by shape `{kind}`"));
        let segments = match o.segments {
            None => 64,
            Some(s) => self.range(&f("segments"), s as f32, 3.0, 4096.0)? as u32,
        };
        let positive = |name: &str, x: f32| self.range(&f(name), x, 1e-6, 1e9);
        let mut mesh = match o.shape {
            ShapeKind::Box | ShapeKind::Quad => {
                let s = o.size.as_ref().ok_or_else(|| need("size"))?;
                let want = if o.shape == ShapeKind::Box { 3 } else { 2 };
                if s.len() != want {
                    return Err(self.invalid(
                        f("size"),
                        format!("shape `{kind}` takes {want} numbers (mm)"),
                    ));
                }
                for x in s {
                    positive("size", *x)?;
                }
                if want == 3 {
                    shapes::make_box(Vec3::new(s[0], s[1], s[2]))
                } else {
                    shapes::make_quad(Vec2::new(s[0], s[1]))
                }
            }
            ShapeKind::Sphere => shapes::make_sphere(
                positive("radius", o.radius.ok_or_else(|| need("radius"))?)?,
                segments,
            ),
            ShapeKind::Cylinder => shapes::make_cylinder(
                positive("radius", o.radius.ok_or_else(|| need("radius"))?)?,
                positive("height", o.height.ok_or_else(|| need("height"))?)?,
                segments,
            ),
            ShapeKind::Lathe => {
                let p = o.profile.as_ref().ok_or_else(|| need("profile"))?;
                if p.len() < 2 {
                    return Err(self.invalid(f("profile"), "needs at least 2 (radius, z) points"));
                }
                for q in p {
                    self.range(&f("profile"), q[0], 0.0, 1e9)?;
                    self.range(&f("profile"), q[1], -1e9, 1e9)?;
                }
                // Its triangle count is known before it is built: a long profile at 4096
                // segments is billions of triangles, refused before a vertex is allocated.
                let triangles = 2 * (p.len() as u64 - 1) * segments as u64;
                let bytes = crate::render::resources::BUILD_BYTES_PER_TRIANGLE;
                crate::render::resources::Resources {
                    what: format!(
                        "{} ({} profile points × {segments} segments = {triangles} triangles)",
                        f("profile"),
                        p.len()
                    ),
                    memory: triangles * bytes,
                    disk: 0,
                    remedy: crate::render::resources::LOWER_TRIANGLES,
                }
                .check(self.base, self.ignore_limits)
                .map_err(|source| SceneError::Resources {
                    path: self.path.to_string(),
                    source,
                })?;
                let pts: Vec<Vec2> = p.iter().map(|q| Vec2::new(q[0], q[1])).collect();
                shapes::make_lathe(&pts, segments)
            }
            ShapeKind::Teapot => {
                let s = o.size.as_ref().map_or(Ok(30.0), |s| match s.as_slice() {
                    [x] => positive("size", *x),
                    _ => Err(self.invalid(
                        f("size"),
                        "shape `teapot` takes 1 number (mm per teapot unit)",
                    )),
                })?;
                let res = match o.resolution {
                    None => 8,
                    Some(r) => self.range(&f("resolution"), r as f32, 1.0, 256.0)? as u32,
                };
                teapot::make_teapot(s, res)
            }
            ShapeKind::Mesh => {
                let file = o.file.as_ref().ok_or_else(|| need("file"))?;
                let p = self.base.join(file);
                // Keyed by file and `smooth`: the second object using a file may want the
                // other normals.
                let key = (p.clone(), o.smooth);
                if let Some(m) = cache.get(&key) {
                    return Ok(m.clone());
                }
                let mut m = mesh_io::load_mesh(&p).map_err(|source| SceneError::Mesh {
                    path: self.path.to_string(),
                    field: f("file"),
                    source,
                })?;
                let dropped = m.drop_degenerate();
                if dropped > 0 {
                    self.warnings.push(format!(
                        "{}: {}: dropped {dropped} degenerate triangles",
                        self.path,
                        f("file")
                    ));
                }
                if m.indices.is_empty() {
                    return Err(
                        self.invalid(f("file"), format!("{} has no valid triangles", p.display()))
                    );
                }
                if !o.smooth {
                    m.normals = None;
                }
                let m = Arc::new(m);
                cache.insert(key, m.clone());
                return Ok(m);
            }
        };
        if !o.smooth {
            mesh.normals = None;
        }
        Ok(Arc::new(mesh))
    }

    fn check_sweep(
        &self,
        s: &SweepTable,
        names: &[Option<String>],
        width: u32,
        height: u32,
    ) -> Result<(), SceneError> {
        self.range("sweep.frames", s.frames as f32, 1.0, 100_000.0)?;
        for a in s.arc_deg {
            self.range("sweep.arc_deg", a, -90.0, 90.0)?;
        }
        self.range("sweep.radius", s.radius, 1e-3, 1e9)?;
        self.finite3("sweep.pivot", s.pivot)?;
        self.unit3("sweep.axis", s.axis)?;
        if s.azimuths_deg.is_empty() || s.azimuths_deg.len() > format::MAX_ARCS {
            return Err(self.invalid(
                "sweep.azimuths_deg",
                format!(
                    "{} azimuths (allowed 1 to {})",
                    s.azimuths_deg.len(),
                    format::MAX_ARCS
                ),
            ));
        }
        for a in &s.azimuths_deg {
            self.range("sweep.azimuths_deg", *a, -360.0, 360.0)?;
        }
        self.range(
            "sweep.frames",
            (s.frames as usize * s.azimuths_deg.len()) as f32,
            1.0,
            100_000.0,
        )?;
        if let Some(b) = &s.board {
            self.finite3("sweep.board.origin", b.origin)?;
            let x = self.unit3("sweep.board.x_axis", b.x_axis)?;
            let y = self.unit3("sweep.board.y_axis", b.y_axis)?;
            if x.dot(y).abs() > 1e-3 {
                return Err(self.invalid(
                    "sweep.board.y_axis",
                    "must be perpendicular to x_axis (|x·y| ≤ 1e-3)".to_string(),
                ));
            }
            for v in b.size_mm {
                self.range("sweep.board.size_mm", v, 1e-3, 1e6)?;
            }
            self.range("sweep.board.eta", b.eta, 1.0, 4.0)?;
        }
        if !names.iter().any(|n| n.as_deref() == Some(s.light.as_str())) {
            let known: Vec<&str> = names.iter().flatten().map(String::as_str).collect();
            return Err(self.invalid(
                "sweep.light",
                format!("no light named `{}` (named lights: {known:?})", s.light),
            ));
        }
        for (k, r) in s.regions.iter().enumerate() {
            if !(r.x0 < r.x1 && r.y0 < r.y1 && r.x1 <= width && r.y1 <= height) {
                return Err(self.invalid(
                    format!("sweep.regions[{k}]"),
                    format!(
                        "region `{}` must satisfy x0 < x1 <= {width}, y0 < y1 <= {height}",
                        r.name
                    ),
                ));
            }
        }
        Ok(())
    }
}

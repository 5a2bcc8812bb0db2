//! The TOML scene format, built-in procedural shapes, mesh loading and preset lookup.
//!
//! [`load`] reads a scene file (format in scenes/README.md) and builds a [`render::Scene`] with
//! its render settings. Every error names the file, the field and what is allowed.

mod build;
pub mod fields;
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
    /// [`MAX_SCENE_BYTES`](crate::resources::MAX_SCENE_BYTES).
    #[error("cannot read scene {0}")]
    Input(crate::resources::ResourceError),
    /// The geometry's BVH build would need more memory than the machine has (estimated before
    /// it starts; `--ignore-limits` skips the check).
    #[error("scene {path}: {source}")]
    Resources {
        /// The scene file.
        path: String,
        /// The estimate and what is available.
        source: crate::resources::ResourceError,
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
    /// The `[expect]` table, unread (see [`SceneFile::expect`]).
    pub expect: Option<toml::Table>,
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
/// [`MAX_SCENE_BYTES`](crate::resources::MAX_SCENE_BYTES).
pub fn source(path: &Path) -> Result<(std::borrow::Cow<'static, [u8]>, PathBuf), SceneError> {
    use crate::resources::MAX_SCENE_BYTES;
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
    /// [`MAX_SCENE_BYTES`](crate::resources::MAX_SCENE_BYTES).
    #[error("preset file {0}")]
    Read(crate::resources::ResourceError),
    /// Not a valid preset (the error names the file, the field and the range).
    #[error(transparent)]
    Wood(#[from] crate::wood::WoodError),
}

/// Reads a species preset file (`preset_file` of a wood material, `--preset-file`): regular
/// TOML text of at most [`MAX_SCENE_BYTES`](crate::resources::MAX_SCENE_BYTES), so a
/// FIFO or a device is refused instead of blocking or reading forever.
pub fn read_preset_file(path: &Path) -> Result<crate::wood::WoodParams, PresetFileError> {
    use crate::resources::{read_text_bounded, MAX_SCENE_BYTES};
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

    /// Number `x` of field `spec` (its range from [`fields`]), reported as `at.<name>`.
    fn number(&self, at: &str, spec: &fields::Field, x: f32) -> Result<f32, SceneError> {
        let (lo, hi) = spec.bounds();
        self.range(&format!("{at}.{}", spec.name), x, lo, hi)
    }

    /// Colour `a` of field `spec` (its range from [`fields`]), reported as `at.<name>`.
    fn color(&self, at: &str, spec: &fields::Field, a: [f32; 3]) -> Result<Vec3, SceneError> {
        let fields::Value::Colour { max } = spec.value else {
            unreachable!("`{}` is a colour field", spec.name)
        };
        let field = format!("{at}.{}", spec.name);
        for x in a {
            self.range(&field, x, 0.0, max)?;
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
                sampling: r.sampling,
            },
            exposure: r.exposure,
            light_names,
            sweep: file.sweep,
            warnings: self.warnings,
            expect: file.expect,
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
}

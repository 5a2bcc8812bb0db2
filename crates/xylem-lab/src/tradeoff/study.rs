//! The study itself: a reference render in two halves, every setting rendered and scored
//! against it, then timed in interleaved rounds.

use super::{
    median_range, reference_from_halves, relative_mse, relative_mse_net, render_with, ssim,
    weak_reference, Knobs, Measurement, Rendered,
};
use std::path::PathBuf;
use xylem::progress::Progress;
use xylem::scene::{LoadedScene, SceneError};

/// What `xylem tradeoff` measures, as its flags say.
#[derive(Clone, Debug)]
pub struct StudyOptions {
    /// Scene file (TOML) or built-in scene.
    pub scene: PathBuf,
    /// Image width, 8 to 4096 (the height keeps the scene's aspect ratio).
    pub width: u32,
    /// Samples per pixel of the reference render (full model), at least 1.
    pub reference_spp: u32,
    /// Replace the preset of every wood material of the scene by this one.
    pub preset: Option<String>,
    /// Also write every render as a PNG into this folder.
    pub images: Option<PathBuf>,
    /// Worker threads (0 = all cores).
    pub threads: usize,
    /// Measure even with a reference under [`super::MIN_REFERENCE_FACTOR`] × the highest
    /// measured spp.
    pub allow_weak_reference: bool,
    /// Times each setting is rendered for its timing, in rounds over all settings.
    pub repeats: u32,
}

/// Why the study could not run or write its report.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// An option out of range, or a weak reference not allowed, as the command line spells it.
    #[error("{0}")]
    Argument(String),
    /// The scene could not be loaded.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// `--preset` names no preset.
    #[error("--preset {name}")]
    Preset {
        /// The name given.
        name: String,
        /// Why.
        #[source]
        source: xylem::wood::WoodError,
    },
    /// A render failed; `what` says which.
    #[error("{what}: {message}")]
    Render {
        /// Which render.
        what: String,
        /// What went wrong.
        message: String,
    },
    /// A folder could not be made.
    #[error("creating {path}")]
    Folder {
        /// The folder.
        path: String,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// An image or plot could not be written.
    #[error(transparent)]
    Image(#[from] xylem::picture::ImageError),
    /// The report could not be written.
    #[error(transparent)]
    Report(#[from] xylem::sweep::SequenceError),
    /// The JSON could not be made.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// A file operation failed.
    #[error(transparent)]
    Io(#[from] std::io::Error),
}

/// Refuses options out of range, and a weak reference unless `allow_weak_reference`;
/// returns why the reference is weak, if it is, for the caller to warn.
pub fn check_options(
    o: &StudyOptions,
    all: &[(String, String, Knobs)],
) -> Result<Option<String>, StudyError> {
    if !(8..=4096).contains(&o.width) {
        return Err(StudyError::Argument(format!(
            "--width {}: allowed 8 to 4096",
            o.width
        )));
    }
    if o.reference_spp < 1 {
        return Err(StudyError::Argument(
            "--reference-spp must be at least 1".into(),
        ));
    }
    let max_spp = all.iter().map(|(_, _, k)| k.spp).max().unwrap_or(1);
    let weak = weak_reference(o.reference_spp, max_spp);
    if let Some(why) = &weak {
        if !o.allow_weak_reference {
            return Err(StudyError::Argument(format!(
                "{why} (or pass --allow-weak-reference to measure anyway)"
            )));
        }
    }
    Ok(weak)
}

/// The study's measurements.
#[derive(Clone, Debug)]
pub struct StudyResult {
    /// The scene's name.
    pub name: String,
    /// The measurement size.
    pub size: (u32, u32),
    /// Render time of the reference (both halves), wall clock.
    pub reference_seconds: f64,
    /// One row per setting, in the order of the settings.
    pub rows: Vec<Measurement>,
}

/// Measures every setting of `all` ([`super::settings`]) on the scene: the reference, each
/// setting's error, then its timing rounds; `progress` counts the renders.
pub fn run_study(
    o: &StudyOptions,
    all: &[(String, String, Knobs)],
    progress: &dyn Progress,
) -> Result<StudyResult, StudyError> {
    let probe = xylem::scene::load(&o.scene)?;
    let (w0, h0) = (probe.scene.camera.width, probe.scene.camera.height);
    let (w, h) = (
        o.width,
        ((o.width as f32 * h0 as f32 / w0 as f32).round() as u32).max(1),
    );
    let (exposure, name) = (probe.exposure, probe.name.clone());
    drop(probe);
    let base = scene_maker(o, (w, h))?;
    let total = all.len() as u64 * o.repeats as u64 + 1;
    progress.start(total, "renders");
    let study = Study {
        opts: o,
        base: &base,
        run: xylem::render::RunOptions {
            threads: o.threads,
            ..Default::default()
        },
        size: (w, h),
        exposure,
        progress,
        total,
        done: std::cell::Cell::new(0),
    };
    let reference = study.reference()?;
    let mut rows = study.measure(all, &reference)?;
    study.time(all, &mut rows)?;
    progress.finish();
    Ok(StudyResult {
        name,
        size: (w, h),
        reference_seconds: reference.seconds,
        rows,
    })
}

/// Loads the scene afresh for each render, at the measurement size `(w, h)`, with `--preset`'s
/// wood in every wood material.
fn scene_maker(
    o: &StudyOptions,
    (w, h): (u32, u32),
) -> Result<impl Fn() -> Result<LoadedScene, String>, StudyError> {
    let preset = match &o.preset {
        Some(p) => Some(xylem::wood::preset(p).map_err(|source| StudyError::Preset {
            name: p.clone(),
            source,
        })?),
        None => None,
    };
    let scene_path = o.scene.clone();
    Ok(move || -> Result<LoadedScene, String> {
        let mut l = xylem::scene::load(&scene_path).map_err(|e| e.to_string())?;
        l.scene.camera = l.scene.camera.with_resolution(w, h);
        if let Some(params) = &preset {
            for m in &mut l.scene.materials {
                if let xylem::material::Material::Wood(wm) = m {
                    let v = xylem::wood::WoodVolume::new(params.clone(), wm.volume.seed())
                        .map_err(|e| e.to_string())?;
                    wm.volume = std::sync::Arc::new(v);
                }
            }
        }
        Ok(l)
    })
}

/// How far the reference halves' seeds lie from the scene's (which every row uses): half k
/// renders with seed + k · this. Any other seed gives independent samples (per-pixel seeding).
const REFERENCE_SEED_OFFSET: u64 = 0x9e37_79b9_7f4a_7c15;

/// The reference render: the mean of two halves, the noise their difference measures, and
/// their render time.
struct Reference {
    image: Vec<glam::Vec3>,
    noise: f64,
    seconds: f64,
}

/// What every render of the study shares: the scene, the run options, the size and exposure
/// of the images, and the progress count.
struct Study<'a> {
    opts: &'a StudyOptions,
    base: &'a dyn Fn() -> Result<LoadedScene, String>,
    run: xylem::render::RunOptions<'a>,
    size: (u32, u32),
    exposure: f32,
    progress: &'a dyn Progress,
    total: u64,
    done: std::cell::Cell<u64>,
}

impl Study<'_> {
    /// Says what renders next.
    fn say(&self, message: &str) {
        self.progress.update(self.done.get(), self.total, message);
    }

    /// One render done.
    fn step(&self) {
        self.done.set(self.done.get() + 1);
        self.progress.update(self.done.get(), self.total, "");
    }

    /// Renders `knobs`; `what` names the render in the error.
    fn render(&self, knobs: &Knobs, what: &str) -> Result<Rendered, StudyError> {
        render_with(self.base, knobs, &self.run).map_err(|message| StudyError::Render {
            what: what.to_string(),
            message,
        })
    }

    /// The reference in two halves of other seeds than the rows' (which share the scene's):
    /// the rows are then independent of it, and the halves' difference measures its own
    /// noise, taken off each row's error (`relative_mse_net`).
    fn reference(&self) -> Result<Reference, StudyError> {
        let spp = self.opts.reference_spp;
        self.say(&format!("reference, {spp} spp"));
        let half = |k: u64| -> Result<Rendered, StudyError> {
            let seeded = || {
                (self.base)().map(|mut l| {
                    l.settings.seed = l.settings.seed.wrapping_add(REFERENCE_SEED_OFFSET * k);
                    l
                })
            };
            render_with(&seeded, &Knobs::reference(spp.div_ceil(2)), &self.run).map_err(|message| {
                StudyError::Render {
                    what: "reference render".into(),
                    message,
                }
            })
        };
        let (a, b) = (half(1)?, half(2)?);
        let (image, noise) = reference_from_halves(&a.image, &b.image);
        self.step();
        self.save("reference", &image)?;
        Ok(Reference {
            image,
            noise,
            seconds: a.seconds + b.seconds,
        })
    }

    /// With `images`, writes `img` as a PNG named after `name`.
    fn save(&self, name: &str, img: &[glam::Vec3]) -> Result<(), StudyError> {
        let Some(dir) = &self.opts.images else {
            return Ok(());
        };
        std::fs::create_dir_all(dir).map_err(|source| StudyError::Folder {
            path: dir.display().to_string(),
            source,
        })?;
        let file: String = name
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        let (w, h) = self.size;
        let path = dir.join(format!("{file}.png"));
        xylem::picture::png::write_png_linear(&path, w, h, img, self.exposure)?;
        Ok(())
    }

    /// Renders every setting once and measures its error against the reference and against
    /// the reference model at the same spp (same seeds, rendered once per spp). Times are
    /// filled in by [`Study::time`].
    fn measure(
        &self,
        all: &[(String, String, Knobs)],
        reference: &Reference,
    ) -> Result<Vec<Measurement>, StudyError> {
        let (w, h) = (self.size.0 as usize, self.size.1 as usize);
        let mut rows = Vec::new();
        let mut same_spp: Vec<(u32, Vec<glam::Vec3>)> = Vec::new();
        for (knob, setting, knobs) in all.iter().cloned() {
            self.say(&setting);
            let r = self.render(&knobs, &format!("render with {setting}"))?;
            if !same_spp.iter().any(|(s, _)| *s == knobs.spp) {
                let what = format!("reference model at {} spp", knobs.spp);
                let m = self.render(&Knobs::reference(knobs.spp), &what)?;
                same_spp.push((knobs.spp, m.image));
            }
            self.save(&format!("{knob} {setting}"), &r.image)?;
            let model_ref = &(same_spp.iter().find(|(s, _)| *s == knobs.spp))
                .expect("pushed")
                .1;
            let img = &r.image;
            rows.push(Measurement {
                knob,
                setting,
                knobs,
                // The first timing round.
                seconds: r.seconds,
                cpu_seconds: r.cpu_seconds,
                cpu_min: f64::NAN,
                cpu_max: f64::NAN,
                repeats: self.opts.repeats,
                prep_seconds: r.prep_seconds,
                relative_mse: relative_mse_net(img, &reference.image, reference.noise),
                ssim: ssim(img, &reference.image, w, h, self.exposure),
                model_mse: relative_mse(img, model_ref),
                model_ssim: ssim(img, model_ref, w, h, self.exposure),
            });
            self.step();
        }
        Ok(rows)
    }

    /// The timing repeats, interleaved (every setting once per round, so that a change in the
    /// machine's load falls on every setting alike); each row's times become the median and
    /// range over its rounds, the first being [`Study::measure`]'s render.
    fn time(
        &self,
        all: &[(String, String, Knobs)],
        rows: &mut [Measurement],
    ) -> Result<(), StudyError> {
        let mut times: Vec<(Vec<f64>, Vec<f64>)> = (rows.iter())
            .map(|r| (vec![r.seconds], vec![r.cpu_seconds]))
            .collect();
        for round in 1..self.opts.repeats {
            for (i, (_, setting, knobs)) in all.iter().enumerate() {
                self.say(&format!("timing round {}: {setting}", round + 1));
                let r = self.render(knobs, &format!("render with {setting}"))?;
                times[i].0.push(r.seconds);
                times[i].1.push(r.cpu_seconds);
                self.step();
            }
        }
        for (row, (wall, cpu)) in rows.iter_mut().zip(&times) {
            row.seconds = median_range(wall).0;
            (row.cpu_seconds, row.cpu_min, row.cpu_max) = median_range(cpu);
        }
        Ok(())
    }
}

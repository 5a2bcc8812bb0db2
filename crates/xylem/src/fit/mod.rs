//! Measuring the wood back: per-texel fibre-BSDF parameters fitted to a light sweep, as
//! Marschner et al. 2005 (§5, "Measuring and modeling the appearance of finished wood") fitted
//! their boards — diffuse colour, fibre highlight colour, fibre axis and highlight width.
//!
//! - [`capture`]: the sweep folder (manifest, frames) read and checked, texels projected;
//! - [`model`]: the model (the renderer's `WoodBsdf`) and the per-texel robust fit;
//! - [`maps`]: the fitted maps in the encoding of the `measured` material, residual map, report.
//!
//! Derivations (parameterisation, initialisation, identifiability, arcs): notes/fit.md.

pub mod capture;
pub mod maps;
pub mod model;

pub use capture::{Capture, CaptureError};
pub use maps::{write_maps, FittedMaps};
pub(crate) use model::fit_texel;
pub use model::{Scratch, TexelData, TexelFit};

use crate::progress::{NoProgress, Progress};
use glam::Vec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Anything that stops a fit.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// The capture could not be read or is inconsistent.
    #[error(transparent)]
    Capture(#[from] CaptureError),
    /// A texel of the board lies outside the frames.
    #[error("{path}: field `board`: texel (column {col}, row {row}) of the {w}x{h} map projects to film point ({x:.1}, {y:.1}), outside the {fw}x{fh} frames (allowed: the whole board in view)")]
    OutOfView {
        /// The manifest.
        path: String,
        /// The texel's column.
        col: usize,
        /// The texel's row.
        row: usize,
        /// Map width (texels).
        w: usize,
        /// Map height (texels).
        h: usize,
        /// Film x of the texel's centre (pixels).
        x: f32,
        /// Film y of the texel's centre (pixels).
        y: f32,
        /// Frame width (pixels).
        fw: u32,
        /// Frame height (pixels).
        fh: u32,
    },
    /// The requested map size is outside 1–8192 texels per side.
    #[error("--texels {w}x{h}: allowed 1 to 8192 each")]
    Texels {
        /// Requested width (texels).
        w: usize,
        /// Requested height (texels).
        h: usize,
    },
    /// The fit would need more memory than is available ([`fit_memory`]).
    #[error("fitting {w}x{h} texels from {frames} frames needs about {need} of memory but {have} is available; lower --texels")]
    Memory {
        /// Map width (texels).
        w: usize,
        /// Map height (texels).
        h: usize,
        /// Frames in the capture.
        frames: usize,
        /// The estimate.
        need: crate::resources::Bytes,
        /// What is available.
        have: crate::resources::Bytes,
    },
    /// The worker thread pool could not be started.
    #[error("cannot start {threads} worker threads: {cause}")]
    Threads {
        /// Threads requested.
        threads: usize,
        /// rayon's error.
        cause: String,
    },
    /// No texel has the 8 usable frames a fit needs: the capture cannot be fitted.
    #[error(
        "{path}: no texel of the {w}x{h} map could be fitted (each needs 8 usable frames): {cause}"
    )]
    Unfittable {
        /// The manifest.
        path: String,
        /// Map width (texels).
        w: usize,
        /// Map height (texels).
        h: usize,
        /// Why the samples were rejected, with the fields to check.
        cause: String,
    },
    /// The maps could not be written.
    #[error(transparent)]
    Output(#[from] maps::MapsError),
}

/// The largest reflectance factor (pixel value over irradiance: a BRDF × cos θ) a sample may
/// have, a million times a white diffuse surface's 1/π. A brighter sample comes from a frame
/// or an intensity that does not match the light (a frame of 3e38, an intensity 10⁻³⁰ too
/// small), and its square would overflow the fit's f32 sums into a NaN.
pub const MAX_REFLECTANCE_FACTOR: f32 = 1e6 / std::f32::consts::PI;

/// The least cosine between the face's normal and the light or the view for a sample to count
/// (about 1.1° above the face): grazing samples carry no usable shading.
pub const MIN_COS: f32 = 0.02;

/// Samples (texel × frame) the fit did not use, by cause; `fit.json` reports them, and they
/// name the cause when no texel could be fitted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Rejections {
    /// Samples used.
    pub used: u64,
    /// Clipped (at or above `clip`, or the top code of a PNG), missing or not finite.
    pub clipped: u64,
    /// Pixel value over irradiance above [`MAX_REFLECTANCE_FACTOR`].
    pub too_bright: u64,
    /// The light at most [`MIN_COS`] above the face, or behind it.
    pub light_grazing: u64,
    /// The camera at most [`MIN_COS`] above the face, or behind it.
    pub view_grazing: u64,
    /// The light's irradiance at the texel not a positive normal float in every channel.
    pub no_light: u64,
    /// The finish's mirror glint of a sphere light.
    pub glint: u64,
}

/// What became of one sample (see [`Rejections`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Cause {
    Used,
    Clipped,
    TooBright,
    LightGrazing,
    ViewGrazing,
    NoLight,
    Glint,
}

impl Rejections {
    fn count(&mut self, c: Cause) {
        *match c {
            Cause::Used => &mut self.used,
            Cause::Clipped => &mut self.clipped,
            Cause::TooBright => &mut self.too_bright,
            Cause::LightGrazing => &mut self.light_grazing,
            Cause::ViewGrazing => &mut self.view_grazing,
            Cause::NoLight => &mut self.no_light,
            Cause::Glint => &mut self.glint,
        } += 1;
    }

    fn add(&mut self, o: &Rejections) {
        self.used += o.used;
        self.clipped += o.clipped;
        self.too_bright += o.too_bright;
        self.light_grazing += o.light_grazing;
        self.view_grazing += o.view_grazing;
        self.no_light += o.no_light;
        self.glint += o.glint;
    }

    /// The counts by cause, as `fit.json` reports them.
    pub(crate) fn to_json(self) -> serde_json::Value {
        serde_json::json!({
            "used": self.used,
            "clipped_or_not_finite": self.clipped,
            "too_bright": self.too_bright,
            "light_grazing": self.light_grazing,
            "view_grazing": self.view_grazing,
            "no_irradiance": self.no_light,
            "glint": self.glint,
        })
    }

    /// The causes that rejected samples, most first, each with the fields to check.
    pub fn describe(&self, capture: &Capture) -> String {
        let clip = capture
            .clip
            .map_or("none".to_string(), |c| format!("{c:e}"));
        let mut causes = [
            (self.view_grazing, format!("the camera sees the face edge-on or from behind (within {:.1}° of its plane; fields `camera` and `board`)", MIN_COS.asin().to_degrees())),
            (self.light_grazing, format!("the light is never more than {:.1}° above the face (fields `frames[].position`, `frames[].direction`, `board`)", MIN_COS.asin().to_degrees())),
            (self.no_light, "no irradiance reaches the board (field `frames[].intensity`: every channel must be positive and large enough to divide by)".to_string()),
            (self.clipped, format!("the pixels are clipped, missing or not finite (field `clip` = {clip}, or the frame images)")),
            (self.too_bright, format!("pixel value over the light's irradiance exceeds {MAX_REFLECTANCE_FACTOR:.3e}, a million times a white diffuse surface: the frames do not match field `frames[].intensity`")),
            (self.glint, "every usable sample is the finish's mirror glint of the sphere light (field `frames[].radius`)".to_string()),
        ];
        causes.sort_by_key(|c| std::cmp::Reverse(c.0));
        let total = self.used
            + self.clipped
            + self.too_bright
            + self.light_grazing
            + self.view_grazing
            + self.no_light
            + self.glint;
        let mut parts: Vec<String> = causes
            .iter()
            .filter(|c| c.0 > 0)
            .map(|(n, why)| format!("{n} of {total} samples: {why}"))
            .collect();
        if self.used > 0 {
            parts.push(format!(
                "{} of {total} samples usable, too few at any one texel",
                self.used
            ));
        }
        parts.join("; ")
    }
}

/// How to fit.
#[derive(Clone, Debug)]
pub struct FitOptions<'a> {
    /// Map size in texels; default: the board's size in pixels along each axis (about one texel
    /// per pixel).
    pub texels: Option<(usize, usize)>,
    /// Worker threads; 0 = all cores.
    pub threads: usize,
    /// Told of the texels fitted so far (the CLI draws a bar on stderr).
    pub progress: &'a dyn Progress,
}

impl Default for FitOptions<'_> {
    fn default() -> Self {
        FitOptions {
            texels: None,
            threads: 0,
            progress: &NoProgress,
        }
    }
}

/// Texels the board covers in the frames: its edges' lengths in pixels, rounded.
pub(crate) fn default_texels(c: &Capture) -> (usize, usize) {
    let b = &c.board;
    let px = |d: Vec3| -> f32 {
        match (
            c.camera.project(b.origin - d),
            c.camera.project(b.origin + d),
        ) {
            (Some(a), Some(z)) => ((z.0 - a.0).powi(2) + (z.1 - a.1).powi(2)).sqrt(),
            _ => 1.0,
        }
    };
    (
        (px(0.5 * b.size[0] * b.x).round() as usize).clamp(1, 8192),
        (px(0.5 * b.size[1] * b.y).round() as usize).clamp(1, 8192),
    )
}

/// Bilinear sample of `img` (`w` × `h`, pixel centres at i + ½) at film point (x, y); NaN
/// where a tap is NaN (a clipped or missing pixel).
fn bilinear(img: &[Vec3], w: u32, h: u32, x: f32, y: f32) -> Vec3 {
    let (fx, fy) = (
        (x - 0.5).clamp(0.0, w as f32 - 1.0),
        (y - 0.5).clamp(0.0, h as f32 - 1.0),
    );
    let (x0, y0) = (fx.floor() as u32, fy.floor() as u32);
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (tx, ty) = (fx - x0 as f32, fy - y0 as f32);
    let at = |x: u32, y: u32| img[(y * w + x) as usize];
    let top = at(x0, y0) * (1.0 - tx) + at(x1, y0) * tx;
    let bot = at(x0, y1) * (1.0 - tx) + at(x1, y1) * tx;
    top * (1.0 - ty) + bot * ty
}

/// What [`fit`] measured besides the maps.
#[derive(Clone, Debug)]
pub struct FitStats {
    /// Time spent reading and projecting the frames.
    pub read_time: Duration,
    /// Time spent fitting the texels.
    pub fit_time: Duration,
    /// Frames in the capture.
    pub frames: usize,
    /// Texels with fewer than 8 usable frames, left unfitted (residual 1).
    pub texels_failed: usize,
    /// Samples (texel × frame) used and rejected, by cause.
    pub samples: Rejections,
}

/// Refuses a board the camera sees only edge-on or from behind at every texel, before any
/// frame is read (no sample of it could be used).
fn check_view(capture: &Capture, w: usize, h: usize) -> Result<(), FitError> {
    let (cam, board) = (&capture.camera, &capture.board);
    let corners = [
        (0, 0),
        (w - 1, 0),
        (0, h - 1),
        (w - 1, h - 1),
        (w / 2, h / 2),
    ];
    let seen = corners.iter().any(|&(c, r)| {
        let p = board.texel_point(c, r, w, h);
        board.local(cam.view_dir(p)).z > MIN_COS
    });
    if seen {
        return Ok(());
    }
    let p = board.texel_point(w / 2, h / 2, w, h);
    let angle = board
        .local(cam.view_dir(p))
        .z
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees();
    let samples = Rejections {
        view_grazing: (w * h * capture.frames.len()) as u64,
        ..Rejections::default()
    };
    Err(FitError::Unfittable {
        path: capture.manifest_path.display().to_string(),
        w,
        h,
        cause: format!(
            "{} (the view is {angle:.1}° from the face's normal at its centre; allowed under {:.1}°)",
            samples.describe(capture),
            MIN_COS.acos().to_degrees()
        ),
    })
}

/// Why a capture folder could not be fitted into maps ([`fit_folder`]).
#[derive(Debug, thiserror::Error)]
pub enum FolderError {
    /// The capture could not be read.
    #[error(transparent)]
    Capture(#[from] CaptureError),
    /// The fit could not run.
    #[error(transparent)]
    Fit(#[from] FitError),
    /// The maps could not be written.
    #[error(transparent)]
    Maps(#[from] maps::MapsError),
}

/// Fits the capture in the folder `sweep` and writes its maps and report into `out`: what
/// `xylem fit` does for each folder, and what the Python package's `fit` runs (one board per
/// call, so a Ray or Dask pool can fit many). Returns the report.
pub fn fit_folder(
    sweep: &std::path::Path,
    out: &std::path::Path,
    opts: &FitOptions,
) -> Result<serde_json::Value, FolderError> {
    let capture = Capture::open(sweep)?;
    let (maps, stats) = fit(&capture, opts)?;
    let mut res: Vec<f32> = maps.residual.clone();
    res.sort_by(f32::total_cmp);
    let median = res.get(res.len() / 2).copied().unwrap_or(f32::NAN);
    let mut report = serde_json::json!({
        "sweep": sweep.display().to_string(),
        "texels": [maps.width, maps.height],
        "frames": stats.frames,
        "arcs_azimuth_deg": capture.arc_azimuths(),
        "eta": capture.board.eta,
        "texels_not_fitted": stats.texels_failed,
        "samples": stats.samples.to_json(),
        "median_relative_residual": median,
        "read_seconds": stats.read_time.as_secs_f64(),
        "fit_seconds": stats.fit_time.as_secs_f64(),
    });
    write_maps(out, &maps, &report)?;
    if 2 * stats.texels_failed > maps.width * maps.height {
        // Not in fit.json: a caller's note on this run, printed by `xylem fit`.
        report["warning"] = format!(
            "{} of {} texels not fitted (black in the maps, residual 1): {}",
            stats.texels_failed,
            maps.width * maps.height,
            stats.samples.describe(&capture)
        )
        .into();
    }
    Ok(report)
}

/// Peak memory estimate (bytes) of a fit of `texels` from `frames` frames of `pixels` each
/// read by `threads` workers at once: every frame's samples at every texel (12 bytes per texel
/// per frame) are held until the fit, plus per texel its point, film position, fit and maps
/// (128 bytes), plus per worker one frame being read (12 bytes a pixel, twice for its decoding).
pub fn fit_memory(texels: usize, frames: usize, pixels: u64, threads: usize) -> u64 {
    let t = texels as u64;
    t * frames as u64 * 12 + t * 128 + threads as u64 * pixels * 24
}

/// Fits every texel of the capture's board (all cores, progress bar), after checking the
/// map size (1 to 8192 per side) and the memory estimate ([`fit_memory`]).
pub fn fit(capture: &Capture, opts: &FitOptions) -> Result<(FittedMaps, FitStats), FitError> {
    let (w, h) = opts.texels.unwrap_or_else(|| default_texels(capture));
    if w == 0 || h == 0 || w > 8192 || h > 8192 {
        return Err(FitError::Texels { w, h });
    }
    let frames = capture.frames.len();
    let threads = match opts.threads {
        0 => rayon::current_num_threads(),
        t => t,
    };
    let pixels = capture.camera.width as u64 * capture.camera.height as u64;
    let need = fit_memory(w * h, frames, pixels, threads);
    if let Some(have) = crate::resources::available_memory().filter(|&a| need > a) {
        use crate::resources::Bytes;
        return Err(FitError::Memory {
            w,
            h,
            frames,
            need: Bytes(need),
            have: Bytes(have),
        });
    }
    check_view(capture, w, h)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads)
        .build()
        .map_err(|e| FitError::Threads {
            threads: opts.threads,
            cause: e.to_string(),
        })?;
    pool.install(|| fit_in_pool(capture, opts, w, h))
}

/// Where each texel's centre `points[i]` falls on the film, refusing a board that leaves the
/// camera's view.
fn film_positions(
    capture: &Capture,
    points: &[Vec3],
    w: usize,
    h: usize,
) -> Result<Vec<(f32, f32)>, FitError> {
    let cam = &capture.camera;
    let mut film = Vec::with_capacity(points.len());
    for (i, p) in points.iter().enumerate() {
        let f = cam.project(*p).filter(|(x, y)| {
            (0.0..=cam.width as f32).contains(x) && (0.0..=cam.height as f32).contains(y)
        });
        match f {
            Some(f) => film.push(f),
            None => {
                let (x, y) = cam.project(*p).unwrap_or((f32::NAN, f32::NAN));
                return Err(FitError::OutOfView {
                    path: capture.manifest_path.display().to_string(),
                    col: i % w,
                    row: i / w,
                    w,
                    h,
                    x,
                    y,
                    fw: cam.width,
                    fh: cam.height,
                });
            }
        }
    }
    Ok(film)
}

/// Fills `d` with texel `i`'s view, and per frame its light direction and reflectance factor
/// (`samples` over the irradiance) where the frame is usable, weight 0 where not; returns why
/// each frame was used or not.
fn texel_data(
    capture: &Capture,
    samples: &[Vec<Vec3>],
    p: Vec3,
    i: usize,
    d: &mut TexelData,
) -> Rejections {
    let (cam, board) = (&capture.camera, &capture.board);
    let wo_world = cam.view_dir(p);
    d.wo = board.local(wo_world);
    d.wi.clear();
    d.z.clear();
    d.w.clear();
    let mut why = Rejections::default();
    for (k, f) in capture.frames.iter().enumerate() {
        let (l, irr) = f.light_at(p);
        let wi = board.local(l);
        let z = samples[k][i] / irr;
        let cause = if d.wo.z <= MIN_COS {
            Cause::ViewGrazing
        } else if wi.z <= MIN_COS {
            Cause::LightGrazing
        } else if irr.min_element() < f32::MIN_POSITIVE || !irr.is_finite() {
            Cause::NoLight
        } else if !samples[k][i].is_finite() {
            Cause::Clipped
        } else if !z.is_finite() || z.max_element() > MAX_REFLECTANCE_FACTOR {
            Cause::TooBright
        } else if f.glint(p, wo_world, board.z) {
            Cause::Glint
        } else {
            Cause::Used
        };
        why.count(cause);
        let ok = cause == Cause::Used;
        d.wi.push(wi);
        d.z.push(if ok { z } else { Vec3::ZERO });
        d.w.push(if ok { 1.0 } else { 0.0 });
    }
    why
}

fn fit_in_pool(
    capture: &Capture,
    opts: &FitOptions,
    w: usize,
    h: usize,
) -> Result<(FittedMaps, FitStats), FitError> {
    let start = Instant::now();
    let cam = &capture.camera;
    let board = &capture.board;
    let n = w * h;
    let points: Vec<Vec3> = (0..n)
        .map(|i| board.texel_point(i % w, i / w, w, h))
        .collect();
    let film = film_positions(capture, &points, w, h)?;
    // Frames in parallel, each sampled at every texel and dropped: memory is the samples.
    let black = capture.black()?;
    let read: Vec<Result<Vec<Vec3>, CaptureError>> = (0..capture.frames.len())
        .into_par_iter()
        .map(|k| {
            let img = capture.frame(k, black.as_deref())?;
            Ok(film
                .iter()
                .map(|&(x, y)| bilinear(&img, cam.width, cam.height, x, y))
                .collect())
        })
        .collect();
    // The first bad frame in frame order is the one reported, whatever the threads did.
    let samples: Vec<Vec<Vec3>> = read.into_iter().collect::<Result<_, CaptureError>>()?;
    let read_time = start.elapsed();
    opts.progress.start(n as u64, "texels");
    let done = AtomicU64::new(0);
    let start = Instant::now();
    let eta = board.eta;
    let fits: Vec<(Option<TexelFit>, Rejections)> = (0..n)
        .into_par_iter()
        .map_init(
            || (Scratch::default(), TexelData::default()),
            |(scratch, d), i| {
                let why = texel_data(capture, &samples, points[i], i, d);
                if i % 256 == 0 {
                    let step = 256.min((n - i) as u64);
                    let d = done.fetch_add(step, Ordering::Relaxed) + step;
                    opts.progress.update(d, n as u64, "");
                }
                (fit_texel(d, eta, scratch), why)
            },
        )
        .collect();
    opts.progress.finish();
    let mut why = Rejections::default();
    for (_, r) in &fits {
        why.add(r);
    }
    let fits: Vec<Option<TexelFit>> = fits.into_iter().map(|(f, _)| f).collect();
    let failed = fits.iter().filter(|f| f.is_none()).count();
    if failed == n {
        return Err(FitError::Unfittable {
            path: capture.manifest_path.display().to_string(),
            w,
            h,
            cause: why.describe(capture),
        });
    }
    let maps = FittedMaps::from_fits(w, h, &fits);
    Ok((
        maps,
        FitStats {
            read_time,
            fit_time: start.elapsed(),
            frames: capture.frames.len(),
            texels_failed: failed,
            samples: why,
        },
    ))
}

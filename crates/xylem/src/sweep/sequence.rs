//! The files of a sweep sequence. Each frame leaves `frame_NNNN.png` (and `.exr`) plus a small
//! `frame_NNNN.json` record of its light angle and mean radiances; [`assemble`] turns a folder of
//! such frames — rendered here or farmed out with `--frames-range` — into the contact sheet, the
//! animated PNG, the CSV and the `index.html` viewer. One code path serves both cases.

use super::path::MAX_FRAMES;
use super::viewer::viewer_html;
use crate::math::{luminance, Vec3};
use crate::output::{remove_if_present, write_atomic};
use crate::picture::contact::{sheet_band, sheet_columns};
use crate::picture::image::shrunk_size;
use crate::picture::png::{
    read_png_rgb8_checked, write_apng_streamed, write_png_bands, write_png_linear,
};
use crate::picture::ImageError;
use crate::picture::Rgb8;
use crate::resources::read_text_bounded;
use serde::{Deserialize, Serialize};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The contact sheet's file name in a sweep folder.
pub const CONTACT_SHEET: &str = "contact_sheet.png";
/// The animated PNG's file name.
pub const ANIMATION: &str = "sweep_animation.png";
/// The per-frame table of light angle and mean radiance.
pub const CSV: &str = "sweep.csv";
/// The viewer page.
pub const VIEWER: &str = "index.html";

/// Errors while writing or assembling a sequence; each names the file concerned.
#[derive(Debug, thiserror::Error)]
pub enum SequenceError {
    /// A file or folder could not be read, written or listed.
    #[error("{path}: {cause}")]
    Io {
        /// The file or folder.
        path: String,
        /// Why.
        cause: std::io::Error,
    },
    /// A frame record could not be encoded or parsed.
    #[error("frame record {path}: {cause}")]
    Json {
        /// The record file.
        path: String,
        /// serde_json's message.
        cause: serde_json::Error,
    },
    /// A frame's PNG, the contact sheet or the animated PNG could not be read or written.
    #[error(transparent)]
    Image(#[from] ImageError),
    /// The folder holds no frame records.
    #[error("{dir}: no frame records (frame_NNNN.json) to assemble; render frames first")]
    Empty {
        /// The folder.
        dir: String,
    },
    /// Frames of the sweep are missing from the folder.
    #[error("{dir}: a {frames}-frame sweep lacks frames {missing}; render them (e.g. --frames-range {hint}) and assemble again")]
    Missing {
        /// The folder.
        dir: String,
        /// Frames of the whole sweep.
        frames: usize,
        /// The missing frame indices, as ranges.
        missing: String,
        /// A `--frames-range` that renders the first missing ones.
        hint: String,
    },
    /// A frame that disagrees with the others or with its record (size, settings, colour type).
    #[error("{path}: {what}")]
    Mismatch {
        /// The file.
        path: String,
        /// How it disagrees.
        what: String,
    },
}

/// A named rectangle of the image whose mean radiance the CSV follows: pixel columns `x0..x1`
/// and rows `y0..y1` (half-open, top-left origin), as the scene's `[[sweep.regions]]` give them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Region {
    /// Name in the CSV header and the viewer.
    pub name: String,
    /// First pixel column.
    pub x0: u32,
    /// First pixel row (from the top).
    pub y0: u32,
    /// Column past the last.
    pub x1: u32,
    /// Row past the last.
    pub y1: u32,
}

impl Region {
    /// The pixel columns and rows the region covers in a `width × height` image, clipped to it
    /// (at least one pixel each, so a region never averages nothing).
    pub fn pixels(&self, width: u32, height: u32) -> (Range<u32>, Range<u32>) {
        let span = |a: u32, b: u32, n: u32| {
            let n = n.max(1);
            let lo = a.min(b).min(n - 1);
            lo..a.max(b).clamp(lo + 1, n)
        };
        (
            span(self.x0, self.x1, width),
            span(self.y0, self.y1, height),
        )
    }

    /// Mean luminance of the region in a linear RGB image.
    pub(crate) fn mean_luminance(&self, width: u32, height: u32, pixels: &[Vec3]) -> f32 {
        let (xs, ys) = self.pixels(width, height);
        let n = xs.len() * ys.len();
        let sum: f64 = ys
            .flat_map(|y| xs.clone().map(move |x| (x, y)))
            .map(|(x, y)| luminance(pixels[(y * width + x) as usize]) as f64)
            .sum();
        (sum / n as f64) as f32
    }
}

/// Mean luminance of one named region in one frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RegionMean {
    /// The region's name.
    pub name: String,
    /// Mean luminance of the region (linear).
    pub luminance: f32,
}

/// Everything besides the frame index that decides a sweep's frames, so that `--assemble` can
/// refuse slices rendered with different settings.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SweepSettings {
    /// The scene's name (file stem).
    pub scene: String,
    /// The arc's ends in degrees.
    pub arc_deg: [f32; 2],
    /// Samples per pixel.
    pub spp: u32,
    /// Random seed.
    pub seed: u64,
    /// What else the run was given: the scene file's CRC-32 and the `--quality` preset.
    pub provenance: String,
}

impl SweepSettings {
    /// The first setting in which `self` differs from `other`, as `name = mine (others: theirs)`.
    pub fn difference(&self, other: &SweepSettings) -> Option<String> {
        self.first_difference(other)
            .map(|(name, a, b)| format!("{name} = {a} (the others: {b})"))
    }

    /// The first setting in which `self` differs from `other`: its name, `self`'s value and
    /// `other`'s.
    pub(crate) fn first_difference(
        &self,
        other: &SweepSettings,
    ) -> Option<(&'static str, String, String)> {
        let pairs = [
            ("scene", self.scene.clone(), other.scene.clone()),
            (
                "arc_deg",
                format!("{:?}", self.arc_deg),
                format!("{:?}", other.arc_deg),
            ),
            ("spp", self.spp.to_string(), other.spp.to_string()),
            ("seed", self.seed.to_string(), other.seed.to_string()),
            (
                "provenance",
                self.provenance.clone(),
                other.provenance.clone(),
            ),
        ];
        pairs.into_iter().find(|(_, a, b)| a != b)
    }
}

/// What a frame leaves beside its images: enough to assemble the sequence without the scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameRecord {
    /// Index of the frame in the whole sweep.
    pub index: usize,
    /// Frames of the whole sweep.
    pub frames: usize,
    /// The settings of the sweep the frame belongs to (empty in records of older versions).
    #[serde(default)]
    pub sweep: SweepSettings,
    /// Light angle from the zenith along the arc (degrees).
    pub light_deg: f32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Mean radiance over the image (linear RGB).
    pub mean_rgb: [f32; 3],
    /// Luminance of `mean_rgb`.
    pub mean_luminance: f32,
    /// Mean luminance of each of the scene's regions, in their order.
    pub regions: Vec<RegionMean>,
}

impl FrameRecord {
    /// Measures a rendered frame (linear RGB, row-major, top row first).
    pub fn measure(
        index: usize,
        frames: usize,
        light_deg: f32,
        (width, height): (u32, u32),
        pixels: &[Vec3],
        regions: &[Region],
    ) -> Self {
        let n = pixels.len().max(1) as f64;
        let sum = pixels.iter().fold([0f64; 3], |a, p| {
            [a[0] + p.x as f64, a[1] + p.y as f64, a[2] + p.z as f64]
        });
        let mean_rgb = sum.map(|s| (s / n) as f32);
        FrameRecord {
            index,
            frames,
            sweep: SweepSettings::default(),
            light_deg,
            width,
            height,
            mean_luminance: luminance(Vec3::from_array(mean_rgb)),
            mean_rgb,
            regions: regions
                .iter()
                .map(|r| RegionMean {
                    name: r.name.clone(),
                    luminance: r.mean_luminance(width, height, pixels),
                })
                .collect(),
        }
    }
}

/// The file stem of frame `index`: `frame_0007`.
pub(crate) fn frame_stem(index: usize) -> String {
    format!("frame_{index:04}")
}

/// Writes `text` to `path` through a uniquely named temporary file, so a failure leaves no
/// half-written file and concurrent writers never mix.
pub fn write_text_atomic(path: &Path, text: &str) -> Result<(), SequenceError> {
    write_atomic(path, text.as_bytes()).map_err(|cause| io_error(path, cause))
}

fn io_error(path: &Path, cause: std::io::Error) -> SequenceError {
    SequenceError::Io {
        path: path.display().to_string(),
        cause,
    }
}

/// The record of frame `index` in `dir`.
pub(crate) fn record_path(dir: &Path, index: usize) -> PathBuf {
    dir.join(format!("{}.json", frame_stem(index)))
}

/// Removes frame `index`'s record, so that while its images are being replaced it does not look
/// complete (a record marks a frame complete).
pub(crate) fn unmark_frame(dir: &Path, index: usize) -> Result<(), SequenceError> {
    let path = record_path(dir, index);
    remove_if_present(&path).map_err(|cause| io_error(&path, cause))
}

/// Writes a frame's PNG preview (exposure in stops) and then its record, which marks it complete.
pub fn write_frame(
    dir: &Path,
    record: &FrameRecord,
    pixels: &[Vec3],
    exposure: f32,
) -> Result<(), SequenceError> {
    let stem = frame_stem(record.index);
    let png = dir.join(format!("{stem}.png"));
    write_png_linear(&png, record.width, record.height, pixels, exposure)?;
    write_record(dir, record)
}

/// Writes a frame's record, which marks the frame complete: call it after its images.
pub(crate) fn write_record(dir: &Path, record: &FrameRecord) -> Result<(), SequenceError> {
    let json = record_path(dir, record.index);
    let text = serde_json::to_string_pretty(record).map_err(|cause| SequenceError::Json {
        path: json.display().to_string(),
        cause,
    })?;
    write_text_atomic(&json, &text)
}

/// How [`assemble`] lays out its outputs.
#[derive(Clone, Debug)]
pub struct AssembleOptions {
    /// Largest thumbnail width on the contact sheet, in pixels.
    pub thumb_width: u32,
    /// Largest frame width in the animated PNG.
    pub animation_width: u32,
    /// Frames per second of the animated PNG and the viewer's playback.
    pub fps: u16,
    /// Title of the viewer page; empty: "`<scene>` — light sweep" from the frames' records, so a
    /// sweep assembled by `--assemble` gets the same page as one assembled by its own run.
    pub title: String,
}

impl Default for AssembleOptions {
    fn default() -> Self {
        AssembleOptions {
            thumb_width: 240,
            animation_width: 480,
            fps: 12,
            title: String::new(),
        }
    }
}

/// The largest frame record read (a record is under 1 KiB; this bounds `/dev/zero`).
pub(crate) const MAX_RECORD_BYTES: u64 = 1 << 20;

/// Reads every `frame_NNNN.json` in `dir`, sorted by frame index, and checks that they describe
/// one complete sweep (same frame count and size, every frame present exactly once).
pub fn read_records(dir: &Path) -> Result<Vec<FrameRecord>, SequenceError> {
    let records = read_record_files(dir)?;
    let Some((_, first)) = records.first() else {
        return Err(SequenceError::Empty {
            dir: dir.display().to_string(),
        });
    };
    for (k, (path, r)) in records.iter().enumerate() {
        let previous = k.checked_sub(1).map(|p| &records[p]);
        if let Some(what) = record_mismatch(path, r, first, previous) {
            return Err(SequenceError::Mismatch {
                path: path.display().to_string(),
                what,
            });
        }
    }
    check_every_frame(dir, &records, first.frames)?;
    Ok(records.into_iter().map(|(_, r)| r).collect())
}

/// Every `frame_*.json` in `dir` with its path, parsed, sorted by frame index.
fn read_record_files(dir: &Path) -> Result<Vec<(PathBuf, FrameRecord)>, SequenceError> {
    let io = |cause| SequenceError::Io {
        path: dir.display().to_string(),
        cause,
    };
    let mut records = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(io)? {
        let path = entry.map_err(io)?.path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if !(name.starts_with("frame_") && name.ends_with(".json")) {
            continue;
        }
        let text = read_text_bounded(&path, MAX_RECORD_BYTES, "JSON text").map_err(|e| {
            SequenceError::Io {
                path: path.display().to_string(),
                cause: std::io::Error::other(e.reason()),
            }
        })?;
        let rec: FrameRecord =
            serde_json::from_str(&text).map_err(|cause| SequenceError::Json {
                path: path.display().to_string(),
                cause,
            })?;
        records.push((path, rec));
    }
    records.sort_by_key(|(_, r)| r.index);
    Ok(records)
}

/// What is wrong with record `r` (read from `path`) in a sweep whose first record is `first`,
/// `previous` the record before it in index order; `None` if it fits.
fn record_mismatch(
    path: &Path,
    r: &FrameRecord,
    first: &FrameRecord,
    previous: Option<&(PathBuf, FrameRecord)>,
) -> Option<String> {
    let (frames, size) = (first.frames, (first.width, first.height));
    let stem = path.file_stem().and_then(|n| n.to_str()).unwrap_or("");
    if !(1..=MAX_FRAMES).contains(&r.frames) {
        Some(format!(
            "claims a {}-frame sweep (allowed 1 to {MAX_FRAMES})",
            r.frames
        ))
    } else if stem != frame_stem(r.index) {
        Some(format!(
            "holds the record of frame {} (its file would be {}.json)",
            r.index,
            frame_stem(r.index)
        ))
    } else if let Some((other, _)) = previous.filter(|(_, p)| p.index == r.index) {
        Some(format!(
            "is a second record of frame {} (the other: {})",
            r.index,
            other.display()
        ))
    } else if let Some(d) = r.sweep.difference(&first.sweep) {
        Some(format!(
            "belongs to a sweep with {d}; every slice must be rendered with the same settings"
        ))
    } else if r.frames != frames {
        Some(format!(
            "belongs to a {}-frame sweep, the others to a {frames}-frame one",
            r.frames
        ))
    } else if (r.width, r.height) != size {
        Some(format!(
            "is {}x{}, the others {}x{}",
            r.width, r.height, size.0, size.1
        ))
    } else if r.index >= frames {
        Some(format!(
            "frame {} is past the sweep's end ({frames} frames)",
            r.index
        ))
    } else {
        None
    }
}

/// Refuses a set of records (sorted by index) that misses any of the sweep's `frames`, naming
/// the missing ones as runs and the first run as a `--frames-range` to render.
fn check_every_frame(
    dir: &Path,
    records: &[(PathBuf, FrameRecord)],
    frames: usize,
) -> Result<(), SequenceError> {
    let present: Vec<usize> = records.iter().map(|(_, r)| r.index).collect();
    let missing: Vec<usize> = (0..frames)
        .filter(|i| present.binary_search(i).is_err())
        .collect();
    if missing.is_empty() {
        return Ok(());
    }
    let runs = runs(&missing);
    let hint = format!("{}..{}", runs[0].start, runs[0].end);
    let missing = runs
        .iter()
        .map(|r| {
            if r.len() == 1 {
                r.start.to_string()
            } else {
                format!("{}..={}", r.start, r.end - 1)
            }
        })
        .collect::<Vec<_>>()
        .join(", ");
    Err(SequenceError::Missing {
        dir: dir.display().to_string(),
        frames,
        missing,
        hint,
    })
}

/// Groups sorted indices into runs of consecutive values.
fn runs(sorted: &[usize]) -> Vec<Range<usize>> {
    let mut out: Vec<Range<usize>> = Vec::new();
    for &i in sorted {
        match out.last_mut() {
            Some(r) if r.end == i => r.end = i + 1,
            _ => out.push(i..i + 1),
        }
    }
    out
}

/// The CSV of light angle and mean radiance per frame, one column per named region.
pub(crate) fn csv_table(records: &[FrameRecord]) -> String {
    let mut s = String::from("frame,light_deg,mean_luminance,mean_r,mean_g,mean_b");
    if let Some(r) = records.first() {
        for reg in &r.regions {
            s.push_str(&format!(",region_{}", csv_name(&reg.name)));
        }
    }
    s.push('\n');
    for r in records {
        let [cr, cg, cb] = r.mean_rgb;
        s.push_str(&format!(
            "{},{},{},{cr},{cg},{cb}",
            r.index, r.light_deg, r.mean_luminance
        ));
        for reg in &r.regions {
            s.push_str(&format!(",{}", reg.luminance));
        }
        s.push('\n');
    }
    s
}

/// A region name safe inside a CSV header (no separators or quotes).
fn csv_name(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// The files [`assemble`] wrote.
#[derive(Clone, Debug)]
pub struct Assembled {
    /// Frames assembled.
    pub frames: usize,
    /// The files written: contact sheet, animated PNG, CSV and viewer.
    pub files: Vec<PathBuf>,
}

/// The files [`assemble`] writes, the viewer (written last, so it marks the sweep complete) first.
pub(crate) const ASSEMBLED: [&str; 4] = [VIEWER, CSV, CONTACT_SHEET, ANIMATION];

/// Removes the outputs of an earlier assembly (the viewer first), so that a sweep being
/// re-rendered never looks complete with the old viewer, CSV and sheet beside new frames.
pub(crate) fn clear_assembled(dir: &Path) -> Result<(), SequenceError> {
    for name in ASSEMBLED {
        let path = dir.join(name);
        remove_if_present(&path).map_err(|cause| io_error(&path, cause))?;
    }
    Ok(())
}

/// The widest contact sheet [`assemble`] writes: a long sweep's thumbnails shrink to fit it.
pub(crate) const MAX_SHEET_WIDTH: u32 = 4096;

/// Builds the contact sheet, the animated PNG, the CSV and the viewer from the frames in `dir`.
/// The stale outputs of an earlier assembly go first and the viewer is written last. The sheet
/// and the animation are written a few frames at a time, so assembling 4800 frames needs no
/// more memory than 48 (notes/cluster.md).
pub fn assemble(dir: &Path, opts: &AssembleOptions) -> Result<Assembled, SequenceError> {
    let records = read_records(dir)?;
    clear_assembled(dir)?;
    let (w, h) = (records[0].width, records[0].height);
    let gap = 4;
    let cols = sheet_columns(records.len());
    let fit = (MAX_SHEET_WIDTH.saturating_sub(gap * (cols as u32 + 1)) / cols as u32).max(1);
    let thumb = shrunk_size(w, h, opts.thumb_width.min(fit));
    let anim = shrunk_size(w, h, opts.animation_width);
    let read = |r: &FrameRecord| -> Result<Rgb8, ImageError> {
        let path = dir.join(format!("{}.png", frame_stem(r.index)));
        // The record's size is checked on the header, before the frame is decoded.
        let size_ok = |w: u32, h: u32| -> Result<(), String> {
            match (w, h) == (r.width, r.height) {
                true => Ok(()),
                false => Err(format!(
                    "is {w}x{h} but its record says {}x{}",
                    r.width, r.height
                )),
            }
        };
        let img = read_png_rgb8_checked(&path, &size_ok)?;
        size_ok(img.width, img.height).map_err(|what| ImageError::Invalid {
            path: path.display().to_string(),
            what,
        })?;
        Ok(img)
    };
    let labels: Vec<String> = records
        .iter()
        .map(|r| format!("{:.1}°", r.light_deg))
        .collect();
    let rows = records.len().div_ceil(cols);
    let sheet_size = (
        cols as u32 * thumb.0 + (cols as u32 + 1) * gap,
        rows as u32 * thumb.1 + (rows as u32 + 1) * gap,
    );
    let sheet_path = dir.join(CONTACT_SHEET);
    let anim_path = dir.join(ANIMATION);
    // The two PNG encodings are independent; each reads the frames it needs as it goes.
    let (sheet, animation) = rayon::join(
        || {
            write_png_bands(&sheet_path, sheet_size, rows, |r| {
                let recs = &records[r * cols..((r + 1) * cols).min(records.len())];
                let thumbs = (recs.iter())
                    .map(|rec| Ok(read(rec)?.shrink_to_width(opts.thumb_width.min(fit))))
                    .collect::<Result<Vec<_>, ImageError>>()?;
                Ok(sheet_band(
                    &thumbs,
                    &labels[r * cols..],
                    cols,
                    gap,
                    r + 1 == rows,
                ))
            })
        },
        || {
            write_apng_streamed(&anim_path, anim, records.len(), opts.fps, |k| {
                Ok(read(&records[k])?.shrink_to_width(opts.animation_width))
            })
        },
    );
    sheet?;
    animation?;

    let csv_path = dir.join(CSV);
    write_text_atomic(&csv_path, &csv_table(&records))?;
    let html_path = dir.join(VIEWER);
    let title = match (opts.title.is_empty(), records[0].sweep.scene.as_str()) {
        (false, _) => opts.title.clone(),
        (true, "") => "xylem light sweep".to_string(),
        (true, scene) => format!("{scene} — light sweep"),
    };
    write_text_atomic(&html_path, &viewer_html(&records, &title, opts.fps))?;
    Ok(Assembled {
        frames: records.len(),
        files: vec![sheet_path, anim_path, csv_path, html_path],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regions_cover_their_pixels_and_average_them() {
        let r = Region {
            name: "left".into(),
            x0: 0,
            y0: 0,
            x1: 2,
            y1: 2,
        };
        assert_eq!(r.pixels(4, 2), (0..2, 0..2));
        let px: Vec<Vec3> = (0..8)
            .map(|i| Vec3::splat(if i % 4 < 2 { 1.0 } else { 3.0 }))
            .collect();
        assert!((r.mean_luminance(4, 2, &px) - 1.0).abs() < 1e-6);
        // A degenerate region still covers one pixel, never none.
        let thin = Region {
            name: "t".into(),
            x0: 9,
            y0: 9,
            x1: 9,
            y1: 9,
        };
        let (xs, ys) = thin.pixels(4, 2);
        assert_eq!((xs.len(), ys.len()), (1, 1));
    }

    #[test]
    fn missing_frames_are_named_as_runs() {
        assert_eq!(runs(&[1, 2, 3, 7, 9, 10]), vec![1..4, 7..8, 9..11]);
        assert!(runs(&[]).is_empty());
    }

    #[test]
    fn csv_has_one_row_per_frame_and_a_column_per_region() {
        let rec = |i| FrameRecord {
            index: i,
            frames: 2,
            sweep: SweepSettings::default(),
            light_deg: i as f32 * 10.0,
            width: 1,
            height: 1,
            mean_rgb: [0.5, 0.25, 1.0],
            mean_luminance: 0.4,
            regions: vec![RegionMean {
                name: "a stripe,1".into(),
                luminance: 2.0,
            }],
        };
        let t = csv_table(&[rec(0), rec(1)]);
        let lines: Vec<&str> = t.lines().collect();
        assert_eq!(
            lines[0],
            "frame,light_deg,mean_luminance,mean_r,mean_g,mean_b,region_a_stripe_1"
        );
        assert_eq!(lines[2], "1,10,0.4,0.5,0.25,1,2");
        assert_eq!(lines.len(), 3);
    }
}

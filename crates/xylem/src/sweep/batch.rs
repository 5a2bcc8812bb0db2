//! Sweeps rendered in batches of frames that fit a memory budget (`--memory`), so a sweep's peak
//! memory stops growing with its frame count. Each batch is one pass of the renderer, written
//! before the next begins. The per-sweep primary work (camera rays, first hits, texels, BSDFs)
//! is kept from the first batch for the others when it fits and measures cheaper
//! ([`plan`]: it costs [`Primaries::bytes`] of memory, recomputing it costs a primary pass per
//! batch; figures in notes/cluster.md). A frame has the same bits in any batch, kept or not
//! (crates/xylem/tests/sweep_frames.rs: a frame of a one-pass sweep equals that frame rendered alone).

use crate::render::resources::Resources;
use crate::render::Primaries;
use crate::resources::{available_memory, Bytes};
use std::ops::Range;

/// The budget when `--memory` is not given and the machine's memory is unknown.
pub const FALLBACK_BUDGET: u64 = 1 << 30;

/// A memory budget too small for one frame.
#[derive(Debug, thiserror::Error)]
#[error("--memory {budget}: too small for one frame of a {width}x{height} sweep, which needs about {need} ({frame} a frame and {fixed} besides); give at least {need}")]
pub struct BudgetError {
    /// The budget given.
    pub budget: Bytes,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// What a batch of one frame needs.
    pub need: Bytes,
    /// Bytes per frame of a batch.
    pub frame: Bytes,
    /// Bytes held whatever the batch.
    pub fixed: Bytes,
}

/// How much of the machine's memory a sweep may take by default: a quarter of the memory
/// available to this process (so that a few sweeps, e.g. array tasks sharing a node, fit beside
/// each other), or [`FALLBACK_BUDGET`].
pub fn memory_cap() -> u64 {
    available_memory().map_or(FALLBACK_BUDGET, |m| m / 4)
}

/// Whether a sweep in several batches keeps its primary samples from the first batch for the
/// others (`--primaries`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PrimaryMode {
    /// Keep them when they fit and the cost model says it is faster ([`plan`]).
    #[default]
    Auto,
    /// Keep them whenever they fit the budget beside one frame.
    Keep,
    /// Compute them again in every batch.
    Recompute,
}

impl PrimaryMode {
    /// Every mode, in the order of [`PrimaryMode::NAMES`].
    pub const ALL: [PrimaryMode; 3] =
        [PrimaryMode::Auto, PrimaryMode::Keep, PrimaryMode::Recompute];
    /// Their command-line names (`--primaries`).
    pub const NAMES: [&'static str; 3] = ["auto", "keep", "recompute"];
}

impl std::str::FromStr for PrimaryMode {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let i = Self::NAMES
            .iter()
            .position(|n| *n == s)
            .ok_or_else(|| format!("`{s}`: expected one of {}", Self::NAMES.join(", ")))?;
        Ok(Self::ALL[i])
    }
}

/// What decides a sweep's memory and batches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SweepSize {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Worker threads (0 = all cores).
    pub threads: usize,
    /// Frames to render.
    pub frames: usize,
}

/// How a sweep's frames are cut into batches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Plan {
    /// Most frames in one batch.
    pub batch: usize,
    /// Whether the primary samples of the first batch are kept for the others
    /// ([`Primaries`]).
    pub keep: bool,
}

impl Plan {
    /// The memory a sweep of `size` holds with this plan: one batch of frames, what any batch
    /// holds, and the kept primary samples.
    pub fn memory(&self, size: &SweepSize) -> u64 {
        let SweepSize {
            width,
            height,
            spp,
            threads,
            ..
        } = *size;
        Resources::sweep_frame_bytes(width, height, threads) * self.batch as u64
            + Resources::sweep_fixed_bytes(width, height, threads)
            + if self.keep {
                Primaries::bytes(width, height, spp)
            } else {
                0
            }
    }
}

/// A pass over a batch's pixel samples that computes their primary samples (camera ray, first
/// hit, texels, BSDF, first bounce) costs about as much as rendering this many frames of the
/// sweep's light-dependent work: 16–50 on the 256² board at 1 and 8 spp (notes/cluster.md,
/// "Primary work: kept or recomputed"), the low end taken.
pub const PRIMARY_PASS_FRAMES: f64 = 16.0;
/// A pass that reads kept primary samples instead costs about this many frames (lighting them
/// anew: the BSDF's view-dependent terms, emission along the rays; 3–8 measured).
pub const REUSED_PASS_FRAMES: f64 = 5.0;
/// The default batch's own cost (a pass, [`PRIMARY_PASS_FRAMES`] or [`REUSED_PASS_FRAMES`])
/// is at most this share of its frames' work ([`default_plan`]).
pub const BATCH_OVERHEAD: f64 = 0.3;

/// The batches of a sweep of `size` within `budget` bytes: as many frames per batch as fit; the primary samples kept (as `mode` says) when there
/// is more than one batch and, for [`PrimaryMode::Auto`], when the model of
/// [`PRIMARY_PASS_FRAMES`] and [`REUSED_PASS_FRAMES`] finds it faster than computing them per
/// batch (the kept samples leave less of the budget for frames).
pub fn plan(size: &SweepSize, budget: u64, mode: PrimaryMode) -> Result<Plan, BudgetError> {
    let (width, height, threads) = (size.width, size.height, size.threads);
    let frames = size.frames.max(1);
    let batch = frames_per_batch(width, height, threads, budget)?.min(frames);
    let recompute = Plan { batch, keep: false };
    if batch >= frames || mode == PrimaryMode::Recompute {
        return Ok(recompute);
    }
    let room = budget.saturating_sub(Primaries::bytes(width, height, size.spp));
    let Ok(kept_batch) = frames_per_batch(width, height, threads, room) else {
        return Ok(recompute);
    };
    let keep = Plan {
        batch: kept_batch.min(frames),
        keep: true,
    };
    let passes = |p: &Plan| frames.div_ceil(p.batch) as f64;
    let cost_recompute = passes(&recompute) * PRIMARY_PASS_FRAMES;
    let cost_keep = PRIMARY_PASS_FRAMES + (passes(&keep) - 1.0) * REUSED_PASS_FRAMES;
    Ok(match mode {
        PrimaryMode::Auto if cost_recompute <= cost_keep => recompute,
        _ => keep,
    })
}

/// The plan without `--memory`: the one of least memory whose batches cost at most
/// [`BATCH_OVERHEAD`] of their frames' work: batches of ⌈[`PRIMARY_PASS_FRAMES`] /
/// [`BATCH_OVERHEAD`]⌉ = 54 frames with the primary samples recomputed, or of
/// ⌈[`REUSED_PASS_FRAMES`] / [`BATCH_OVERHEAD`]⌉ = 17 with them kept (which pays where they take
/// less than 37 frames' memory: at 1 spp). Either way a sweep's memory stops growing beyond a
/// few dozen frames. Where that exceeds [`memory_cap`], the [`plan`] of that cap.
pub fn default_plan(size: &SweepSize, mode: PrimaryMode) -> Result<Plan, BudgetError> {
    let frames = size.frames.max(1);
    let batch = |pass: f64| ((pass / BATCH_OVERHEAD).ceil() as usize).clamp(1, frames);
    let recompute = Plan {
        batch: batch(PRIMARY_PASS_FRAMES),
        keep: false,
    };
    let kept_batch = batch(REUSED_PASS_FRAMES);
    let keep = Plan {
        batch: kept_batch,
        keep: kept_batch < frames,
    };
    let memory = |p: &Plan| p.memory(size);
    let best = match mode {
        PrimaryMode::Keep => keep,
        PrimaryMode::Recompute => recompute,
        PrimaryMode::Auto if memory(&keep) < memory(&recompute) => keep,
        PrimaryMode::Auto => recompute,
    };
    let cap = memory_cap();
    if memory(&best) <= cap {
        Ok(best)
    } else {
        plan(size, cap, mode)
    }
}

/// The most frames of a `width × height` sweep one batch may hold within `budget` bytes.
pub(crate) fn frames_per_batch(
    width: u32,
    height: u32,
    threads: usize,
    budget: u64,
) -> Result<usize, BudgetError> {
    let frame = Resources::sweep_frame_bytes(width, height, threads).max(1);
    let fixed = Resources::sweep_fixed_bytes(width, height, threads);
    let n = budget.saturating_sub(fixed) / frame;
    if n == 0 {
        return Err(BudgetError {
            budget: Bytes(budget),
            width,
            height,
            need: Bytes(fixed + frame),
            frame: Bytes(frame),
            fixed: Bytes(fixed),
        });
    }
    Ok(usize::try_from(n).unwrap_or(usize::MAX))
}

/// `range` cut into consecutive batches of at most `per` frames (at least one).
pub fn batches(range: Range<usize>, per: usize) -> impl Iterator<Item = Range<usize>> {
    let per = per.max(1);
    range
        .clone()
        .step_by(per)
        .map(move |a| a..a.saturating_add(per).min(range.end))
}

/// A byte count [`parse_bytes`] cannot read, with the text given.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ByteCountError {
    /// A unit other than K, M, G, T (and their `KiB`, `MB`, … forms).
    #[error("`{text}`: unknown unit `{unit}` (use K, M, G or T, e.g. 512M)")]
    UnknownUnit {
        /// The text given.
        text: String,
        /// The unit found.
        unit: String,
    },
    /// No number before the unit.
    #[error("`{0}` is not a byte count (e.g. 512M, 2G)")]
    NotANumber(String),
    /// Below 1 byte or above 16 EiB.
    #[error("`{0}` is out of range (1 byte to 16 EiB)")]
    OutOfRange(String),
}

/// Parses a byte count: a number with an optional unit `K`, `M`, `G`, `T` (powers of 1024;
/// `KiB`, `MB`, … and lower case alike), e.g. `512M`, `1.5G`, `4000000`.
pub fn parse_bytes(s: &str) -> Result<u64, ByteCountError> {
    let t = s.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let shift = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 0,
        "k" | "kb" | "kib" => 10,
        "m" | "mb" | "mib" => 20,
        "g" | "gb" | "gib" => 30,
        "t" | "tb" | "tib" => 40,
        _ => {
            return Err(ByteCountError::UnknownUnit {
                text: s.into(),
                unit: unit.trim().into(),
            })
        }
    };
    let value: f64 = num
        .parse()
        .map_err(|_| ByteCountError::NotANumber(s.into()))?;
    let bytes = value * (1u64 << shift) as f64;
    if !(1.0..=u64::MAX as f64).contains(&bytes) {
        return Err(ByteCountError::OutOfRange(s.into()));
    }
    Ok(bytes as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_counts_parse_with_binary_units() {
        assert_eq!(parse_bytes("512M"), Ok(512 << 20));
        assert_eq!(parse_bytes("1.5GiB"), Ok(3 << 29));
        assert_eq!(parse_bytes(" 4000 "), Ok(4000));
        assert!(parse_bytes("12X")
            .unwrap_err()
            .to_string()
            .contains("unknown unit"));
        assert_eq!(
            parse_bytes("0"),
            Err(ByteCountError::OutOfRange("0".into()))
        );
        assert!(parse_bytes("M").is_err());
    }

    #[test]
    fn batches_cover_the_range_in_order() {
        let b: Vec<_> = batches(5..17, 5).collect();
        assert_eq!(b, vec![5..10, 10..15, 15..17]);
        assert_eq!(batches(0..3, 0).count(), 3);
    }

    #[test]
    fn a_batch_holds_what_the_budget_allows_and_no_frame_is_refused_clearly() {
        let frame = Resources::sweep_frame_bytes(256, 256, 2);
        let fixed = Resources::sweep_fixed_bytes(256, 256, 2);
        assert_eq!(
            frames_per_batch(256, 256, 2, fixed + 10 * frame).unwrap(),
            10
        );
        let e = frames_per_batch(256, 256, 2, 1000).unwrap_err();
        assert!(e
            .to_string()
            .contains("too small for one frame of a 256x256 sweep"));
    }

    #[test]
    fn primaries_are_kept_where_they_fit_and_the_model_finds_it_faster() {
        use PrimaryMode::*;
        let frame = Resources::sweep_frame_bytes(256, 256, 2);
        let fixed = Resources::sweep_fixed_bytes(256, 256, 2);
        let kept = Primaries::bytes(256, 256, 1);
        let size = |frames| SweepSize {
            width: 256,
            height: 256,
            spp: 1,
            threads: 2,
            frames,
        };
        let at = |budget, frames, mode| plan(&size(frames), budget, mode).unwrap();
        let one = Plan {
            batch: 48,
            keep: false,
        };
        assert_eq!(at(fixed + 48 * frame, 48, Keep), one);
        // Kept samples and 100 frames: 48 passes lighting them beat 40 recomputing them.
        let roomy = fixed + kept + 100 * frame;
        let keep = Plan {
            batch: 100,
            keep: true,
        };
        assert_eq!(at(roomy, 4800, Auto), keep);
        assert!(!at(roomy, 4800, Recompute).keep);
        // Room for 6 frames beside them: 800 passes cost more than the 166 of 29 frames.
        assert!(!at(fixed + kept + 6 * frame, 4800, Auto).keep);
        assert!(at(fixed + kept + 6 * frame, 4800, Keep).keep);
        // No room for them at all: recomputed even when asked to keep.
        assert!(!at(fixed + 6 * frame, 4800, Keep).keep);
        assert_eq!(keep.memory(&size(4800)), roomy);
    }
}

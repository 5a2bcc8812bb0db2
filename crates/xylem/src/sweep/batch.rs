//! Sweeps rendered in batches of frames that fit a memory budget (`--memory`), so a sweep's peak
//! memory stops growing with its frame count. Each batch is one pass of the renderer, written
//! before the next begins. The per-sweep primary work (camera paths, BSDF samples) is recomputed
//! per batch rather than kept: keeping it costs memory per pixel sample, which grows with the
//! spp, while recomputing costs one primary pass per batch (measured in notes/cluster.md). A
//! frame has the same bits in any batch (crates/xylem/tests/sweep_cache.rs: a frame of a one-pass sweep
//! equals that frame rendered alone).

use crate::render::resources::{available_memory, Bytes, Resources};
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

/// The default budget: a quarter of the memory available to this process (so that a few
/// sweeps, e.g. array tasks sharing a node, fit beside each other), or [`FALLBACK_BUDGET`].
pub fn default_budget() -> u64 {
    available_memory().map_or(FALLBACK_BUDGET, |m| m / 4)
}

/// The most frames of a `width × height` sweep one batch may hold within `budget` bytes.
pub fn frames_per_batch(
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

/// Parses a byte count: a number with an optional unit `K`, `M`, `G`, `T` (powers of 1024;
/// `KiB`, `MB`, … and lower case alike), e.g. `512M`, `1.5G`, `4000000`.
pub fn parse_bytes(s: &str) -> Result<u64, String> {
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
            return Err(format!(
                "`{s}`: unknown unit `{}` (use K, M, G or T, e.g. 512M)",
                unit.trim()
            ))
        }
    };
    let value: f64 = num
        .parse()
        .map_err(|_| format!("`{s}` is not a byte count (e.g. 512M, 2G)"))?;
    let bytes = value * (1u64 << shift) as f64;
    if !(1.0..=u64::MAX as f64).contains(&bytes) {
        return Err(format!("`{s}` is out of range (1 byte to 16 EiB)"));
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
        assert!(parse_bytes("12X").unwrap_err().contains("unknown unit"));
        assert!(parse_bytes("0").unwrap_err().contains("out of range"));
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
}

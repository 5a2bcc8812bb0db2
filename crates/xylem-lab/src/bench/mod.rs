//! Benchmark harnesses (behind `xylem bench` and crates/xylem-lab/benches/): the tracing benchmark against obvhs's
//! own traversal and, with the feature `embree-anchor`, Embree 3.

pub mod clock;
#[cfg(feature = "embree-anchor")]
pub mod embree;
pub mod trace;

//! Benchmark harnesses (behind `xylem bench` and crates/xylem-lab/benches/): tracing against
//! obvhs's own traversal and, with the feature `embree-anchor`, Embree 3; the wood BSDF; noise;
//! wood texels; a render against Mitsuba 3. Each returns its figures; the command line prints.

pub mod bsdf;
pub mod clock;
#[cfg(feature = "embree-anchor")]
pub mod embree;
pub mod noise;
pub mod render;
pub mod trace;
pub mod wood;

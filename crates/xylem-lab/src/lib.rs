//! xylem's validation lab: the suites that check the engine (`xylem validate`), the reference
//! oracles they measure against, the speed/accuracy study (`xylem tradeoff`), the benchmark
//! harnesses (`xylem bench`, crates/xylem-lab/benches/) and the reports they write. It depends on the engine
//! (the `xylem` crate) and never the other way round.
//!
//! - [`bsdf`]: white furnace, reciprocity, chi-square, pdf normalisation, sample weights and
//!   extremes of the wood BSDF over the case grid of `validation/bsdf_cases.toml`;
//! - [`sweep`]: highlight tracking, renderer against the BSDF, figure signatures of light sweeps;
//! - [`layered_reference`]: the position-free random walk through a rough finish, ground truth
//!   for [`rough_finish`], the rough-finish rows of `validate bsdf`;
//! - [`scenes`]: does each built-in scene show its subject (contrast, fireflies, figure);
//! - [`fit`]: `xylem fit` by round trip — known boards rendered, fitted back, compared;
//! - [`gltf`]: the exported glTF material (a KHR_materials_anisotropy reference shader) against
//!   xylem's fibre highlight;
//! - [`pattern`]: pattern statistics of a board face (correlation lengths, spectra, orientation
//!   coherence, dark streaks, rings, fibre-field correlation), measured against preset (issue 25);
//! - [`report`]: validation/REPORT.md, one replaceable section per suite;
//! - [`tradeoff`]: error and time of every quality knob (validation/TRADEOFF.md);
//! - [`aliasing`]: aliasing energy and error at equal time with and without the footprint
//!   filter (validation/ALIASING.md);
//! - [`mod@bench`]: the tracing benchmark against obvhs's own traversal and Embree 3;
//! - [`tables`]: the engine's generated BSDF tables, written by the binary `xylem-tables`.

pub mod aliasing;
pub mod appearance;
pub mod bench;
pub mod bsdf;
pub mod fit;
pub mod gltf;
pub mod highlight;
pub use xylem::bsdf::layered_reference;
pub mod pattern;
pub mod report;
pub mod rough_finish;
pub mod scene_template;
pub mod scenes;
pub mod sweep;
pub mod tables;
pub mod tradeoff;

pub use report::update_report_section;

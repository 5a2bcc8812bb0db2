//! The validation suite (BSDF and sweep checks) and its report.
//!
//! - [`bsdf`]: white furnace, reciprocity, chi-square, pdf normalisation, sample weights and
//!   extremes of the wood BSDF over the case grid of `validation/bsdf_cases.toml`;
//! - [`sweep`]: highlight tracking, renderer against the BSDF, figure signatures of light sweeps;
//! - [`report`]: validation/REPORT.md, one replaceable section per suite.

pub mod appearance;
pub mod bsdf;
pub mod report;
pub mod sweep;

pub use report::update_report_section;

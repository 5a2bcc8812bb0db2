//! The validation suite (BSDF and sweep checks) and its report.
//!
//! - [`bsdf`]: white furnace, reciprocity, chi-square, pdf normalisation, sample weights and
//!   extremes of the wood BSDF over the case grid of `validation/bsdf_cases.toml`;
//! - [`report`]: validation/REPORT.md, one replaceable section per suite.

pub mod bsdf;
pub mod report;

pub use report::update_report_section;

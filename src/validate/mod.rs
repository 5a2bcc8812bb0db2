//! The validation suite (BSDF and sweep checks) and its report.

//! Errors of the wood model: every message names the file (or preset), the field and what is allowed.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum WoodError {
    #[error("cannot read wood parameters {file}")]
    Io {
        file: PathBuf,
        source: std::io::Error,
    },
    #[error("{file}: {message}")]
    Parse { file: String, message: String },
    #[error("{file}: `{field}` = {value} is out of range; allowed: {allowed}")]
    OutOfRange {
        file: String,
        field: String,
        value: String,
        allowed: String,
    },
    #[error("unknown wood preset `{name}`; valid presets: {valid}")]
    UnknownPreset { name: String, valid: String },
}

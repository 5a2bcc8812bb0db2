//! Errors of the wood model: every message names the file (or preset), the field and what is allowed.

use std::path::PathBuf;

/// Why wood parameters could not be loaded or are invalid.
#[derive(Debug, thiserror::Error)]
pub enum WoodError {
    /// A preset file could not be read.
    #[error("cannot read wood parameters {file}")]
    Io {
        /// The file.
        file: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file is not valid TOML for [`WoodParams`](super::WoodParams) (unknown field, wrong
    /// type...).
    #[error("{file}: {message}")]
    Parse {
        /// The preset file or name.
        file: String,
        /// toml's message.
        message: String,
    },
    /// A parameter is outside its allowed range.
    #[error("{file}: `{field}` = {value} is out of range; allowed: {allowed}")]
    OutOfRange {
        /// The preset file or name.
        file: String,
        /// The field, e.g. `rings.width`.
        field: String,
        /// The value given.
        value: String,
        /// The allowed range.
        allowed: String,
    },
    /// No built-in preset of this name.
    #[error("unknown wood preset `{name}`; valid presets: {valid}")]
    UnknownPreset {
        /// The name given.
        name: String,
        /// The built-in names.
        valid: String,
    },
}

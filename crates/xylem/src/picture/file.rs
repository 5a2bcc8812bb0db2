//! Image files written whole or not at all: the error that names the file, and the one staging
//! path every image writer (PNG, animated PNG, EXR) goes through — encode into a uniquely named
//! temporary file beside the final name ([`crate::output::Staged`]), flush, and [`commit`] by
//! renaming, so no reader ever sees a half-written image and two runs never share a temporary.

use crate::output::Staged;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

/// Errors while writing or reading an image, naming the file.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// The file could not be created, written or opened.
    #[error("cannot write image {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        source: std::io::Error,
    },
    /// The PNG encoder failed.
    #[error("cannot encode PNG {path}: {source}")]
    Png {
        /// The file.
        path: String,
        /// Why.
        source: png::EncodingError,
    },
    /// A PNG could not be decoded.
    #[error("cannot read PNG {path}: {source}")]
    PngRead {
        /// The file.
        path: String,
        /// The png crate's message.
        source: png::DecodingError,
    },
    /// The exr crate could not write the file.
    #[error("cannot write EXR {path}: {message}")]
    ExrWrite {
        /// The file.
        path: String,
        /// The exr crate's message.
        message: String,
    },
    /// The exr crate could not read the file.
    #[error("cannot read EXR {path}: {message}")]
    ExrRead {
        /// The file.
        path: String,
        /// The exr crate's message.
        message: String,
    },
    /// A pixel buffer whose length does not match the image size.
    #[error("image {path}: buffer holds {got} pixels, {width}x{height} needs {want}")]
    Size {
        /// The file.
        path: String,
        /// Image width in pixels.
        width: u32,
        /// Image height in pixels.
        height: u32,
        /// Pixels the buffer holds.
        got: usize,
        /// Pixels the size needs (width × height).
        want: usize,
    },
    /// Input that no image can be made of (an animation without frames, frames of two sizes, a
    /// PNG of a colour type xylem does not read).
    #[error("image {path}: {what}")]
    Invalid {
        /// The file.
        path: String,
        /// What is wrong.
        what: String,
    },
}

/// The buffered writer an encoder writes a staged file through.
pub(crate) type StagedWriter<'a> = BufWriter<&'a mut File>;

/// Encodes an image into a uniquely named temporary file beside `path` with `encode`, and
/// flushes it, to [`commit`] later (dropping the result deletes the temporary).
pub fn stage(
    path: &Path,
    encode: impl FnOnce(&mut StagedWriter) -> Result<(), ImageError>,
) -> Result<Staged, ImageError> {
    let io = |source| ImageError::Io {
        path: path.display().to_string(),
        source,
    };
    let mut staged = Staged::new(path).map_err(io)?;
    let mut out = BufWriter::new(staged.file());
    encode(&mut out)?;
    // An explicit flush: a dropped `BufWriter` would hide a failed write.
    std::io::Write::flush(&mut out).map_err(io)?;
    drop(out);
    Ok(staged)
}

/// Renames a staged image over its final name.
pub fn commit(staged: Staged) -> Result<(), ImageError> {
    let path = staged.path().display().to_string();
    staged
        .commit()
        .map_err(|source| ImageError::Io { path, source })
}

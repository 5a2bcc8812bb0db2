//! Which sweep an output folder is for: `sweep.json`, the folder's claim.
//!
//! Frames of one sweep are rendered by many runs (slices of a farm, reruns after a failure), so
//! a folder can only ever hold one run's frames if every run that writes a frame renders the
//! same frames. The claim says which: the sweep's settings ([`SweepSettings`]: scene, arc, spp,
//! seed, scene digest, quality), its frame count and the digest of its capture manifest (camera,
//! board, lights). The first run into a folder creates it before rendering — atomically, so of
//! two slices started at once with other settings exactly one creates it and the other refuses —
//! and every later slice must match it; a whole sweep, which holds the folder alone, clears the
//! folder and replaces it. A frame rendered with the same settings is the same frame
//! (byte-stable), so two runs that agree with the claim never mix.

use super::job::SweepError;
use super::sequence::{SweepSettings, MAX_RECORD_BYTES};
use crate::output::{stage_bytes, write_atomic};
use crate::resources::read_text_bounded;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The claim's file name in a sweep folder.
pub(crate) const CLAIM_FILE: &str = "sweep.json";

/// What decides a sweep's frames; two runs with equal claims render equal frames.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub(crate) struct Claim {
    /// Scene, arc, spp, seed, scene digest and quality.
    pub settings: SweepSettings,
    /// Frames of the whole sweep.
    pub frames: usize,
    /// The camera's image size, `WxH`.
    pub camera: String,
    /// CRC-32 of the capture manifest's text (camera pose, board, every frame's light).
    pub manifest_crc32: String,
}

impl Claim {
    /// The first way `self` (this run's claim) differs from `theirs` (the folder's), as
    /// `what: theirs there, ours in this run`.
    fn difference(&self, theirs: &Claim) -> Option<String> {
        let shape = |c: &Claim| format!("{} frames, {} camera", c.frames, c.camera);
        if let Some((name, ours, there)) = self.settings.first_difference(&theirs.settings) {
            Some(format!("{name} {there} there, {ours} in this run"))
        } else if shape(self) != shape(theirs) {
            Some(format!(
                "{} there, {} in this run",
                shape(theirs),
                shape(self)
            ))
        } else if self.manifest_crc32 != theirs.manifest_crc32 {
            Some("other lights, board or camera pose".into())
        } else {
            None
        }
    }
}

fn io_error(path: &Path, cause: std::io::Error) -> SweepError {
    SweepError::OutDir {
        path: path.display().to_string(),
        cause,
    }
}

/// Reads the claim at `path`; `None` where there is none.
fn read(path: &Path) -> Result<Option<Claim>, SweepError> {
    if std::fs::symlink_metadata(path).is_err() {
        return Ok(None);
    }
    let other = |difference: String| SweepError::Claimed {
        path: path.display().to_string(),
        difference,
    };
    let text = read_text_bounded(path, MAX_RECORD_BYTES, "JSON text")
        .map_err(|e| other(format!("unreadable: {}", e.reason())))?;
    serde_json::from_str(&text).map(Some).map_err(|e| {
        other(format!(
            "unreadable: {}",
            crate::jsonpath::describe(&text, &e)
        ))
    })
}

/// Refuses `ours` where it differs from `theirs`, the claim or record at `path`.
fn agree(path: &Path, ours: &Claim, theirs: &Claim) -> Result<(), SweepError> {
    match ours.difference(theirs) {
        None => Ok(()),
        Some(difference) => Err(SweepError::Claimed {
            path: path.display().to_string(),
            difference,
        }),
    }
}

/// Claims `dir` for a slice: where a claim exists, the slice must match it; where none does,
/// every frame record already in the folder (left by a build without claims) must match, and
/// the claim is created — atomically, so that of two slices racing into an empty folder one
/// creates it and the other compares with it. Called before the slice touches a file.
pub(crate) fn claim_for_slice(dir: &Path, ours: &Claim) -> Result<(), SweepError> {
    let path = dir.join(CLAIM_FILE);
    if let Some(theirs) = read(&path)? {
        return agree(&path, ours, &theirs);
    }
    check_records(dir, ours)?;
    let text = serde_json::to_string_pretty(ours).expect("a claim serializes");
    let staged = stage_bytes(&path, text.as_bytes()).map_err(|e| io_error(&path, e))?;
    match staged.commit_new() {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => match read(&path)? {
            Some(theirs) => agree(&path, ours, &theirs),
            None => Err(io_error(&path, e)),
        },
        Err(e) => Err(io_error(&path, e)),
    }
}

/// Replaces the claim of `dir` (a whole sweep, which holds the folder alone and has cleared its
/// frames first).
pub(crate) fn replace_claim(dir: &Path, ours: &Claim) -> Result<(), SweepError> {
    let path = dir.join(CLAIM_FILE);
    let text = serde_json::to_string_pretty(ours).expect("a claim serializes");
    write_atomic(&path, text.as_bytes()).map_err(|e| io_error(&path, e))
}

/// Refuses a folder holding a frame record of another sweep than `ours`.
fn check_records(dir: &Path, ours: &Claim) -> Result<(), SweepError> {
    for entry in std::fs::read_dir(dir).map_err(|e| io_error(dir, e))? {
        let path = entry.map_err(|e| io_error(dir, e))?.path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if !(name.starts_with("frame_") && name.ends_with(".json")) {
            continue;
        }
        let other = |difference: String| SweepError::Claimed {
            path: path.display().to_string(),
            difference,
        };
        let text = read_text_bounded(&path, MAX_RECORD_BYTES, "JSON text")
            .map_err(|e| other(format!("unreadable: {}", e.reason())))?;
        let rec: super::FrameRecord = serde_json::from_str(&text).map_err(|e| {
            other(format!(
                "unreadable: {}",
                crate::jsonpath::describe(&text, &e)
            ))
        })?;
        let theirs = Claim {
            settings: rec.sweep,
            frames: rec.frames,
            camera: format!("{}x{}", rec.width, rec.height),
            // A record does not carry the manifest: compared on the rest.
            manifest_crc32: ours.manifest_crc32.clone(),
        };
        agree(&path, ours, &theirs)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eight slices of other settings claiming one empty folder at the same instant (a barrier):
    /// exactly one succeeds, and the folder's claim is that one's.
    #[test]
    fn of_slices_racing_into_an_empty_folder_exactly_one_claims_it() {
        let dir = tempfile::tempdir().unwrap();
        let claim = |spp: u32| Claim {
            settings: SweepSettings {
                spp,
                ..SweepSettings::default()
            },
            frames: 4,
            camera: "8x6".into(),
            manifest_crc32: "00000000".into(),
        };
        let barrier = std::sync::Barrier::new(8);
        let results: Vec<(u32, bool)> = std::thread::scope(|s| {
            let runs: Vec<_> = (1..=8)
                .map(|spp| {
                    let (barrier, dir) = (&barrier, dir.path());
                    s.spawn(move || {
                        barrier.wait();
                        (spp, claim_for_slice(dir, &claim(spp)).is_ok())
                    })
                })
                .collect();
            runs.into_iter().map(|r| r.join().unwrap()).collect()
        });
        let won: Vec<u32> = results.iter().filter(|r| r.1).map(|r| r.0).collect();
        assert_eq!(won.len(), 1, "{results:?}");
        let theirs = read(&dir.path().join(CLAIM_FILE)).unwrap().unwrap();
        assert_eq!(theirs, claim(won[0]));
        // A later slice of the winner's settings is welcome.
        assert!(claim_for_slice(dir.path(), &claim(won[0])).is_ok());
    }
}

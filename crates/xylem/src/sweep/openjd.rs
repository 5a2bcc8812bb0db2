//! A sweep as an Open Job Description job template (`xylem sweep --emit-openjd DIR`), for
//! OpenJD runners such as AWS Deadline Cloud or `openjd run`: a `Render` step whose one task
//! parameter is a `CHUNK[INT]` range of frames (the `TASK_CHUNKING` extension; each chunk runs
//! `--frames-range` on a contiguous run, so the work its frames share still pays), and an `Assemble`
//! step that depends on it. Specification: jobtemplate-2023-09 and RFC 0001 (task chunking).

use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// The template's file name in the job bundle folder (Deadline Cloud's job bundle layout).
pub const TEMPLATE_FILE: &str = "template.json";

/// The largest `defaultTaskCount` of a chunk the specification allows.
pub const MAX_CHUNK: usize = 150;

/// What a sweep's job template runs.
#[derive(Clone, Debug)]
pub struct OpenJdSweep {
    /// The job's name (the scene's name).
    pub name: String,
    /// The xylem binary the tasks run (absolute: tasks run in a session folder of their own).
    pub xylem: PathBuf,
    /// The scene file (absolute: tasks run in a session folder of their own).
    pub scene: PathBuf,
    /// The output folder (absolute).
    pub out: PathBuf,
    /// Frames of the whole sweep.
    pub frames: usize,
    /// Frames per chunk by default (the `ChunkSize` job parameter), 1 to [`MAX_CHUNK`].
    pub chunk: usize,
    /// Options every render task passes (`--frames`, `--arc`, `--spp`, …): every slice of a
    /// sweep must be rendered with the same settings.
    pub render_args: Vec<String>,
    /// Options the assembly passes (`--thumb-width`).
    pub assemble_args: Vec<String>,
}

/// A render task's shell script: the chunk arrives as `A-B` (inclusive, CONTIGUOUS chunks) or
/// a lone `A`, and becomes `--frames-range A..=B`.
const RENDER_SCRIPT: &str = r#"set -eu
chunk="$4"; a="${chunk%%-*}"; b="${chunk##*-}"
xylem="$1"; scene="$2"; out="$3"; shift 4
exec "$xylem" sweep "$scene" --out "$out" --frames-range "${a}..=${b}" --quiet "$@""#;

/// The default frames per chunk for `frames` frames: about 8 chunks (few enough that the
/// work shared between frames pays, enough to spread), within the specification's limit.
pub fn default_chunk(frames: usize) -> usize {
    frames.div_ceil(8).clamp(1, MAX_CHUNK)
}

/// The job template (JSON) of `sweep`.
pub(crate) fn job_template(sweep: &OpenJdSweep) -> Value {
    let path = |p: &Path| p.display().to_string();
    let mut render_args: Vec<Value> = [
        "-c",
        RENDER_SCRIPT,
        "xylem-render",
        "{{Param.Xylem}}",
        "{{Param.Scene}}",
        "{{Param.Out}}",
        "{{Task.Param.Frame}}",
    ]
    .iter()
    .map(|s| json!(s))
    .collect();
    render_args.extend(sweep.render_args.iter().map(|s| json!(s)));
    let mut assemble_args = vec![json!("sweep"), json!("--assemble"), json!("{{Param.Out}}")];
    assemble_args.extend(sweep.assemble_args.iter().map(|s| json!(s)));
    json!({
        "specificationVersion": "jobtemplate-2023-09",
        "extensions": ["TASK_CHUNKING"],
        "name": format!("xylem sweep of {}", sweep.name),
        "description": format!("{} frames rendered in chunks of contiguous frames, then assembled", sweep.frames),
        "parameterDefinitions": [
            {"name": "Xylem", "type": "STRING", "default": path(&sweep.xylem),
             "description": "The xylem binary every task runs"},
            // STRING, not PATH: a PATH parameter's default must lie inside the template's
            // folder, and the scene and the output are elsewhere.
            {"name": "Scene", "type": "STRING", "default": path(&sweep.scene),
             "description": "The scene file (absolute)"},
            {"name": "Out", "type": "STRING", "default": path(&sweep.out),
             "description": "The output folder the tasks share (absolute)"},
            {"name": "ChunkSize", "type": "INT", "default": sweep.chunk.clamp(1, MAX_CHUNK),
             "minValue": 1, "maxValue": MAX_CHUNK,
             "description": "Frames per render task (consecutive frames share their light-independent work)"}
        ],
        "steps": [
            {
                "name": "Render",
                "parameterSpace": {"taskParameterDefinitions": [{
                    "name": "Frame",
                    "type": "CHUNK[INT]",
                    "range": format!("0-{}", sweep.frames.saturating_sub(1)),
                    "chunks": {"defaultTaskCount": "{{Param.ChunkSize}}", "rangeConstraint": "CONTIGUOUS"}
                }]},
                "script": {"actions": {"onRun": {"command": "bash", "args": render_args}}}
            },
            {
                "name": "Assemble",
                "dependencies": [{"dependsOn": "Render"}],
                "script": {"actions": {"onRun": {"command": "{{Param.Xylem}}", "args": assemble_args}}}
            }
        ]
    })
}

/// Writes `sweep`'s job template into `dir` (created if missing) as [`TEMPLATE_FILE`], whole or
/// not at all, and returns its path.
pub fn write_template(dir: &Path, sweep: &OpenJdSweep) -> std::io::Result<PathBuf> {
    std::fs::create_dir_all(dir)?;
    let path = dir.join(TEMPLATE_FILE);
    let text = serde_json::to_string_pretty(&job_template(sweep)).map_err(std::io::Error::other)?;
    crate::output::write_atomic(&path, format!("{text}\n").as_bytes())?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_render_step_chunks_every_frame_and_the_assembly_waits_for_it() {
        let t = job_template(&OpenJdSweep {
            name: "board".into(),
            xylem: "/bin/xylem".into(),
            scene: "/s/board.toml".into(),
            out: "/o".into(),
            frames: 48,
            chunk: default_chunk(48),
            render_args: vec!["--frames".into(), "48".into()],
            assemble_args: vec![],
        });
        let frame = &t["steps"][0]["parameterSpace"]["taskParameterDefinitions"][0];
        assert_eq!(frame["type"], "CHUNK[INT]");
        assert_eq!(frame["range"], "0-47");
        assert_eq!(t["extensions"][0], "TASK_CHUNKING");
        assert_eq!(t["parameterDefinitions"][3]["default"], 6);
        assert_eq!(t["steps"][1]["dependencies"][0]["dependsOn"], "Render");
        assert_eq!(default_chunk(100_000), MAX_CHUNK);
    }
}

//! Regenerates one of the engine's BSDF tables from its exact functions (like pbrt-v4's cmd/):
//!
//! `cargo run --release -p xylem-lab --bin xylem-tables -- TABLE [--out FILE]`
//!
//! TABLE is rough-finish (70 s on 2 cores), rough-transmission (18 s) or fiber-albedo (8 s); the
//! file is the engine's (crates/xylem/src/bsdf/…) unless `--out` names another. It is written
//! through `xylem::output`, so a killed run leaves the old table whole.

use std::path::PathBuf;
use std::process::ExitCode;
use xylem_lab::tables::{generate, TABLES};

fn main() -> ExitCode {
    xylem::output::remove_temporaries_on_signal();
    match run(std::env::args().skip(1).collect()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: Vec<String>) -> Result<(), String> {
    let names: Vec<&str> = TABLES.iter().map(|t| t.0).collect();
    let usage = format!("usage: xylem-tables {{{}}} [--out FILE]", names.join("|"));
    let mut it = args.into_iter();
    let name = it.next().ok_or_else(|| usage.clone())?;
    let out = match (it.next().as_deref(), it.next(), it.next()) {
        (None, _, _) => None,
        (Some("--out"), Some(p), None) => Some(PathBuf::from(p)),
        _ => return Err(usage),
    };
    let Some(&(_, file)) = TABLES.iter().find(|t| t.0 == name) else {
        return Err(format!("unknown table `{name}`; {usage}"));
    };
    let path = out.unwrap_or_else(|| {
        PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../xylem")).join(file)
    });
    let start = std::time::Instant::now();
    let bytes = generate(&name).ok_or(usage)?;
    xylem::output::write_atomic(&path, &bytes)
        .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    println!(
        "wrote {} ({} bytes, {:.1} s)",
        path.display(),
        bytes.len(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

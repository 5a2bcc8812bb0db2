//! `xylem fit SWEEP_DIR... --out DIR`: per-texel fibre-BSDF parameters fitted to light sweeps,
//! one board after another in one run (each fit uses every core).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use xylem::fit::{fit_folder, FitOptions};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Sweep folders: `manifest.json` and the frames it names (`xylem sweep` writes both). A
    /// `*` or `?` in a folder's last name is expanded here (quote it), e.g. 'captures/board_*'.
    #[arg(required = true, num_args = 1..)]
    pub sweeps: Vec<PathBuf>,
    /// Output folder for the maps, residual map and report; with several sweep folders, each
    /// board's go into a subfolder named as its sweep folder.
    #[arg(long)]
    pub out: PathBuf,
    /// Map size W×H in texels, each 1 to 8192 (default: the board's size in pixels); refused
    /// when the fit's memory estimate (12 bytes per texel per frame, and more) exceeds what is
    /// available.
    #[arg(long, value_parser = parse_texels)]
    pub texels: Option<(usize, usize)>,
    /// Worker threads (0 = all cores; at most 16 per core).
    #[arg(long, default_value_t = 0, value_parser = super::parse_threads)]
    pub threads: usize,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// Parses `W×H` (or `WxH`, or one number for a square map), each 1 to 8192.
fn parse_texels(s: &str) -> Result<(usize, usize), String> {
    let parts: Vec<&str> = s.split(['x', 'X', '×']).collect();
    let num = |p: &str| -> Result<usize, String> {
        let v: usize = p
            .trim()
            .parse()
            .map_err(|_| format!("`{s}`: `{p}` is not a whole number"))?;
        if (1..=8192).contains(&v) {
            Ok(v)
        } else {
            Err(format!("`{s}`: {v} texels (allowed 1 to 8192)"))
        }
    };
    match parts.as_slice() {
        [a] => Ok((num(a)?, num(a)?)),
        [a, b] => Ok((num(a)?, num(b)?)),
        _ => Err(format!("`{s}`: expected W×H texels, e.g. 256x128")),
    }
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let mut sweeps = Vec::new();
    for p in &args.sweeps {
        sweeps.extend(expand(p)?);
    }
    let outs = out_folders(&sweeps, &args.out)?;
    let bar = super::progress::Bar::new(!args.quiet);
    let opts = FitOptions {
        texels: args.texels,
        threads: args.threads,
        progress: &bar,
    };
    if let [sweep] = sweeps.as_slice() {
        report(&fit_folder(sweep, &args.out, &opts)?, &args.out);
        return Ok(ExitCode::SUCCESS);
    }
    // Several boards: a board that fails does not stop the others; all failures are listed.
    let mut failed = Vec::new();
    for (sweep, out) in sweeps.iter().zip(&outs) {
        match fit_folder(sweep, out, &opts) {
            Ok(r) => report(&r, out),
            Err(e) => {
                eprintln!("error: fitting {}: {e}", sweep.display());
                failed.push(sweep.display().to_string());
            }
        }
    }
    if failed.is_empty() {
        println!("fitted {} boards into {}", sweeps.len(), args.out.display());
        Ok(ExitCode::SUCCESS)
    } else {
        eprintln!(
            "error: {} of {} boards failed: {}",
            failed.len(),
            sweeps.len(),
            failed.join(", ")
        );
        Ok(ExitCode::FAILURE)
    }
}

/// Prints one board's fit.
fn report(r: &serde_json::Value, out: &Path) {
    if let Some(w) = r["warning"].as_str() {
        eprintln!("warning: {w}");
    }
    println!(
        "fitted {}x{} texels from {} frames in {:.2} s (+{:.2} s reading); median relative residual {:.4}; {} texels not fitted; maps in {}",
        r["texels"][0],
        r["texels"][1],
        r["frames"],
        r["fit_seconds"].as_f64().unwrap_or(0.0),
        r["read_seconds"].as_f64().unwrap_or(0.0),
        r["median_relative_residual"].as_f64().unwrap_or(f64::NAN),
        r["texels_not_fitted"],
        out.display()
    );
}

/// Where each board's maps go: `out` itself for one board, `out/<folder name>` for several
/// (refused when two folders share a name).
fn out_folders(sweeps: &[PathBuf], out: &Path) -> anyhow::Result<Vec<PathBuf>> {
    if sweeps.len() == 1 {
        return Ok(vec![out.to_path_buf()]);
    }
    let mut seen = std::collections::HashMap::new();
    let mut outs = Vec::new();
    for s in sweeps {
        let canon = std::path::absolute(s).unwrap_or_else(|_| s.clone());
        let Some(name) = canon.file_name() else {
            anyhow::bail!(
                "{}: a sweep folder needs a name (its maps go into --out/<name>)",
                s.display()
            );
        };
        if let Some(other) = seen.insert(name.to_owned(), s.clone()) {
            anyhow::bail!(
                "{} and {} share the folder name {:?}; their maps would both go into {}",
                other.display(),
                s.display(),
                name,
                out.join(name).display()
            );
        }
        outs.push(out.join(name));
    }
    Ok(outs)
}

/// The folders a sweep argument names: itself, or where its last name holds `*` or `?`, the
/// folders beside it that match (sorted; none is an error).
fn expand(p: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let wild = |s: &str| s.contains(['*', '?']);
    let Some(name) = p.file_name().and_then(|n| n.to_str()).filter(|n| wild(n)) else {
        return Ok(vec![p.to_path_buf()]);
    };
    let parent = match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if wild(&parent.to_string_lossy()) {
        anyhow::bail!("{}: only the last name may hold * or ?", p.display());
    }
    let entries = std::fs::read_dir(parent).map_err(|e| {
        anyhow::anyhow!("{}: {e} (listing it for {})", parent.display(), p.display())
    })?;
    let mut found: Vec<PathBuf> = entries
        .filter_map(|e| e.ok())
        .filter(|e| e.path().is_dir())
        .filter(|e| e.file_name().to_str().is_some_and(|n| wildcard(name, n)))
        .map(|e| parent.join(e.file_name()))
        .collect();
    found.sort();
    if found.is_empty() {
        anyhow::bail!("{}: no folder matches", p.display());
    }
    Ok(found)
}

/// Whether `name` matches `pattern` (`*`: any run of characters, `?`: one character).
fn wildcard(pattern: &str, name: &str) -> bool {
    let (p, n): (Vec<char>, Vec<char>) = (pattern.chars().collect(), name.chars().collect());
    // Classic two-pointer match with backtracking to the last `*`.
    let (mut i, mut j, mut star, mut mark) = (0, 0, None, 0);
    while j < n.len() {
        if i < p.len() && (p[i] == '?' || p[i] == n[j]) {
            i += 1;
            j += 1;
        } else if i < p.len() && p[i] == '*' {
            star = Some(i);
            mark = j;
            i += 1;
        } else if let Some(s) = star {
            i = s + 1;
            mark += 1;
            j = mark;
        } else {
            return false;
        }
    }
    p[i..].iter().all(|&c| c == '*')
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wildcards_match_names() {
        assert!(wildcard("board_*", "board_maple"));
        assert!(wildcard("b?ard*", "board"));
        assert!(!wildcard("board_*", "boards"));
        assert!(wildcard("*", ""));
        assert!(!wildcard("a*b", "acbx"));
    }
}

//! The `xylem` command line: clap subcommands, each in its own file, each a thin layer that
//! parses, calls the library and reports errors with context. No logic of its own.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

mod bake;
mod bench;
mod docs;
mod fit;
mod gallery;
#[cfg(unix)]
mod oom;
mod preset;
mod progress;
mod render;
mod sweep;
mod texture;
mod tradeoff;
mod validate;

/// An allocation the system refuses is a clean error, not an abort (src/oom.rs).
#[cfg(unix)]
#[global_allocator]
static ALLOCATOR: oom::CleanOom = oom::CleanOom;

#[derive(Parser, Debug)]
#[command(
    name = "xylem",
    version,
    about = "Wood-appearance simulator: fibre BSDF, procedural solid wood, light sweeps"
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render a scene to EXR (with AOV layers) and a PNG preview.
    Render(render::Args),
    /// Render a light sweep: frames, contact sheet, animated PNG, CSV and an HTML viewer.
    Sweep(sweep::Args),
    /// Run the validation suite (BSDF and sweep checks) and write validation/REPORT.md.
    Validate(validate::Args),
    /// Render a planar slice of a solid texture, a noise or a wood preset to PNG.
    Texture(texture::Args),
    /// The README's images: every built-in scene with its subject check, the presets on one
    /// board, and light-sweep close-ups of the figured presets.
    Gallery(gallery::Args),
    /// Species presets.
    Preset(preset::Args),
    /// Benchmarks (tracing, BSDF, noise, wood).
    Bench(bench::Args),
    /// Measure the speed/accuracy trade of every quality knob for a scene.
    Tradeoff(tradeoff::Args),
    /// Bake texture maps of a preset for other tools.
    Bake(bake::Args),
    /// Fit per-texel fibre-BSDF maps (measured-material encoding) to a light sweep.
    Fit(fit::Args),
    /// Print a shell completion script (bash, zsh, fish, elvish, powershell).
    Completions(docs::CompletionsArgs),
    /// Print the man page, or write every subcommand's into a folder (--out DIR).
    Man(docs::ManArgs),
}

/// Entry point of the binary: runs the subcommand and turns an error into a message and exit code 1.
fn main() -> ExitCode {
    let cli = Cli::parse();
    // Ctrl-C or a kill(1) leaves no temporary behind (notes/limits.md).
    xylem::output::remove_temporaries_on_signal();
    // Output piped into a reader that stops early (`xylem … | head`) ends the program quietly
    // with SIGPIPE's usual status, as any Unix tool, instead of a panic on the failed print.
    // SAFETY: restores the default action of one signal.
    #[cfg(unix)]
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL)
    };
    // A forced SIMD level with an unknown name is refused here, before any work.
    if let Err(e) = xylem::simd::Simd::from_env() {
        eprintln!("error: {e}");
        return ExitCode::FAILURE;
    }
    let result = match cli.command {
        Command::Render(a) => render::run(a),
        Command::Sweep(a) => sweep::run(a),
        Command::Validate(a) => validate::run(a),
        Command::Texture(a) => texture::run(a),
        Command::Gallery(a) => gallery::run(a),
        Command::Preset(a) => preset::run(a),
        Command::Bench(a) => bench::run(a),
        Command::Tradeoff(a) => tradeoff::run(a),
        Command::Bake(a) => bake::run(a),
        Command::Fit(a) => fit::run(a),
        Command::Completions(a) => docs::completions(a),
        Command::Man(a) => docs::man(a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {}", error_chain(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes joined by `: `, leaving out a cause whose text the message already
/// holds (our error types print their source, so `{:#}` gave every OS error twice).
/// `--threads`: 0 (all cores) up to [`MAX_THREADS_PER_CORE`] per core
/// ([`check_threads`](xylem::resources::check_threads)).
///
/// [`MAX_THREADS_PER_CORE`]: xylem::resources::MAX_THREADS_PER_CORE
pub(crate) fn parse_threads(s: &str) -> Result<usize, String> {
    let n: usize = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a whole number (allowed 0 = all cores, or more)"))?;
    xylem::resources::check_threads(n).map_err(|e| e.to_string())?;
    Ok(n)
}

/// `--spp`: 1 to [`MAX_SPP`] samples per pixel.
///
/// [`MAX_SPP`]: xylem::scene::MAX_SPP
pub(crate) fn parse_spp(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(n) if (1..=xylem::scene::MAX_SPP).contains(&n) => Ok(n),
        _ => Err(format!(
            "`{s}` is out of range (allowed 1 to {} samples per pixel)",
            xylem::scene::MAX_SPP
        )),
    }
}

/// A value parser for an engine enum with a fixed list of names (`--quality`,
/// `--exr-compression`): clap lists the names in `--help` and refuses others, then the name is
/// parsed by the enum's own `FromStr`, so the engine needs no clap.
pub(crate) fn named<T>(
    names: &'static [&'static str],
) -> impl clap::builder::TypedValueParser<Value = T>
where
    T: std::str::FromStr + Clone + Send + Sync + 'static,
    T::Err: std::fmt::Debug,
{
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(names)
        .map(|s| s.parse::<T>().expect("every listed name parses"))
}

/// Parses `on` / `off` (also `true` / `false`).
pub(crate) fn parse_on_off(s: &str) -> Result<bool, String> {
    match s.trim() {
        "on" | "true" => Ok(true),
        "off" | "false" => Ok(false),
        _ => Err(format!("`{s}`: expected on or off")),
    }
}

/// The largest `--exposure` magnitude in stops: ±30 stops scales by 2^±30 ≈ 10^±9, beyond
/// which every pixel of any image is black or white.
pub(crate) const MAX_EXPOSURE_STOPS: f32 = 30.0;

/// `--exposure`: a finite number of stops within ±[`MAX_EXPOSURE_STOPS`].
pub(crate) fn parse_exposure(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(x) if x.is_finite() && x.abs() <= MAX_EXPOSURE_STOPS => Ok(x),
        _ => Err(format!(
            "`{s}` is out of range (allowed -{MAX_EXPOSURE_STOPS} to {MAX_EXPOSURE_STOPS} stops)"
        )),
    }
}

fn error_chain(e: &anyhow::Error) -> String {
    let mut msg = e.to_string();
    for cause in e.chain().skip(1) {
        let c = cause.to_string();
        if !msg.contains(&c) {
            msg.push_str(": ");
            msg.push_str(&c);
        }
    }
    msg
}

/// Where a run writes: `given`, else `default` (a committed full result) — unless the run is
/// reduced (`reduced` says how, e.g. `--reduce 20`), which must name its output itself so that
/// reduced numbers never overwrite the full ones.
pub(crate) fn output_path(
    given: Option<std::path::PathBuf>,
    default: &str,
    option: &str,
    reduced: Option<String>,
) -> anyhow::Result<std::path::PathBuf> {
    match (given, reduced) {
        (Some(p), _) => Ok(p),
        (None, None) => Ok(default.into()),
        (None, Some(how)) => anyhow::bail!(
            "{how} is a reduced run: it would overwrite the full results in {default}; name where it should write with {option} (e.g. {option} out/reduced/{})",
            std::path::Path::new(default)
                .file_name()
                .map_or(String::new(), |n| n.to_string_lossy().into_owned())
        ),
    }
}

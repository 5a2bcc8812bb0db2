//! `xylem tradeoff SCENE.toml`: measures every speed/accuracy knob against a reference render and
//! writes validation/TRADEOFF.md with an error-against-time plot ([`xylem_lab::tradeoff`]).

use std::path::PathBuf;
use std::process::ExitCode;
use xylem_lab::tradeoff::{check_options, run_study, settings, write_report, StudyOptions};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Image width for the measurements, 8 to 4096 (the height keeps the scene's aspect ratio).
    #[arg(long, default_value_t = 160)]
    pub width: u32,
    /// Samples per pixel of the reference render (full model), 1 to 1000000.
    #[arg(long, default_value_t = 256, value_parser = super::parse_spp)]
    pub reference_spp: u32,
    /// Report to write.
    #[arg(long, default_value = "validation/TRADEOFF.md")]
    pub out: PathBuf,
    /// Also write every number as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Replace the preset of every wood material of the scene by this one (e.g. curly_maple, to
    /// measure the distortion knobs on a strongly figured wood).
    #[arg(long)]
    pub preset: Option<String>,
    /// Also write every render (reference and each row) as a PNG into this folder.
    #[arg(long)]
    pub images: Option<PathBuf>,
    /// Worker threads (0 = all cores; at most 16 per core).
    #[arg(long, default_value_t = 0, value_parser = super::parse_threads)]
    pub threads: usize,
    /// Measure even with a reference under 4× the highest measured spp (the report then says
    /// so at its top; without this flag such a run is refused).
    #[arg(long)]
    pub allow_weak_reference: bool,
    /// Times each setting is rendered for its timing, 1 to 20, in rounds over all settings (so
    /// that a change in the machine's load falls on every setting alike); the report gives the
    /// median and the range.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=20))]
    pub repeats: u32,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let all = settings();
    let opts = StudyOptions {
        scene: args.scene,
        width: args.width,
        reference_spp: args.reference_spp,
        preset: args.preset,
        images: args.images,
        threads: args.threads,
        allow_weak_reference: args.allow_weak_reference,
        repeats: args.repeats,
    };
    let weak = check_options(&opts, &all)?;
    if let Some(why) = &weak {
        eprintln!("warning: {why}");
    }
    let result = run_study(&opts, &all, &Bar::default())?;
    write_report(
        &opts,
        &result,
        &args.out,
        args.json.as_deref(),
        weak.as_deref(),
    )?;
    for r in &result.rows {
        println!(
            "{:<20} {:<28} {:>8.3} s CPU ({:.3}–{:.3}), {:.3} s wall (+{:.3} s)  rel. MSE {:>10.3e}  SSIM {:.4}  model {:>10.3e} {:.4}",
            r.knob, r.setting, r.cpu_seconds, r.cpu_min, r.cpu_max, r.seconds, r.prep_seconds, r.relative_mse, r.ssim, r.model_mse, r.model_ssim
        );
    }
    println!("report: {}", args.out.display());
    Ok(ExitCode::SUCCESS)
}

/// The study's renders as `tradeoff ████░░ 12/88 render with 4 spp`, cleared at the end.
#[derive(Default)]
struct Bar(std::sync::Mutex<Option<indicatif::ProgressBar>>);

impl Bar {
    fn bar(&self) -> Option<indicatif::ProgressBar> {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }
}

impl xylem::progress::Progress for Bar {
    fn start(&self, total: u64, _unit: &str) {
        let b = indicatif::ProgressBar::new(total).with_style(
            indicatif::ProgressStyle::with_template("tradeoff {bar:40} {pos}/{len} {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        *self.0.lock().unwrap_or_else(|e| e.into_inner()) = Some(b);
    }

    fn update(&self, done: u64, _total: u64, message: &str) {
        let Some(b) = self.bar() else { return };
        if !message.is_empty() {
            b.set_message(message.to_string());
        }
        b.set_position(done);
    }

    fn finish(&self) {
        if let Some(b) = self.bar() {
            b.finish_and_clear();
        }
    }
}

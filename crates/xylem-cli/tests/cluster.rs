//! Sweeps beyond one process and one memory (issue 31): frames streamed in batches that fit
//! `--memory`, the Slurm recipe of notes/cluster.md run on a local cluster, and the Open Job
//! Description template run with `openjd run`. Each farmed sweep must give the same files, byte
//! for byte, as one process.

#[allow(dead_code)] // only the venv of crates/xylem-cli/tests/common/python.rs is used here
mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};
use xylem::render::resources::Resources;

fn repo() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

fn xylem(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_xylem"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("xylem runs")
}

fn ok(o: Output, what: &str) -> String {
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(o.status.success(), "{what} failed: {text}");
    text
}

/// The built-in board scene at `w × h`, 1 spp, written into `dir` as board.toml.
fn tiny_board(dir: &Path, w: u32, h: u32) -> PathBuf {
    let text = std::fs::read_to_string(repo().join("scenes/sweep_board.toml")).unwrap();
    let text = text
        .replace("width = 512", &format!("width = {w}"))
        .replace("height = 384", &format!("height = {h}"))
        .replace("spp = 16", "spp = 1");
    // The named regions are in pixels of the full-size image.
    let text = &text[..text.find("[[sweep.regions]]").unwrap_or(text.len())];
    let p = dir.join("board.toml");
    std::fs::write(&p, text).unwrap();
    p
}

/// Every file of a folder (names and bytes), without the lock file of the folder lock.
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read(&p).unwrap())
        })
        .collect()
}

/// Asserts two sweep folders hold the same files with the same bytes.
fn assert_same_files(a: &Path, b: &Path) {
    let (fa, fb) = (files(a), files(b));
    let names = |f: &BTreeMap<String, Vec<u8>>| f.keys().cloned().collect::<Vec<_>>();
    assert_eq!(
        names(&fa),
        names(&fb),
        "{} and {}",
        a.display(),
        b.display()
    );
    assert!(fa.contains_key("index.html") && fa.contains_key("aov.exr"));
    for (name, bytes) in &fa {
        assert!(
            bytes == &fb[name],
            "{name} differs between {} and {}",
            a.display(),
            b.display()
        );
    }
}

#[test]
fn a_sweep_in_batches_writes_the_same_files_as_one_batch() {
    use xylem::render::Primaries;
    let dir = tempfile::tempdir().unwrap();
    let scene = tiny_board(dir.path(), 24, 16);
    let s = scene.to_str().unwrap();
    // The path tracer too (its later bounces follow a kept first bounce).
    let text = std::fs::read_to_string(&scene).unwrap();
    let path = dir.path().join("path.toml");
    std::fs::write(&path, text.replace("\"direct\"", "\"path\"")).unwrap();
    // A budget of three frames (at the one thread asked for) cuts the sweep into 10 batches;
    // with the kept primary samples' memory on top, `keep` keeps them (`auto` would rather
    // take the 17 frames that memory holds without them).
    let budget =
        Resources::sweep_fixed_bytes(24, 16, 1) + 3 * Resources::sweep_frame_bytes(24, 16, 1);
    let kept = (budget + Primaries::bytes(24, 16, 1)).to_string();
    let budget = budget.to_string();
    for scene in [s, path.to_str().unwrap()] {
        let sweep = |out: &str, more: &[&str]| {
            let args = [
                "sweep",
                scene,
                "--frames",
                "30",
                "--threads",
                "1",
                "--out",
                out,
            ];
            ok(xylem(dir.path(), &[&args[..], more].concat()), out)
        };
        let one = sweep("one", &["--memory", "1G"]);
        assert!(one.contains("1 batch of up to 30)"), "{one}");
        for (memory, mode, says) in [
            (&budget, "auto", "10 batches of up to 3)"),
            (&kept, "keep", "10 batches of up to 3, primary samples kept"),
        ] {
            let many = sweep("many", &["--memory", memory, "--primaries", mode]);
            assert!(many.contains(says), "{many}");
            assert_same_files(&dir.path().join("one"), &dir.path().join("many"));
        }
    }
    // A budget below one frame is refused up front, naming the option and what one frame needs.
    let o = xylem(dir.path(), &["sweep", s, "--memory", "1K", "--out", "no"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && !e.contains("panicked"), "{e}");
    assert!(
        e.contains("--memory 1.0 KiB") || e.contains("--memory"),
        "{e}"
    );
    assert!(
        e.contains("too small for one frame of a 24x16 sweep"),
        "{e}"
    );
    let o = xylem(dir.path(), &["sweep", s, "--memory", "12 parsecs"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && e.contains("unknown unit"), "{e}");
}

#[test]
fn the_memory_a_sweep_needs_does_not_grow_with_its_frames() {
    use xylem::sweep::batch::{default_plan, PrimaryMode, SweepSize};
    // Batches of 48 frames: 48 frames and 100000 need the same memory (the disk still grows).
    let short = Resources::sweep(512, 384, 48, 48, 2);
    let long = Resources::sweep(512, 384, 100_000, 48, 2);
    assert_eq!(short.memory, long.memory);
    assert!(long.disk > 1000 * short.disk);
    // The default plan: a 4800-frame sweep holds at most 1.2 times what a 48-frame one holds
    // (the goal of issue 31), at 256² from 1 to 64 spp and at the board's own 512×384, 16 spp.
    for (w, h, spp) in [(256, 256, 1), (256, 256, 8), (256, 256, 64), (512, 384, 16)] {
        let memory = |frames| {
            let size = SweepSize {
                width: w,
                height: h,
                spp,
                threads: 2,
                frames,
            };
            let plan = default_plan(&size, PrimaryMode::Auto).unwrap();
            plan.memory(&size) as f64
        };
        let (m48, m4800) = (memory(48), memory(4800));
        assert!(
            m4800 <= 1.2 * m48,
            "{w}x{h} at {spp} spp: 4800 frames plan {m4800} bytes, 48 frames {m48}"
        );
    }
}

/// Runs `xylem ARGS` in `dir` with its output discarded and returns its peak resident memory
/// in bytes (the child's `ru_maxrss`, from `wait4`).
#[cfg(target_os = "linux")]
fn peak_rss(dir: &Path, args: &[&str]) -> u64 {
    #[allow(clippy::zombie_processes)] // reaped by the wait4 below, which also gives its rusage
    let child = Command::new(env!("CARGO_BIN_EXE_xylem"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let (mut status, mut usage) = (0, unsafe { std::mem::zeroed::<libc::rusage>() });
    // SAFETY: waits for our own child; `status` and `usage` are writable.
    let pid = unsafe { libc::wait4(child.id() as i32, &mut status, 0, &mut usage) };
    assert!(pid > 0 && libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0);
    usage.ru_maxrss as u64 * 1024
}

#[cfg(target_os = "linux")]
#[test]
fn a_long_sweep_peaks_at_the_memory_of_a_short_one_by_default() {
    // 128×128 at 1 spp: 480 frames held at once would add ≥ 240 MiB (512 KiB of radiance and
    // error each) to the 48-frame sweep's ~33 MiB peak; the default batches keep them level
    // within issue 31's goal of 1.2×. Peak RSS varies run to run (+1.5 % to +5.8 % measured
    // for 480 frames, the latter on CI), so each length takes the least of three runs; the
    // heap creep the held malloc thresholds prevent (+9 % without them) is measured in
    // notes/cluster.md, not here.
    let dir = tempfile::tempdir().unwrap();
    let scene = tiny_board(dir.path(), 128, 128);
    let s = scene.to_str().unwrap();
    let peak = |n: &str| {
        let out = format!("out_{n}");
        let args = [
            "sweep",
            s,
            "--frames",
            n,
            "--out",
            &out,
            "--quiet",
            "--threads",
            "2",
        ];
        (0..3).map(|_| peak_rss(dir.path(), &args)).min().unwrap()
    };
    let (short, long) = (peak("48"), peak("480"));
    assert!(
        (long as f64) < 1.2 * short as f64,
        "peak RSS {long} bytes for 480 frames, {short} for 48"
    );
}

/// `sbatch`, or None (with the reason printed) where Slurm is not installed.
fn slurm() -> Option<()> {
    let found = Command::new("sbatch")
        .arg("--version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !found {
        println!("skipped: sbatch is not installed, so there is no Slurm cluster to submit to (Debian: apt-get install slurm-wlm munge, then tools/slurm-local/start.sh as root; .ci/run does both)");
        return None;
    }
    let o = Command::new("bash")
        .arg(repo().join("tools/slurm-local/start.sh"))
        .output()
        .unwrap();
    ok(
        o,
        "tools/slurm-local/start.sh (bringing up the local Slurm cluster)",
    );
    Some(())
}

/// The state of Slurm job `id` (`COMPLETED`, `PENDING`, …).
fn job_state(id: &str) -> String {
    let o = Command::new("scontrol")
        .args(["show", "job", "-o", id])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    (text.split_whitespace())
        .find_map(|f| f.strip_prefix("JobState="))
        .unwrap_or("UNKNOWN")
        .to_string()
}

#[test]
fn the_slurm_recipe_of_notes_cluster_md_matches_one_process() {
    let notes = std::fs::read_to_string(repo().join("notes/cluster.md")).unwrap();
    let tools = repo().join("tools/slurm-local");
    // The notes give these two files verbatim: the recipe there is the one run here.
    for f in ["submit.sh", "sweep_array.sbatch"] {
        let text = std::fs::read_to_string(tools.join(f)).unwrap();
        assert!(
            notes.contains(&format!("```bash\n{text}```")),
            "notes/cluster.md does not give tools/slurm-local/{f} verbatim"
        );
    }
    if slurm().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let scene = tiny_board(dir.path(), 32, 32);
    ok(
        xylem(
            dir.path(),
            &[
                "sweep",
                scene.to_str().unwrap(),
                "--frames",
                "8",
                "--out",
                "single",
                "--quiet",
            ],
        ),
        "the single-process sweep",
    );
    let o = Command::new("bash")
        .arg(tools.join("submit.sh"))
        .env("XYLEM", env!("CARGO_BIN_EXE_xylem"))
        .env("SCENE", &scene)
        .env("FRAMES", "8")
        .env("OUT", "out/farm")
        .env("TASKS", "3")
        .env("CPUS", "1")
        .current_dir(dir.path())
        .output()
        .unwrap();
    let ids = ok(o, "tools/slurm-local/submit.sh");
    let ids: Vec<&str> = ids.split_whitespace().collect();
    assert_eq!(ids.len(), 2, "submit.sh printed {ids:?}");
    let start = Instant::now();
    let logs = || {
        let mut s = String::new();
        for e in std::fs::read_dir(dir.path().join("logs"))
            .into_iter()
            .flatten()
        {
            let p = e.unwrap().path();
            s += &format!(
                "--- {}\n{}",
                p.display(),
                std::fs::read_to_string(&p).unwrap_or_default()
            );
        }
        s
    };
    loop {
        let state = job_state(ids[1]);
        match state.as_str() {
            "COMPLETED" => break,
            "PENDING" | "RUNNING" | "CONFIGURING" | "COMPLETING" => {}
            _ => panic!("the assembly job {} ended {state}:\n{}", ids[1], logs()),
        }
        if start.elapsed() > Duration::from_secs(240) {
            let _ = Command::new("scancel").args(&ids).status();
            panic!("the Slurm jobs did not finish in 240 s:\n{}", logs());
        }
        std::thread::sleep(Duration::from_millis(500));
    }
    println!(
        "8 frames in 3 array tasks plus the assembly: {:.1} s on Slurm",
        start.elapsed().as_secs_f64()
    );
    assert_same_files(&dir.path().join("single"), &dir.path().join("out/farm"));
}

#[test]
fn the_openjd_template_checks_and_runs_to_the_same_files_as_one_process() {
    let dir = tempfile::tempdir().unwrap();
    let scene = tiny_board(dir.path(), 32, 32);
    let s = scene.to_str().unwrap();
    ok(
        xylem(
            dir.path(),
            &["sweep", s, "--frames", "8", "--out", "single", "--quiet"],
        ),
        "the single-process sweep",
    );
    let emitted = ok(
        xylem(
            dir.path(),
            &[
                "sweep",
                s,
                "--frames",
                "8",
                "--out",
                "farm",
                "--emit-openjd",
                "job",
            ],
        ),
        "--emit-openjd",
    );
    assert!(emitted.contains("template.json"), "{emitted}");
    assert!(!dir.path().join("farm").exists(), "--emit-openjd rendered");
    let template = dir.path().join("job/template.json");
    let text = std::fs::read_to_string(&template).unwrap();
    assert!(text.contains("\"CHUNK[INT]\"") && text.contains("\"TASK_CHUNKING\""));
    // openjd-cli from the test venv (python/requirements-test.txt pins it).
    let openjd = common::python::venv().join("bin/openjd");
    ok(
        Command::new(&openjd)
            .arg("check")
            .arg(&template)
            .output()
            .unwrap(),
        "openjd check",
    );
    // Chunks of 3 frames: 0-2, 3-5, 6-7, then the assembly.
    let run = ok(
        Command::new(&openjd)
            .arg("run")
            .arg(&template)
            .args(["--job-param", "ChunkSize=3"])
            .current_dir(dir.path())
            .output()
            .unwrap(),
        "openjd run",
    );
    assert!(run.contains("Chunks run: 4"), "{run}");
    assert_same_files(&dir.path().join("single"), &dir.path().join("farm"));
}

/// `xylem fit` over several capture folders and a quoted glob (notes/cluster.md, "Fitting many
/// boards"): each board's maps go into `--out/<folder name>`, byte for byte those of fitting it
/// alone; a failing board does not stop the others; same-named folders are refused up front.
#[test]
fn fit_takes_several_captures_or_a_glob_and_fits_each_as_alone() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir_all(d.join("caps")).unwrap();
    for (name, frames) in [("board_a", "3"), ("board_b", "4")] {
        let out = format!("caps/{name}");
        let args = [
            "sweep",
            "fit_maple_sweep",
            "--frames",
            frames,
            "--spp",
            "1",
            "--quiet",
            "--out",
            &out,
        ];
        ok(xylem(d, &args), &out);
    }
    // Not a folder: the glob passes it by.
    std::fs::write(d.join("caps/board_notes.txt"), "not a capture").unwrap();
    let fit = |args: &[&str]| {
        let base = ["fit", "--quiet", "--texels", "8", "--threads", "1"];
        xylem(d, &[&base[..], args].concat())
    };
    let says = ok(fit(&["caps/board_*", "--out", "maps"]), "fit of a glob");
    assert!(says.contains("fitted 2 boards into maps"), "{says}");
    for name in ["board_a", "board_b"] {
        let alone = format!("alone_{name}");
        ok(fit(&[&format!("caps/{name}"), "--out", &alone]), &alone);
        for f in ["maps.exr", "diffuse.png", "residual.png"] {
            let (a, b) = (d.join("maps").join(name).join(f), d.join(&alone).join(f));
            assert!(
                std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap(),
                "{} differs from {}",
                a.display(),
                b.display()
            );
        }
    }
    assert!(!d.join("maps/board_notes.txt").exists());
    // A folder that is no capture, between two that are: the others are fitted, and the run
    // ends with status 1 naming it.
    std::fs::create_dir_all(d.join("caps/empty")).unwrap();
    let o = fit(&["caps/board_a", "caps/empty", "caps/board_b", "--out", "m2"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("1 of 3 boards failed: caps/empty"), "{e}");
    assert!(d.join("m2/board_a/maps.exr").exists() && d.join("m2/board_b/maps.exr").exists());
    // Two folders of one name would share their maps' folder: refused before any fit.
    std::fs::create_dir_all(d.join("other")).unwrap();
    std::fs::rename(d.join("caps/empty"), d.join("other/board_a")).unwrap();
    let o = fit(&["caps/board_a", "other/board_a", "--out", "m3"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && e.contains("share the folder name"),
        "{e}"
    );
    assert!(!d.join("m3").exists(), "fitted before refusing");
    let o = fit(&["caps/plank_*", "--out", "m4"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && e.contains("no folder matches"),
        "{e}"
    );
}

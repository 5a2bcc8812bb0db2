//! Never corrupt (issue 15): the binary driven as a user would drive it — concurrent renders
//! and sweep slices into one folder, the farm recipe of notes/cluster.md, runs killed at random
//! points, mixed slices given to `--assemble`. Every run is tiny (tens of pixels, 1 spp). Bad
//! scenes and requests beyond the machine are in scene_errors.rs.

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};
use xylem::picture::exr::read_exr_channels;
use xylem::picture::png::read_png_rgb8;
use xylem::picture::srgb::to_srgb8;
use xylem::picture::Image;
use xylem::sweep::sequence::{read_records, FrameRecord, CSV, VIEWER};

#[path = "common/cli.rs"]
mod cli;

use cli::{assert_clean_error, repo, run, stderr, tiny_board, xylem};

/// Checks that the render's PNG is the sRGB preview of its EXR (so both come from one run).
fn assert_pair_matches(exr: &Path, png: &Path) {
    let linear = Image::read(exr).unwrap();
    let img = read_png_rgb8(png).unwrap();
    assert_eq!((img.width, img.height), (linear.width, linear.height));
    assert!(
        img == linear.to_rgb8(0.0),
        "{} is not the preview of {}",
        png.display(),
        exr.display()
    );
}

fn leftovers(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp") || n.ends_with(".partial"))
        .collect()
}

#[test]
fn two_renders_into_one_folder_leave_one_consistent_pair() {
    let dir = tempfile::tempdir().unwrap();
    let scene = tiny_board(dir.path(), 96, 64, 4);
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    // Another run's temporary file under the old fixed name must not stop or harm this one.
    std::fs::create_dir(out.join("board.exr.partial")).unwrap();
    std::fs::create_dir(out.join("board.png.partial")).unwrap();
    let o = run(&[
        "render",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    for round in 0..3 {
        let kids: Vec<_> = [1, 2]
            .map(|seed: u32| {
                xylem()
                    .args([
                        "render",
                        scene.to_str().unwrap(),
                        "--quiet",
                        "--threads",
                        "1",
                    ])
                    .args(["--seed", &(seed + 10 * round).to_string()])
                    .args(["--out", out.to_str().unwrap()])
                    .stderr(Stdio::piped())
                    .stdout(Stdio::null())
                    .spawn()
                    .unwrap()
            })
            .into_iter()
            .collect();
        for k in kids {
            let o = k.wait_with_output().unwrap();
            assert!(o.status.success(), "{}", stderr(&o));
        }
        assert_pair_matches(&out.join("board.exr"), &out.join("board.png"));
    }
    let left: Vec<String> = leftovers(&out)
        .into_iter()
        .filter(|n| !n.ends_with(".partial"))
        .collect();
    assert!(left.is_empty(), "temporary files left: {left:?}");
}

/// What a folder must satisfy at any moment, even after a run was killed: every image under a
/// final name decodes; every frame record describes the EXR and PNG beside it (their mean
/// radiance); and a viewer is only present beside a complete, consistent sweep.
fn assert_nothing_looks_complete_that_is_not(dir: &Path) {
    if !dir.exists() {
        return;
    }
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if name.starts_with('.') {
            continue; // a temporary of a killed run: never under a final name
        }
        if name.ends_with(".png") {
            read_png_rgb8(&p).unwrap_or_else(|e| panic!("{name}: {e}"));
        } else if name.ends_with(".exr") {
            read_exr_channels(&p).unwrap_or_else(|e| panic!("{name}: {e}"));
        } else if name == "manifest.json" {
            // The capture manifest for `xylem fit`, written atomically: it must parse whole.
            let text = std::fs::read_to_string(&p).unwrap();
            serde_json::from_str::<xylem::sweep::manifest::Manifest>(&text)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
        } else if name.starts_with("frame_") && name.ends_with(".json") {
            let rec: FrameRecord =
                serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
            let exr = p.with_extension("exr");
            let px = Image::read(&exr)
                .unwrap_or_else(|e| panic!("{name} is there but its EXR is not: {e}"))
                .pixels;
            let n = px.len() as f64;
            for c in 0..3 {
                let mean = px.iter().map(|v| v[c] as f64).sum::<f64>() / n;
                let want = rec.mean_rgb[c] as f64;
                assert!(
                    (mean - want).abs() <= 1e-5 * want.abs().max(1e-6),
                    "{name} says mean {want} but its EXR has {mean}: they come from different runs"
                );
            }
            let png = read_png_rgb8(&p.with_extension("png"))
                .unwrap_or_else(|e| panic!("{name} is there but its PNG is not: {e}"));
            assert!(png.data == to_srgb8(&px, 0.0), "{name}: PNG and EXR differ");
        }
    }
    if dir.join("manifest.json").exists() {
        // The capture `xylem fit` takes as complete: every frame there, all of one sweep.
        let records = read_records(dir).unwrap_or_else(|e| {
            panic!("a manifest beside frames of two runs or an incomplete sweep: {e}")
        });
        let text = std::fs::read_to_string(dir.join("manifest.json")).unwrap();
        let m: xylem::sweep::manifest::Manifest = serde_json::from_str(&text).unwrap();
        assert_eq!(m.frames.len(), records.len(), "manifest and records");
    }
    if dir.join(VIEWER).exists() {
        let records = read_records(dir).expect("a viewer beside an incomplete sweep");
        let csv = std::fs::read_to_string(dir.join(CSV)).expect("a viewer without its CSV");
        assert_eq!(csv.lines().count(), records.len() + 1);
    }
}

/// A deterministic stream of kill delays (xorshift64*, fixed seed).
fn delays(n: usize, max: Duration, mut s: u64) -> Vec<Duration> {
    (0..n)
        .map(|_| {
            s ^= s >> 12;
            s ^= s << 25;
            s ^= s >> 27;
            let u = (s.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64;
            max.mul_f64(u)
        })
        .collect()
}

#[test]
fn sweeps_killed_at_random_points_leave_nothing_that_looks_complete() {
    let dir = tempfile::tempdir().unwrap();
    let scene = tiny_board(dir.path(), 40, 30, 9);
    let out = dir.path().join("out");
    let args = |frames: &str| {
        let mut c = xylem();
        c.args([
            "sweep",
            scene.to_str().unwrap(),
            "--quiet",
            "--frames",
            frames,
        ])
        .args(["--out", out.to_str().unwrap()])
        .stdout(Stdio::null())
        .stderr(Stdio::null());
        c
    };
    // A complete earlier sweep of another frame count (so other light angles) in the folder.
    let start = Instant::now();
    assert!(args("5").status().unwrap().success());
    let full = start.elapsed();
    assert_nothing_looks_complete_that_is_not(&out);
    for d in delays(10, full.mul_f64(1.5), 0x9e37_79b9_7f4a_7c15) {
        let mut kid = args("9").spawn().unwrap();
        std::thread::sleep(d);
        let _ = kid.kill(); // SIGKILL
        kid.wait().unwrap();
        assert_nothing_looks_complete_that_is_not(&out);
    }
    assert!(args("9").status().unwrap().success());
    assert_eq!(read_records(&out).unwrap().len(), 9);
    assert_nothing_looks_complete_that_is_not(&out);
}

/// `xylem sweep SCENE --quiet --out OUT EXTRA…`, its errors kept.
fn sweep_into(scene: &Path, out: &Path, extra: &[&str]) -> Command {
    let mut c = xylem();
    c.args(["sweep", scene.to_str().unwrap(), "--quiet", "--out"])
        .arg(out)
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    c
}

/// Issue 26: reruns into a folder that holds a complete sweep, killed at points spread over
/// their run — slices of other settings, slices of the same, whole sweeps of other settings —
/// never leave a folder that looks complete (a manifest for `fit`, a viewer) with frames of two
/// runs. Before, a slice of another spp kept the old manifest beside frames of both runs.
#[test]
fn reruns_killed_part_way_never_leave_a_capture_of_two_runs() {
    let dir = tempfile::tempdir().unwrap();
    let scene = tiny_board(dir.path(), 40, 30, 9);
    let out = dir.path().join("out");
    let sweep = |extra: &[&str]| sweep_into(&scene, &out, extra);
    let start = Instant::now();
    assert!(sweep(&[]).status().unwrap().success());
    let full = start.elapsed();
    let other_slice = ["--spp", "2", "--frames-range", "0..5"];
    let reruns: [&[&str]; 3] = [&other_slice, &["--frames-range", "0..5"], &["--spp", "2"]];
    for (k, d) in delays(12, full.mul_f64(1.3), 0x2545_f491_4f6c_dd1d)
        .into_iter()
        .enumerate()
    {
        // Four of each, the whole sweeps last (they change the folder's settings).
        let mut kid = sweep(reruns[k / 4]).spawn().unwrap();
        std::thread::sleep(d);
        let _ = kid.kill(); // SIGKILL
        kid.wait().unwrap();
        assert_nothing_looks_complete_that_is_not(&out);
    }
    assert!(sweep(&["--spp", "2"]).status().unwrap().success());
    // The folder is a 2-spp sweep now: a 1-spp slice is refused before it writes a file.
    let before = std::fs::read(out.join("frame_0000.exr")).unwrap();
    let o = sweep(&["--frames-range", "0..5"]).output().unwrap();
    assert_clean_error(&o, "sweep.json");
    assert_clean_error(&o, "spp 2 there, 1 in this run");
    assert_eq!(std::fs::read(out.join("frame_0000.exr")).unwrap(), before);
    assert!(out.join("manifest.json").exists());
    assert_nothing_looks_complete_that_is_not(&out);
}

/// Issue 26: two slices of other settings started at once into an empty folder — one claims it
/// (`sweep.json`), the other refuses before writing a file, naming the setting (before, both
/// rendered and the folder held frames of two sweeps); slices of the same settings share it.
#[test]
fn slices_racing_into_an_empty_folder_never_both_write() {
    let dir = tempfile::tempdir().unwrap();
    let scene = tiny_board(dir.path(), 40, 30, 6);
    let race = |out: &Path, spp: [&str; 2]| -> Vec<Output> {
        let kids: Vec<_> = [(spp[0], "0..3"), (spp[1], "3..6")]
            .map(|(spp, range)| {
                let extra = ["--spp", spp, "--frames-range", range];
                sweep_into(&scene, out, &extra).spawn().unwrap()
            })
            .into_iter()
            .collect();
        kids.into_iter()
            .map(|k| k.wait_with_output().unwrap())
            .collect()
    };
    let spps = |out: &Path| -> std::collections::BTreeSet<u32> {
        (std::fs::read_dir(out).unwrap())
            .map(|e| e.unwrap().path())
            .filter(|p| {
                p.file_name()
                    .unwrap()
                    .to_string_lossy()
                    .starts_with("frame_")
            })
            .filter(|p| p.extension().is_some_and(|e| e == "json"))
            .map(|p| {
                let text = std::fs::read_to_string(p).unwrap();
                serde_json::from_str::<FrameRecord>(&text)
                    .unwrap()
                    .sweep
                    .spp
            })
            .collect()
    };
    for round in 0..3 {
        let out = dir.path().join(format!("race{round}"));
        let outs = race(&out, ["1", "2"]);
        let refused: Vec<&Output> = outs.iter().filter(|o| !o.status.success()).collect();
        assert_eq!(refused.len(), 1, "round {round}: both slices ran");
        assert_clean_error(refused[0], "sweep.json");
        assert_clean_error(
            refused[0],
            "this folder holds a sweep of other settings (spp ",
        );
        assert_eq!(spps(&out).len(), 1, "round {round}: records of two sweeps");
        assert_nothing_looks_complete_that_is_not(&out);
    }
    let out = dir.path().join("same");
    for o in race(&out, ["1", "1"]) {
        assert!(o.status.success(), "{}", stderr(&o));
    }
    assert_eq!(read_records(&out).unwrap().len(), 6);
    assert!(out.join("manifest.json").exists());
    assert_nothing_looks_complete_that_is_not(&out);
    // A refused slice's folder is incomplete (its frames 3..6 missing): `fit` says so.
    let (race0, maps) = (dir.path().join("race0"), dir.path().join("maps"));
    let o = run(&[
        "fit",
        race0.to_str().unwrap(),
        "--out",
        maps.to_str().unwrap(),
    ]);
    assert_clean_error(&o, "an incomplete sweep");
}

#[test]
fn a_whole_sweep_refuses_a_folder_another_run_holds() {
    let dir = tempfile::tempdir().unwrap();
    let scene = tiny_board(dir.path(), 16, 12, 3);
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    let held = xylem::output::FolderLock::try_new(&out, xylem::output::LockMode::Shared).unwrap();
    let o = run(&[
        "sweep",
        scene.to_str().unwrap(),
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_clean_error(&o, "in use by another xylem run");
    drop(held);
    // Once released the folder is free. A child forked by another test thread of this binary
    // shares the lock's open file until it execs (flock locks belong to the open file), so a
    // busy answer within that moment is retried; a lock that stays held fails all three tries.
    let mut o = None;
    for _ in 0..3 {
        let r = run(&[
            "sweep",
            scene.to_str().unwrap(),
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ]);
        let busy = stderr(&r).contains("in use by another xylem run");
        o = Some(r);
        if !busy {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(300));
    }
    let o = o.unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
}

/// `xylem sweep SCENE --out OUT --frames-range 2..4 --arc -30..30`: a slice of another arc than
/// the scene's.
fn other_arc_slice(scene: &str, out: &str) -> Output {
    run(&[
        "sweep",
        scene,
        "--quiet",
        "--out",
        out,
        "--frames-range",
        "2..4",
        "--arc",
        "-30..30",
    ])
}

#[test]
fn assemble_refuses_slices_that_disagree_and_absurd_records() {
    let dir = tempfile::tempdir().unwrap();
    let scene = tiny_board(dir.path(), 16, 12, 4);
    let out = dir.path().join("out");
    let s = scene.to_str().unwrap();
    let o_ = out.to_str().unwrap();
    let slice = |range: &str, extra: &[&str]| {
        let o = run(&[
            &["sweep", s, "--quiet", "--out", o_, "--frames-range", range],
            extra,
        ]
        .concat());
        assert!(o.status.success(), "{}", stderr(&o));
        // A slice never assembles, even when it completes the folder.
        assert!(!out.join(VIEWER).exists());
    };
    slice("0..2", &[]);
    // A slice of other settings is refused before it renders: the folder's claim (issue 26) ...
    let o = run(&[
        "sweep",
        s,
        "--quiet",
        "--out",
        o_,
        "--frames-range",
        "2..4",
        "--spp",
        "2",
    ]);
    assert_clean_error(&o, "spp 1 there, 2 in this run");
    // ... and records of two settings (as a build without claims left them) are refused by
    // `--assemble`.
    slice("2..4", &[]);
    let p = out.join("frame_0003.json");
    let text = std::fs::read_to_string(&p).unwrap();
    std::fs::write(&p, text.replace("\"spp\": 1", "\"spp\": 2")).unwrap();
    let o = run(&["sweep", "--assemble", o_]);
    assert_clean_error(&o, "spp = ");
    std::fs::write(&p, &text).unwrap();
    // A slice of another arc is refused before it renders: the folder's manifest is of the
    // scene's arc (issue 26) ...
    let o = other_arc_slice(s, o_);
    assert_clean_error(&o, "manifest.json");
    // ... and where neither manifest nor claim says so, the records do; `--assemble` refuses
    // records of two arcs.
    std::fs::remove_file(out.join("manifest.json")).unwrap();
    std::fs::remove_file(out.join("sweep.json")).unwrap();
    let o = other_arc_slice(s, o_);
    assert_clean_error(
        &o,
        ".json: this folder holds a sweep of other settings (arc_deg",
    );
    std::fs::write(&p, text.replace("-60.0", "-30.0")).unwrap();
    let o = run(&["sweep", "--assemble", o_]);
    assert_clean_error(&o, "arc_deg");
    std::fs::write(&p, &text).unwrap();
    slice("2..4", &[]);
    let o = run(&["sweep", "--assemble", o_]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_nothing_looks_complete_that_is_not(&out);
    // A duplicated record under another frame's name.
    std::fs::copy(out.join("frame_0001.json"), out.join("frame_0002.json")).unwrap();
    let o = run(&["sweep", "--assemble", o_]);
    assert_clean_error(&o, "frame_0002.json");
    slice("2..3", &[]);
    // A record that claims 10¹² frames is refused at once, not allocated for.
    let p = out.join("frame_0003.json");
    let text = std::fs::read_to_string(&p).unwrap();
    std::fs::write(
        &p,
        text.replace("\"frames\": 4", "\"frames\": 1000000000000"),
    )
    .unwrap();
    let start = Instant::now();
    let o = run(&["sweep", "--assemble", o_]);
    assert_clean_error(&o, "1000000000000");
    assert!(start.elapsed() < Duration::from_secs(20));
    // --arc 1...2 is a syntax error, not 1 → 0.2.
    let o = run(&["sweep", s, "--quiet", "--out", o_, "--arc", "1...2"]);
    assert_clean_error(&o, "1...2");
}

#[test]
fn sweep_frame_exrs_are_byte_stable_run_to_run() {
    let dir = tempfile::tempdir().unwrap();
    // 200×136 is 4×3 RLE tiles of 64², so the parallel compressor has chunks to reorder.
    let scene = tiny_board(dir.path(), 200, 136, 3);
    let outs = ["a", "b"].map(|n| dir.path().join(n));
    for o in &outs {
        let r = run(&[
            "sweep",
            scene.to_str().unwrap(),
            "--quiet",
            "--out",
            o.to_str().unwrap(),
        ]);
        assert!(r.status.success(), "{}", stderr(&r));
    }
    for f in [
        "frame_0000.exr",
        "frame_0001.exr",
        "frame_0002.exr",
        "aov.exr",
    ] {
        let [a, b] = outs.clone().map(|o| std::fs::read(o.join(f)).unwrap());
        assert!(a == b, "{f} differs between two identical runs");
    }
}

/// The GNU parallel recipe of notes/cluster.md, run as written (from a folder where `scenes/`
/// and `target/release/xylem` are this checkout's), then assembled.
#[test]
fn the_farm_recipe_of_notes_cluster_md_works_as_written() {
    let notes = std::fs::read_to_string(repo().join("notes/cluster.md")).unwrap();
    let section = &notes[notes.find("## GNU parallel").unwrap()..];
    let block = &section[section.find("```bash\n").unwrap() + 8..];
    let script = &block[..block.find("```").unwrap()];
    assert!(script.contains("parallel") && script.contains("--assemble"));
    let dir = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink(repo().join("scenes"), dir.path().join("scenes")).unwrap();
    std::fs::create_dir_all(dir.path().join("target/release")).unwrap();
    std::os::unix::fs::symlink(
        env!("CARGO_BIN_EXE_xylem"),
        dir.path().join("target/release/xylem"),
    )
    .unwrap();
    let has_parallel = Command::new("parallel")
        .arg("--version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    let out = dir.path().join("out/sweep_board");
    if has_parallel {
        let o = Command::new("bash")
            .args(["-euo", "pipefail", "-c", script])
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert!(o.status.success(), "the recipe failed: {}", stderr(&o));
    } else {
        println!("notice: GNU parallel is not installed; running the recipe's 8 slices as concurrent processes instead");
        let kids: Vec<_> = (0..48)
            .step_by(6)
            .map(|a| {
                Command::new("target/release/xylem")
                    .args(["sweep", "scenes/sweep_board.toml", "--frames", "48"])
                    .args(["--out", "out/sweep_board", "--quiet"])
                    .args(["--frames-range", &format!("{a}..{}", a + 6)])
                    .current_dir(dir.path())
                    .stdout(Stdio::null())
                    .stderr(Stdio::piped())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for k in kids {
            let o = k.wait_with_output().unwrap();
            assert!(o.status.success(), "a slice failed: {}", stderr(&o));
        }
        let o = Command::new("target/release/xylem")
            .args(["sweep", "--assemble", "out/sweep_board"])
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
    }
    assert_eq!(read_records(&out).unwrap().len(), 48);
    assert!(out.join(VIEWER).exists() && out.join("aov.exr").exists());
    assert_nothing_looks_complete_that_is_not(&out);
}

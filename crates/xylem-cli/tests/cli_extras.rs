//! The command line as a user installs it (issue 30): shell completions that complete,
//! man pages that groff renders without warnings, `render --json`, `sweep --res` and the camera,
//! spp and light in every sweep frame's EXR header.

#[path = "common/capture.rs"]
mod common_capture;

use common_capture::xylem;
use std::path::Path;
use std::process::Command;

fn ok(o: &std::process::Output) -> String {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout.clone()).unwrap()
}

/// What bash's completion function offers for the words `line` (the last one being completed).
fn bash_complete(script: &Path, line: &[&str]) -> String {
    let words = line
        .iter()
        .map(|w| format!("'{w}'"))
        .collect::<Vec<_>>()
        .join(" ");
    let cmd = format!(
        "source '{}'; COMP_WORDS=({words}); COMP_CWORD={}; COMP_LINE='{}'; COMP_POINT=${{#COMP_LINE}}; _xylem xylem \"${{COMP_WORDS[COMP_CWORD]}}\" \"${{COMP_WORDS[COMP_CWORD-1]}}\"; printf '%s\\n' \"${{COMPREPLY[@]}}\"",
        script.display(),
        line.len() - 1,
        line.join(" ")
    );
    let o = Command::new("bash").arg("-c").arg(&cmd).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout).unwrap()
}

#[test]
fn bash_completion_completes_subcommands_and_options() {
    let tmp = tempfile::tempdir().unwrap();
    let script = tmp.path().join("xylem.bash");
    std::fs::write(&script, ok(&xylem(&["completions", "bash"], tmp.path()))).unwrap();
    let subs = bash_complete(&script, &["xylem", "sw"]);
    assert_eq!(subs.trim(), "sweep", "{subs}");
    let opts = bash_complete(&script, &["xylem", "sweep", "--r"]);
    assert!(opts.lines().any(|l| l == "--res"), "{opts}");
    let all = bash_complete(&script, &["xylem", ""]);
    for sub in [
        "render",
        "sweep",
        "validate",
        "bake",
        "fit",
        "completions",
        "man",
    ] {
        assert!(all.lines().any(|l| l == sub), "{sub} missing: {all}");
    }
    // Negative control: nothing is offered for a prefix no subcommand has.
    assert_eq!(bash_complete(&script, &["xylem", "zz"]).trim(), "");
    for shell in ["zsh", "fish", "elvish", "powershell"] {
        let text = ok(&xylem(&["completions", shell], tmp.path()));
        // fish names options without their dashes (`-l res`).
        assert!(
            text.contains("sweep") && (text.contains("--res") || text.contains("-l res")),
            "{shell}"
        );
    }
    let bad = xylem(&["completions", "tcsh"], tmp.path());
    let e = String::from_utf8_lossy(&bad.stderr);
    assert!(
        !bad.status.success() && e.contains("possible values: bash, elvish, fish, powershell, zsh"),
        "{e}"
    );
}

/// groff's warnings for a man page (empty when it is clean).
fn groff_warnings(page: &Path) -> String {
    let o = Command::new("groff")
        // -k: preconv, as man(1) runs it, for the UTF-8 in the help texts (≈, ×).
        .args(["-k", "-man", "-Tutf8", "-ww", "-z"])
        .arg(page)
        .output()
        .expect("groff (Debian: groff-base) renders the man pages");
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn man_pages_render_cleanly_for_every_subcommand() {
    let tmp = tempfile::tempdir().unwrap();
    let page = ok(&xylem(&["man"], tmp.path()));
    assert!(page.contains(".TH xylem 1"), "{page}");
    let o = ok(&xylem(&["man", "--out", "man1"], tmp.path()));
    assert!(o.contains("man pages into man1"), "{o}");
    for sub in [
        "xylem",
        "xylem-render",
        "xylem-sweep",
        "xylem-validate",
        "xylem-validate-bsdf",
        "xylem-man",
    ] {
        let p = tmp.path().join(format!("man1/{sub}.1"));
        let text =
            std::fs::read_to_string(&p).unwrap_or_else(|_| panic!("{} missing", p.display()));
        assert!(text.contains(".SH NAME"), "{sub}");
        assert_eq!(groff_warnings(&p), "", "{sub}");
    }
    let sweep = std::fs::read_to_string(tmp.path().join("man1/xylem-sweep.1")).unwrap();
    assert!(sweep.contains("\\-\\-res"), "{sweep}");
    // Negative control: groff does warn about a page with a broken macro.
    let broken = tmp.path().join("broken.1");
    std::fs::write(&broken, page.replace(".SH NAME", ".SH NAME\n.XYZZY\n\\f")).unwrap();
    assert_ne!(groff_warnings(&broken), "");
}

#[test]
fn render_json_summary_matches_the_image() {
    let tmp = tempfile::tempdir().unwrap();
    let args = [
        "render",
        "sweep_board",
        "--res",
        "40x30",
        "--spp",
        "2",
        "--seed",
        "9",
        "--quiet",
    ];
    let o = xylem(
        &[&args[..], &["--out", "o", "--json", "o/summary.json"]].concat(),
        tmp.path(),
    );
    let said = ok(&o);
    assert!(said.contains("wrote o/summary.json"), "{said}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(tmp.path().join("o/summary.json")).unwrap())
            .unwrap();
    assert_eq!(v["scene"], "sweep_board");
    assert_eq!(
        (v["width"].as_u64(), v["height"].as_u64()),
        (Some(40), Some(30))
    );
    assert_eq!((v["spp"].as_u64(), v["seed"].as_u64()), (Some(2), Some(9)));
    assert!(v["camera"].as_str().unwrap().contains("40x30 px"));
    assert!(v["seconds"].as_f64().unwrap() > 0.0 && v["rays"].as_u64().unwrap() > 0);
    assert_eq!(v["outputs"][0], "o/sweep_board.exr");
    // The mean is the EXR's mean, channel by channel.
    let ch = xylem::picture::exr::read_exr_channels(&tmp.path().join("o/sweep_board.exr")).unwrap();
    for (k, c) in ["R", "G", "B"].iter().enumerate() {
        let data = &ch.iter().find(|(n, _)| n == c).unwrap().1;
        let mean = data.iter().map(|&x| x as f64).sum::<f64>() / data.len() as f64;
        let got = v["mean_rgb"][k].as_f64().unwrap();
        assert!(
            (got - mean).abs() <= 1e-6 * mean.max(1e-3),
            "{c}: {got} vs {mean}"
        );
    }
    // `--json -`: stdout is the JSON alone; without it stdout is text (the control).
    let piped = ok(&xylem(
        &[&args[..], &["--out", "p", "--json", "-"]].concat(),
        tmp.path(),
    ));
    let p: serde_json::Value = serde_json::from_str(&piped).expect("stdout is one JSON document");
    assert_eq!(p["mean_rgb"], v["mean_rgb"]);
    let text = ok(&xylem(&[&args[..], &["--out", "t"]].concat(), tmp.path()));
    assert!(
        serde_json::from_str::<serde_json::Value>(&text).is_err(),
        "{text}"
    );
}

#[test]
fn sweep_res_and_frame_headers() {
    let tmp = tempfile::tempdir().unwrap();
    let o = xylem(
        &[
            "sweep",
            "sweep_board",
            "--res",
            "32x24",
            "--frames",
            "2",
            "--spp",
            "1",
            "--quiet",
            "--out",
            "sw",
        ],
        tmp.path(),
    );
    ok(&o);
    let dir = tmp.path().join("sw");
    let png = xylem::picture::png::read_png_rgb8(&dir.join("frame_0000.png")).unwrap();
    assert_eq!((png.width, png.height), (32, 24));
    let header = |f: &str| {
        let h = xylem::picture::exr::read_exr_text(&dir.join(f)).unwrap();
        h.into_iter()
            .find(|(k, _)| k == "sweep_frame")
            .expect("sweep_frame attribute")
            .1
    };
    let (h0, h1) = (header("frame_0000.exr"), header("frame_0001.exr"));
    for needle in [
        "frame 0 of 2",
        "light at -60 deg",
        "moving light key (sphere)",
        "1 spp",
        "seed 1",
        "integrator direct",
        "camera eye (0, -250, 190)",
        "32x24 px",
        "position (",
    ] {
        assert!(h0.contains(needle), "{needle} not in {h0}");
    }
    assert!(
        h1.contains("frame 1 of 2") && h1.contains("light at 60 deg"),
        "{h1}"
    );
    // The light's position differs between the frames; the rest of the header does not.
    let pos = |h: &str| {
        h.split("position ")
            .nth(1)
            .unwrap()
            .split(" mm")
            .next()
            .unwrap()
            .to_string()
    };
    assert_ne!(pos(&h0), pos(&h1));
    assert_eq!(
        h0.split("; ").skip(1).collect::<Vec<_>>(),
        h1.split("; ").skip(1).collect::<Vec<_>>()
    );
    // Bad sizes are refused with the range.
    let bad = xylem(
        &["sweep", "sweep_board", "--res", "0x24", "--out", "x"],
        tmp.path(),
    );
    let e = String::from_utf8_lossy(&bad.stderr);
    assert!(
        !bad.status.success() && e.contains("out of range (allowed 1 to 16384)"),
        "{e}"
    );
}

#[test]
fn unwritable_output_folders_are_named_not_measured() {
    let tmp = tempfile::tempdir().unwrap();
    let small = ["--res", "8x6", "--spp", "1", "--quiet"];
    // /proc is a read-only file system even for root: before, "needs about … but 0.0 MiB is
    // available".
    for cmd in [
        &["render", "sweep_board"][..],
        &["sweep", "sweep_board", "--frames", "2"][..],
    ] {
        let o = xylem(
            &[cmd, &small[..], &["--out", "/proc/xylem-out"]].concat(),
            tmp.path(),
        );
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{e}");
        assert!(
            e.contains("cannot write into the output folder /proc/xylem-out"),
            "{e}"
        );
        assert!(
            e.contains("tried /proc, where it would be made") && e.contains("--out"),
            "{e}"
        );
        assert!(!e.contains("MiB"), "{e}");
    }
    // A file where the folder should be.
    std::fs::write(tmp.path().join("afile"), "x").unwrap();
    let o = xylem(
        &[
            &["render", "sweep_board"][..],
            &small[..],
            &["--out", "afile"],
        ]
        .concat(),
        tmp.path(),
    );
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("cannot write into the output folder afile") && e.contains("is not a folder"),
        "{e}"
    );
    // The control: a writable folder that does not exist yet is made and written, and the
    // probe leaves nothing behind.
    let o = xylem(
        &[
            &["render", "sweep_board"][..],
            &small[..],
            &["--out", "new/dir"],
        ]
        .concat(),
        tmp.path(),
    );
    ok(&o);
    let left: Vec<_> = std::fs::read_dir(tmp.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert!(
        left.iter()
            .all(|n| !n.to_string_lossy().contains("write-probe")),
        "{left:?}"
    );
    assert!(tmp.path().join("new/dir/sweep_board.png").exists());
}

/// `bench render --scene` other than the Cornell box is refused while Mitsuba is timed (its side
/// renders only the Cornell box, so the two figures would be of different images), and runs with
/// `--no-mitsuba` (issue 29's bug).
#[test]
fn bench_render_compares_only_like_scenes() {
    let tmp = tempfile::tempdir().unwrap();
    let bench = |extra: &[&str]| {
        let args = [
            "bench",
            "render",
            "--scene",
            "grazing_oak",
            "--spp",
            "1",
            "--repeats",
            "1",
        ];
        xylem(&[&args[..], extra].concat(), tmp.path())
    };
    let o = bench(&[]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{e}");
    assert!(
        e.contains("--scene grazing_oak") && e.contains("--no-mitsuba"),
        "{e}"
    );
    let o = bench(&["--no-mitsuba"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // A reference of no samples is refused before anything starts (it used to reach Python).
    let o = bench(&["--no-mitsuba", "--reference-spp", "0"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && e.contains("--reference-spp 0: allowed 1 to 1000000"),
        "{e}"
    );
}

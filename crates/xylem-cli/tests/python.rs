//! The Python package (python/) and its pytest suite, run by `cargo test --release`.
//!
//! 1. Computes reference numbers with the Rust library (BSDF eval / pdf / sample, wood texels,
//!    a wood surface shaded in world space, a render and a sweep of small scenes) into
//!    target/python-test/reference.json.
//! 2. Makes (or reuses) a virtual environment in target/python-venv with the pinned
//!    python/requirements-test.txt (numpy, pytest, mitsuba), stages the package (python/xylem
//!    and the extension module this `cargo test` built as the `_xylem` example, from the same
//!    python/src/lib.rs that `pip install ./python` builds) in target/python-test/site, and runs
//!    `pytest python/tests`, which checks that the bindings give the same numbers, runs Mitsuba
//!    3's chi-square test on the `xylem_wood` plugin and compares a Mitsuba render of a board
//!    with xylem's (notes/python.md).
//!
//! Python is `python3` or `$XYLEM_PYTHON`; Mitsuba's LLVM variant needs libLLVM (Debian's
//! libllvm19), found in the usual places or given as `$DRJIT_LIBLLVM_PATH`.

mod common;

use common::python::{libllvm, stage_package, venv};
use glam::{Vec2, Vec3};
use serde_json::{json, Value};
use std::path::PathBuf;
use std::process::Command;
use xylem::bsdf::{Bsdf, WoodBsdf, WoodBsdfParams};
use xylem::material::{Cutting, Material, MaterialHit, Placement, WoodMaterial};
use xylem::math::Pcg32;
use xylem::wood::{Needs, WoodVolume};

fn root() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

fn v3(v: Vec3) -> Value {
    json!([v.x, v.y, v.z])
}

fn rows(v: &[Vec3]) -> Value {
    Value::Array(v.iter().map(|&x| v3(x)).collect())
}

/// A unit direction in the upper hemisphere (`upper`) or on the whole sphere.
fn direction(rng: &mut Pcg32, upper: bool) -> Vec3 {
    let u = rng.next_vec2();
    let z = if upper {
        u.x.max(1e-3)
    } else {
        2.0 * u.x - 1.0
    };
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z).normalize()
}

fn bsdf_cases() -> Value {
    let base = WoodBsdfParams::default();
    let cases = [
        ("smooth_finish", base),
        (
            "rough_finish_rays",
            WoodBsdfParams {
                roughness: 0.3,
                ray_mask: 0.4,
                fiber_dir: Vec3::new(0.8, 0.0, 0.6),
                ray_dir: Vec3::new(0.0, 0.6, 0.8),
                ..base
            },
        ),
        (
            "unfinished",
            WoodBsdfParams {
                eta: 1.0,
                highlight_width: 0.2,
                fiber_dir: Vec3::new(0.0, 1.0, 0.0),
                ..base
            },
        ),
    ];
    let mut rng = Pcg32::new(2026, 16);
    let mut out = Vec::new();
    for (name, p) in cases {
        let b = WoodBsdf::new(p).expect("valid parameters");
        let n = 64;
        let wo: Vec<Vec3> = (0..n).map(|_| direction(&mut rng, true)).collect();
        let wi: Vec<Vec3> = (0..n).map(|i| direction(&mut rng, i % 5 != 0)).collect();
        let uc: Vec<f32> = (0..n).map(|_| rng.next_f32()).collect();
        let u: Vec<Vec2> = (0..n).map(|_| rng.next_vec2()).collect();
        let f: Vec<Vec3> = (0..n).map(|i| b.eval(wo[i], wi[i])).collect();
        let pdf: Vec<f32> = (0..n).map(|i| b.pdf(wo[i], wi[i])).collect();
        let s: Vec<_> = (0..n).map(|i| b.sample(wo[i], uc[i], u[i])).collect();
        out.push(json!({
            "name": name,
            "params": {
                "diffuse": v3(p.diffuse), "fiber_color": v3(p.fiber_color),
                "fiber_dir": v3(p.fiber_dir), "ray_dir": v3(p.ray_dir),
                "ray_mask": p.ray_mask, "highlight_width": p.highlight_width,
                "eta": p.eta, "roughness": p.roughness,
            },
            "wo": rows(&wo), "wi": rows(&wi),
            "uc": uc, "u": u.iter().map(|v| json!([v.x, v.y])).collect::<Vec<_>>(),
            "f": rows(&f), "pdf": pdf,
            "sample_wi": rows(&s.iter().map(|x| x.map_or(Vec3::ZERO, |x| x.wi)).collect::<Vec<_>>()),
            "sample_f": rows(&s.iter().map(|x| x.map_or(Vec3::ZERO, |x| x.f)).collect::<Vec<_>>()),
            "sample_pdf": s.iter().map(|x| x.map_or(0.0, |x| x.pdf)).collect::<Vec<_>>(),
            "sample_delta": s.iter().map(|x| x.is_some_and(|x| x.is_delta)).collect::<Vec<_>>(),
            "sample_valid": s.iter().map(|x| x.is_some()).collect::<Vec<_>>(),
        }));
    }
    Value::Array(out)
}

fn volume_case() -> Value {
    let v = WoodVolume::new(xylem::wood::preset("red_oak").unwrap(), 11).unwrap();
    let points = xylem::wood::sample_points(200, 5);
    let t: Vec<_> = points.iter().map(|&p| v.eval(p, Needs::ALL)).collect();
    json!({
        "preset": "red_oak", "seed": 11, "points": rows(&points),
        "diffuse": rows(&t.iter().map(|x| x.diffuse).collect::<Vec<_>>()),
        "fiber_color": rows(&t.iter().map(|x| x.fiber_color).collect::<Vec<_>>()),
        "fiber_dir": rows(&t.iter().map(|x| x.fiber_dir).collect::<Vec<_>>()),
        "ray_dir": rows(&t.iter().map(|x| x.ray_dir).collect::<Vec<_>>()),
        "bump_grad": rows(&t.iter().map(|x| x.bump_grad).collect::<Vec<_>>()),
        "ray_mask": t.iter().map(|x| x.ray_mask).collect::<Vec<_>>(),
        "pore_mask": t.iter().map(|x| x.pore_mask).collect::<Vec<_>>(),
        "bump": t.iter().map(|x| x.bump).collect::<Vec<_>>(),
        "highlight_width": t.iter().map(|x| x.highlight_width).collect::<Vec<_>>(),
        "growth_time": t.iter().map(|x| x.growth_time).collect::<Vec<_>>(),
    })
}

/// The board material of scenes/sweep_board.toml, shaded as the renderer shades a hit on a
/// world-space solid cutting.
fn surface_case() -> Value {
    let volume = WoodVolume::new(xylem::wood::preset("african_mahogany").unwrap(), 7).unwrap();
    let material = Material::Wood(Box::new(WoodMaterial {
        volume: std::sync::Arc::new(volume),
        finish: xylem::bsdf::Finish::new(1.5, 0.2),
        bump: 0.0,
        switches: Default::default(),
    }));
    let placement = Placement {
        origin: Vec3::new(0.0, 120.0, 0.0),
        axis: Vec3::X,
        rotation: 30f32.to_radians(),
        scale: 1.0,
        cutting: Cutting::Solid,
        world_space: true,
        tilt: Default::default(),
    };
    let mut rng = Pcg32::new(77, 1);
    let n = 64;
    let (mut p, mut nn, mut wo, mut wi, mut f, mut pdf) =
        (vec![], vec![], vec![], vec![], vec![], vec![]);
    for _ in 0..n {
        let pt = Vec3::new(
            rng.next_f32() * 200.0 - 100.0,
            rng.next_f32() * 80.0 - 40.0,
            rng.next_f32() * 10.0,
        );
        let normal = (Vec3::Z + 0.3 * direction(&mut rng, false)).normalize();
        let frame = xylem::math::Frame::from_normal(normal);
        let (o, i) = (
            frame.to_world(direction(&mut rng, true)),
            frame.to_world(direction(&mut rng, true)),
        );
        let hit = MaterialHit {
            p_object: pt,
            p_world: pt,
            n_object: normal,
            ng: normal,
            ns: normal,
            tangent: normal.any_orthonormal_vector(),
            object_to_world: glam::Mat3::IDENTITY,
            normal_to_world: glam::Mat3::IDENTITY,
            placement,
            footprint: 0.0,
        };
        let s = material.shade(&hit);
        let (lo, li) = (s.frame.to_local(o), s.frame.to_local(i));
        f.push(s.bsdf.eval(lo, li));
        pdf.push(s.bsdf.pdf(lo, li));
        p.push(pt);
        nn.push(normal);
        wo.push(o);
        wi.push(i);
    }
    json!({
        "preset": "african_mahogany", "seed": 7, "eta": 1.5, "roughness": 0.2,
        "origin": [0.0, 120.0, 0.0], "axis": [1.0, 0.0, 0.0], "rotation_deg": 30.0,
        "p": rows(&p), "n": rows(&nn), "wo": rows(&wo), "wi": rows(&wi),
        "f": rows(&f), "pdf": pdf,
    })
}

fn render_case() -> Value {
    let scene = root().join("scenes/sweep_board.toml");
    let mut loaded = xylem::scene::load(&scene).unwrap();
    loaded.settings.spp = 2;
    loaded.scene.camera = loaded.scene.camera.with_resolution(24, 18);
    let run = xylem::render::RunOptions::default();
    let img = xylem::render::render(&loaded.scene, &loaded.settings, &run)
        .unwrap()
        .image;
    let (path, moving) =
        xylem::sweep::SweepPath::from_scene(&loaded, Some(3), Some((-40.0, 40.0))).unwrap();
    let sweep =
        xylem::sweep::render_sweep(&loaded.scene, &loaded.settings, &path, moving, 0..3, &run)
            .unwrap();
    json!({
        "scene": scene.display().to_string(), "spp": 2, "res": [24, 18],
        "beauty": rows(&img.beauty), "std_error": img.std_error,
        "albedo": rows(&img.aov.iter().map(|a| a.albedo).collect::<Vec<_>>()),
        "sweep_frames": 3, "sweep_arc": [-40.0, 40.0],
        "sweep": sweep.frames.iter().map(|f| rows(&f.beauty)).collect::<Vec<_>>(),
        "sweep_light_deg": (0..3).map(|k| path.light_deg(k)).collect::<Vec<_>>(),
    })
}

#[test]
fn python_bindings_and_mitsuba_plugin() {
    let dir = root().join("target/python-test");
    std::fs::create_dir_all(&dir).unwrap();
    let reference = json!({
        "bsdf": bsdf_cases(),
        "volume": volume_case(),
        "surface": surface_case(),
        "render": render_case(),
    });
    let ref_path = dir.join("reference.json");
    std::fs::write(&ref_path, serde_json::to_string(&reference).unwrap()).unwrap();

    let venv = venv();
    let site = stage_package(&dir);
    let bin = venv.join("bin");
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut pytest = Command::new(venv.join("bin/python"));
    pytest
        .args([
            "-m",
            "pytest",
            "-q",
            "-p",
            "no:cacheprovider",
            "--durations=6",
            "python/tests",
        ])
        .env("XYLEM_REFERENCE", &ref_path)
        .env("PYTHONPATH", &site)
        .env("XYLEM_ROOT", root())
        .env("XYLEM_BIN", env!("CARGO_BIN_EXE_xylem"))
        .env("PATH", &path)
        .current_dir(root());
    match libllvm() {
        Some(p) => {
            pytest.env("DRJIT_LIBLLVM_PATH", p);
        }
        None => panic!(
            "Mitsuba's LLVM variant needs libLLVM: apt-get install libllvm19 (or set DRJIT_LIBLLVM_PATH)"
        ),
    }
    let started = std::time::Instant::now();
    let out = pytest.output().expect("running pytest");
    println!("{}", String::from_utf8_lossy(&out.stdout));
    eprintln!("{}", String::from_utf8_lossy(&out.stderr));
    eprintln!("pytest ran {:.1} s", started.elapsed().as_secs_f64());
    assert!(
        out.status.success(),
        "pytest python/tests failed (output above)"
    );
}

/// The ```python blocks of the README's "Python and Mitsuba 3" section.
fn readme_python_blocks() -> Vec<String> {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let start = readme.find("## Python and Mitsuba 3").unwrap();
    let section = &readme[start..];
    let end = section[3..].find("\n## ").map_or(section.len(), |e| e + 3);
    let section = &section[..end];
    section
        .split("```python\n")
        .skip(1)
        .map(|b| b.split("```").next().unwrap().to_string())
        .collect()
}

/// The README's Python snippets run as written, from an empty folder (issue 26: the first
/// stopped with `NameError: wo`). The Mitsuba one at 4 spp instead of 64, to keep the suite
/// short; nothing else is changed.
#[test]
fn readme_python_snippets_run() {
    let blocks = readme_python_blocks();
    assert_eq!(blocks.len(), 2, "{blocks:?}");
    assert!(blocks[1].contains("spp=64"), "{}", blocks[1]);
    let venv = venv();
    let site = stage_package(&root().join("target/python-test-readme"));
    let work = tempfile::tempdir().unwrap();
    let mut scripts = blocks.clone();
    scripts[0] +=
        "\nassert img.shape == (96, 128, 3) and frames.shape[0] == 4, (img.shape, frames.shape)\n";
    scripts[1] = scripts[1].replace("spp=64", "spp=4");
    scripts[1] += "\nimport numpy as np\nassert np.isfinite(np.array(image)).all()\n";
    for (k, script) in scripts.iter().enumerate() {
        let mut py = Command::new(venv.join("bin/python"));
        py.arg("-c")
            .arg(script)
            .env("PYTHONPATH", &site)
            .current_dir(work.path());
        if let Some(p) = libllvm() {
            py.env("DRJIT_LIBLLVM_PATH", p);
        }
        let out = py.output().unwrap();
        assert!(
            out.status.success(),
            "README Python block {k} failed:\n{script}\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// Ctrl-C stops a Python render or sweep within moments and raises KeyboardInterrupt, after
/// which numpy works (issue 26: the render ran on, and the first numpy call after it raised
/// PanicException). The SIGINT is real, sent by a timer thread 1 s into a render of minutes.
#[test]
fn ctrl_c_stops_a_python_render() {
    let venv = venv();
    let site = stage_package(&root().join("target/python-test-ctrl-c"));
    let work = tempfile::tempdir().unwrap();
    let script = r#"
import os, signal, threading, time
import numpy as np, xylem
# As an interactive Python has it: a shell starts background jobs with SIGINT ignored, and
# Python then leaves it ignored.
signal.signal(signal.SIGINT, signal.default_int_handler)
for name, call in [("render", lambda: xylem.render("sweep_board", spp=1024, res=(512, 512))),
                   ("sweep", lambda: xylem.sweep("sweep_board", frames=48, spp=256))]:
    threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
    start = time.time()
    try:
        call()
        raise SystemExit(f"{name}: not interrupted")
    except KeyboardInterrupt:
        took = time.time() - start
    assert took < 8, (name, took)
    assert np.arange(4).sum() == 6
    print(name, "stopped after", round(took, 2), "s")
"#;
    let mut child = Command::new(venv.join("bin/python"))
        .arg("-c")
        .arg(script)
        .env("PYTHONPATH", &site)
        .current_dir(work.path())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed().as_secs() > 60 {
            child.kill().unwrap();
            panic!("Ctrl-C did not stop the render within 60 s");
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let out = child.wait_with_output().unwrap();
    let said = String::from_utf8_lossy(&out.stdout);
    eprintln!("{said}");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(said.contains("render stopped") && said.contains("sweep stopped"));
}

/// The distribution as users get it: `maturin build` (pinned in python/requirements-test.txt,
/// reusing this `cargo test --release`'s compiled engine through the shared target folder)
/// makes the `xylem-wood` wheel — abi3, manylinux, stripped, carrying the sources, stubs and
/// `py.typed` — and the wheel installed alone into an empty folder imports, reports the
/// workspace's version and evaluates the BSDF as the Rust library does.
#[test]
fn wheel_builds_installs_and_imports() {
    let venv = venv();
    let dir = root().join("target/python-wheel");
    let _ = std::fs::remove_dir_all(&dir);
    let wheels = dir.join("wheels");
    common::python::run(
        Command::new(venv.join("bin/maturin"))
            .args(["build", "--quiet", "--profile", "release", "-m"])
            .arg(root().join("python/Cargo.toml"))
            .arg("--target-dir")
            .arg(root().join("target"))
            .arg("--out")
            .arg(&wheels),
        "maturin build",
        "maturin comes with python/requirements-test.txt",
    );
    let names: Vec<String> = std::fs::read_dir(&wheels)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    let version = env!("CARGO_PKG_VERSION");
    let expected = format!("xylem_wood-{version}-cp38-abi3-manylinux_2_34_x86_64.whl");
    assert_eq!(names, std::slice::from_ref(&expected), "the one wheel");
    let wheel = wheels.join(&expected);
    let site = dir.join("site");
    common::python::run(
        Command::new(venv.join("bin/python"))
            .args([
                "-m",
                "pip",
                "install",
                "--quiet",
                "--no-deps",
                "--disable-pip-version-check",
            ])
            .arg("--target")
            .arg(&site)
            .arg(&wheel),
        "pip install of the wheel",
        "",
    );
    for f in [
        "__init__.py",
        "mitsuba.py",
        "_xylem.pyi",
        "py.typed",
        "_xylem.abi3.so",
    ] {
        assert!(
            site.join("xylem").join(f).exists(),
            "the wheel lacks xylem/{f}"
        );
    }
    // Stripped: no debug sections, and small (the module with debug info was 57.7 MB).
    let so = site.join("xylem/_xylem.abi3.so");
    let size = std::fs::metadata(&so).unwrap().len();
    assert!(size < 20 << 20, "{} bytes", size);
    let bytes = std::fs::read(&so).unwrap();
    assert!(
        !bytes.windows(12).any(|w| w == b".debug_info\0"),
        "the module carries debug info"
    );
    let b = WoodBsdf::new(WoodBsdfParams::default()).unwrap();
    let (wo, wi) = (
        Vec3::new(0.3, 0.1, 0.9).normalize(),
        Vec3::new(-0.4, 0.2, 0.8).normalize(),
    );
    let f = b.eval(wo, wi);
    let script = format!(
        "import sys; sys.path.insert(0, {site:?})\n\
         import numpy as np, xylem\n\
         assert xylem.__file__.startswith({site:?}), xylem.__file__\n\
         assert xylem.__version__ == {version:?}, xylem.__version__\n\
         f = xylem.WoodBsdf().eval(np.array({wo:?}), np.array({wi:?}))\n\
         assert np.allclose(f, {f:?}, rtol=1e-6, atol=0), f\n",
        site = site.display().to_string(),
        wo = wo.to_array(),
        wi = wi.to_array(),
        f = f.to_array(),
    );
    common::python::run(
        Command::new(venv.join("bin/python")).args(["-c", &script]),
        "importing the installed wheel",
        "",
    );
}

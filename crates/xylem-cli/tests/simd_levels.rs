//! `XYLEM_SIMD` forces every SIMD level in a whole run of the binary, and every level gives the
//! scalar level's images bit for bit: a wood render (fibre BSDF, distortion and pore noise, the
//! wide-BVH traversal of a mesh), a path-traced box of every material, a flat wood slice (the
//! batched colour blocks) and an fBm slice (the gradient lane kernels). Every kernel promises the scalar values, so the expected image
//! is the scalar run's. A level this CPU lacks is clamped down with a warning, never run; an
//! unknown name is refused.

use std::path::Path;
use std::process::{Command, Output};
use xylem::simd::Simd;

fn xylem(level: &str, args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_xylem"))
        .args(args)
        .env("XYLEM_SIMD", level)
        .current_dir(dir)
        .output()
        .unwrap()
}

/// Every channel of every output of one run at `level`, as bits (EXR headers hold timings).
fn images(level: &str, dir: &Path) -> Vec<(String, Vec<u32>)> {
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/carved_bunny.toml"
    );
    // The path tracer's every material (Lambertian, wood, texture, mirror, glass) and its rect
    // light: the light sampling, shading and BSDF sampling the render tile inlines at each level.
    let box_scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/cornell_wood_marble.toml"
    );
    let runs: [&[&str]; 4] = [
        &[
            "render", scene, "--res", "24x16", "--spp", "1", "--quiet", "--out", "r",
        ],
        &[
            "render", box_scene, "--res", "24x24", "--spp", "4", "--quiet", "--out", "c",
        ],
        &[
            "texture",
            "--preset",
            "african_mahogany",
            "--flat",
            "--res",
            "40",
            "--out",
            "wood.exr",
        ],
        &["texture", "fbm", "--res", "40", "--out", "fbm.exr"],
    ];
    let mut out = Vec::new();
    for args in runs {
        let o = xylem(level, args, dir);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{level} {args:?}: {stderr}");
        let clamped = Simd::parse(level).unwrap() > Simd::detected();
        assert_eq!(
            stderr.contains(&format!("XYLEM_SIMD={level} needs CPU features")),
            clamped,
            "{level}: {stderr}"
        );
    }
    for file in [
        "r/carved_bunny.exr",
        "c/cornell_wood_marble.exr",
        "wood.exr",
        "fbm.exr",
    ] {
        for (name, values) in xylem::picture::exr::read_exr_channels(&dir.join(file)).unwrap() {
            out.push((
                format!("{file} {name}"),
                values.iter().map(|v| v.to_bits()).collect(),
            ));
        }
    }
    out
}

#[test]
fn every_level_gives_the_scalar_images() {
    let tmp = tempfile::tempdir().unwrap();
    let scalar = images("scalar", tmp.path());
    assert!(scalar.len() > 10, "{} channels", scalar.len());
    for level in Simd::ALL {
        if level == Simd::Scalar {
            continue;
        }
        let got = images(level.name(), tmp.path());
        assert_eq!(got.len(), scalar.len());
        for ((name, a), (_, b)) in got.iter().zip(&scalar) {
            let differ = a.iter().zip(b).filter(|(x, y)| x != y).count();
            assert_eq!(differ, 0, "{level:?}: {name}: {differ} values differ");
        }
    }
}

#[test]
fn an_unknown_level_is_refused_by_name() {
    let tmp = tempfile::tempdir().unwrap();
    let o = xylem("avx512f", &["texture", "fbm", "--res", "8"], tmp.path());
    assert!(!o.status.success());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("XYLEM_SIMD=\"avx512f\" is not one of scalar, sse2, avx2, avx512"),
        "{stderr}"
    );
}

/// The Cornell box with a mirror sphere (flat facets) and a smooth-shaded glass sphere
/// (vertex normals), written into `dir`.
fn spheres_scene(dir: &Path) -> std::path::PathBuf {
    let box_scene = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell_box.toml");
    let mut text = std::fs::read_to_string(box_scene).unwrap();
    text.push_str(
        r#"
[materials.mirror]
type = "mirror"
reflectance = [0.9, 0.9, 0.9]

[materials.glass]
type = "glass"
eta = 1.5

[[objects]]
shape = "sphere"
radius = 90.0
segments = 24
smooth = false
translate = [-130.0, 350.0, 90.0]
material = "mirror"

[[objects]]
shape = "sphere"
radius = 90.0
segments = 24
translate = [120.0, 180.0, 90.0]
material = "glass"
"#,
    );
    let path = dir.join("cornell_spheres.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// A scene's beauty and AOV channels as bits, and the schedule its run reports, from one run
/// of the binary at `level` with `XYLEM_WAVES` set to `waves` (`on` or `off`).
fn render_bits(
    scene: &Path,
    level: &str,
    waves: &str,
    extra: &[&str],
    dir: &Path,
) -> (Vec<u32>, String) {
    let out = format!("w_{level}_{waves}");
    let name = scene.file_stem().unwrap().to_str().unwrap();
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "--res",
        "40x40",
        "--quiet",
        "--out",
        &out,
        "--json",
        "-",
    ];
    args.extend_from_slice(extra);
    let o = Command::new(env!("CARGO_BIN_EXE_xylem"))
        .args(&args)
        .env("XYLEM_SIMD", level)
        .env("XYLEM_WAVES", waves)
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let exr = dir.join(&out).join(format!("{name}.exr"));
    let bits = xylem::picture::exr::read_exr_channels(&exr)
        .unwrap()
        .into_iter()
        .flat_map(|(_, v)| v.into_iter().map(f32::to_bits))
        .collect();
    (bits, json["schedule"].as_str().unwrap_or("").to_string())
}

/// Scenes of Lambertian, mirror and glass materials run their tiles as waves of paths in lanes
/// (render/wave.rs), and the waves give the per-path loop's image bit for bit at every SIMD
/// level this CPU has, for uniform and adaptive sampling (whose second pass continues each
/// pixel's samples): the Cornell box, and the box with a mirror and a glass sphere; and the
/// same bits on 1 and 3 threads. Control: the same comparison tells two seeds apart.
#[test]
fn waves_give_the_per_path_images_at_every_level() {
    let tmp = tempfile::tempdir().unwrap();
    let cornell_box = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/cornell_box.toml"
    ));
    let spheres = spheres_scene(tmp.path());
    let settings: [&[&str]; 2] = [&["--spp", "4", "--sampling", "uniform"], &["--spp", "16"]];
    for scene in [cornell_box, &spheres] {
        for level in Simd::ALL.into_iter().filter(|&l| l <= Simd::detected()) {
            for extra in settings {
                let (waves, schedule) = render_bits(scene, level.name(), "on", extra, tmp.path());
                let (paths, per_path) = render_bits(scene, level.name(), "off", extra, tmp.path());
                assert_eq!((schedule.as_str(), per_path.as_str()), ("waves", "paths"));
                assert_eq!(waves.len(), paths.len());
                let differ = waves.iter().zip(&paths).filter(|(a, b)| a != b).count();
                assert_eq!(differ, 0, "{scene:?} {level:?} {extra:?}: {differ} differ");
            }
        }
    }
    // Any thread count: the waves are per tile.
    let threads = |t| {
        let args = ["--spp", "16", "--threads", t];
        render_bits(&spheres, Simd::detected().name(), "on", &args, tmp.path()).0
    };
    assert!(threads("1") == threads("3"), "1 and 3 threads differ");
    let seed: &[&str] = &["--spp", "4", "--sampling", "uniform", "--seed", "2"];
    let (other, _) = render_bits(&spheres, "scalar", "on", seed, tmp.path());
    let (paths, _) = render_bits(&spheres, "scalar", "off", settings[0], tmp.path());
    let differ = other.iter().zip(&paths).filter(|(a, b)| a != b).count();
    assert!(
        differ > 1000,
        "another seed differs in {differ} values only"
    );
}

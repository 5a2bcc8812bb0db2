//! `xylem bake` writes a glTF 2.0 binary that the Khronos glTF validator (the npm package pinned
//! in tools/gltf-validator/) passes with 0 errors and 0 warnings, whose anisotropy map stretches
//! the highlight across the fibres (checked against the wood model's own fibre direction), and
//! whose data maps carry no colour-space chunk.

use glam::Vec3;
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// The validator's folder with its node_modules, installed from the lock file if missing.
fn validator() -> PathBuf {
    let dir = repo().join("tools/gltf-validator");
    if !dir.join("node_modules/gltf-validator").exists() {
        let npm = Command::new("npm")
            .args(["ci", "--no-audit", "--no-fund"])
            .current_dir(&dir)
            .status();
        match npm {
            Ok(s) if s.success() => {}
            Ok(s) => panic!(
                "`npm ci` in {} failed ({s}): the glTF validator is needed (see .ci/run)",
                dir.display()
            ),
            Err(e) => panic!(
                "npm not found ({e}): install Node.js and npm to run the Khronos glTF validator \
                 (`npm ci` in tools/gltf-validator; .ci/run does it)"
            ),
        }
    }
    dir
}

fn bake(preset: &str, cut: &str, out: &Path) -> PathBuf {
    let st = Command::new(env!("CARGO_BIN_EXE_xylem"))
        .args(["bake", preset, "--board", "200x80x20", "--cut", cut])
        .args(["--res", "96", "--seed", "3", "--out"])
        .arg(out)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    out.join(format!("{preset}.glb"))
}

/// Runs `xylem ARGS OUT` and returns its stderr, asserting success.
fn run_ok(args: &[&str], out: &Path) -> String {
    let st = Command::new(env!("CARGO_BIN_EXE_xylem"))
        .args(args)
        .arg(out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&st.stderr).to_string();
    assert!(st.status.success(), "{err}");
    err
}

/// An OBJ of two triangles (a 40 mm square), with `vt` when `uvs` is given (OBJ v up).
fn square_obj(path: &Path, uvs: Option<[[f32; 2]; 4]>) {
    let mut s = String::from("v 0 0 0\nv 40 0 0\nv 40 40 0\nv 0 40 0\n");
    match uvs {
        Some(t) => {
            for [u, v] in t {
                s += &format!("vt {u} {v}\n");
            }
            s += "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
        }
        None => s += "f 1 2 3\nf 1 3 4\n",
    }
    std::fs::write(path, s).unwrap();
}

/// A mesh without UVs is refused naming the file and what is missing; with UVs it bakes
/// (the control). Overlapping UVs (both triangles on one half of the texture) are baked with
/// a warning and counted in bake.json; a layout without overlap counts none.
#[test]
fn mesh_bakes_need_uvs_and_report_overlaps() {
    let tmp = tempfile::tempdir().unwrap();
    let obj = tmp.path().join("square.obj");
    square_obj(&obj, None);
    let st = Command::new(env!("CARGO_BIN_EXE_xylem"))
        .args(["bake", "walnut", "--res", "16", "--mesh"])
        .arg(&obj)
        .arg("--out")
        .arg(tmp.path().join("no_uv"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(!st.status.success());
    assert!(
        err.contains("square.obj") && err.contains("no texture coordinates"),
        "{err}"
    );
    let record = |dir: &Path| -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(dir.join("bake.json")).unwrap()).unwrap()
    };
    let bake_obj = |out: &Path| {
        let args = [
            "bake",
            "walnut",
            "--res",
            "16",
            "--mesh",
            obj.to_str().unwrap(),
            "--out",
        ];
        run_ok(&args, out)
    };
    square_obj(&obj, Some([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]));
    let ok = tmp.path().join("ok");
    let err = bake_obj(&ok);
    assert!(!err.contains("overlapping"), "{err}");
    assert_eq!(record(&ok)["texels_overlapping"], 0);
    assert_eq!(record(&ok)["texels_covered"], 256);
    // Both triangles folded onto the lower-right half: every texel there is covered twice.
    square_obj(&obj, Some([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [1.0, 0.0]]));
    let over = tmp.path().join("over");
    let err = bake_obj(&over);
    assert!(err.contains("overlapping"), "{err}");
    assert!(record(&over)["texels_overlapping"].as_u64().unwrap() > 50);
}

/// The GLB's JSON document and binary chunk (glTF 2.0 §4.4, read independently of the writer).
fn split_glb(bytes: &[u8]) -> (serde_json::Value, Vec<u8>) {
    let word = |i: usize| u32::from_le_bytes(bytes[i..i + 4].try_into().unwrap()) as usize;
    assert_eq!(&bytes[..4], b"glTF");
    assert_eq!((word(4), word(8)), (2, bytes.len()));
    let jlen = word(12);
    assert_eq!(&bytes[16..20], b"JSON");
    let json = serde_json::from_slice(&bytes[20..20 + jlen]).unwrap();
    let b = 20 + jlen;
    assert_eq!(&bytes[b + 4..b + 8], b"BIN\0");
    (json, bytes[b + 8..b + 8 + word(b)].to_vec())
}

/// An image of the document by name: (its PNG bytes, decoded RGB8, width).
fn image(doc: &serde_json::Value, bin: &[u8], name: &str) -> (Vec<u8>, Vec<u8>, usize) {
    let img = doc["images"]
        .as_array()
        .unwrap()
        .iter()
        .find(|i| i["name"] == name)
        .unwrap_or_else(|| panic!("no image {name}"));
    assert_eq!(img["mimeType"], "image/png");
    let view = &doc["bufferViews"][img["bufferView"].as_u64().unwrap() as usize];
    let off = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    let png = bin[off..off + view["byteLength"].as_u64().unwrap() as usize].to_vec();
    let mut r = png::Decoder::new(&png[..]).read_info().unwrap();
    let mut buf = vec![0; r.output_buffer_size()];
    let info = r.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    (png, buf, info.width as usize)
}

#[test]
fn baked_glb_passes_the_khronos_validator_with_no_errors_or_warnings() {
    let dir = validator();
    let tmp = tempfile::tempdir().unwrap();
    let mut files = Vec::new();
    for (preset, cut) in [("curly_maple", "radial"), ("red_oak", "tangential")] {
        files.push(bake(preset, cut, &tmp.path().join(preset)));
    }
    // A mesh bake: the teapot's 32 patch charts (u32-free, 16-bit indices) with its textures.
    let teapot = tmp.path().join("teapot");
    run_ok(
        &["bake", "walnut", "--mesh", "teapot", "--res", "64", "--out"],
        &teapot,
    );
    files.push(teapot.join("walnut.glb"));
    let out = Command::new("node")
        .arg(dir.join("validate.js"))
        .args(&files)
        .output()
        .expect("node not found: install Node.js to run the Khronos glTF validator");
    let stdout = String::from_utf8_lossy(&out.stdout);
    eprintln!("{stdout}{}", String::from_utf8_lossy(&out.stderr));
    let reports: Vec<serde_json::Value> = stdout
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(reports.len(), files.len(), "one report per file");
    for r in &reports {
        assert_eq!(r["validator"], "2.0.0-dev.3.10", "the pinned validator ran");
        assert_eq!(
            (r["errors"].as_u64(), r["warnings"].as_u64()),
            (Some(0), Some(0)),
            "{r}"
        );
        assert_eq!(r["extensionsUsed"][0], "KHR_materials_anisotropy");
    }
    assert!(out.status.success());
}

#[test]
fn anisotropy_runs_across_the_fibre_and_data_maps_are_untagged() {
    let tmp = tempfile::tempdir().unwrap();
    let glb = bake("curly_maple", "radial", tmp.path());
    let (doc, bin) = split_glb(&std::fs::read(glb).unwrap());
    let ext = &doc["materials"][0]["extensions"]["KHR_materials_anisotropy"];
    assert_eq!(ext["anisotropyStrength"], 1.0);
    let tex = ext["anisotropyTexture"]["index"].as_u64().unwrap() as usize;
    assert_eq!(
        doc["images"][doc["textures"][tex]["source"].as_u64().unwrap() as usize]["name"],
        "anisotropy"
    );
    // Every embedded image: untagged (glTF says how to read each; no sRGB, gAMA, cHRM, iCCP).
    for name in ["base_color", "normal", "metallic_roughness", "anisotropy"] {
        let (png, _, _) = image(&doc, &bin, name);
        let c = xylem::picture::png::png_chunk_types(&png);
        for tag in ["sRGB", "gAMA", "cHRM", "iCCP"] {
            assert!(!c.iter().any(|x| x == tag), "{name}: {c:?}");
        }
    }
    // The fibre direction from the wood model itself at texel centres, in the face's tangent
    // space (radial cut: right = tree z, up = −tree y; the board centre 150 mm out along +y).
    let volume =
        xylem::wood::WoodVolume::new(xylem::wood::preset("curly_maple").unwrap(), 3).unwrap();
    let (_, aniso, w) = image(&doc, &bin, "anisotropy");
    let (_, rough, _) = image(&doc, &bin, "metallic_roughness");
    let h = aniso.len() / 3 / w;
    let (mut across, mut n) = (0.0f64, 0);
    for y in (0..h).step_by(5) {
        for x in (0..w).step_by(7) {
            let (u, v) = ((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
            let p = Vec3::new(0.0, 150.0, 0.0)
                + Vec3::new(10.0, 0.0, 0.0)
                + Vec3::new(0.0, 0.0, 200.0 * (u - 0.5))
                + Vec3::new(0.0, 80.0 * (v - 0.5), 0.0);
            let f = volume.eval(p, xylem::wood::Needs::ALL).fiber_dir;
            let fiber = glam::Vec2::new(f.z, -f.y);
            if fiber.length() < 0.5 {
                continue;
            }
            let i = 3 * (y * w + x);
            let d = glam::Vec2::new(
                aniso[i] as f32 / 127.5 - 1.0,
                aniso[i + 1] as f32 / 127.5 - 1.0,
            );
            across += (d.normalize().dot(fiber.normalize()) as f64).abs();
            n += 1;
            // Roughness in green (β mapped, 0 < r < 1), metalness 0 in blue.
            assert!(rough[i + 1] > 0 && rough[i + 1] < 255 && rough[i + 2] == 0);
        }
    }
    assert!(n > 100, "{n} samples");
    // 8-bit quantisation leaves |cos| ≲ 0.01 for a direction ⟂ the fibre (it is 1 along it).
    assert!(
        across / (n as f64) < 0.02,
        "mean |cos(direction, fibre)| = {}",
        across / n as f64
    );
}

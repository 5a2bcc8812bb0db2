//! `xylem bake --materialx` writes an OpenPBR MaterialX document and a USD stage that the
//! MaterialX and OpenUSD Python packages (pinned in python/requirements-test.txt, installed into
//! target/python-venv) accept: tools/materialx-check/check.py validates the document against
//! the standard libraries, checks its textures, shader, anisotropy, coat IOR and GLSL
//! generation, and the stage's binding to the document. Negative controls: a document with a
//! wrong input type, a missing texture, a wrong coat IOR and a stage pointing elsewhere fail.

// `common::python::libllvm` serves the Mitsuba tests only.
#[allow(dead_code)]
mod common;

use common::python::venv;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// The board of these tests.
const BOARD: [&str; 4] = ["--board", "120x40x20", "--cut", "tangential"];

fn bake(preset: &str, shape: &[&str], out: &Path) {
    let st = Command::new(env!("CARGO_BIN_EXE_xylem"))
        .args(["bake", preset])
        .args(shape)
        .args(["--res", "24", "--seed", "3", "--materialx", "--out"])
        .arg(out)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
}

/// A change to a file's text (a negative control).
type Edit = Box<dyn Fn(&str) -> String>;

/// The checker's report and whether it passed.
fn check(dir: &Path, preset: &str, coat_ior: f32, prim: &str) -> (bool, Value) {
    let out = Command::new(venv().join("bin/python"))
        .arg(root().join("tools/materialx-check/check.py"))
        .arg(dir)
        .arg(preset)
        .args(["--coat-ior", &coat_ior.to_string(), "--prim", prim])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    eprintln!("{stdout}{}", String::from_utf8_lossy(&out.stderr));
    let report = serde_json::from_str(stdout.lines().last().unwrap_or("null"))
        .unwrap_or_else(|e| panic!("checker printed no report ({e}): {stdout}"));
    (out.status.success(), report)
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
}

/// A copy of the bake in `dir` with `edit` applied to `file`'s text.
fn broken(src: &Path, dir: &Path, file: &str, edit: impl Fn(&str) -> String) -> PathBuf {
    copy_dir(src, dir);
    let p = dir.join(file);
    let text = std::fs::read_to_string(&p).unwrap();
    let changed = edit(&text);
    assert_ne!(changed, text, "the negative control changed {file}");
    std::fs::write(p, changed).unwrap();
    dir.to_path_buf()
}

#[test]
fn baked_materialx_and_usd_pass_the_materialx_and_usd_checks() {
    let tmp = tempfile::tempdir().unwrap();
    let good = tmp.path().join("good");
    bake("curly_maple", &BOARD, &good);
    for f in [
        "curly_maple.mtlx",
        "curly_maple.usda",
        "openpbr_specular_roughness.png",
        "openpbr_specular_anisotropy.png",
        "bake.json",
    ] {
        assert!(good.join(f).is_file(), "{f}");
    }
    let record: Value =
        serde_json::from_slice(&std::fs::read(good.join("bake.json")).unwrap()).unwrap();
    let listed = record.to_string();
    for f in ["curly_maple.mtlx", "curly_maple.usda"] {
        assert!(listed.contains(f), "bake.json lists {f}: {listed}");
    }
    let coat = xylem::bake::materialx::COAT_IOR;
    let (ok, r) = check(&good, "curly_maple", coat, "/Board/top");
    assert!(ok, "{r}");
    assert_eq!(r["validate"], true);
    assert_eq!(r["shader"]["category"], "open_pbr_surface");
    assert_eq!(r["coat_ior"].as_f64().unwrap() as f32, coat);
    assert!(r["anisotropy_mean"].as_f64().unwrap() > 0.1, "{r}");
    assert!(r["glsl_pixel_chars"].as_u64().unwrap() > 1000, "{r}");
    assert_eq!(r["binding"], "/Board/Materials/wood");
    assert_eq!(r["images"].as_object().unwrap().len(), 5, "{r}");

    // Negative controls: each must fail, for its own reason.
    let controls: [(&str, &str, Edit, &str); 5] = [
        (
            "wrong_type",
            "curly_maple.mtlx",
            Box::new(|t| {
                t.replace(
                    r#"<input name="coat_ior" type="float" value="1.5" />"#,
                    r#"<input name="coat_ior" type="color3" value="1.5, 1.5, 1.5" />"#,
                )
            }),
            "coat_ior",
        ),
        (
            "missing_texture",
            "curly_maple.mtlx",
            Box::new(|t| t.replace("openpbr_specular_anisotropy.png", "no_such_map.png")),
            "no_such_map.png",
        ),
        (
            "dangling_node",
            "curly_maple.mtlx",
            Box::new(|t| t.replace(r#"nodename="across_fiber_texel""#, r#"nodename="nowhere""#)),
            "validate",
        ),
        (
            "wrong_coat_ior",
            "curly_maple.mtlx",
            Box::new(|t| {
                t.replace(
                    r#"name="coat_ior" type="float" value="1.5""#,
                    r#"name="coat_ior" type="float" value="1.3""#,
                )
            }),
            "coat_ior 1.29",
        ),
        (
            "stage_elsewhere",
            "curly_maple.usda",
            Box::new(|t| t.replace("@./curly_maple.mtlx@", "@./other.mtlx@")),
            "references",
        ),
    ];
    for (name, file, edit, reason) in controls {
        let dir = broken(&good, &tmp.path().join(name), file, edit);
        let (ok, r) = check(&dir, "curly_maple", coat, "/Board/top");
        assert!(!ok, "{name}: the checker passed a broken bake: {r}");
        let why = r["failures"].to_string();
        assert!(
            why.contains(reason),
            "{name}: failed for another reason: {why}"
        );
    }
}

/// A mesh bake with `--materialx`: the same document over the mesh's maps, and a stage whose
/// `/Object/mesh` (triangles, per-vertex normals and st) is bound to it; checked by the same
/// checker, which fails it when asked for the board's prim (the control).
#[test]
fn a_mesh_bake_carries_its_materialx_material_into_usd() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("teapot");
    bake("walnut", &["--mesh", "teapot"], &dir);
    let coat = xylem::bake::materialx::COAT_IOR;
    let (ok, r) = check(&dir, "walnut", coat, "/Object/mesh");
    assert!(ok, "{r}");
    assert_eq!(r["validate"], true);
    assert_eq!(r["binding"], "/Object/Materials/wood");
    let (ok, r) = check(&dir, "walnut", coat, "/Board/top");
    assert!(!ok, "the board's prim in a mesh stage: {r}");
}

//! Bad scenes and requests beyond the machine give one clean error naming the file, the field
//! and the allowed range, never a panic (issue 15; split from robustness.rs). Every run is tiny.

#[path = "common/cli.rs"]
mod cli;

use cli::{assert_clean_error, repo, run, stderr, tiny_board};
use std::time::{Duration, Instant};

#[test]
fn scenes_without_objects_or_with_far_objects_are_errors_not_panics() {
    let dir = tempfile::tempdir().unwrap();
    let board = std::fs::read_to_string(repo().join("scenes/sweep_board.toml")).unwrap();
    // Cut before the first object: camera, lights and materials but no [[objects]].
    let cut = &board[..board.find("[[objects]]").unwrap()];
    let p = dir.path().join("cut.toml");
    std::fs::write(&p, cut).unwrap();
    let out = dir.path().join("out");
    let o = run(&[
        "render",
        p.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_clean_error(&o, "objects");
    let far = board.replacen(
        "translate = [0.0, 0.0, 9.0]",
        "translate = [1e38, 0.0, 0.0]",
        1,
    );
    assert_ne!(far, board);
    let p = dir.path().join("far.toml");
    std::fs::write(&p, far).unwrap();
    let o = run(&[
        "render",
        p.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_clean_error(&o, "objects[1].translate");
    // A scene or mesh that is a device is refused before it is read.
    let o = run(&["render", "/dev/zero", "--out", out.to_str().unwrap()]);
    assert_clean_error(&o, "not a regular file");
    let mesh = board.replacen(
        "shape = \"box\"\nsize = [260.0, 110.0, 18.0]",
        "shape = \"mesh\"\nfile = \"/dev/zero.obj\"",
        1,
    );
    assert_ne!(mesh, board);
    std::os::unix::fs::symlink("/dev/zero", dir.path().join("zero.obj")).unwrap();
    let p = dir.path().join("mesh.toml");
    std::fs::write(&p, mesh.replace("/dev/zero.obj", "zero.obj")).unwrap();
    let o = run(&[
        "render",
        p.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_clean_error(&o, "not a regular file");
}

#[test]
fn resources_beyond_the_machine_are_refused_up_front() {
    let dir = tempfile::tempdir().unwrap();
    let scene = tiny_board(dir.path(), 16, 12, 4);
    let out = dir.path().join("out");
    let s = scene.to_str().unwrap();
    let o = run(&[
        "render",
        s,
        "--threads",
        "100000",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_clean_error(&o, "--threads 100000");
    // 100000 frames of 512×384: streamed in batches within --memory, but ≈ 348 GiB of frame
    // files on disk.
    let board = repo().join("scenes/sweep_board.toml");
    let start = Instant::now();
    let o = run(&[
        "sweep",
        board.to_str().unwrap(),
        "--frames",
        "100000",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_clean_error(&o, "--ignore-limits");
    assert!(start.elapsed() < Duration::from_secs(30), "refused late");
    // The documented maximum resolution: refused when the estimate exceeds the memory here.
    let need = xylem::render::resources::Resources::render(16384, 16384).memory;
    // 16384² pixels hold at least the beauty, the standard error and the AOVs (16 floats).
    assert!(need >= 16384 * 16384 * 16 * 4);
    if xylem::resources::available_memory().is_some_and(|m| m < need) {
        let o = run(&[
            "render",
            s,
            "--res",
            "16384x16384",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_clean_error(&o, "memory");
    }
}

#[test]
fn objects_sharing_a_mesh_file_keep_their_own_smooth_setting() {
    let dir = tempfile::tempdir().unwrap();
    // One triangle with vertex normals.
    let obj = "v 0 0 0\nv 10 0 0\nv 0 10 0\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nf 1//1 2//2 3//3\n";
    std::fs::write(dir.path().join("tri.obj"), obj).unwrap();
    let board = std::fs::read_to_string(repo().join("scenes/sweep_board.toml")).unwrap();
    let head = &board[..board.find("[[objects]]").unwrap()];
    let text = format!(
        "{head}[[objects]]\nshape = \"mesh\"\nfile = \"tri.obj\"\nmaterial = \"table\"\n\n\
         [[objects]]\nshape = \"mesh\"\nfile = \"tri.obj\"\nsmooth = false\nmaterial = \"table\"\n"
    );
    let loaded = xylem::scene::from_str(&text, "two.toml", dir.path(), "two").unwrap();
    let inst = &loaded.scene.accel.instances;
    assert!(
        inst[0].mesh.normals.is_some(),
        "smooth = true (default) keeps the file's normals"
    );
    assert!(
        inst[1].mesh.normals.is_none(),
        "smooth = false on the second object was ignored"
    );
}

#[test]
fn an_os_error_is_printed_once_and_the_output_folder_is_checked_first() {
    let dir = tempfile::tempdir().unwrap();
    let o = run(&["render", dir.path().join("missing.toml").to_str().unwrap()]);
    assert_clean_error(&o, "missing.toml");
    assert_eq!(stderr(&o).matches("os error").count(), 1, "{}", stderr(&o));
    // An output folder that cannot exist is reported before rendering, not after.
    let scene = tiny_board(dir.path(), 16, 12, 2);
    std::fs::write(dir.path().join("file"), "").unwrap();
    let bad_out = dir.path().join("file/out");
    let o = run(&[
        "render",
        scene.to_str().unwrap(),
        "--out",
        bad_out.to_str().unwrap(),
    ]);
    assert_clean_error(&o, "output folder");
    assert!(
        !String::from_utf8_lossy(&o.stdout).contains("rendered"),
        "rendered first"
    );
}

#[test]
fn a_far_eye_and_far_tree_origins_are_named_not_blamed_on_other_fields() {
    let board = std::fs::read_to_string(repo().join("scenes/sweep_board.toml")).unwrap();
    let load = |text: &str| {
        xylem::scene::from_str(text, "far.toml", repo(), "far")
            .err()
            .map(|e| e.to_string())
    };
    let eye = board.replace("eye = [0.0, -250.0, 190.0]", "eye = [0.0, -1e30, 190.0]");
    assert_ne!(eye, board);
    let e = load(&eye).expect("a far eye is an error");
    assert!(e.contains("camera.eye") && !e.contains("camera.up"), "{e}");
    let tree = board
        .lines()
        .find(|l| l.starts_with("tree = "))
        .expect("the board's tree line");
    let origin = board.replace(
        tree,
        "tree = { origin = [0.0, 1e12, 0.0], axis = [1.0, 0.0, 0.0] }",
    );
    assert_ne!(origin, board);
    let e = load(&origin).expect("a tree origin at 1e12 mm is an error");
    assert!(e.contains("objects[1].tree.origin"), "{e}");
    // A direction of huge components keeps its direction (it became a zero vector).
    let key = board.replace(
        "[sweep]\nframes = 48",
        "[[lights]]\ntype = \"distant\"\ndirection = [3e19, 0.0, -3e19]\nirradiance = 1.0\n\n[sweep]\nframes = 48",
    );
    assert_ne!(key, board);
    let loaded = xylem::scene::from_str(&key, "far.toml", repo(), "far").unwrap();
    let dir = loaded.scene.lights.iter().find_map(|l| match l {
        xylem::render::Light::Distant(xylem::render::DistantLight { direction, .. }) => {
            Some(*direction)
        }
        _ => None,
    });
    let want = xylem::math::Vec3::new(1.0, 0.0, -1.0).normalize();
    let got = dir.expect("the distant light");
    // (Stored towards the light or away from it: either way along ±(1, 0, −1)/√2, not zero.)
    assert!(got.dot(want).abs() > 1.0 - 1e-6, "{got} (want ±{want})");
}

/// Each case: a replacement in scenes/sweep_board.toml and the field its error must name.
/// (On the old code: a type error in a tagged table named only its `[[lights]]` / `[materials.X]`
/// header, a 4th number was dropped, an orthographic camera ignored `fov_deg`.)
#[test]
fn errors_name_the_field_inside_tables_and_arrays_have_exact_lengths() {
    let board = std::fs::read_to_string(repo().join("scenes/sweep_board.toml")).unwrap();
    let cases = [
        (
            "radiance = 4000.0",
            "radiance = \"bright\"",
            "lights[0].radiance",
            "expected f32",
        ),
        ("radiance = 4000.0", "", "lights[0].radiance", "required"),
        (
            "type = \"sphere\"",
            "type = \"spheer\"",
            "lights[0].type",
            "sphere",
        ),
        (
            "albedo = [0.03, 0.03, 0.035]",
            "albedo = \"dark\"",
            "materials.table.albedo",
            "sequence",
        ),
        (
            "eta = 1.5 ",
            "eta = \"glassy\" ",
            "materials.board.eta",
            "expected f32",
        ),
        (
            "target = [0.0, 0.0, 5.0]",
            "target = [0.0, 0.0, 5.0, 7.0]",
            "target = [",
            "3 numbers",
        ),
        (
            "center = [250.0, 0.0, 433.0]",
            "center = [250.0, 0.0, 433.0, 1.0]",
            "lights[0].center",
            "3 numbers",
        ),
        (
            "arc_deg = [-60.0, 60.0]",
            "arc_deg = [-60.0, 60.0, 0.0]",
            "arc_deg",
            "2 numbers",
        ),
        (
            "projection = \"perspective\"",
            "projection = \"orthographic\"\nwidth = 300.0",
            "camera.fov_deg",
            "perspective",
        ),
    ];
    for (from, to, field, what) in cases {
        let text = board.replacen(from, to, 1);
        assert_ne!(text, board, "{from}");
        let e = match xylem::scene::from_str(&text, "x.toml", repo(), "x") {
            Ok(_) => panic!("{to:?} was accepted"),
            Err(e) => e.to_string(),
        };
        assert!(
            e.contains("x.toml") && e.contains(field) && e.contains(what),
            "{to:?}: {e}"
        );
    }
}

#[test]
fn messages_print_user_facing_names_not_rust_enum_variants() {
    let dir = tempfile::tempdir().unwrap();
    let scene = tiny_board(dir.path(), 8, 6, 2);
    let text = std::fs::read_to_string(&scene).unwrap();
    std::fs::write(
        &scene,
        text.replace(
            "integrator = \"direct\"",
            "integrator = \"path\"\nmax_depth = 5",
        ),
    )
    .unwrap();
    let out = dir.path().join("out");
    let o = run(&[
        "render",
        scene.to_str().unwrap(),
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("path (max_depth 5)") && !e.contains("Path {"),
        "{e}"
    );
    let o = run(&[
        "texture",
        "marble",
        "--plane",
        "xz",
        "--res",
        "8",
        "--out",
        dir.path().join("t.png").to_str().unwrap(),
    ]);
    let s = String::from_utf8_lossy(&o.stdout).to_string() + &stderr(&o);
    assert!(o.status.success(), "{s}");
    assert!(s.contains("plane xz") && !s.contains("Xz"), "{s}");
}

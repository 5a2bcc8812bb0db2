//! Readers of a fit's maps verify its set record (issue 26): a `measured` material whose maps
//! sit beside `fit.json` must be the files it lists, and maps `xylem fit` wrote (their
//! `Software` text chunk) need that record, which the fit writes last. So a fit killed while
//! committing (maps, no record) or a map of another fit dropped in is refused, not rendered.

#[path = "common/capture.rs"]
mod common_capture;

use common_capture::{small_capture, xylem};
use std::path::Path;

#[test]
fn maps_of_an_incomplete_or_mixed_fit_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    small_capture(dir);
    // Another fit of the same size (a map of another size is refused before its record is
    // read, as the wrong size): from a capture of 4 frames an arc.
    let sweep = ["sweep", "fit_maple_sweep", "--frames", "4", "--spp", "1"];
    let o = xylem(&[&sweep[..], &["--quiet", "--out", "cap4"]].concat(), dir);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for (cap, out) in [("cap", "f"), ("cap4", "g")] {
        let o = xylem(&["fit", cap, "--out", out, "--quiet", "--texels", "8"], dir);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let repo = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
    let text = std::fs::read_to_string(repo.join("scenes/measured_maple_sweep.toml")).unwrap();
    std::fs::write(
        dir.join("board.toml"),
        text.replace("../data/marschner2005/maple/", "f/"),
    )
    .unwrap();
    let render = || {
        let args = [
            "render",
            "board.toml",
            "--res",
            "8x8",
            "--spp",
            "1",
            "--quiet",
            "--out",
            "o",
        ];
        xylem(&args, dir)
    };
    // The complete fit renders (negative control).
    let o = render();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Another fit's map in its place: refused, naming the map and the record.
    let ours = std::fs::read(dir.join("f/fiber_axis.png")).unwrap();
    std::fs::copy(dir.join("g/fiber_axis.png"), dir.join("f/fiber_axis.png")).unwrap();
    let o = render();
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains("f/fiber_axis.png") && e.contains("fit.json lists"),
        "{e}"
    );
    std::fs::write(dir.join("f/fiber_axis.png"), ours).unwrap();
    assert!(render().status.success());
    // A fit killed between its maps and its record: the maps alone.
    std::fs::remove_file(dir.join("f/fit.json")).unwrap();
    let o = render();
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains("f/diffuse.png") && e.contains("fit.json is missing"),
        "{e}"
    );
}

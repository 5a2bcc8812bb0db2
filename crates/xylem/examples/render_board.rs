//! Renders the README's board scene small and writes `board.exr` (beauty with alpha, AOV
//! layers, the settings in the header) and `board.png` into the current folder. The scene is
//! found on disk or, from any other folder, built into the binary.
//!
//! `cargo run --release --example render_board`

use std::path::Path;
use xylem::render::{image_io, render, RunOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let file = "scenes/sweep_board.toml";
    let mut loaded = xylem::scene::load(Path::new(file))?;
    loaded.scene.camera = loaded.scene.camera.with_resolution(128, 96);
    loaded.settings.spp = 4;
    let out = render(&loaded.scene, &loaded.settings, &RunOptions::default())?;
    let meta = loaded
        .settings
        .exr_meta(&loaded.name, file, &loaded.scene.camera);
    image_io::write_image_exr(Path::new("board.exr"), &out.image, &meta)?;
    xylem::picture::png::write_png_linear(
        Path::new("board.png"),
        out.image.width,
        out.image.height,
        &out.image.beauty,
        loaded.exposure,
    )?;
    println!(
        "rendered {} ({}x{}, {} spp) in {:.2} s: board.exr, board.png",
        loaded.name,
        out.image.width,
        out.image.height,
        loaded.settings.spp,
        out.elapsed.as_secs_f64()
    );
    Ok(())
}

//! Bakes a species preset over a quartersawn board's face and writes it as a glTF 2.0 binary
//! (`board.glb`: base colour, normal, roughness and KHR_materials_anisotropy maps).
//!
//! `cargo run --release --example bake_gltf`

use std::path::Path;
use xylem::bake::{bake, gltf::write_glb, BakeCut, BoardCut};
use xylem::wood::{preset, WoodVolume};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let volume = WoodVolume::new(preset("african_mahogany")?, 1)?;
    let board = BoardCut {
        size: [300.0, 120.0, 20.0],
        cut: BakeCut::Radial,
        radius: 150.0,
    };
    let maps = bake(&volume, &board, 256);
    let sides = board.bake_sides(&volume, 256).maps;
    write_glb(
        Path::new("board.glb"),
        &board,
        &maps,
        &sides,
        "african_mahogany",
    )?;
    println!("wrote board.glb ({}x{} texels)", maps.width, maps.height);
    Ok(())
}

//! The white-light check: under a uniform white environment a preset board's rendered
//! brightness must follow its diffuse albedo.

use super::*;
use crate::scene_template::{inline_table, SceneTemplate};

/// A board of `preset` under a uniform white environment (validation/scenes/
/// white_light_board.toml), cut as the gallery cuts it (`SawnCut::showcase_board`), at `spp`.
fn white_light_board_scene(preset: &str, spp: u32) -> String {
    let tree = SawnCut::showcase_board(xylem::wood::showcase_ring_angle_deg(preset)).tree_toml();
    SceneTemplate::named("white_light_board")
        .set("render.spp", spp as i64)
        .set("materials.board.preset", preset)
        .set("objects.0.tree", inline_table(&tree))
        .text()
}

/// How a preset's board renders under uniform white light, against its diffuse albedo.
#[derive(Clone, Debug, PartialEq)]
pub struct WhiteLightOrder {
    /// The preset's name.
    pub preset: String,
    /// Pearson correlation, over the board's pixels, of rendered luminance with the luminance of
    /// the preset's diffuse albedo (the albedo AOV).
    pub correlation: f64,
    /// Mean rendered luminance of the palest third of the pixels by albedo (earlywood in most
    /// species) and of the darkest third (latewood).
    pub pale_third: f64,
    /// Mean rendered luminance of the darkest third by albedo (latewood in most species).
    pub dark_third: f64,
}

impl WhiteLightOrder {
    /// The order of the albedo is kept: positive correlation and the pale third renders paler.
    pub fn keeps_order(&self) -> bool {
        self.correlation > 0.0 && self.pale_third > self.dark_third
    }
}

/// Renders `white_light_board_scene` for `preset` and compares radiance with albedo.
pub fn white_light_ring_order(preset: &str, spp: u32) -> Result<WhiteLightOrder, String> {
    let text = white_light_board_scene(preset, spp);
    let loaded = scene::from_str(&text, "<white-light board>", Path::new("."), "white")
        .map_err(|e| e.to_string())?;
    let out = render(&loaded.scene, &loaded.settings, &RunOptions::default())
        .map_err(|e| e.to_string())?;
    let img = out.image;
    let pairs: Vec<(f64, f64)> = img
        .aov
        .iter()
        .zip(&img.beauty)
        .map(|(a, b)| (luminance(a.albedo) as f64, luminance(*b) as f64))
        .collect();
    let mut by_albedo = pairs.clone();
    by_albedo.sort_by(|a, b| a.0.total_cmp(&b.0));
    let third = by_albedo.len() / 3;
    let mean = |s: &[(f64, f64)]| s.iter().map(|p| p.1).sum::<f64>() / s.len().max(1) as f64;
    Ok(WhiteLightOrder {
        preset: preset.to_string(),
        correlation: pearson(&pairs),
        dark_third: mean(&by_albedo[..third]),
        pale_third: mean(&by_albedo[by_albedo.len() - third..]),
    })
}

//! The white-light check: under a uniform white environment a preset board's rendered
//! brightness must follow its diffuse albedo.

use super::*;

/// A board of `preset` seen straight down through an orthographic camera (1 mm pixels over
/// 200 × 100 mm of its showcase face, as the gallery cuts it: `SawnCut::showcase_board`) under a
/// uniform white environment, smooth finish η 1.5.
fn white_light_board_scene(preset: &str, spp: u32) -> String {
    let tree = SawnCut::showcase_board(xylem::wood::showcase_ring_angle_deg(preset)).tree_toml();
    format!(
        r#"
[render]
width = 200
height = 100
spp = {spp}
integrator = "direct"
seed = 3
filter = "box"
[camera]
projection = "orthographic"
eye = [0.0, 0.0, 400.0]
target = [0.0, 0.0, 18.0]
up = [0.0, 1.0, 0.0]
width = 200.0
[[lights]]
type = "environment"
radiance = 1.0
[materials.board]
type = "wood"
preset = "{preset}"
seed = 7
eta = 1.5
roughness = 0.0
bump = 0.0
[[objects]]
name = "board"
shape = "box"
size = [260.0, 110.0, 18.0]
translate = [0.0, 0.0, 9.0]
material = "board"
tree = {tree}
"#
    )
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

//! What is compared: a preset or a measured board ([`Subject`]), sampled as maps or swept
//! under a moving light ([`SweepLuminance`]).

use super::*;
use crate::scene_template::{pair, vec3, SceneTemplate};

/// A board to compare: a preset (with its tree placement) or a measured board's maps.
#[derive(Clone, Debug)]
pub enum Subject {
    /// A preset by name: built in, or `dir/NAME.toml` when `dir` is given (for calibration).
    Preset {
        /// Preset name.
        name: String,
        /// Selects the tree.
        seed: u64,
        /// Folder of preset files to read instead of the built-in presets.
        dir: Option<PathBuf>,
        /// The board's cut: the angle (degrees) its face meets the rings at
        /// ([`SawnCut::showcase_board`]: 0 flat-sawn, 90 quartersawn).
        ring_angle_deg: f32,
    },
    /// A measured board's maps, from a folder of data/marschner2005/ (relative to the repository).
    Measured {
        /// The board's folder, e.g. `data/marschner2005/maple`.
        dir: String,
        /// Which image axis the grain runs along: true for columns (x), false for rows (y).
        grain_along_x: bool,
    },
}

/// Square board side (mm) of the comparisons: the measured boards at the 0.25 mm pitch
/// notes/measured.md assumes (390 px = 97.5 mm).
pub const BOARD_MM: f32 = 97.5;

impl Subject {
    fn grain_along_x(&self) -> bool {
        match self {
            Subject::Preset { .. } => true,
            Subject::Measured { grain_along_x, .. } => *grain_along_x,
        }
    }

    /// The scene material table and the board object's extra fields.
    fn material_toml(&self) -> (String, String) {
        match self {
            Subject::Preset {
                name,
                seed,
                dir,
                ring_angle_deg,
            } => (
                format!(
                    "type = \"wood\"\n{}\nseed = {seed}\neta = 1.5\nroughness = 0.0\nbump = 0.0\n",
                    match dir {
                        Some(d) => format!("preset_file = {:?}", d.join(format!("{name}.toml"))),
                        None => format!("preset = \"{name}\""),
                    }
                ),
                format!(
                    "tree = {}\n",
                    SawnCut::showcase_board(*ring_angle_deg).tree_toml()
                ),
            ),
            Subject::Measured { dir, .. } => (
                format!(
                    "type = \"measured\"\ndiffuse = \"{dir}/diffuse.png\"\nfiber_color = \"{dir}/fiber_color.png\"\nfiber_axis = \"{dir}/fiber_axis.png\"\nsize_mm = [{BOARD_MM}, {BOARD_MM}]\nface = \"+z\"\neta = 1.5\nroughness = 0.0\n"
                ),
                String::new(),
            ),
        }
    }

    /// The board's maps: the measured ones as read, a preset's sampled at the same texel count.
    pub fn maps(&self, base: &Path) -> Result<BoardMaps, String> {
        match self {
            Subject::Measured { dir, grain_along_x } => {
                let board = MeasuredBoard::load(&base.join(dir)).map_err(|e| e.to_string())?;
                Ok(BoardMaps {
                    board,
                    grain_along_x: *grain_along_x,
                })
            }
            Subject::Preset {
                name,
                seed,
                dir,
                ring_angle_deg,
            } => {
                let params = match dir {
                    Some(d) => {
                        let path = d.join(format!("{name}.toml"));
                        let text = std::fs::read_to_string(&path)
                            .map_err(|e| format!("{}: {e}", path.display()))?;
                        xylem::wood::WoodParams::from_toml_str(&text, &path.display().to_string())
                    }
                    None => xylem::wood::preset(name),
                }
                .map_err(|e| e.to_string())?;
                let volume = WoodVolume::new(params, *seed).map_err(|e| e.to_string())?;
                let placement =
                    Placement::sawn(Vec3::X, 1.0, &SawnCut::showcase_board(*ring_angle_deg))
                        .map_err(|e| e.to_string())?;
                let n = 390;
                Ok(BoardMaps::from_preset(
                    &volume,
                    &placement,
                    (n, n),
                    BOARD_MM / n as f32,
                    9.0,
                ))
            }
        }
    }

    /// A top-down orthographic sweep of the board (validation/scenes/appearance_sweep.toml): a
    /// distant light moving along the grain over `arc` degrees from the zenith in `frames`
    /// steps, `res`² pixels over the board.
    pub fn sweep_scene(&self, frames: usize, arc: f32, res: u32, spp: u32) -> String {
        let (material, tree) = self.material_toml();
        let table = |text: &str| -> toml::Table { toml::from_str(text).expect("a TOML table") };
        let axis = if self.grain_along_x() {
            Vec3::Y
        } else {
            Vec3::X
        };
        let mut t = SceneTemplate::named("appearance_sweep")
            .set("render.width", res as i64)
            .set("render.height", res as i64)
            .set("render.spp", spp as i64)
            .set("camera.width", BOARD_MM as f64)
            .set("materials.board", toml::Value::Table(table(&material)))
            .set("objects.0.size", vec3(Vec3::new(BOARD_MM, BOARD_MM, 18.0)))
            .set("sweep.frames", frames as i64)
            .set("sweep.arc_deg", pair(-arc, arc))
            .set("sweep.axis", vec3(axis));
        if let Some(tree) = table(&tree).get("tree") {
            t = t.set("objects.0.tree", tree.clone());
        }
        t.text()
    }

    /// Renders [`Subject::sweep_scene`]: per-pixel luminance of every frame.
    pub fn sweep(
        &self,
        base: &Path,
        frames: usize,
        res: u32,
        spp: u32,
    ) -> Result<SweepLuminance, String> {
        self.render_sweep(base, frames, res, spp, None)
    }

    /// One frame of [`Subject::sweep_scene`]'s light at each of `angles` (degrees).
    pub fn sweep_at(
        &self,
        base: &Path,
        angles: &[f32],
        res: u32,
        spp: u32,
    ) -> Result<SweepLuminance, String> {
        let mut out: Option<SweepLuminance> = None;
        for &a in angles {
            let s = self.render_sweep(base, 1, res, spp, Some((a, a)))?;
            match &mut out {
                Some(o) => {
                    o.angles.extend(s.angles);
                    o.frames.extend(s.frames);
                }
                None => out = Some(s),
            }
        }
        out.ok_or_else(|| "no light angle to render".into())
    }

    /// The sweep of [`Subject::sweep_scene`] in `frames` frames over its ±60° arc, or over `arc`.
    fn render_sweep(
        &self,
        base: &Path,
        frames: usize,
        res: u32,
        spp: u32,
        arc: Option<(f32, f32)>,
    ) -> Result<SweepLuminance, String> {
        let text = self.sweep_scene(frames, 60.0, res, spp);
        let loaded = scene::from_str(&text, "<appearance sweep>", base, "appearance")
            .map_err(|e| e.to_string())?;
        let (path, moving) =
            SweepPath::from_scene(&loaded, arc.map(|_| frames), arc).map_err(|e| e.to_string())?;
        let r = render_sweep(
            &loaded.scene,
            &loaded.settings,
            &path,
            moving,
            0..path.frames(),
            &RunOptions::default(),
        )
        .map_err(|e| e.to_string())?;
        Ok(SweepLuminance {
            width: r.width,
            height: r.height,
            angles: (0..r.frames.len()).map(|k| path.light_deg(k)).collect(),
            frames: r.frames.iter().map(|f| f.beauty.clone()).collect(),
        })
    }
}

/// The frames of a top-down sweep (linear RGB, row-major) and their light angles.
#[derive(Clone, Debug)]
pub struct SweepLuminance {
    /// Image width (pixels).
    pub width: u32,
    /// Image height (pixels).
    pub height: u32,
    /// Light angle of each frame (degrees from the zenith).
    pub angles: Vec<f32>,
    /// Each frame's pixels (linear RGB, row-major, top row first).
    pub frames: Vec<Vec<Vec3>>,
}

impl SweepLuminance {
    /// Per-pixel chatoyance: max / min luminance over the sweep, the strength of the highlight
    /// that moves with the light (a Lambertian board under the distant light of ±60° gives
    /// cos 0 / cos 60° = 2; NaN where a pixel is black in some frame).
    pub fn chatoyance(&self) -> Vec<f64> {
        let n = (self.width * self.height) as usize;
        (0..n)
            .map(|i| {
                let (lo, hi) = self.frames.iter().fold((f64::MAX, 0.0f64), |(lo, hi), f| {
                    let y = luminance(f[i]) as f64;
                    (lo.min(y), hi.max(y))
                });
                if lo > 0.0 {
                    hi / lo
                } else {
                    f64::NAN
                }
            })
            .collect()
    }
}

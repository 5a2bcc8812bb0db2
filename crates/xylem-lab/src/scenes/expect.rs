//! A scene's `[expect]` table: what its render must show, written as data in the scene file
//! (scenes/*.toml) rather than as code keyed by the scene's name. Each check names the objects
//! it looks at by the prefix of their names; its thresholds are this module's constants, derived
//! in notes/scenes.md.
//!
//! ```toml
//! [expect]
//! companion = "mirrored_lights"   # the second render some checks compare against
//!
//! [[expect.checks]]
//! check = "step"
//! what = "tails against pins"
//! a = ["tails"]
//! b = ["pins"]
//! face = [0.0, -1.0, 0.0]
//! ```

use super::*;
use serde::Deserialize;

/// The `[expect]` table of a scene file.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Expectations {
    /// The second render the checks need, if any.
    pub companion: Option<Companion>,
    /// The checks, in the order their measures are reported.
    #[serde(default)]
    pub checks: Vec<Check>,
}

/// The second render of a scene that a check compares its render with.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Companion {
    /// The lights mirrored through the plane x = 0 ([`mirrored_x`]): the other side along the
    /// fibre (a curl's chatoyance) or across it (a pore bump's relief).
    MirroredLights,
    /// The same lights without the environment (a background's colour on the wood).
    WithoutBackground,
}

impl Companion {
    /// The companion render's lights.
    pub fn lights(self, scene: &Scene) -> Vec<Light> {
        match self {
            Companion::MirroredLights => mirrored_x(&scene.lights),
            Companion::WithoutBackground => (scene.lights.iter())
                .filter(|l| !matches!(l, Light::Environment(_)))
                .cloned()
                .collect(),
        }
    }

    /// What the companion render is, as a file-name suffix (the gallery writes it beside the
    /// scene's image as `NAME_SUFFIX.png`).
    pub fn label(self) -> &'static str {
        match self {
            Companion::MirroredLights => "light_mirrored",
            Companion::WithoutBackground => "no_background",
        }
    }
}

/// One check of `[[expect.checks]]`, tagged by `check = "…"`. Objects are given by name prefix.
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "check", rename_all = "snake_case", deny_unknown_fields)]
pub enum Check {
    /// `objects` lit well enough to compare by eye: median sRGB ≥ [`LIT_SRGB`].
    Lit {
        /// The objects, in words.
        what: String,
        /// Object name prefixes.
        objects: Vec<String>,
    },
    /// A visible figure on `objects`: local contrast ≥ [`VISIBLE_FIGURE`].
    Figure {
        /// The figure, in words.
        what: String,
        /// Object name prefixes.
        objects: Vec<String>,
    },
    /// Readable growth rings on each of `objects` (a visible step, [`ring_contrast`]).
    Rings {
        /// Object name prefixes, one measure pair each.
        objects: Vec<String>,
    },
    /// A visible step between the objects `a` and `b`, on faces within 25° of `face` if given.
    Step {
        /// The step, in words.
        what: String,
        /// Object name prefixes of one side.
        a: Vec<String>,
        /// Object name prefixes of the other.
        b: Vec<String>,
        /// World direction the faces must face.
        face: Option<[f32; 3]>,
    },
    /// The (first) rect light seen directly is its radiance × colour within [`MAX_LIGHT_ERROR`].
    LightSeenDirectly {},
    /// Colour bleeding onto `objects` from a red left and a green right wall, each ≥
    /// [`MIN_BLEED_RATIO`].
    Bleeding {
        /// The white surfaces' name prefixes.
        objects: Vec<String>,
    },
    /// No firefly on diffuse or glossy surfaces: every pixel ≤ [`MAX_FIREFLY_RATIO`] × its 3×3
    /// median.
    Fireflies {},
    /// The light's colour on `objects` (blue over red, [`light_blue_over_red`]): with
    /// `black_background`, no cooler than the ceiling light; without, cooler than the companion
    /// render without the background.
    LightColour {
        /// Object name prefixes.
        objects: Vec<String>,
        /// Whether the scene's background is black.
        black_background: bool,
    },
    /// Curl bands on the upward faces of `objects` that flip with the light mirrored along the
    /// fibre (the companion render), Weber ≥ [`VISIBLE_WEBER`] and correlation ≤
    /// [`MAX_CURL_CORRELATION`].
    CurlFlip {
        /// Object name prefixes (the first object's curl sets the band length).
        objects: Vec<String>,
    },
    /// The veneered object's wood jumps across its edges ≥ [`MIN_SEAM_RATIO`] × the carved one's.
    SeamRatio {
        /// Name prefix of the object carved from one block.
        carved: String,
        /// Name prefix of the veneered object.
        veneered: String,
    },
    /// Relief under a raking light on `objects` ([`pore_relief`] against the companion render
    /// lit from the other side) ≥ [`MIN_PORE_RELIEF`].
    PoreRelief {
        /// The relief, in words.
        what: String,
        /// Object name prefixes.
        objects: Vec<String>,
    },
}

impl Expectations {
    /// The `[expect]` table of a loaded scene (none: no checks); an error names `file`, the
    /// table and what is wrong in it.
    pub fn of(table: Option<&toml::Table>, file: &str) -> Result<Expectations, String> {
        match table {
            None => Ok(Expectations::default()),
            Some(t) => toml::Value::Table(t.clone())
                .try_into()
                .map_err(|e| format!("{file}: [expect]: {e}")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Expectations, String> {
        let t: toml::Table = toml::from_str(text).unwrap();
        Expectations::of(t.get("expect").and_then(|v| v.as_table()), "s.toml")
    }

    #[test]
    fn checks_parse_in_order_with_their_companion() {
        let e = parse(
            "[expect]\ncompanion = \"mirrored_lights\"\n\
             [[expect.checks]]\ncheck = \"fireflies\"\n\
             [[expect.checks]]\ncheck = \"step\"\nwhat = \"x\"\na = [\"a\"]\nb = [\"b\"]\n",
        )
        .unwrap();
        assert_eq!(e.companion, Some(Companion::MirroredLights));
        assert!(matches!(e.checks[0], Check::Fireflies {}));
        assert!(matches!(&e.checks[1], Check::Step { face: None, .. }));
        assert!(parse("").unwrap().checks.is_empty());
    }

    /// A misspelt check, a missing field and an unknown field are errors that name the file,
    /// the table and the culprit.
    #[test]
    fn bad_expectations_name_file_table_and_culprit() {
        for (text, culprit) in [
            ("[[expect.checks]]\ncheck = \"firefly\"\n", "firefly"),
            (
                "[[expect.checks]]\ncheck = \"lit\"\nwhat = \"x\"\n",
                "objects",
            ),
            ("[[expect.checks]]\ncheck = \"fireflies\"\nmax = 3\n", "max"),
            ("[expect]\ncompanion = \"mirror\"\n", "mirror"),
        ] {
            let e = parse(text).unwrap_err();
            assert!(
                e.starts_with("s.toml: [expect]:") && e.contains(culprit),
                "{text}: {e}"
            );
        }
    }
}

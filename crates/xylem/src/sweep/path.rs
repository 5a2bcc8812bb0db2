//! The light path of a sweep: an arc of light directions over the object, the light angle of each
//! frame, and the slice of frames (`--frames-range`) one machine renders.
//!
//! The setup is that of Marschner et al. 2005 (§5, the gantry measurements) and Liu et al. 2016
//! (Fig. 13): the camera and the object stay fixed while the light travels along an arc in a plane
//! through the object's zenith.

use crate::math::Vec3;
use crate::render::{DistantLight, Light, LightFrames, PointLight, SphereLight, SpotLight};
use crate::scene::{LoadedScene, MAX_ARCS};
use std::ops::Range;

/// Errors in a light path or frame selection; each message names the value and the allowed range.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum PathError {
    /// An `--arc` value that is not `FROM..TO`.
    #[error("arc `{0}`: expected FROM..TO in degrees, e.g. `-60..60`")]
    ArcSyntax(String),
    /// An arc end outside [−90°, 90°] (below the horizon) or not finite.
    #[error("arc {from}..{to} deg: both ends must lie in [-90, 90] (above the horizon)")]
    ArcRange {
        /// First end (degrees).
        from: f32,
        /// Last end (degrees).
        to: f32,
    },
    /// A `--frames-range` value that is not `A..B` or `A..=B`.
    #[error("frames-range `{0}`: expected A..B (frames A to B-1) or A..=B, with whole numbers")]
    RangeSyntax(String),
    /// A `--frames-range` that selects no frame.
    #[error("frames-range `{text}`: selects no frame (needs A < B, or A <= B with ..=)")]
    RangeEmpty {
        /// The range as given.
        text: String,
    },
    /// A `--frames-range` that ends past the last frame.
    #[error("frames-range `{text}`: frame {end} is past the last frame of a {frames}-frame sweep (allowed 0..{frames})")]
    RangePastEnd {
        /// The range as given.
        text: String,
        /// The first frame past the range.
        end: usize,
        /// Frames of the sweep.
        frames: usize,
    },
    /// A frame count outside 1 to [`MAX_FRAMES`].
    #[error("frames = {0}: out of range (allowed 1 to {MAX_FRAMES})")]
    Frames(usize),
}

/// The most frames a sweep may have.
pub const MAX_FRAMES: usize = 100_000;

/// The light angles of a sweep: `frames` angles spread evenly from `from_deg` to `to_deg`
/// (inclusive), measured from the zenith towards the arc direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightArc {
    /// Light angle of the first frame (degrees from the zenith, −90–90).
    pub from_deg: f32,
    /// Light angle of the last frame (degrees from the zenith, −90–90).
    pub to_deg: f32,
    /// Frames along the arc (1 to [`MAX_FRAMES`]).
    pub frames: usize,
}

impl LightArc {
    /// Checks the frame count and that both ends lie above the horizon.
    pub fn new(from_deg: f32, to_deg: f32, frames: usize) -> Result<Self, PathError> {
        if frames == 0 || frames > MAX_FRAMES {
            return Err(PathError::Frames(frames));
        }
        let ok = |a: f32| a.is_finite() && (-90.0..=90.0).contains(&a);
        if !ok(from_deg) || !ok(to_deg) {
            return Err(PathError::ArcRange {
                from: from_deg,
                to: to_deg,
            });
        }
        Ok(LightArc {
            from_deg,
            to_deg,
            frames,
        })
    }

    /// The light angle of frame `i` in degrees; a single frame sits at the middle of the arc.
    pub fn angle_deg(&self, i: usize) -> f32 {
        if self.frames == 1 {
            return 0.5 * (self.from_deg + self.to_deg);
        }
        let t = i as f64 / (self.frames - 1) as f64;
        (self.from_deg as f64 + t * (self.to_deg as f64 - self.from_deg as f64)) as f32
    }

    /// The signed change of light angle from one frame to the next, in degrees.
    pub fn step_deg(&self) -> f32 {
        if self.frames < 2 {
            0.0
        } else {
            (self.to_deg - self.from_deg) / (self.frames - 1) as f32
        }
    }

    /// All light angles in degrees, frame by frame.
    #[cfg(test)]
    pub(crate) fn angles_deg(&self) -> Vec<f32> {
        (0..self.frames).map(|i| self.angle_deg(i)).collect()
    }
}

/// The plane an arc moves in: `zenith` is the direction at angle 0 (the object's up), `toward` the
/// direction at +90°. Both are unit vectors and orthogonal (the constructor makes them so).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArcPlane {
    /// Unit direction towards the light at angle 0.
    pub zenith: Vec3,
    /// Unit direction towards the light at +90°, perpendicular to `zenith`.
    pub toward: Vec3,
}

impl ArcPlane {
    /// The plane through `zenith` perpendicular to the rotation `axis`; `None` when the two are
    /// parallel (or either is zero), so no plane is defined.
    pub(crate) fn from_axis(zenith: Vec3, axis: Vec3) -> Option<Self> {
        let z = zenith.try_normalize()?;
        let toward = axis.cross(z).try_normalize()?;
        Some(ArcPlane { zenith: z, toward })
    }

    /// The unit direction towards the light at `angle_deg` from the zenith:
    /// `cos θ · zenith + sin θ · toward` (a rotation of the zenith about the arc's axis).
    pub fn direction(&self, angle_deg: f32) -> Vec3 {
        let (s, c) = angle_deg.to_radians().sin_cos();
        (c * self.zenith + s * self.toward).normalize()
    }

    /// The position of a light at distance `radius` from `pivot`, at `angle_deg` along the arc.
    pub fn position(&self, pivot: Vec3, radius: f32, angle_deg: f32) -> Vec3 {
        pivot + radius * self.direction(angle_deg)
    }
}

/// Parses `FROM..TO` (degrees; either may be negative, e.g. `-60..60`, and TO may be below FROM
/// to sweep the other way).
pub fn parse_arc(text: &str) -> Result<(f32, f32), PathError> {
    let err = || PathError::ArcSyntax(text.to_string());
    let (a, b) = text.trim().split_once("..").ok_or_else(err)?;
    // A number that starts or ends with its decimal point would let `1...2` read as 1..0.2.
    let number = |t: &str| -> Result<f32, PathError> {
        let t = t.trim();
        let digits = t.trim_start_matches(['+', '-']);
        if digits.starts_with('.') || digits.ends_with('.') {
            return Err(err());
        }
        t.parse().map_err(|_| err())
    };
    let (from, to) = (number(a)?, number(b)?);
    if !from.is_finite() || !to.is_finite() {
        return Err(err());
    }
    Ok((from, to))
}

/// Parses `A..B` (frames A to B-1, as Rust ranges) or `A..=B` (frames A to B) against a sweep of
/// `frames` frames. `A..` runs to the last frame.
pub(crate) fn parse_frames_range(text: &str, frames: usize) -> Result<Range<usize>, PathError> {
    let syntax = || PathError::RangeSyntax(text.to_string());
    let (a, rest) = text.trim().split_once("..").ok_or_else(syntax)?;
    let (inclusive, b) = match rest.strip_prefix('=') {
        Some(b) => (true, b),
        None => (false, rest),
    };
    let start: usize = a.trim().parse().map_err(|_| syntax())?;
    let end = if b.trim().is_empty() && !inclusive {
        frames
    } else {
        let b: usize = b.trim().parse().map_err(|_| syntax())?;
        if inclusive {
            b.checked_add(1).ok_or_else(syntax)?
        } else {
            b
        }
    };
    if start >= end {
        return Err(PathError::RangeEmpty {
            text: text.to_string(),
        });
    }
    if end > frames {
        return Err(PathError::RangePastEnd {
            text: text.to_string(),
            end: end - 1,
            frames,
        });
    }
    Ok(start..end)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angles_cover_the_arc_evenly() {
        let arc = LightArc::new(-60.0, 60.0, 49).unwrap();
        assert_eq!(arc.angle_deg(0), -60.0);
        assert_eq!(arc.angle_deg(48), 60.0);
        assert!((arc.angle_deg(24)).abs() < 1e-5);
        assert!((arc.step_deg() - 2.5).abs() < 1e-6);
        let a = arc.angles_deg();
        for w in a.windows(2) {
            assert!((w[1] - w[0] - 2.5).abs() < 1e-4);
        }
        assert_eq!(LightArc::new(10.0, 30.0, 1).unwrap().angle_deg(0), 20.0);
        assert_eq!(LightArc::new(30.0, -30.0, 3).unwrap().angle_deg(2), -30.0);
    }

    #[test]
    fn bad_arcs_are_refused() {
        assert!(matches!(
            LightArc::new(-95.0, 0.0, 4),
            Err(PathError::ArcRange { .. })
        ));
        assert_eq!(LightArc::new(0.0, 1.0, 0), Err(PathError::Frames(0)));
        assert!(LightArc::new(f32::NAN, 0.0, 4).is_err());
    }

    #[test]
    fn arc_directions_rotate_the_zenith_about_the_axis() {
        let plane = ArcPlane::from_axis(Vec3::Z, Vec3::Y).unwrap();
        // Rotating +z about +y by +90° gives +x (right-handed).
        assert!((plane.direction(90.0) - Vec3::X).length() < 1e-6);
        assert!((plane.direction(0.0) - Vec3::Z).length() < 1e-6);
        let d = plane.direction(30.0);
        assert!((d.z - 30f32.to_radians().cos()).abs() < 1e-6 && d.y.abs() < 1e-7);
        let p = plane.position(Vec3::new(1.0, 2.0, 3.0), 10.0, -90.0);
        assert!((p - Vec3::new(-9.0, 2.0, 3.0)).length() < 1e-5);
        assert!(ArcPlane::from_axis(Vec3::Z, Vec3::Z).is_none());
        assert!(ArcPlane::from_axis(Vec3::ZERO, Vec3::Y).is_none());
    }

    #[test]
    fn arcs_parse_with_negative_ends() {
        assert_eq!(parse_arc("-60..60"), Ok((-60.0, 60.0)));
        assert_eq!(parse_arc(" 45 .. -45.5 "), Ok((45.0, -45.5)));
        for bad in [
            "", "60", "a..b", "1..", "..3", "nan..2", "1..inf", "1...2", "1.5...2", "1....2",
        ] {
            assert!(
                matches!(parse_arc(bad), Err(PathError::ArcSyntax(_))),
                "{bad}"
            );
        }
    }

    #[test]
    fn frame_ranges_parse_and_name_their_errors() {
        assert_eq!(parse_frames_range("0..12", 48), Ok(0..12));
        assert_eq!(parse_frames_range("12..=23", 48), Ok(12..24));
        assert_eq!(parse_frames_range("40..", 48), Ok(40..48));
        assert_eq!(parse_frames_range("47..=47", 48), Ok(47..48));
        assert!(matches!(
            parse_frames_range("5..5", 48),
            Err(PathError::RangeEmpty { .. })
        ));
        assert!(matches!(
            parse_frames_range("9..3", 48),
            Err(PathError::RangeEmpty { .. })
        ));
        let e = parse_frames_range("40..=48", 48).unwrap_err();
        assert!(matches!(e, PathError::RangePastEnd { end: 48, .. }));
        assert!(e.to_string().contains("allowed 0..48"), "{e}");
        for bad in ["", "3", "-1..4", "a..4", "1..b", "1..=", "1.5..3"] {
            assert!(
                matches!(parse_frames_range(bad, 48), Err(PathError::RangeSyntax(_))),
                "{bad}"
            );
        }
    }
}

/// Where the moving light goes: the arc's angles, its plane, and for lights with a position the
/// pivot and distance. The light runs the arc once per azimuth (`azimuths[..arcs]`, degrees
/// about the zenith from `plane`): frame k is angle `k % arc.frames` of arc `k / arc.frames`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SweepPath {
    /// The light angles of one arc.
    pub arc: LightArc,
    /// The plane of the arc at azimuth 0.
    pub plane: ArcPlane,
    /// Centre of the arc (world, mm).
    pub pivot: Vec3,
    /// Distance of a positioned light from the pivot (mm, > 0).
    pub radius: f32,
    /// Azimuth of each arc about the zenith (degrees); the first `arcs` are used.
    pub azimuths: [f32; MAX_ARCS],
    /// Arcs the light runs (1 to [`MAX_ARCS`]).
    pub arcs: usize,
}

/// Why a scene's sweep cannot be set up; each names the scene and the `[sweep]` field.
#[derive(Debug, thiserror::Error)]
pub enum SetupError {
    #[error(
        "scene `{scene}` has no [sweep] table (it needs at least `light`, `arc_deg` and `radius`)"
    )]
    /// The scene has no `[sweep]` table.
    NoTable {
        /// The scene's name.
        scene: String,
    },
    #[error(
        "scene `{scene}`: [sweep] light = \"{light}\" names no light; lights with names: {names}"
    )]
    /// The `[sweep] light` names no light of the scene.
    NoLight {
        /// The scene's name.
        scene: String,
        /// The name given.
        light: String,
        /// The names the scene's lights have, for the message.
        names: String,
    },
    /// The named light is an area or environment light, which a sweep cannot move.
    #[error("scene `{scene}`: [sweep] light = \"{light}\" is an area or environment light; a sweep moves a point, spot, sphere or distant light")]
    Immovable {
        /// The scene's name.
        scene: String,
        /// The light's name.
        light: String,
    },
    /// A `[sweep]` field out of range.
    #[error("scene `{scene}`: [sweep] {field}: {message}")]
    Field {
        /// The scene's name.
        scene: String,
        /// The field.
        field: &'static str,
        /// What is wrong and what is allowed.
        message: String,
    },
    /// The arc or frame count of the table (or its overrides) is invalid.
    #[error("scene `{scene}`: {source}")]
    Path {
        /// The scene's name.
        scene: String,
        /// What is wrong with the arc or frame count.
        source: PathError,
    },
}

impl SweepPath {
    /// The sweep of a loaded scene's `[sweep]` table, with `frames` and `arc` (degrees) overriding
    /// the table's; returns the path and the index of the light that moves.
    pub fn from_scene(
        loaded: &LoadedScene,
        frames: Option<usize>,
        arc: Option<(f32, f32)>,
    ) -> Result<(SweepPath, usize), SetupError> {
        let scene = loaded.name.clone();
        let t = loaded.sweep.as_ref().ok_or_else(|| SetupError::NoTable {
            scene: scene.clone(),
        })?;
        let moving = loaded
            .light_names
            .iter()
            .position(|n| n.as_deref() == Some(t.light.as_str()))
            .ok_or_else(|| SetupError::NoLight {
                scene: scene.clone(),
                light: t.light.clone(),
                names: loaded
                    .light_names
                    .iter()
                    .flatten()
                    .map(|n| format!("\"{n}\""))
                    .collect::<Vec<_>>()
                    .join(", "),
            })?;
        let movable = match &loaded.scene.lights[moving] {
            Light::Point(_) | Light::Spot(_) | Light::Sphere(_) | Light::Distant(_) => true,
            Light::Rect(_) | Light::Environment(_) => false,
        };
        if !movable {
            return Err(SetupError::Immovable {
                scene,
                light: t.light.clone(),
            });
        }
        let field = |field, message: &str| SetupError::Field {
            scene: scene.clone(),
            field,
            message: message.to_string(),
        };
        let radius = t.radius;
        if !(radius.is_finite() && radius > 0.0) {
            return Err(field(
                "radius",
                &format!("{radius} must be a positive distance (mm)"),
            ));
        }
        let pivot = Vec3::from_array(t.pivot);
        if !pivot.is_finite() {
            return Err(field("pivot", "every component must be finite"));
        }
        let plane = ArcPlane::from_axis(Vec3::Z, Vec3::from_array(t.axis)).ok_or_else(|| {
            field(
                "axis",
                "must be a non-zero direction not parallel to +z (the zenith)",
            )
        })?;
        let (from, to) = arc.unwrap_or((t.arc_deg[0], t.arc_deg[1]));
        let arc =
            LightArc::new(from, to, frames.unwrap_or(t.frames as usize)).map_err(|source| {
                SetupError::Path {
                    scene: scene.clone(),
                    source,
                }
            })?;
        let arcs = t.azimuths_deg.len();
        if arcs == 0 || arcs > MAX_ARCS {
            return Err(field(
                "azimuths_deg",
                &format!("{arcs} azimuths (allowed 1 to {MAX_ARCS})"),
            ));
        }
        if arc.frames * arcs > MAX_FRAMES {
            return Err(SetupError::Path {
                scene,
                source: PathError::Frames(arc.frames * arcs),
            });
        }
        let path = SweepPath::with_arcs(arc, plane, pivot, radius, &t.azimuths_deg);
        Ok((path, moving))
    }

    /// A path of one arc per entry of `azimuths_deg` (at most [`MAX_ARCS`]; extra ones are
    /// dropped).
    pub(crate) fn with_arcs(
        arc: LightArc,
        plane: ArcPlane,
        pivot: Vec3,
        radius: f32,
        azimuths_deg: &[f32],
    ) -> SweepPath {
        let given = azimuths_deg.len().min(MAX_ARCS);
        let mut azimuths = [0.0; MAX_ARCS];
        azimuths[..given].copy_from_slice(&azimuths_deg[..given]);
        let arcs = given.max(1);
        SweepPath {
            arc,
            plane,
            pivot,
            radius,
            azimuths,
            arcs,
        }
    }

    /// Frames of the whole sweep: every arc's.
    pub fn frames(&self) -> usize {
        self.arc.frames * self.arcs
    }

    /// The light angle (degrees from the zenith along its arc) of frame `frame`.
    pub fn light_deg(&self, frame: usize) -> f32 {
        self.arc.angle_deg(frame % self.arc.frames)
    }

    /// The azimuth (degrees about the zenith) of the arc frame `frame` lies on.
    pub fn azimuth_deg(&self, frame: usize) -> f32 {
        self.azimuths[(frame / self.arc.frames).min(self.arcs - 1)]
    }

    /// The plane of the arc frame `frame` lies on: `plane` turned about its zenith by the arc's
    /// azimuth (Rodrigues' rotation of `toward`, which is perpendicular to the zenith).
    pub(crate) fn frame_plane(&self, frame: usize) -> ArcPlane {
        let (s, c) = self.azimuth_deg(frame).to_radians().sin_cos();
        let (z, a) = (self.plane.zenith, self.plane.toward);
        ArcPlane {
            zenith: z,
            toward: (c * a + s * z.cross(a)).normalize(),
        }
    }

    /// The unit direction from the pivot towards the light of frame `frame`.
    pub fn direction(&self, frame: usize) -> Vec3 {
        self.frame_plane(frame).direction(self.light_deg(frame))
    }

    /// `light` moved to frame `frame`: point and sphere lights move to the arc point, spot
    /// lights move there and aim at the pivot, distant lights shine from the arc direction.
    /// Other lights (area, environment) have no position on an arc and are returned unchanged.
    pub fn place(&self, light: &Light, frame: usize) -> Light {
        let dir = self.direction(frame);
        let at = self.pivot + self.radius * dir;
        match light.clone() {
            Light::Point(l) => Light::Point(PointLight { position: at, ..l }),
            Light::Spot(l) => Light::Spot(SpotLight {
                position: at,
                direction: -dir,
                ..l
            }),
            Light::Sphere(l) => Light::Sphere(SphereLight { center: at, ..l }),
            Light::Distant(l) => Light::Distant(DistantLight {
                direction: dir,
                ..l
            }),
            other @ (Light::Rect(_) | Light::Environment(_)) => other,
        }
    }

    /// The scene's lights over frames `frames` of this path, light `moving` placed on the arc.
    pub fn light_frames(
        &self,
        lights: &[Light],
        moving: usize,
        frames: Range<usize>,
    ) -> LightFrames {
        let places = frames.map(|f| self.place(&lights[moving], f)).collect();
        LightFrames::moving(lights, moving, places)
    }
}

//! The fields of every light and material type of a scene file: name, value, allowed range,
//! default and meaning. The one list that the scene checks follow (errors name the field and
//! quote its range), that scenes/README.md's light and material tables are generated from
//! ([`markdown`], compared by crates/xylem/tests/scene_fields.rs) and that the serde defaults of
//! [`format`](super::format) read; Python's dict scenes go through the same checks.

use crate::bsdf::{ParamKind, WOOD_BSDF_PARAMS};

/// One field of a light or material table.
#[derive(Clone, Copy, Debug)]
pub struct Field {
    /// The TOML key.
    pub name: &'static str,
    /// What it holds and its allowed range.
    pub value: Value,
    /// Its value when absent.
    pub default: FieldDefault,
    /// What it means, for the documentation.
    pub meaning: &'static str,
}

/// What a field holds and its allowed range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    /// A number in `[min, max]` in `unit` (empty: none).
    Number {
        /// Unit of the number, in words.
        unit: &'static str,
        /// Smallest allowed value.
        min: f32,
        /// Largest allowed value.
        max: f32,
    },
    /// A non-negative integer (any u64).
    Integer,
    /// A point `[x, y, z]` in mm, every coordinate finite.
    Point,
    /// A vector `[x, y, z]` in mm, every component finite.
    Vector,
    /// A direction `[x, y, z]`: finite, non-zero (normalised on load).
    Direction,
    /// A colour `[r, g, b]`, each channel in `[0, max]`.
    Colour {
        /// Largest allowed channel.
        max: f32,
    },
    /// A pair `[w, h]` of numbers in `[min, max]` mm.
    Size {
        /// Smallest allowed value.
        min: f32,
        /// Largest allowed value.
        max: f32,
    },
    /// One of these names.
    OneOf(&'static [&'static str]),
    /// A string: a name or a path relative to the scene file, as `allowed` says.
    Text {
        /// The allowed values in words.
        allowed: &'static str,
    },
    /// A table `{ name = value, … }`.
    Table,
}

/// A field's value when the table leaves it out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FieldDefault {
    /// The table must give it.
    Required,
    /// Absent means none (or as `meaning` says).
    Optional,
    /// This number.
    Number(f32),
    /// This `[x, y, z]` or `[r, g, b]`.
    Triple([f32; 3]),
    /// Said in words.
    Words(&'static str),
}

/// The fields of one `type` of light or material.
#[derive(Clone, Copy, Debug)]
pub struct TypeFields {
    /// The value of `type`.
    pub name: &'static str,
    /// What it is, for the documentation.
    pub what: &'static str,
    /// Its fields (besides `type`).
    pub fields: &'static [Field],
}

impl Field {
    /// The default number; a compile-time error where the default is not a number.
    pub const fn default_number(&self) -> f32 {
        match self.default {
            FieldDefault::Number(x) => x,
            _ => panic!("the field's default is not a number"),
        }
    }

    /// The default triple; a compile-time error where the default is not one.
    pub const fn default_triple(&self) -> [f32; 3] {
        match self.default {
            FieldDefault::Triple(x) => x,
            _ => panic!("the field's default is not a triple"),
        }
    }

    /// `[min, max]` of a number or size field.
    pub const fn bounds(&self) -> (f32, f32) {
        match self.value {
            Value::Number { min, max, .. } | Value::Size { min, max } => (min, max),
            _ => panic!("the field is not a number"),
        }
    }
}

const fn same(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

/// The scalar field `name` of the wood BSDF's table, as a scene field: the range is the BSDF's own
/// ([`WOOD_BSDF_PARAMS`]), so the scene and [`WoodBsdf::new`](crate::bsdf::WoodBsdf::new) cannot
/// disagree.
const fn bsdf_number(name: &'static str, default: f32, meaning: &'static str) -> Field {
    let mut i = 0;
    while i < WOOD_BSDF_PARAMS.len() {
        if same(WOOD_BSDF_PARAMS[i].name, name) {
            if let ParamKind::Scalar { min, max } = WOOD_BSDF_PARAMS[i].kind {
                return Field {
                    name,
                    value: Value::Number { unit: "", min, max },
                    default: FieldDefault::Number(default),
                    meaning,
                };
            }
        }
        i += 1;
    }
    panic!("not a scalar field of WOOD_BSDF_PARAMS")
}

const fn number(
    name: &'static str,
    unit: &'static str,
    (min, max): (f32, f32),
    default: FieldDefault,
    meaning: &'static str,
) -> Field {
    Field {
        name,
        value: Value::Number { unit, min, max },
        default,
        meaning,
    }
}

const fn field(
    name: &'static str,
    value: Value,
    default: FieldDefault,
    meaning: &'static str,
) -> Field {
    Field {
        name,
        value,
        default,
        meaning,
    }
}

/// Upper bound of a light's strength (intensity, irradiance, radiance).
const STRENGTH: (f32, f32) = (0.0, 1e12);

/// `name` of any light.
pub(crate) const LIGHT_NAME: Field = field(
    "name",
    Value::Text {
        allowed: "unique among the lights",
    },
    FieldDefault::Optional,
    "the sweep moves a light by name",
);
/// `color` of any light.
pub(crate) const LIGHT_COLOR: Field = field(
    "color",
    Value::Colour { max: 1e3 },
    FieldDefault::Triple([1.0; 3]),
    "multiplies the strength",
);
/// `position` of a point or spot light.
pub(crate) const POSITION: Field = field("position", Value::Point, FieldDefault::Required, "");
/// `intensity` of a point or spot light.
pub(crate) const INTENSITY: Field = number(
    "intensity",
    "W/sr",
    STRENGTH,
    FieldDefault::Required,
    "radiant intensity (a spot's on its axis)",
);
/// `target` of a spot light.
pub(crate) const SPOT_TARGET: Field = field(
    "target",
    Value::Point,
    FieldDefault::Required,
    "the point the cone's axis passes through; must differ from `position`",
);
/// `cone_deg` of a spot light.
pub(crate) const CONE: Field = number(
    "cone_deg",
    "degrees",
    (0.01, 180.0),
    FieldDefault::Required,
    "half-angle of the cone",
);
/// `falloff_deg` of a spot light.
pub(crate) const FALLOFF: Field = number(
    "falloff_deg",
    "degrees",
    (0.0, 180.0),
    FieldDefault::Number(0.0),
    "width of the smooth edge inside the cone; at most `cone_deg`",
);
/// `direction` of a distant light.
pub(crate) const DISTANT_DIRECTION: Field = field(
    "direction",
    Value::Direction,
    FieldDefault::Required,
    "towards the light",
);
/// `irradiance` of a distant light.
pub(crate) const IRRADIANCE: Field = number(
    "irradiance",
    "W/mm²",
    STRENGTH,
    FieldDefault::Required,
    "on a surface facing the light",
);
/// `corner` of a rect light.
pub(crate) const CORNER: Field =
    field("corner", Value::Point, FieldDefault::Required, "one corner");
/// `edge_u` of a rect light.
pub(crate) const EDGE_U: Field = field(
    "edge_u",
    Value::Vector,
    FieldDefault::Required,
    "first edge from `corner`; the light emits to the side of `edge_u × edge_v`",
);
/// `edge_v` of a rect light.
pub(crate) const EDGE_V: Field = field(
    "edge_v",
    Value::Vector,
    FieldDefault::Required,
    "second edge from `corner`; the edges must span a non-zero area",
);
/// `radiance` of a rect or sphere light.
pub(crate) const RADIANCE: Field = number(
    "radiance",
    "W/(sr·mm²)",
    STRENGTH,
    FieldDefault::Required,
    "emitted radiance",
);
/// `center` of a sphere light.
pub(crate) const CENTER: Field = field("center", Value::Point, FieldDefault::Required, "");
/// `radius` of a sphere light.
pub(crate) const SPHERE_RADIUS: Field =
    number("radius", "mm", (1e-4, 1e9), FieldDefault::Required, "");
/// `radiance` of the environment.
pub(crate) const ENV_RADIANCE: Field = number(
    "radiance",
    "W/(sr·mm²)",
    STRENGTH,
    FieldDefault::Number(1.0),
    "scales the map (or the constant sky)",
);
/// `map` of the environment.
pub(crate) const ENV_MAP: Field = field(
    "map",
    Value::Text {
        allowed: "an EXR path; texels finite, ≥ 0",
    },
    FieldDefault::Optional,
    "lat-long map, z up, u = φ/2π from +x, v = θ/π from +z; absent: constant",
);
/// `rotate_deg` of the environment.
pub(crate) const ENV_ROTATE: Field = number(
    "rotate_deg",
    "degrees",
    (-360.0, 360.0),
    FieldDefault::Number(0.0),
    "turn of the map about z (exact: the lookup direction is turned)",
);

/// Every `[[lights]]` type and its fields.
pub const LIGHTS: [TypeFields; 6] = [
    TypeFields {
        name: "point",
        what: "a point light",
        fields: &[LIGHT_NAME, POSITION, INTENSITY, LIGHT_COLOR],
    },
    TypeFields {
        name: "spot",
        what: "a point light in a smooth-edged cone",
        fields: &[
            LIGHT_NAME,
            POSITION,
            SPOT_TARGET,
            INTENSITY,
            LIGHT_COLOR,
            CONE,
            FALLOFF,
        ],
    },
    TypeFields {
        name: "distant",
        what: "a directional light, like the sun",
        fields: &[LIGHT_NAME, DISTANT_DIRECTION, IRRADIANCE, LIGHT_COLOR],
    },
    TypeFields {
        name: "rect",
        what: "a parallelogram area light",
        fields: &[LIGHT_NAME, CORNER, EDGE_U, EDGE_V, RADIANCE, LIGHT_COLOR],
    },
    TypeFields {
        name: "sphere",
        what: "a spherical area light",
        fields: &[LIGHT_NAME, CENTER, SPHERE_RADIUS, RADIANCE, LIGHT_COLOR],
    },
    TypeFields {
        name: "environment",
        what: "light from infinitely far away in every direction",
        fields: &[LIGHT_NAME, ENV_RADIANCE, LIGHT_COLOR, ENV_MAP, ENV_ROTATE],
    },
];

/// A reflectance `[r, g, b]` in `[0, 1]`.
const REFLECTANCE: Value = Value::Colour { max: 1.0 };

/// `albedo` of a Lambertian material.
pub(crate) const ALBEDO: Field =
    field("albedo", REFLECTANCE, FieldDefault::Required, "reflectance");
/// `diffuse` of a fibre material.
pub(crate) const FIBER_DIFFUSE: Field = field(
    "diffuse",
    REFLECTANCE,
    FieldDefault::Required,
    "diffuse colour",
);
/// `fiber_color` of a fibre material.
pub(crate) const FIBER_COLOR: Field = field(
    "fiber_color",
    REFLECTANCE,
    FieldDefault::Required,
    "fibre highlight colour",
);
/// `fiber_dir` of a fibre material.
pub(crate) const FIBER_DIR: Field = field(
    "fiber_dir",
    Value::Direction,
    FieldDefault::Required,
    "fibre direction (object space)",
);
/// `ray_dir` of a fibre material.
pub(crate) const RAY_DIR: Field = field(
    "ray_dir",
    Value::Direction,
    FieldDefault::Triple([0.0, 0.0, 1.0]),
    "ray-cell direction (object space)",
);
/// `ray_mask` of a fibre material.
pub(crate) const RAY_MASK: Field =
    bsdf_number("ray_mask", 0.0, "how much of the surface is ray cells");
/// `highlight_width_deg` of a fibre material.
pub(crate) const FIBER_WIDTH: Field = number(
    "highlight_width_deg",
    "degrees",
    (0.06, 90.0),
    FieldDefault::Number(8.0),
    "fibre highlight width β",
);
/// `eta` of any finished material.
pub(crate) const ETA: Field = bsdf_number("eta", 1.5, "refractive index of the finish");
/// `roughness` of any finished material.
pub(crate) const ROUGHNESS: Field =
    bsdf_number("roughness", 0.0, "GGX roughness of the finish (0 = smooth)");
/// `preset` of a wood material.
pub(crate) const PRESET: Field = field(
    "preset",
    Value::OneOf(&crate::wood::PRESET_NAMES),
    FieldDefault::Optional,
    "give exactly one of `preset` and `preset_file`",
);
/// `preset_file` of a wood material.
pub(crate) const PRESET_FILE: Field = field(
    "preset_file",
    Value::Text {
        allowed: "a preset TOML path",
    },
    FieldDefault::Optional,
    "a preset of one's own instead of a built-in",
);
/// `seed` of a wood material.
pub(crate) const WOOD_SEED: Field = field(
    "seed",
    Value::Integer,
    FieldDefault::Number(0.0),
    "selects the tree",
);
/// `bump` of a wood material.
pub(crate) const BUMP: Field = number(
    "bump",
    "",
    (0.0, 100.0),
    FieldDefault::Words("1 for open-grain presets (vessels ≥ 0.15 mm across), else 0"),
    "pore bump strength; 1 = the preset's pores at their anatomical depth; 0 skips the bump",
);
/// `diffuse` map of a measured material.
pub(crate) const MEASURED_DIFFUSE: Field = field(
    "diffuse",
    Value::Text {
        allowed: "an 8-bit PNG path",
    },
    FieldDefault::Required,
    "diffuse colour map",
);
/// `fiber_color` map of a measured material.
pub(crate) const MEASURED_FIBER_COLOR: Field = field(
    "fiber_color",
    Value::Text {
        allowed: "an 8-bit PNG path, the size of `diffuse`",
    },
    FieldDefault::Required,
    "fibre colour map",
);
/// `fiber_axis` map of a measured material.
pub(crate) const MEASURED_FIBER_AXIS: Field = field(
    "fiber_axis",
    Value::Text {
        allowed: "an 8-bit PNG path, the size of `diffuse`; axis length 0.95–1.05",
    },
    FieldDefault::Required,
    "fibre axis map: axis = 2v/255 − 1 in the frame x = columns, y = towards the top row, z = the normal",
);
/// `highlight_width` map of a measured material.
pub(crate) const MEASURED_WIDTH_MAP: Field = field(
    "highlight_width",
    Value::Text {
        allowed: "an 8-bit PNG path, the size of `diffuse`",
    },
    FieldDefault::Optional,
    "β map, β = 90° · v/255; give this or `highlight_width_deg`",
);
/// `highlight_width_deg` of a measured material.
pub(crate) const MEASURED_WIDTH: Field = number(
    "highlight_width_deg",
    "degrees",
    (0.06, 90.0),
    FieldDefault::Number(crate::material::DEFAULT_HIGHLIGHT_WIDTH_DEG),
    "β everywhere, when there is no β map",
);
/// `fiber_color_scale` of a measured material.
pub(crate) const FIBER_COLOR_SCALE: Field = number(
    "fiber_color_scale",
    "",
    (0.0, 1000.0),
    FieldDefault::Number(crate::material::DEFAULT_FIBER_COLOR_SCALE),
    "the published lobe's k_f per stored unit (notes/measured.md); converted to xylem's lobe as 2π ×, texels above 1 scaled down to 1 keeping hue, with a warning",
);
/// `color_space` of a measured material.
pub(crate) const COLOR_SPACE: Field = field(
    "color_space",
    Value::OneOf(&["linear", "srgb"]),
    FieldDefault::Words("\"linear\""),
    "encoding of the colour maps",
);
/// `size_mm` of a measured material.
pub(crate) const SIZE_MM: Field = field(
    "size_mm",
    Value::Size {
        min: 1e-3,
        max: 1e6,
    },
    FieldDefault::Required,
    "the image's [width, height] on the face (object space), centred on the object's origin",
);
/// `face` of a measured material.
pub(crate) const FACE: Field = field(
    "face",
    Value::OneOf(&crate::material::BoardFace::NAMES),
    FieldDefault::Words("\"+z\""),
    "the face of the object the maps lie on",
);
/// `texture` of a texture material.
pub(crate) const TEXTURE: Field = field(
    "texture",
    Value::OneOf(&crate::texture::NAMES),
    FieldDefault::Required,
    "a classic solid texture (`xylem texture --help`) as a Lambertian albedo clamped to 0–1, looked up at the object's `tree` placement point (mm); clouds and rust take a `time` in seconds",
);
/// `params` of a texture material.
pub(crate) const TEXTURE_PARAMS: Field = field(
    "params",
    Value::Table,
    FieldDefault::Words("the texture's defaults"),
    "the texture's parameters, `{ name = value, … }`",
);
/// `reflectance` of a mirror.
pub(crate) const MIRROR_REFLECTANCE: Field = field(
    "reflectance",
    REFLECTANCE,
    FieldDefault::Triple([0.95; 3]),
    "",
);
/// `eta` of glass.
pub(crate) const GLASS_ETA: Field = number(
    "eta",
    "",
    (1.0, 4.0),
    FieldDefault::Number(1.5),
    "refractive index",
);
/// `tint` of glass.
pub(crate) const GLASS_TINT: Field = field(
    "tint",
    REFLECTANCE,
    FieldDefault::Triple([1.0; 3]),
    "transmission tint",
);

/// Every `[materials.NAME]` type and its fields.
pub const MATERIALS: [TypeFields; 7] = [
    TypeFields {
        name: "lambertian",
        what: "a Lambertian diffuse surface",
        fields: &[ALBEDO],
    },
    TypeFields {
        name: "fiber",
        what: "the finished-wood BSDF (Marschner et al. 2005) with constant parameters",
        fields: &[
            FIBER_DIFFUSE,
            FIBER_COLOR,
            FIBER_DIR,
            RAY_DIR,
            RAY_MASK,
            FIBER_WIDTH,
            ETA,
            ROUGHNESS,
        ],
    },
    TypeFields {
        name: "wood",
        what: "the procedural wood volume of a species preset (Liu et al. 2016) under a finish",
        fields: &[PRESET, PRESET_FILE, WOOD_SEED, ETA, ROUGHNESS, BUMP],
    },
    TypeFields {
        name: "measured",
        what: "a board measured by Marschner et al. 2005: per-texel BSDF parameters from image \
               maps (encoding: data/marschner2005/README.md; assumptions: notes/measured.md) on one \
               face of the object; paths relative to the scene file",
        fields: &[
            MEASURED_DIFFUSE,
            MEASURED_FIBER_COLOR,
            MEASURED_FIBER_AXIS,
            MEASURED_WIDTH_MAP,
            MEASURED_WIDTH,
            FIBER_COLOR_SCALE,
            COLOR_SPACE,
            SIZE_MM,
            FACE,
            ETA,
            ROUGHNESS,
        ],
    },
    TypeFields {
        name: "texture",
        what: "a classic solid texture as a Lambertian albedo",
        fields: &[TEXTURE, TEXTURE_PARAMS],
    },
    TypeFields {
        name: "mirror",
        what: "a perfect mirror",
        fields: &[MIRROR_REFLECTANCE],
    },
    TypeFields {
        name: "glass",
        what: "a smooth dielectric (refracting) surface",
        fields: &[GLASS_ETA, GLASS_TINT],
    },
];

/// `x` as the documentation writes it: `1e12`, `0.06`, `-360` written `−360`.
fn num(x: f32) -> String {
    let s = if x != 0.0 && (x.abs() >= 1e5 || x.abs() < 1e-3) {
        format!("{x:e}")
    } else {
        format!("{x}")
    };
    s.replace('-', "−")
}

fn triple(t: [f32; 3]) -> String {
    format!("[{}, {}, {}]", num(t[0]), num(t[1]), num(t[2]))
}

impl Value {
    /// The value's kind and unit, in words.
    fn kind(&self) -> String {
        match *self {
            Value::Number { unit: "", .. } => "number".into(),
            Value::Number { unit, .. } => format!("number, {unit}"),
            Value::Integer => "integer".into(),
            Value::Point => "[x, y, z] mm".into(),
            Value::Vector => "[x, y, z] mm".into(),
            Value::Direction => "[x, y, z]".into(),
            Value::Colour { .. } => "[r, g, b]".into(),
            Value::Size { .. } => "[w, h] mm".into(),
            Value::Text { .. } | Value::OneOf(_) => "string".into(),
            Value::Table => "table".into(),
        }
    }

    /// The allowed range, in words.
    pub fn range(&self) -> String {
        match *self {
            Value::Number { min, max, .. } | Value::Size { min, max } => {
                format!("{}–{}", num(min), num(max))
            }
            Value::Integer => "any u64".into(),
            Value::Point | Value::Vector => "finite".into(),
            Value::Direction => "finite, non-zero".into(),
            Value::Colour { max } => format!("each 0–{}", num(max)),
            Value::Text { allowed } => allowed.into(),
            Value::OneOf(names) => names
                .iter()
                .map(|n| format!("\"{n}\""))
                .collect::<Vec<_>>()
                .join(", "),
            Value::Table => String::new(),
        }
    }
}

impl FieldDefault {
    fn words(&self) -> String {
        match *self {
            FieldDefault::Required => "— (required)".into(),
            FieldDefault::Optional => "none".into(),
            FieldDefault::Number(x) => num(x),
            FieldDefault::Triple(t) => triple(t),
            FieldDefault::Words(w) => w.into(),
        }
    }
}

/// scenes/README.md's table of `types`: one row per field, the type named on its first row.
pub fn markdown(types: &[TypeFields]) -> String {
    let mut s = String::from(
        "| type | field | value | range | default | meaning |\n| --- | --- | --- | --- | --- | --- |\n",
    );
    for t in types {
        for (i, f) in t.fields.iter().enumerate() {
            let ty = if i == 0 {
                format!("`{}`: {}", t.name, t.what)
            } else {
                String::new()
            };
            s += &format!(
                "| {ty} | `{}` | {} | {} | {} | {} |\n",
                f.name,
                f.value.kind(),
                f.value.range().replace('|', "\\|"),
                f.default.words(),
                f.meaning.replace('|', "\\|"),
            );
        }
    }
    s
}

//! `scene::fields` is the one list of the light and material fields: the scene format accepts
//! exactly its fields, the scene checks use its ranges (each number accepted at its bounds,
//! refused beyond, naming the field) and scenes/README.md's tables are generated from it
//! (`XYLEM_BLESS=1 cargo test --test scene_fields` rewrites them).

use std::collections::BTreeSet;
use std::path::Path;
use xylem::scene::fields::{markdown, Field, FieldDefault, TypeFields, Value, LIGHTS, MATERIALS};

const SCENES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes");

/// A value `field` accepts (measured maps: the repository's maple board).
fn sample(field: &Field) -> String {
    match (field.value, field.name) {
        (Value::Number { min, max, .. }, _) => format!("{}", 0.5 * (min + max.min(min + 1.0))),
        (Value::Integer, _) => "0".into(),
        (Value::Point, "target") => "[0.0, 0.0, 0.0]".into(),
        (Value::Point, _) => "[0.0, 0.0, 100.0]".into(),
        (Value::Vector, "edge_u") => "[10.0, 0.0, 0.0]".into(),
        (Value::Vector, _) => "[0.0, 10.0, 0.0]".into(),
        (Value::Direction, _) => "[1.0, 0.0, 0.0]".into(),
        (Value::Colour { .. }, _) => "[0.5, 0.5, 0.5]".into(),
        (Value::Size { .. }, _) => "[10.0, 10.0]".into(),
        (Value::Table, _) => "{}".into(),
        (Value::OneOf(names), _) => format!("\"{}\"", names[names.len() - 1]),
        (Value::Text { .. }, name) => match name {
            "diffuse" | "fiber_color" | "fiber_axis" => {
                format!("\"../data/marschner2005/maple/{name}.png\"")
            }
            other => panic!("no sample for text field `{other}`"),
        },
    }
}

/// The fields a minimal table of `t` gives: the required ones, and `preset` of `wood`.
fn minimal(t: &TypeFields) -> Vec<(&'static str, String)> {
    t.fields
        .iter()
        .filter(|f| f.default == FieldDefault::Required || (t.name, f.name) == ("wood", "preset"))
        .map(|f| (f.name, sample(f)))
        .collect()
}

/// A scene with one light and one material, `is_light` choosing which one is `t` with `fields`.
fn scene(t: &TypeFields, is_light: bool, fields: &[(&str, String)]) -> String {
    let body: String = fields.iter().map(|(k, v)| format!("{k} = {v}\n")).collect();
    let (light, material) = if is_light {
        (
            format!("type = \"{}\"\n{body}", t.name),
            "type = \"lambertian\"\nalbedo = [0.5, 0.5, 0.5]\n".to_string(),
        )
    } else {
        (
            "type = \"point\"\nposition = [0.0, 0.0, 100.0]\nintensity = 1.0\n".to_string(),
            format!("type = \"{}\"\n{body}", t.name),
        )
    };
    format!(
        "[render]\nwidth = 8\nheight = 8\n[camera]\neye = [0.0, -100.0, 50.0]\ntarget = [0.0, 0.0, 0.0]\n\
         [[lights]]\n{light}[materials.m]\n{material}[[objects]]\nshape = \"box\"\nsize = [10.0, 10.0, 10.0]\nmaterial = \"m\"\n"
    )
}

fn load(text: &str) -> Result<(), String> {
    xylem::scene::from_str(text, "test.toml", Path::new(SCENES), "test")
        .map(drop)
        .map_err(|e| e.to_string())
}

fn kinds() -> impl Iterator<Item = (&'static TypeFields, bool, String)> {
    let lights = LIGHTS.iter().map(|t| (t, true, "lights[0]".to_string()));
    lights.chain(
        MATERIALS
            .iter()
            .map(|t| (t, false, "materials.m".to_string())),
    )
}

/// The field names serde lists when it meets an unknown field in a table of `t`.
fn serde_fields(t: &TypeFields, is_light: bool) -> BTreeSet<String> {
    let mut fields = minimal(t);
    fields.push(("zz_unknown", "1".into()));
    let e = load(&scene(t, is_light, &fields)).unwrap_err();
    let list = e
        .split("expected ")
        .nth(1)
        .unwrap_or_else(|| panic!("{}: {e}", t.name));
    list.split('`')
        .skip(1)
        .step_by(2)
        .filter(|k| *k != "type")
        .map(str::to_string)
        .collect()
}

fn names(t: &TypeFields) -> BTreeSet<String> {
    t.fields.iter().map(|f| f.name.to_string()).collect()
}

#[test]
fn the_format_accepts_exactly_the_listed_fields() {
    for (t, is_light, _) in kinds() {
        assert_eq!(serde_fields(t, is_light), names(t), "type `{}`", t.name);
    }
    // Control: the sets tell two types apart.
    assert_ne!(serde_fields(&LIGHTS[0], true), names(&LIGHTS[1]));
}

#[test]
fn a_table_with_the_required_fields_builds_and_one_without_fails() {
    for (t, is_light, at) in kinds() {
        let fields = minimal(t);
        load(&scene(t, is_light, &fields)).unwrap_or_else(|e| panic!("{}: {e}", t.name));
        for skip in 0..fields.len() {
            let mut less = fields.clone();
            let (name, _) = less.remove(skip);
            let e = load(&scene(t, is_light, &less)).expect_err(name);
            assert!(e.contains(&format!("{at}.{name}")), "{}: {e}", t.name);
        }
    }
}

#[test]
fn each_number_is_accepted_at_its_bounds_and_refused_beyond() {
    let mut checked = 0;
    for (t, is_light, at) in kinds() {
        for f in t.fields {
            let (Value::Number { min, max, .. } | Value::Size { min, max }) = f.value else {
                continue;
            };
            let with = |x: f32| {
                let mut fields: Vec<_> = minimal(t)
                    .into_iter()
                    .filter(|(k, _)| *k != f.name)
                    .collect();
                // TOML spells NaN `nan`.
                let x = if x.is_nan() {
                    "nan".to_string()
                } else {
                    format!("{x:?}")
                };
                let v = match f.value {
                    Value::Size { .. } => format!("[{x}, 10.0]"),
                    _ => x,
                };
                fields.push((f.name, v));
                if f.name == "falloff_deg" {
                    // The falloff is bounded by the cone as well.
                    fields.retain(|(k, _)| *k != "cone_deg");
                    fields.push(("cone_deg", "180.0".into()));
                }
                load(&scene(t, is_light, &fields))
            };
            for x in [min, max] {
                with(x).unwrap_or_else(|e| panic!("{}.{} = {x}: {e}", t.name, f.name));
            }
            for x in [
                min - 1e-3 * (1.0 + min.abs()),
                max + 1e-3 * (1.0 + max.abs()),
                f32::NAN,
            ] {
                let e = with(x).expect_err(f.name);
                assert!(
                    e.contains(&format!("{at}.{}", f.name)) && e.contains("allowed"),
                    "{}.{} = {x}: {e}",
                    t.name,
                    f.name
                );
            }
            checked += 1;
        }
    }
    assert_eq!(checked, 23, "number fields");
}

#[test]
fn the_scene_documentation_is_generated_from_the_table() {
    let path = Path::new(SCENES).join("README.md");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut fresh = text.clone();
    for (tag, types) in [("LIGHTS", &LIGHTS[..]), ("MATERIALS", &MATERIALS[..])] {
        let begin = format!("<!-- generated from scene::fields::{tag} -->\n");
        let end = "<!-- end generated -->";
        let a = fresh
            .find(&begin)
            .unwrap_or_else(|| panic!("{begin} missing"))
            + begin.len();
        let b = a + fresh[a..].find(end).expect("end marker");
        fresh.replace_range(a..b, &markdown(types));
    }
    if std::env::var_os("XYLEM_BLESS").is_some() {
        std::fs::write(&path, &fresh).unwrap();
    }
    assert!(
        text == fresh,
        "scenes/README.md's field tables differ from scene::fields; rewrite them with \
         XYLEM_BLESS=1 cargo test --test scene_fields"
    );
    // Control: a changed range shows in the generated text.
    let mut eta = MATERIALS[1];
    let fields: Vec<Field> = eta
        .fields
        .iter()
        .map(|f| Field {
            meaning: "changed",
            ..*f
        })
        .collect();
    eta.fields = Box::leak(fields.into_boxed_slice());
    assert!(!fresh.contains(&markdown(&[eta])));
}

#[test]
fn each_listed_name_is_accepted_and_others_refused() {
    let mut checked = 0;
    for (t, is_light, at) in kinds() {
        for f in t.fields {
            let Value::OneOf(names) = f.value else {
                continue;
            };
            let with = |name: &str| {
                let mut fields: Vec<_> = minimal(t)
                    .into_iter()
                    .filter(|(k, _)| *k != f.name)
                    .collect();
                fields.push((f.name, format!("\"{name}\"")));
                load(&scene(t, is_light, &fields))
            };
            for name in names {
                with(name).unwrap_or_else(|e| panic!("{}.{} = {name}: {e}", t.name, f.name));
            }
            let e = with("zz_none").expect_err(f.name);
            assert!(e.contains(&format!("{at}.{}", f.name)), "{e}");
            checked += 1;
        }
    }
    assert_eq!(checked, 4);
}

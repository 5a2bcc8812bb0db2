//! Validation scenes as data: each study's base scene is a file in validation/scenes/ (compiled
//! in, so `xylem validate` runs from any folder), and the code sets only what the study varies,
//! by path (`render.width`, `objects.0.tree`, `materials.board`).

/// The base scenes, by file stem.
const SCENES: [(&str, &str); 5] = [
    (
        "fibre_board",
        include_str!("../../../validation/scenes/fibre_board.toml"),
    ),
    (
        "preset_board",
        include_str!("../../../validation/scenes/preset_board.toml"),
    ),
    (
        "white_light_board",
        include_str!("../../../validation/scenes/white_light_board.toml"),
    ),
    (
        "appearance_sweep",
        include_str!("../../../validation/scenes/appearance_sweep.toml"),
    ),
    (
        "fit_round_trip",
        include_str!("../../../validation/scenes/fit_round_trip.toml"),
    ),
];

/// A validation scene being set up: a base scene's TOML table with some values replaced.
#[derive(Clone, Debug)]
pub struct SceneTemplate {
    table: toml::Table,
}

impl SceneTemplate {
    /// The base scene validation/scenes/`name`.toml. Panics on a name that is not one (the
    /// names are the lab's own, so that is a bug here, not a user's error).
    pub fn named(name: &str) -> SceneTemplate {
        let (_, text) = SCENES
            .iter()
            .find(|(n, _)| *n == name)
            .unwrap_or_else(|| panic!("no validation scene `{name}`"));
        let table =
            toml::from_str(text).unwrap_or_else(|e| panic!("validation/scenes/{name}.toml: {e}"));
        SceneTemplate { table }
    }

    /// Replaces (or adds) the value at `path`: keys separated by dots, array elements by their
    /// index (`objects.0.size`); tables missing on the way are created.
    pub fn set(mut self, path: &str, value: impl Into<toml::Value>) -> SceneTemplate {
        let keys: Vec<&str> = path.split('.').collect();
        set_in(&mut self.table, &keys, value.into(), path);
        self
    }

    /// The scene as TOML text, for `xylem::scene::from_str`.
    pub fn text(&self) -> String {
        toml::to_string(&self.table).expect("a TOML table serialises")
    }
}

/// [`SceneTemplate::set`] below `table`.
fn set_in(table: &mut toml::Table, keys: &[&str], value: toml::Value, path: &str) {
    let [key, rest @ ..] = keys else {
        panic!("`{path}`: an empty path")
    };
    if rest.is_empty() {
        table.insert(key.to_string(), value);
        return;
    }
    let next = (table.entry(*key)).or_insert_with(|| toml::Value::Table(toml::Table::new()));
    let (next, rest) = match next {
        toml::Value::Array(items) => {
            let i: usize = rest[0]
                .parse()
                .unwrap_or_else(|_| panic!("`{path}`: an index"));
            (&mut items[i], &rest[1..])
        }
        other => (other, rest),
    };
    match next {
        toml::Value::Table(t) => set_in(t, rest, value, path),
        _ => panic!("`{path}`: `{key}` is not a table"),
    }
}

/// A 3-vector as a TOML array of three floats (exactly the f32s, widened).
pub fn vec3(v: glam::Vec3) -> toml::Value {
    toml::Value::Array(v.to_array().map(|x| toml::Value::Float(x as f64)).to_vec())
}

/// A pair of numbers as a TOML array of two floats.
pub fn pair(a: f32, b: f32) -> toml::Value {
    toml::Value::Array(vec![
        toml::Value::Float(a as f64),
        toml::Value::Float(b as f64),
    ])
}

/// A TOML inline-table text (`{ origin = [...], ... }`) as a value.
pub fn inline_table(text: &str) -> toml::Value {
    let t: toml::Table = toml::from_str(&format!("v = {text}")).expect("an inline table");
    t["v"].clone()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_base_scene_loads_and_values_set_by_path_land_there() {
        for (name, _) in SCENES {
            let t = SceneTemplate::named(name);
            let text = t.text();
            xylem::scene::parse(&text, name).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
        let t = SceneTemplate::named("preset_board")
            .set("render.width", 7)
            .set("objects.0.size", pair(3.0, 4.0))
            .set("materials.board.preset", "walnut");
        let f = xylem::scene::parse(&t.text(), "t").unwrap();
        assert_eq!(f.render.width, 7);
        assert_eq!(f.objects[0].size, Some(vec![3.0, 4.0]));
        assert!(t.text().contains("preset = \"walnut\""));
    }

    /// The control: a path through a value that is not a table is refused, not ignored.
    #[test]
    #[should_panic(expected = "is not a table")]
    fn a_path_through_a_number_is_refused() {
        let _ = SceneTemplate::named("preset_board").set("render.width.x", 1);
    }
}

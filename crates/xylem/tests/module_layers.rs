//! The engine's modules form layers (notes/design.md, "Modules"): each module uses only modules
//! listed before it in [`LAYERS`], so no import runs up the table and there is no circle. The
//! compiler enforces the crates' direction; this test the modules' inside the engine, reading
//! the `crate::name` paths of each module's source (comments left out).

use std::collections::BTreeSet;
use std::path::Path;

/// The engine's top-level modules, lowest first: the order of notes/design.md's module table.
const LAYERS: [&str; 19] = [
    "math",
    "simd",
    "progress",
    "resources",
    "output",
    "jsonpath",
    "builtin",
    "picture",
    "noise",
    "field",
    "wood",
    "texture",
    "bsdf",
    "material",
    "render",
    "scene",
    "sweep",
    "fit",
    "bake",
];

/// The `crate::name` modules a source text uses (code only: `//` comments are cut off).
fn uses_in(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for line in text.lines() {
        let code = line.split("//").next().unwrap_or("");
        for (i, _) in code.match_indices("crate::") {
            let name: String = code[i + 7..]
                .chars()
                .take_while(|c| c.is_ascii_lowercase() || *c == '_')
                .collect();
            if !name.is_empty() && !code[..i].ends_with("xylem_") {
                out.insert(name);
            }
        }
    }
    out
}

/// Every `.rs` file under `path` (or `path` itself).
fn sources(path: &Path, out: &mut Vec<std::path::PathBuf>) {
    if path.is_dir() {
        for e in std::fs::read_dir(path).unwrap() {
            sources(&e.unwrap().path(), out);
        }
    } else if path.extension().is_some_and(|x| x == "rs") {
        out.push(path.to_path_buf());
    }
}

/// The imports that run the wrong way: (module, a module it uses that is not below it).
fn wrong_way(uses: &[(&str, BTreeSet<String>)], layers: &[&str]) -> Vec<(String, String)> {
    let pos = |m: &str| layers.iter().position(|l| *l == m);
    let mut bad = Vec::new();
    for (module, used) in uses {
        let me = pos(module).unwrap_or_else(|| panic!("module `{module}` is not in LAYERS"));
        for u in used.iter().filter(|u| u.as_str() != *module) {
            if pos(u).is_none_or(|p| p >= me) {
                bad.push((module.to_string(), u.clone()));
            }
        }
    }
    bad
}

#[test]
fn no_engine_module_uses_one_above_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut uses = Vec::new();
    for module in LAYERS {
        let (dir, file) = (src.join(module), src.join(format!("{module}.rs")));
        let mut files = Vec::new();
        sources(if dir.is_dir() { &dir } else { &file }, &mut files);
        assert!(!files.is_empty(), "no source for module `{module}`");
        let used = (files.iter())
            .flat_map(|f| uses_in(&std::fs::read_to_string(f).unwrap()))
            .collect();
        uses.push((module, used));
    }
    // Every top-level module is in the table.
    for e in std::fs::read_dir(&src).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().replace(".rs", "");
        assert!(
            name == "lib" || LAYERS.contains(&name.as_str()),
            "`{name}` is not in LAYERS"
        );
    }
    let bad = wrong_way(&uses, &LAYERS);
    assert!(
        bad.is_empty(),
        "imports up the table (module, uses): {bad:?}"
    );
}

/// The control: an import up the table, and a circle, are found.
#[test]
fn an_import_up_the_table_is_found() {
    let set = |s: &[&str]| s.iter().map(|x| x.to_string()).collect::<BTreeSet<_>>();
    assert_eq!(
        uses_in("use crate::render::Ray; // crate::scene\nfn f() { crate::math::PI }"),
        set(&["math", "render"])
    );
    let layers = ["math", "wood", "render"];
    let ok = [
        ("math", set(&[])),
        ("wood", set(&["math"])),
        ("render", set(&["wood", "math"])),
    ];
    assert!(wrong_way(&ok, &layers).is_empty());
    let up = [
        ("wood", set(&["math", "render"])),
        ("render", set(&["wood"])),
    ];
    assert_eq!(wrong_way(&up, &layers), [("wood".into(), "render".into())]);
}

//! Mutation fuzzing of every built-in scene and species preset (issue 15): fields removed,
//! wrong-typed, out of range, non-finite, huge; unknown fields; duplicated tables; truncated and
//! binary files. Every case must load with an error that names the file, or load and render a
//! small image of finite pixels — never panic. A bounded number of cases from a fixed seed
//! (xorshift64*), so the suite is fast and repeatable.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use toml::Value;
use xylem::render::{render, RunOptions};

/// Cases drawn per scene file and per preset.
const CASES_PER_SCENE: usize = 48;
const CASES_PER_PRESET: usize = 24;

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() >> 33) as usize % n.max(1)
    }
}

/// Paths (keys and array indices) to every value in a TOML document.
fn paths(v: &Value, prefix: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    match v {
        Value::Table(t) => {
            for (k, x) in t {
                prefix.push(k.clone());
                out.push(prefix.clone());
                paths(x, prefix, out);
                prefix.pop();
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                prefix.push(format!("#{i}"));
                out.push(prefix.clone());
                paths(x, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

/// The replacements tried at a path; `None` removes the value.
fn mutations() -> Vec<Option<Value>> {
    let f = Value::Float;
    vec![
        None,
        Some(Value::String("not a number".into())),
        Some(Value::Boolean(true)),
        Some(Value::Integer(-1)),
        Some(Value::Integer(0)),
        Some(Value::Integer(i64::MAX)),
        Some(f(1e38)),
        Some(f(-1e38)),
        Some(f(1e-30)),
        Some(f(f64::NAN)),
        Some(f(f64::INFINITY)),
        Some(Value::Array(vec![f(1.0), f(2.0), f(3.0), f(4.0)])),
        Some(Value::Array(vec![f(0.0), f(0.0), f(0.0)])),
        Some(Value::Array(vec![])),
        Some(Value::Table(Default::default())),
    ]
}

/// Applies `m` at `path` (removal, replacement, or an unknown sibling when `unknown`).
fn mutate(doc: &Value, path: &[String], m: &Option<Value>, unknown: bool) -> Value {
    let mut doc = doc.clone();
    let mut cur = &mut doc;
    for key in &path[..path.len() - 1] {
        cur = match (cur, key.strip_prefix('#')) {
            (Value::Array(a), Some(i)) => &mut a[i.parse::<usize>().unwrap()],
            (Value::Table(t), None) => t.get_mut(key).unwrap(),
            _ => unreachable!(),
        };
    }
    let last = &path[path.len() - 1];
    match (cur, last.strip_prefix('#')) {
        (Value::Table(t), None) if unknown => {
            t.insert("bogus_field".into(), Value::Integer(1));
        }
        (Value::Table(t), None) => match m {
            None => {
                t.remove(last);
            }
            Some(v) => {
                t.insert(last.clone(), v.clone());
            }
        },
        (Value::Array(a), Some(i)) => {
            let i: usize = i.parse().unwrap();
            match m {
                None => {
                    a.remove(i);
                }
                Some(v) => a[i] = v.clone(),
            }
        }
        _ => unreachable!(),
    }
    doc
}

/// Loads `text` as a scene and, when it loads, renders it at 8×6, 1 spp; panics only if xylem
/// panicked or gave an unnamed error or a non-finite pixel. True when it rendered.
fn check_scene(text: &str, what: &str) -> bool {
    let base = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("scenes");
    let result = catch_unwind(AssertUnwindSafe(|| {
        let mut loaded = xylem::scene::from_str(text, "fuzz.toml", &base, "fuzz")?;
        loaded.scene.camera = loaded.scene.camera.with_resolution(8, 6);
        loaded.settings.spp = 1;
        let run = RunOptions {
            threads: 1,
            ..Default::default()
        };
        let out = render(&loaded.scene, &loaded.settings, &run)?;
        Ok::<_, Box<dyn std::error::Error>>(out.image)
    }));
    match result {
        Err(_) => panic!("xylem panicked on {what}:\n{text}"),
        Ok(Err(e)) => {
            let e = e.to_string();
            assert!(
                e.contains("fuzz.toml"),
                "{what}: the error does not name the file: {e}"
            );
            false
        }
        Ok(Ok(image)) => {
            let bad = image.beauty.iter().filter(|c| !c.is_finite()).count();
            assert_eq!(bad, 0, "{what}: {bad} non-finite pixels");
            true
        }
    }
}

fn toml_files(dir: &str) -> Vec<(String, String)> {
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join(dir);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read_to_string(&p).unwrap())
        })
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no TOML files in {}", dir.display());
    files
}

/// A drawn mutation of `text` (a parsed TOML document) with a description.
fn draw(rng: &mut Rng, doc: &Value, all: &[Vec<String>], text: &str) -> (String, String) {
    let ms = mutations();
    match rng.below(20) {
        0 => {
            let cut = rng.below(text.len());
            let cut = (0..=cut).rev().find(|&c| text.is_char_boundary(c)).unwrap();
            (text[..cut].to_string(), format!("truncated at byte {cut}"))
        }
        1 => {
            let bytes: Vec<u8> = (0..256).map(|_| rng.next() as u8).collect();
            (
                String::from_utf8_lossy(&bytes).into_owned(),
                "binary garbage".into(),
            )
        }
        2 => {
            // A table given twice (a duplicate name).
            let start = text.find("\n[").map_or(0, |i| i + 1);
            let end = text[start + 1..]
                .find("\n[")
                .map_or(text.len(), |i| start + 1 + i);
            (
                format!("{text}\n{}", &text[start..end]),
                "a table repeated".into(),
            )
        }
        k => {
            let path = &all[rng.below(all.len())];
            let unknown = k == 3;
            let m = &ms[rng.below(ms.len())];
            let doc = mutate(doc, path, m, unknown);
            let what = if unknown {
                format!("an unknown field beside {}", path.join("."))
            } else {
                format!("{} = {m:?}", path.join("."))
            };
            (toml::to_string(&doc).unwrap(), what)
        }
    }
}

/// `per_file` drawn mutations of every TOML file in `dir`: (file name, description, text).
fn cases(dir: &str, per_file: usize, seed: u64) -> Vec<(String, String, String)> {
    let mut rng = Rng(seed);
    let mut out = Vec::new();
    for (name, text) in toml_files(dir) {
        let doc: Value = toml::from_str(&text).unwrap();
        let mut all = Vec::new();
        paths(&doc, &mut Vec::new(), &mut all);
        for _ in 0..per_file {
            let (mutated, what) = draw(&mut rng, &doc, &all, &text);
            out.push((name.clone(), what, mutated));
        }
    }
    out
}

#[test]
fn mutated_builtin_scenes_give_named_errors_or_finite_images() {
    let cases = cases("scenes", CASES_PER_SCENE, 0x5eed_0015_dead_beef);
    let rendered = cases
        .iter()
        .filter(|(name, what, text)| check_scene(text, &format!("{name}: {what}")))
        .count();
    // Both outcomes are exercised (a suite where everything failed to parse would test little).
    let n = cases.len();
    println!(
        "{n} mutated scenes: {rendered} rendered, {} refused",
        n - rendered
    );
    assert!(rendered * 10 >= n && rendered < n, "{rendered} of {n}");
}

#[test]
fn mutated_presets_give_named_errors_or_valid_wood() {
    for (name, what, text) in cases("scenes/presets", CASES_PER_PRESET, 0x0015_feed_cafe_f00d) {
        let r = catch_unwind(AssertUnwindSafe(|| {
            let p = xylem::wood::WoodParams::from_toml_str(&text, "fuzz_preset.toml")?;
            let v = xylem::wood::WoodVolume::new(p, 1)?;
            let t = v.eval(
                xylem::math::Vec3::new(3.0, 40.0, 7.0),
                xylem::wood::Needs::ALL,
            );
            Ok::<_, xylem::wood::WoodError>(t.diffuse)
        }));
        match r {
            Err(_) => panic!("xylem panicked on {name}: {what}"),
            Ok(Err(e)) => {
                let e = e.to_string();
                assert!(e.contains("fuzz_preset.toml"), "{name}: {what}: {e}");
            }
            Ok(Ok(c)) => assert!(c.is_finite(), "{name}: {what}: colour {c}"),
        }
    }
}

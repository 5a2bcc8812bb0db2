//! The engine's doc examples and `crates/xylem/examples/` compile in a new project that depends on xylem alone
//! (issue 26, item 10: they needed `glam` and `tempfile` added): every crate they name is
//! `xylem` or `std` (xylem re-exports its vector types as `xylem::math::{Vec2, Vec3, Mat3}`).
//! A text check, so it runs in milliseconds; `cargo test --doc` compiles them.

use std::path::Path;

fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// Crate names in `text` used as paths (`name::`), other than xylem, std, core and alloc.
fn foreign_crates(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for c in [
        "glam::",
        "tempfile::",
        "serde_json::",
        "rayon::",
        "exr::",
        "png::",
    ] {
        // At the start of a path: not after `::` or an identifier (`xylem::picture::png::`).
        let rooted = text.match_indices(c).any(|(i, _)| {
            let before = text[..i].chars().next_back();
            !before.is_some_and(|b| b == ':' || b == '_' || b.is_alphanumeric())
        });
        if rooted {
            out.push(c.trim_end_matches(':').to_string());
        }
    }
    out
}

#[test]
fn doc_examples_name_only_xylem_and_std() {
    // The engine crate: its doc examples and examples/ are what a library user copies.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    rust_files(&root.join("src"), &mut files);
    assert!(
        files.len() > 50,
        "the engine's sources: {} files",
        files.len()
    );
    let mut bad = Vec::new();
    for f in &files {
        let rel = f.strip_prefix(root).unwrap().display().to_string();
        let text = std::fs::read_to_string(f).unwrap();
        // The lines inside ``` blocks of doc comments.
        let mut code = String::new();
        let mut inside = false;
        for line in text.lines() {
            let t = line.trim_start();
            let Some(doc) = t.strip_prefix("///").or_else(|| t.strip_prefix("//!")) else {
                inside = false;
                continue;
            };
            let doc = doc.trim_start();
            if doc.starts_with("```") {
                inside =
                    !inside && (doc == "```" || doc == "```rust" || doc.starts_with("```no_run"));
                continue;
            }
            if inside {
                code += doc;
                code += "\n";
            }
        }
        let crates = foreign_crates(&code);
        if !crates.is_empty() {
            bad.push(format!("{rel}: {crates:?}"));
        }
    }
    let mut examples = Vec::new();
    rust_files(&root.join("examples"), &mut examples);
    assert!(!examples.is_empty(), "the engine's examples/");
    for f in &examples {
        let crates = foreign_crates(&std::fs::read_to_string(f).unwrap());
        if !crates.is_empty() {
            bad.push(format!("{}: {crates:?}", f.display()));
        }
    }
    assert!(
        bad.is_empty(),
        "doc examples naming crates a new project lacks: {bad:?}"
    );
}

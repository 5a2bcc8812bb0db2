//! The README's shell commands name commands and options that exist (issue 26, item 10): every
//! `cargo run --release -- …` line of its code blocks is checked against the binary's `--help`
//! (subcommand and each `--option`), and the quick ones run as written from a scratch copy of
//! the files they read. Rendering every command in full would take many minutes; the Python
//! snippets run in crates/xylem-cli/tests/python.rs.

use std::path::Path;
use std::process::Command;

fn xylem(args: &[&str], dir: &Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_xylem"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

/// The argument words of every `cargo run --release -- …` line in the README's code blocks
/// (a trailing `# comment` cut; a `$t` loop variable replaced by a preset name).
fn readme_commands() -> Vec<Vec<String>> {
    let readme = std::fs::read_to_string(
        Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("README.md"),
    )
    .unwrap();
    let mut out = Vec::new();
    let mut in_code = false;
    for line in readme.lines() {
        if line.trim_start().starts_with("```") {
            in_code = !in_code;
            continue;
        }
        let Some(rest) = line.trim().split("cargo run --release -- ").nth(1) else {
            continue;
        };
        if !in_code {
            continue;
        }
        let rest = rest.split(" #").next().unwrap().replace("$t", "marble");
        out.push(rest.split_whitespace().map(str::to_string).collect());
    }
    out
}

#[test]
fn readme_commands_name_existing_commands_and_options() {
    let tmp = tempfile::tempdir().unwrap();
    let commands = readme_commands();
    assert!(commands.len() >= 10, "{commands:?}");
    for words in &commands {
        // The subcommand path: the leading words that `--help` accepts as one.
        let mut path: Vec<&str> = vec![words[0].as_str()];
        if let Some(second) = words.get(1).filter(|w| !w.starts_with('-')) {
            let o = xylem(&[words[0].as_str(), second.as_str(), "--help"], tmp.path());
            if o.status.success() && !String::from_utf8_lossy(&o.stdout).is_empty() {
                let probe = xylem(&[words[0].as_str(), "--help"], tmp.path());
                let sub = String::from_utf8_lossy(&probe.stdout).contains(&format!("  {second} "));
                if sub {
                    path.push(second);
                }
            }
        }
        let help_args: Vec<&str> = path.iter().copied().chain(["--help"]).collect();
        let o = xylem(&help_args, tmp.path());
        let help = String::from_utf8_lossy(&o.stdout);
        assert!(
            o.status.success(),
            "README: xylem {words:?}: no such command"
        );
        for w in words.iter().filter(|w| w.starts_with("--")) {
            let flag = w.split('=').next().unwrap();
            assert!(
                help.contains(&format!("{flag} "))
                    || help.contains(&format!("{flag}\n"))
                    || help.contains(&format!("{flag} <")),
                "README: xylem {}: no option {flag}",
                words.join(" ")
            );
        }
    }
}

#[test]
fn readme_preset_commands_run_as_written() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let repo = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
    // The README's `cp scenes/presets/cherry.toml my_wood.toml`, then its texture command.
    std::fs::copy(
        repo.join("scenes/presets/cherry.toml"),
        dir.join("my_wood.toml"),
    )
    .unwrap();
    let readme = std::fs::read_to_string(repo.join("README.md")).unwrap();
    assert!(readme.contains("cp scenes/presets/cherry.toml my_wood.toml"));
    for words in readme_commands().into_iter().filter(|w| {
        w[0] == "texture" && w.iter().any(|a| a.starts_with("--preset"))
            || w[..] == ["preset", "list"]
    }) {
        let mut args: Vec<&str> = words.iter().map(String::as_str).collect();
        // A quick look: --res 32 in place of the README's.
        if args[0] == "texture" {
            match args.iter().position(|a| *a == "--res") {
                Some(i) => args[i + 1] = "32",
                None => args.extend(["--res", "32"]),
            }
        }
        let o = xylem(&args, dir);
        assert!(
            o.status.success(),
            "README: xylem {}: {}",
            words.join(" "),
            String::from_utf8_lossy(&o.stderr)
        );
    }
    assert!(dir.join("mine.png").exists());
}

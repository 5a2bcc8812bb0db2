//! The Python side of the integration tests: the pinned virtual environment in
//! target/python-venv and the libLLVM that Mitsuba's LLVM variants need. Shared by
//! crates/xylem-cli/tests/python.rs and crates/xylem-cli/tests/crosscheck.rs.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

pub fn run(cmd: &mut Command, what: &str, hint: &str) {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("{what}: cannot run {cmd:?}: {e}. {hint}"));
    if !out.status.success() {
        panic!(
            "{what} failed ({}): {cmd:?}\n--- stdout\n{}\n--- stderr\n{}\n{hint}",
            out.status,
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// The virtual environment with the pinned test requirements, made once and reused while the
/// requirements file is unchanged. Test threads and processes take turns through a lock file,
/// and a venv without the stamp of the wanted requirements (new, changed, or left half-made by a
/// killed run) is made afresh (`venv --clear`) before pip installs into it.
pub fn venv() -> PathBuf {
    let venv = root().join("target/python-venv");
    let python = venv.join("bin/python");
    std::fs::create_dir_all(root().join("target")).expect("target/");
    let lock = std::fs::File::create(root().join("target/python-venv.lock"))
        .expect("target/python-venv.lock");
    lock.lock().expect("locking target/python-venv.lock");
    let req = root().join("python/requirements-test.txt");
    let wanted = std::fs::read_to_string(&req).expect("python/requirements-test.txt");
    let stamp = venv.join("xylem-requirements.txt");
    if std::fs::read_to_string(&stamp).ok().as_deref() != Some(wanted.as_str()) {
        let base = std::env::var("XYLEM_PYTHON").unwrap_or_else(|_| "python3".into());
        run(
            Command::new(&base).args(["-m", "venv", "--clear"]).arg(&venv),
            "creating target/python-venv",
            "Python 3.11+ with venv is needed (Debian: apt-get install python3 python3-venv; or set XYLEM_PYTHON)",
        );
        run(
            Command::new(&python)
                .args([
                    "-m",
                    "pip",
                    "install",
                    "--quiet",
                    "--disable-pip-version-check",
                    "-r",
                ])
                .arg(&req),
            "installing python/requirements-test.txt",
            "pip needs the package index (PyPI) to install numpy, pytest and mitsuba",
        );
        std::fs::write(&stamp, wanted).unwrap();
    }
    venv
}

/// libLLVM for Dr.Jit's LLVM backend (Mitsuba's llvm_* variants).
pub fn libllvm() -> Option<PathBuf> {
    if let Ok(p) = std::env::var("DRJIT_LIBLLVM_PATH") {
        return Some(PathBuf::from(p));
    }
    let dirs = [
        "/usr/lib/x86_64-linux-gnu",
        "/usr/lib/aarch64-linux-gnu",
        "/usr/lib/llvm-19/lib",
    ];
    let names = ["libLLVM-19.so", "libLLVM.so.19.1", "libLLVM.so"];
    dirs.iter()
        .flat_map(|d| names.iter().map(move |n| Path::new(d).join(n)))
        .find(|p| p.exists())
}

/// The package as pip would install it: python/xylem/*.py, *.pyi, py.typed and the extension module that this
/// `cargo test` built (the `_xylem` example, from python/src/lib.rs) in target/python-test/site.
pub fn stage_package(dir: &Path) -> PathBuf {
    let exe = std::env::current_exe().expect("test binary path");
    // target/<profile>/deps/python-<hash> → target/<profile>/examples/lib_xylem.so
    let profile = exe
        .parent()
        .and_then(Path::parent)
        .expect("target/<profile>");
    let ext = profile.join("examples/lib_xylem.so");
    assert!(
        ext.exists(),
        "{} is missing: `cargo test --release` builds it as the `_xylem` example (when selecting tests, build it first: `cargo build --release --example _xylem`)",
        ext.display()
    );
    let site = dir.join("site");
    let pkg = site.join("xylem");
    std::fs::create_dir_all(&pkg).unwrap();
    for entry in std::fs::read_dir(root().join("python/xylem")).unwrap() {
        let p = entry.unwrap().path();
        // Sources, type stubs and the PEP 561 marker, as the wheel carries them.
        let name = p.file_name().unwrap().to_string_lossy();
        if p.extension().is_some_and(|e| e == "py" || e == "pyi") || name == "py.typed" {
            std::fs::copy(&p, pkg.join(p.file_name().unwrap())).unwrap();
        }
    }
    std::fs::copy(&ext, pkg.join("_xylem.abi3.so")).unwrap();
    site
}

//! The Python package (`pip install .`, PyO3 + maturin) and its pytest
//! suite, run by `cargo test` so that the README's one test command covers
//! them: builds the wheel into a virtual environment under `target/`
//! (kept between runs; pip and cargo cache what did not change), installs
//! the `fleet` and `test` extras, and runs `python/tests` (numpy in and out,
//! the same numbers as this crate's `friction-node` binary, exceptions for
//! bad input, the fleet functions on a two-worker local Dask cluster on
//! loopback).
//!
//! Needs Python 3.9+ with `venv` and the package registry (PyPI), as CI
//! has; `PYTHON` chooses the interpreter (default `python3`). A missing
//! interpreter fails the test with the reason: it is never skipped.

// The suite compares with the binary's replay (feature `mcap`) and drives a
// node over iceoryx2: it runs with the default features.
#![cfg(all(feature = "mcap", feature = "iceoryx2"))]

use std::path::{Path, PathBuf};
use std::process::Command;

fn run(cmd: &mut Command, what: &str) {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("{what}: cannot start {cmd:?}: {e}"));
    assert!(
        out.status.success(),
        "{what} failed ({}):\n--- stdout\n{}\n--- stderr\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

fn venv_python(venv: &Path) -> PathBuf {
    venv.join("bin").join("python")
}

#[test]
fn the_python_package_builds_with_pip_and_its_pytest_suite_passes() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let venv = repo.join("target").join("python-venv");
    let python = std::env::var("PYTHON").unwrap_or_else(|_| "python3".into());
    if !venv_python(&venv).exists() {
        run(
            Command::new(&python).args(["-m", "venv"]).arg(&venv),
            "creating the virtual environment (python3 -m venv)",
        );
    }
    let py = venv_python(&venv);
    // The package and its extras from this checkout (maturin builds the
    // Rust extension in release mode), and the MCAP writer the bag
    // fixtures use.
    run(
        Command::new(&py)
            .args([
                "-m",
                "pip",
                "install",
                "--quiet",
                "--disable-pip-version-check",
                ".[fleet,test]",
                "mcap-ros2-support==0.*",
                "dask[dataframe]",
            ])
            .current_dir(repo)
            // The nested cargo (maturin's) must not take this test run's
            // settings for its own.
            .env_remove("CARGO_TARGET_DIR")
            .env_remove("RUSTFLAGS"),
        "pip install '.[fleet,test]'",
    );
    let tmp = std::env::temp_dir().join(format!("fn-pytest-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).expect("a temporary directory");
    run(
        Command::new(&py)
            .args([
                "-m",
                "pytest",
                "-q",
                "-p",
                "no:cacheprovider",
                "--import-mode=importlib",
            ])
            .arg(repo.join("python").join("tests"))
            .env("FRICTION_NODE_BIN", env!("CARGO_BIN_EXE_friction-node"))
            // Import the installed package, never the source tree.
            .current_dir(&tmp),
        "pytest python/tests",
    );
    let _ = std::fs::remove_dir_all(&tmp);
}

//! Running the binary from a test: the command, a fresh directory per
//! test, and a run's exit code and output.

use std::ops::Deref;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The `friction-node` binary this test suite was built with.
pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_friction-node"))
}

/// A test's own directory, removed with everything in it when the test
/// ends (passing or panicking), so a test run leaves nothing in the
/// temporary directory.
pub struct FreshDir(PathBuf);

impl Deref for FreshDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for FreshDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for FreshDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// An empty directory of its own for test `name` of `suite`:
/// `<temp>/fn-<suite>-<pid>-<name>`, emptied if it was there, removed
/// when the returned guard drops.
pub fn fresh_dir(suite: &str, name: &str) -> FreshDir {
    let d = std::env::temp_dir().join(format!("fn-{suite}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    FreshDir(d)
}

/// Runs the binary with `args`: (exit code, stdout, stderr); the code is
/// −1 when a signal ended it.
pub fn run(args: &[&str]) -> (i32, String, String) {
    let o = bin().args(args).output().unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// `fit DATA --fit KEYS` as the quick tests run it (one local run, no
/// global phase, 32 cells), written to `out`, with `extra` arguments after:
/// (exit code, stdout, stderr).
pub fn quick_fit(data: &Path, keys: &str, out: &Path, extra: &[&str]) -> (i32, String, String) {
    let mut args = vec!["fit", data.to_str().unwrap(), "--fit", keys];
    args.extend(["--starts", "1", "--global-points", "0"]);
    args.extend(["--set", "solver.cells=32", "--out", out.to_str().unwrap()]);
    args.extend_from_slice(extra);
    run(&args)
}

/// `fit --rotary --fit auto` of the joint fixture `name`
/// (`tests/fixtures/{name}-train.csv`, copied into a fresh directory of
/// `suite`, validated on `{name}-validate.csv`), with `extra` arguments:
/// (exit code, stdout, stderr).
pub fn fit_joint_fixture(suite: &str, name: &str, extra: &[&str]) -> (i32, String, String) {
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let d = fresh_dir(suite, name);
    let train = d.join("train.csv");
    std::fs::copy(fixtures.join(format!("{name}-train.csv")), &train).unwrap();
    let validate = fixtures.join(format!("{name}-validate.csv"));
    let out = d.join("f.yaml");
    let mut args = vec![
        "fit",
        train.to_str().unwrap(),
        "--validate",
        validate.to_str().unwrap(),
        "--rotary",
        "--fit",
        "auto",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    run(&args)
}

/// The value in column `col` of `model`'s row in a fit's models table.
pub fn models_cell(stdout: &str, model: &str, col: usize) -> String {
    let row = stdout
        .lines()
        .find(|l| l.starts_with(&format!("| {model} |")))
        .unwrap_or_else(|| panic!("no row {model}: {stdout}"));
    row.split('|').nth(col).unwrap().trim().to_string()
}

/// The held-out RMS of `model` in a fit's models table.
pub fn held_out(stdout: &str, model: &str) -> f64 {
    models_cell(stdout, model, 7).parse().unwrap()
}

/// The value ours fitted to `key`, read from its row of the models table.
pub fn fitted_key(stdout: &str, key: &str) -> f64 {
    let keys = models_cell(stdout, "friction-node", 3);
    keys.split(&format!("{key}="))
        .nth(1)
        .and_then(|s| s.split([',', ' ']).next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no {key} in {keys}"))
}

/// The line of `--fit auto`'s output that names the chosen set.
pub fn chosen(stdout: &str) -> &str {
    stdout
        .lines()
        .find(|l| l.starts_with("Chosen: "))
        .unwrap_or_else(|| panic!("no chosen set: {stdout}"))
}

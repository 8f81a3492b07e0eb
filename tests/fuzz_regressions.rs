//! Inputs the fuzzers (fuzz/) found crashing, out-of-memory or timing out,
//! each run again through the code its target exercises. `fuzz/README.md`
//! says how to add one.

use std::path::{Path, PathBuf};

/// Every file in `folder` (relative to the repository), sorted; the folder
/// must exist and hold at least one file, so that a moved or emptied folder
/// fails here instead of passing on nothing.
fn files_in(folder: &str) -> Vec<PathBuf> {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join(folder);
    let mut v: Vec<PathBuf> = std::fs::read_dir(&d)
        .unwrap_or_else(|e| panic!("{}: {e}", d.display()))
        .map(|r| r.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    assert!(!v.is_empty(), "{} holds no input", d.display());
    v.sort();
    v
}

/// The inputs the fuzzer found for `target` (crashes, out-of-memory, timeouts).
#[cfg(feature = "mcap")]
fn inputs(target: &str) -> Vec<PathBuf> {
    files_in(&format!("tests/fuzz_regressions/{target}"))
}

#[cfg(feature = "mcap")]
#[test]
fn replay_inputs_the_fuzzer_found_are_refused_or_replayed_without_a_crash() {
    use friction_node::bag::Bag;
    use friction_node::replay::{self, ReplayOptions};
    let files = inputs("replay");
    for f in files {
        let bytes = std::fs::read(&f).unwrap();
        let Ok(bag) = Bag::from_bytes(&f, bytes) else {
            continue;
        };
        let opts = ReplayOptions {
            overrides: vec!["solver.cells=16".into()],
            ..Default::default()
        };
        if let Ok(mut p) = replay::prepare(&bag, &opts) {
            p.commands.truncate(200);
            p.recorded.truncate(200);
            let _ = replay::run(&p, &mut |_, _| Ok(()), &mut |_, _, _| {});
        }
    }
}

/// The config fuzzer has found nothing (fuzz/README.md), so there is no
/// regression folder for it; its minimized corpus (the shipped parameter
/// files and what the fuzzer kept for coverage) is run instead.
#[test]
fn config_inputs_of_the_fuzz_corpus_load_or_are_refused() {
    use friction_node::config::{Config, Origin};
    let files = files_in("fuzz/corpus/config");
    let mut loaded = 0;
    for f in &files {
        let Ok(text) = std::fs::read_to_string(f) else {
            continue;
        };
        if let Ok(c) = Config::from_yaml(&text, &Origin::Embedded, &[]) {
            c.validate()
                .unwrap_or_else(|e| panic!("{} loads but does not validate: {e}", f.display()));
            loaded += 1;
        }
    }
    // The shipped parameter files are among the seeds: they must load.
    assert!(loaded > 0, "none of {} config inputs loaded", files.len());
}

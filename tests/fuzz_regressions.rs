//! Inputs the fuzzers (fuzz/) found crashing, out-of-memory or timing out,
//! each run again through the code its target exercises. `fuzz/README.md`
//! says how to add one.

use std::path::{Path, PathBuf};

fn inputs(target: &str) -> Vec<PathBuf> {
    let d = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz_regressions")
        .join(target);
    let mut v: Vec<PathBuf> = std::fs::read_dir(&d)
        .map(|r| r.map(|e| e.unwrap().path()).collect())
        .unwrap_or_default();
    v.sort();
    v
}

#[cfg(feature = "mcap")]
#[test]
fn replay_inputs_the_fuzzer_found_are_refused_or_replayed_without_a_crash() {
    use friction_node::bag::Bag;
    use friction_node::replay::{self, ReplayOptions};
    let files = inputs("replay");
    assert!(!files.is_empty());
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

#[test]
fn config_inputs_the_fuzzer_found_load_or_are_refused() {
    use friction_node::config::{Config, Origin};
    for f in inputs("config") {
        if let Ok(text) = std::fs::read_to_string(&f) {
            if let Ok(c) = Config::from_yaml(&text, &Origin::Embedded, &[]) {
                c.validate().unwrap();
            }
        }
    }
}

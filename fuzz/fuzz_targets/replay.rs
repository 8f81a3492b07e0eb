//! Replay of an arbitrary byte string as an MCAP bag: refused with an
//! error, or replayed (at most 200 steps on a coarse grid) with finite or
//! flagged estimates; never a panic.
#![no_main]
use friction_node::bag::Bag;
use friction_node::replay::{self, ReplayOptions};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(bag) = Bag::from_bytes(Path::new("fuzz.mcap"), data.to_vec()) else {
        return;
    };
    let opts = ReplayOptions {
        overrides: vec!["solver.cells=16".into()],
        ..Default::default()
    };
    let Ok(mut p) = replay::prepare(&bag, &opts) else {
        return;
    };
    p.commands.truncate(200);
    p.recorded.truncate(200);
    if let Ok(r) = replay::run(&p, &mut |_, _| {}, &mut |_, _, _| {}) {
        for (_, rec) in &r.estimates {
            assert!(rec.friction_force_n.is_finite() || rec.status != 0);
        }
    }
});

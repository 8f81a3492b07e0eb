//! `csv:` tables: an error with a line number, or a table that evaluates to
//! finite values everywhere.
#![no_main]
use friction_node::signal::parse_table;
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if data.is_empty() {
        return;
    }
    let column = match data[0] % 3 {
        0 => None,
        1 => Some("v"),
        _ => Some("load_n"),
    };
    if let Ok(text) = std::str::from_utf8(&data[1..]) {
        if let Ok(s) = parse_table(text, Path::new("fuzz.csv"), column, "velocity") {
            for t in [-1.0, 0.0, 0.37, 1e3, f64::MAX] {
                assert!(s.at(t).is_finite());
            }
            let (lo, hi) = s.range();
            assert!(lo <= hi);
        }
    }
});

//! `--set` overrides on the default configuration: an error naming the
//! override or a validated configuration.
#![no_main]
use friction_node::config::{Config, Origin, DEFAULT_YAML};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let sets: Vec<String> = text.split('\n').map(str::to_string).collect();
        if let Ok(c) = Config::from_yaml(DEFAULT_YAML, &Origin::Embedded, &sets) {
            c.validate().expect("a loaded configuration validates");
        }
    }
});

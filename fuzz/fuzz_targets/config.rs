//! The configuration loader on arbitrary text: an error or a validated
//! configuration, never a panic.
#![no_main]
use friction_node::config::{Config, Origin};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(c) = Config::from_yaml(text, &Origin::Embedded, &[]) {
            // A configuration that loads is valid and round-trips.
            c.validate().expect("a loaded configuration validates");
            let again = Config::from_yaml(&c.to_yaml(), &Origin::Embedded, &[])
                .expect("the resolved configuration reloads");
            assert_eq!(again, c);
        }
    }
});

//! `include/friction_node.h` is what cbindgen generates from `src/lib.rs`
//! today. `FRICTION_NODE_BLESS=1` rewrites it.

use std::path::Path;

#[test]
fn the_checked_in_c_header_is_current() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let bindings = cbindgen::Builder::new()
        .with_config(config)
        .with_src(dir.join("src/lib.rs"))
        .generate()
        .expect("cbindgen parses src/lib.rs");
    let mut generated = Vec::new();
    bindings.write(&mut generated);
    let generated = String::from_utf8(generated).unwrap();
    let path = dir.join("include/friction_node.h");
    if std::env::var_os("FRICTION_NODE_BLESS").is_some() {
        std::fs::write(&path, &generated).unwrap();
    }
    let checked_in = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        checked_in == generated,
        "capi/include/friction_node.h is not current: run \
         FRICTION_NODE_BLESS=1 cargo test -p friction-node-capi --test header"
    );
}

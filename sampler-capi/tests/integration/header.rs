//! `include/ppis.h` is what cbindgen makes of the sources: CI fails when it is stale.
//! `PPIS_BLESS=1 cargo test -p sampler-capi --test integration header` rewrites it.

use std::path::Path;

#[test]
fn the_checked_in_header_is_current() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_config(config)
        // cbindgen follows lib.rs's `mod` declarations.
        .with_src(dir.join("src/lib.rs"))
        .generate()
        .expect("cbindgen parses the sources")
        .write(&mut generated);
    let path = dir.join("include/ppis.h");
    if std::env::var_os("PPIS_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("write the header");
    }
    let checked_in = std::fs::read(&path).unwrap_or_default();
    assert!(
        checked_in == generated,
        "sampler-capi/include/ppis.h is stale: run `PPIS_BLESS=1 cargo test -p sampler-capi --test integration header`"
    );
}

//! `include/msp.h` is what cbindgen makes of the sources: the test
//! regenerates it and fails when the committed header differs
//! (`MSP_WRITE_HEADER=1 cargo test` writes it).
//!
//! The entry points of both precisions come from one macro, so cbindgen
//! reads the crate as the compiler expands it (`cargo rustc --
//! -Zunpretty=expanded`, `[parse.expand]` in `cbindgen.toml`). That printer is
//! a flag of the nightly compiler; `RUSTC_BOOTSTRAP=1` lets the pinned stable
//! compiler run it for this one child process, in its own target directory.

#[test]
fn the_committed_header_is_up_to_date() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml"))?;
    // read by the `cargo rustc` that cbindgen starts (this test's only child)
    std::env::set_var("RUSTC_BOOTSTRAP", "1");
    std::env::set_var(
        "CARGO_EXPAND_TARGET_DIR",
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("expand"),
    );
    let mut fresh = Vec::new();
    cbindgen::Builder::new()
        .with_crate(dir)
        .with_config(config)
        .generate()?
        .write(&mut fresh);
    let path = dir.join("include/msp.h");
    if std::env::var_os("MSP_WRITE_HEADER").is_some() {
        std::fs::write(&path, &fresh)?;
    }
    let committed = std::fs::read(&path).unwrap_or_default();
    assert!(
        committed == fresh,
        "include/msp.h is out of date: run `MSP_WRITE_HEADER=1 cargo test --manifest-path crates/msp-c/Cargo.toml --test header`"
    );
    Ok(())
}

//! Copies the memory layout for the linker and computes the host's f64
//! reference runs with the same loop code the firmware runs in f32.
#![allow(dead_code)]

use std::io::Write;

#[path = "src/loops.rs"]
mod loops;
#[path = "src/mimo.rs"]
mod mimo;

fn main() {
    let out = std::path::PathBuf::from(std::env::var("OUT_DIR").expect("OUT_DIR"));
    std::fs::copy("memory.x", out.join("memory.x")).expect("memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=src/loops.rs");
    println!("cargo:rerun-if-changed=src/mimo.rs");
    let (mut c, mut p) = loops::smith::<f64>();
    let smith = loops::run(&mut c, &mut p, |_| {});
    let (mut c, mut p) = loops::karan_dey::<f64>();
    let kd = loops::run(&mut c, &mut p, |_| {});
    let (mut c, mut p) = loops::fsp::<f64>();
    let fsp = loops::run(&mut c, &mut p, |_| {});
    let (mut c, mut p) = loops::smith_operated::<f64>();
    let operated = loops::run_operated(
        &mut c,
        &mut p,
        |_| {},
        |c, r, y| {
            use msp::Controller;
            c.update(r, y)
        },
    );
    let (mut c, mut p) = loops::smith_adaptive::<f64>();
    let adaptive = loops::run(&mut c, &mut p, |_| {});
    let (mut c, mut p) = mimo::decentralized::<f64>();
    let decentralized = mimo::run(&mut c, &mut p);
    let (mut c, mut p) = mimo::decoupled::<f64>();
    let decoupled = mimo::run(&mut c, &mut p);
    let mut f = std::fs::File::create(out.join("reference.rs")).expect("reference.rs");
    writeln!(
        f,
        "pub const DECENTRALIZED: [f64; {}] = {:?};",
        decentralized.len(),
        decentralized
    )
    .expect("write");
    writeln!(
        f,
        "pub const DECOUPLED: [f64; {}] = {:?};",
        decoupled.len(),
        decoupled
    )
    .expect("write");
    writeln!(f, "pub const SMITH: [f64; {}] = {:?};", smith.len(), smith).expect("write");
    writeln!(f, "pub const KARAN_DEY: [f64; {}] = {:?};", kd.len(), kd).expect("write");
    writeln!(f, "pub const FSP: [f64; {}] = {:?};", fsp.len(), fsp).expect("write");
    writeln!(
        f,
        "pub const ADAPTIVE: [f64; {}] = {:?};",
        adaptive.len(),
        adaptive
    )
    .expect("write");
    writeln!(
        f,
        "pub const OPERATED: [f64; {}] = {:?};",
        operated.len(),
        operated
    )
    .expect("write");
}

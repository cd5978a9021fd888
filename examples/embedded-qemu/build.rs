//! For the bare-metal build only: puts `memory.x` (the mps2-an386 memory map) where
//! cortex-m-rt's `link.x` finds it and links the binary with `link.x`. Host builds (the stub
//! binary and the qemu test) link as usual.
//!
//! `RAYTRAIL_QEMU_ONLY` narrows the program for footprint measurements (`footprint.sh`): unset,
//! it runs everything; `none`, only the measuring scaffold; `N`, that and method `METHODS[N]`
//! alone, so the linker keeps only that method's code.

use std::path::PathBuf;

fn main() {
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed={ONLY_ENV}");
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none") {
        return;
    }
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    std::fs::copy("memory.x", out.join("memory.x")).expect("copy memory.x to OUT_DIR");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    let only = match std::env::var(ONLY_ENV).ok().filter(|s| !s.is_empty()).as_deref() {
        None => "Only::Everything".to_string(),
        Some("none") => "Only::Nothing".to_string(),
        Some(n) => match n.parse::<usize>() {
            Ok(i) => format!("Only::Method({i})"),
            Err(_) => panic!("{ONLY_ENV}={n}: expected `none` or an index into METHODS"),
        },
    };
    let code = format!("/// What this build runs (`{ONLY_ENV}`, see build.rs).\nconst ONLY: Only = {only};\n");
    std::fs::write(out.join("only.rs"), code).expect("write only.rs");
}

/// Environment variable that narrows the program (see the module docs).
const ONLY_ENV: &str = "RAYTRAIL_QEMU_ONLY";

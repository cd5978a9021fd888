//! The embedded example on a Cortex-M4F: traces the self-test grid with every method the flash
//! tables offer and prints, over semihosting, one line per method (hits, work, digest), the grid's
//! digest, the instructions each method spends per ray and its peak stack, then exits with the
//! self-test's verdict. Built for `thumbv7em-none-eabihf` it runs under
//! `qemu-system-arm -M mps2-an386`; `tests/qemu.rs` runs it and compares its lines with the host's.
//!
//! On the host this is a stub that prints the host's report: the reference the device must match.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod device;
#[cfg(target_os = "none")]
mod measure;

#[cfg(not(target_os = "none"))]
fn main() {
    println!("raytrail-embedded-qemu is a Cortex-M4F program; build it with --target thumbv7em-none-eabihf and run it");
    println!("under qemu-system-arm -M mps2-an386 (see examples/embedded-qemu/README.md). The host's report, which");
    println!("the device's must equal line for line:");
    match raytrail_embedded_example::grid_report() {
        Some(r) => println!("{r}"),
        None => {
            eprintln!("the baked tables do not validate");
            std::process::exit(1);
        }
    }
}

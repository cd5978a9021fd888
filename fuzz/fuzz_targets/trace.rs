#![no_main]
// Any triangles and rays trace to the serial backend's hits on the CPU's walks (cli/src/fuzz.rs, `trace`).
libfuzzer_sys::fuzz_target!(|data: &[u8]| raytrail_cli::fuzz::trace(data));

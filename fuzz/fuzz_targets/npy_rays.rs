#![no_main]
// Reading any bytes as a NumPy ray file ends in rays or an error (cli/src/fuzz.rs, `npy_rays`).
libfuzzer_sys::fuzz_target!(|data: &[u8]| raytrail_cli::fuzz::npy_rays(data));

#![no_main]
// Loading any bytes as `x.obj` ends in a mesh or an error (cli/src/fuzz.rs, `mesh_file`).
libfuzzer_sys::fuzz_target!(|data: &[u8]| raytrail_cli::fuzz::mesh_file("x.obj", data));

//! cargo-fuzz target: see penumbra_fuzz::harness::ply.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| penumbra_fuzz::harness::ply(data));

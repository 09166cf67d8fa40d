//! cargo-fuzz target: see penumbra_fuzz::harness::obj.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| penumbra_fuzz::harness::obj(data));

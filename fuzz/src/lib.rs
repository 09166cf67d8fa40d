//! The fuzz targets' shared harness (also compiled into tests/fuzz_replay.rs).

#[path = "harness.rs"]
pub mod harness;

//! Issue 56's `stl_solids` class from fuzz bytes (see `input_classes.rs`, shared with the stable
//! driver `tests/it/fuzz_drive.rs`).
#![no_main]
use libfuzzer_sys::fuzz_target;

#[path = "input_classes.rs"]
mod input_classes;

fuzz_target!(|data: &[u8]| input_classes::stl_solids(data));

//! Issue 56's `obj_polygons` class from fuzz bytes (see `issue56.rs`, shared with the stable driver
//! `tests/it/fuzz_drive.rs`).
#![no_main]
use libfuzzer_sys::fuzz_target;

#[path = "issue56.rs"]
mod issue56;

fuzz_target!(|data: &[u8]| issue56::obj_polygons(data));

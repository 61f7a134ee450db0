//! Issue 56's `scenario_name` class from fuzz bytes (see `input_classes.rs`, shared with the stable
//! driver `tests/it/fuzz_drive.rs`).
#![no_main]
use libfuzzer_sys::fuzz_target;

#[path = "input_classes.rs"]
mod input_classes;

fuzz_target!(|data: &[u8]| {
    let scenarios = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenarios");
    input_classes::scenario_name(data, &scenarios);
});

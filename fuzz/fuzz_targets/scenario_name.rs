//! Issue 56's `scenario_name` class from fuzz bytes (see `issue56.rs`, shared with the stable driver
//! `tests/it/fuzz_drive.rs`).
#![no_main]
use libfuzzer_sys::fuzz_target;

#[path = "issue56.rs"]
mod issue56;

fuzz_target!(|data: &[u8]| {
    let scenarios = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenarios");
    issue56::scenario_name(data, &scenarios);
});

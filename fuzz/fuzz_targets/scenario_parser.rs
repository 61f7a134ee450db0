//! Any text as a scenario file (beside the bundled ones, so the thesis hand resolves): an error
//! or a validated scenario, never a panic.
#![no_main]
use grasp_sim::scenario::Scenario;
use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenarios/fuzz.toml");
        if let Ok(s) = Scenario::parse(text, &path) {
            assert!(s.planner.height_step_mm > 0.0);
            assert!(s.object.friction > 0.0);
        }
    }
});

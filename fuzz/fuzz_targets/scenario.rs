//! Any text as a scenario file (beside the bundled ones, so the thesis hand and the bundled
//! meshes resolve): an error or a validated scenario, never a panic; a scenario that parses has
//! its mesh loaded in its units and taken on to the slicer and the union.
#![no_main]
use grasp_sim::mesh::load_mesh;
use grasp_sim::scenario::Scenario;
use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;

#[path = "reach.rs"]
mod reach;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenarios/fuzz.toml");
    if let Ok(s) = Scenario::parse(text, &path) {
        assert!(s.planner.height_step_mm > 0.0);
        assert!(s.object.friction > 0.0 && s.object.friction <= 2.0);
        if s.object.mesh.extension().is_some_and(|e| e != "urdf") {
            if let Ok(loaded) = load_mesh(&s.object.mesh, s.object.units) {
                reach::reach(&loaded.mesh);
            }
        }
    }
});

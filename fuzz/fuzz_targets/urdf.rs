//! Any bytes as an object's URDF (written to a file beside the bundled meshes, so that
//! `package://` and relative mesh names resolve): an error or a valid mesh, never a panic, hang
//! or memory blow-up; a mesh that loads goes on to the slicer and the union.
#![no_main]
use grasp_sim::mesh::urdf::load_urdf;
use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;

#[path = "reach.rs"]
mod reach;

fuzz_target!(|data: &[u8]| {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets/objects");
    let path = dir.join(format!(".fuzz-{}.urdf", std::process::id()));
    if std::fs::write(&path, data).is_err() {
        return;
    }
    let loaded = load_urdf(&path);
    let _ = std::fs::remove_file(&path);
    if let Ok(loaded) = loaded {
        reach::reach(&loaded.mesh);
    }
});

//! Any bytes as a PLY file: an error or a valid mesh, never a panic, hang or memory blow-up; a
//! mesh that loads goes on to the slicer and the union ([`reach::reach`]).
#![no_main]
use grasp_sim::mesh::{parse_mesh, LengthUnit, MeshFormat};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

#[path = "reach.rs"]
mod reach;

fuzz_target!(|data: &[u8]| {
    if let Ok(loaded) = parse_mesh(data, Path::new("fuzz.ply"), MeshFormat::Ply, LengthUnit::Mm) {
        assert!(loaded.mesh.vertices.iter().all(|p| p.iter().all(|c| c.is_finite())));
        reach::reach(&loaded.mesh);
    }
});

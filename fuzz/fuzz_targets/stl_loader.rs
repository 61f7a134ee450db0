//! Any bytes as an STL file: an error or a valid mesh, never a panic; a mesh that loads can be
//! aligned and sliced.
#![no_main]
use grasp_sim::mesh::{align, parse_stl, LengthUnit};
use grasp_sim::slice::{slice, Plane, SliceOptions};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if let Ok(loaded) = parse_stl(data, Path::new("fuzz.stl"), LengthUnit::Mm) {
        assert!(loaded.mesh.vertices.iter().all(|p| p.iter().all(|c| c.is_finite())));
        let a = align(&loaded.mesh);
        assert!(a.height_mm.is_finite());
        let _ = slice(
            &a.mesh,
            &Plane::horizontal(a.height_mm / 2.0),
            SliceOptions::default(),
        );
    }
});

//! What every reader's fuzz target does with a mesh that loads (issue 32): the union-based mass
//! properties (slices united), the alignment, and a few horizontal and vertical cuts, each
//! joined and bridged (the open-end join, the union and the gap closing), checking that every
//! number that comes out is finite. Included by the targets with `#[path]`.

use grasp_sim::mesh::{align, sliced_mass_properties, Mesh};
use grasp_sim::slice::{Plane, SliceOptions};

/// The slicer and the union on `mesh`: no panic, finite results.
pub fn reach(mesh: &Mesh) {
    let m = sliced_mass_properties(mesh, 6);
    assert!(m.volume_mm3.is_finite(), "volume {}", m.volume_mm3);
    let a = align(mesh);
    assert!(a.height_mm.is_finite());
    let planes = [
        Plane::horizontal(a.height_mm * 0.25),
        Plane::horizontal(a.height_mm * 0.5),
        Plane::horizontal(a.height_mm * 0.75),
        Plane::vertical(0.0),
        Plane::vertical(1.0),
    ];
    for plane in &planes {
        let s = grasp_sim::slice::slice(&a.mesh, plane, SliceOptions::default());
        let joined = s.clone().joined(1.0);
        let bridged = s.bridged_within(5.0, 0.2);
        for c in joined.contours.iter().chain(&bridged.contours) {
            assert!(c.points.iter().all(|p| p.x.is_finite() && p.y.is_finite()));
        }
    }
}

//! Plane ∩ mesh: closed contours with projected outward normals (thesis 3.3.1, Fig. 3.2–3.4).
//!
//! The front door of the slicer, which lives in [`crate::mesh::slice`]: loading a mesh already
//! needs it (the union of overlapping shells is measured slice by slice, so its volume decides
//! the mesh's orientation), and a mesh module below the slicer would otherwise call up into it.
//! The planner, the tests and the benches reach it here.

pub use crate::mesh::slice::*;

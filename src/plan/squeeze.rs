//! The push a grasp's squeeze puts on its object along the grasp axis.
//!
//! The thesis grades a finger on a surface steeper than the friction cone (atan μ from the axis)
//! as ungraspable (its Cat_5): pressed there, the finger pushes the object along the axis more
//! than friction holds back. The rules beyond the thesis grade such elevations instead (balls,
//! mugs and bowls get a grasp only so), where the pushes of contacts on either side of a
//! waist or an equator balance. On a wedge, a pyramid or a cube held on an edge they all lean
//! one way and the squeeze pushes the object out of the hand: none of 16 such candidates held
//! on MyoSuite's pyramids, cube and teapot (docs/studies/2026-12-06-axial-squeeze.md). This
//! module applies the thesis's cone to the net push of all the planned contacts together.

use std::sync::OnceLock;

use nalgebra::{Point3, Vector3};
use parry3d::bounding_volume::Aabb;
use parry3d::math::Vector;
use parry3d::query::PointQuery;
use parry3d::shape::TriMesh;

use crate::mesh::Mesh;
use crate::plan::contacts::Contact;

/// Triangles within this much of a contact's nearest one count towards its surface normal
/// `[mm]`: a contact on an edge or a fine facet takes the area-weighted normal of the patch.
const PATCH_MM: f64 = 0.5;

/// The surface of a mesh, indexed for the nearest triangles to a point; the index is built
/// when first needed.
pub struct Surface<'a> {
    mesh: &'a Mesh,
    index: OnceLock<Option<TriMesh>>,
}

impl<'a> Surface<'a> {
    /// `mesh` in the frame its contacts are given in (the aligned frame, mm).
    pub fn new(mesh: &'a Mesh) -> Surface<'a> {
        Surface {
            mesh,
            index: OnceLock::new(),
        }
    }

    fn index(&self) -> Option<&TriMesh> {
        self.index
            .get_or_init(|| {
                let vertices = self.mesh.vertices.iter().map(to_f32).collect();
                TriMesh::new(vertices, self.mesh.triangles.clone()).ok()
            })
            .as_ref()
    }

    /// The surface's normal at `p`, the area-weighted normal of the triangles within
    /// [`PATCH_MM`] of the nearest one, unit, sensed against `push` (the direction the hand
    /// pushes there: the normal faces the hand). `None` where there is no index or no area.
    fn normal_at(&self, p: &Point3<f64>, push: &Vector3<f64>) -> Option<Vector3<f64>> {
        let index = self.index()?;
        let q = to_f32(p);
        let nearest = index.project_local_point(q, false);
        let reach = (nearest.point - q).length() + PATCH_MM as f32;
        let patch = Aabb::new(q - Vector::splat(reach), q + Vector::splat(reach));
        let mut sum = Vector3::zeros();
        for t in index.bvh().intersect_aabb(&patch) {
            let triangle = index.triangle(t);
            if triangle.distance_to_local_point(q, false) > reach {
                continue;
            }
            // Twice the area along the normal, so the sum weighs each triangle by its area.
            sum += self.mesh.area_normal(t as usize);
        }
        let n = sum.try_normalize(1e-12)?;
        Some(if n.dot(push) > 0.0 { -n } else { n })
    }
}

fn to_f32(p: &Point3<f64>) -> Vector {
    Vector::new(p.x as f32, p.y as f32, p.z as f32)
}

/// The tangent of the net push's lean from the plane across the axis Z: |Σ aᵢ| / Σ bᵢ over the
/// contacts, aᵢ the surface normal's component along Z and bᵢ its length across it (each
/// contact pressing with the same force). Above μ the squeeze pushes the object along the axis
/// harder than friction at the contacts can hold it. `None` without a contact whose normal is
/// known.
pub fn net_push_lean(surface: &Surface, contacts: &[Contact]) -> Option<f64> {
    let (mut along, mut across, mut counted) = (0.0, 0.0, 0);
    for c in contacts {
        let push = Vector3::from(c.normal);
        let Some(n) = surface.normal_at(&Point3::from(c.point_mm), &push) else {
            continue;
        };
        along += n.z;
        across += n.xy().norm();
        counted += 1;
    }
    (counted > 0).then(|| {
        if across > 0.0 {
            along.abs() / across
        } else {
            f64::INFINITY
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::primitives;

    fn contact(p: [f64; 3], push: [f64; 3]) -> Contact {
        Contact {
            point_mm: p,
            normal: push,
            finger: "f".into(),
            phalanx: 1,
            force_n: None,
        }
    }

    #[test]
    fn a_cylinder_balances_and_a_cone_pushes_out_by_its_slope() {
        // A cylinder's side: the normals lie across the axis, no push along it.
        let cylinder = primitives::cylinder(60.0, 80.0);
        let s = Surface::new(&cylinder);
        let on_side = [
            contact([30.0, 0.0, 40.0], [-1.0, 0.0, 0.0]),
            contact([-30.0, 0.0, 40.0], [1.0, 0.0, 0.0]),
        ];
        let lean = net_push_lean(&s, &on_side).unwrap();
        assert!(lean < 1e-6, "{lean}");
        // A frustum narrowing from 80 to 40 mm over 50 mm: its side leans by atan(20 / 50) from
        // the axis, and every contact on it pushes the same way: tan of the lean is 0.4.
        let cone = primitives::frustum(80.0, 40.0, 50.0);
        let s = Surface::new(&cone);
        let r = 30.0; // the radius at mid-height
        let around: Vec<Contact> = (0..3)
            .map(|k| {
                let t = f64::from(k) * std::f64::consts::TAU / 3.0 + 0.1;
                contact([r * t.cos(), r * t.sin(), 25.0], [-t.cos(), -t.sin(), 0.0])
            })
            .collect();
        let lean = net_push_lean(&s, &around).unwrap();
        assert!((lean - 0.4).abs() < 0.01, "{lean}");
        // One contact on the top face and one on the side: the top's normal is along the
        // axis (a = 1, b = 0).
        let top_and_side = [
            contact([0.0, 0.0, 50.0], [0.0, 0.0, -1.0]),
            around[0].clone(),
        ];
        let lean = net_push_lean(&s, &top_and_side).unwrap();
        let (a, b) = (0.4 / 1.16f64.sqrt(), 1.0 / 1.16f64.sqrt());
        assert!((lean - (1.0 + a) / b).abs() < 0.01, "{lean}");
    }
}

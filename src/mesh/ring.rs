//! Rings: objects whose centroid lies in a hole the material surrounds (a torus, a bangle, a
//! watch), and the arcs of their tube the planner searches before the whole object.
//!
//! The planner's axes pass through the centroid, which for a ring lies in its hole, so no axis
//! runs along the tube the way a hand holds a ring (docs/studies/2026-12-07-rings-on-an-arc.md:
//! on the random shapes' tori the first candidate held with 0.40–0.60). An arc is the part of
//! the ring within [`ARC_HALF_DEG`] of a direction in its plane, seen from its axis, each cut
//! closed by a fan: the planner grades and searches the arc about its own axis of least moment
//! (along the tube), and the physics check closes on the whole ring in that frame.

use nalgebra::{Point3, Vector3};

use super::align::{align_with_rule, AlignedObject, FrameRule, GraspAxis};
use super::{mass_properties, MassProperties, Mesh};

/// Half the angle an arc spans about the ring's axis `[deg]`: the arc of the study, whose
/// first grasp held best of ±35°, ±50° and ±70° on the tori it was chosen on.
pub const ARC_HALF_DEG: f64 = 50.0;

/// Whether `mesh` is a ring: the line through its centroid along the principal axis of the
/// largest moment meets no triangle, and each line through the centroid along the other two
/// axes crosses the surface on both sides, an even number of times on each (the centroid lies
/// outside the material, which surrounds it in the ring's plane). A cup or a bowl is not one
/// (the axis meets its bottom), nor a U-shaped handle (no material on one side). `axes` are the
/// mesh's [`principal_axes`](super::principal_axes) under the search's frame rule.
pub fn is_ring(mesh: &Mesh, props: &MassProperties, axes: &[Vector3<f64>; 3]) -> bool {
    if props.volume_mm3.is_nan() || props.volume_mm3 <= 0.0 {
        return false;
    }
    let axis = |rank: usize| axes[rank];
    // The lines pass a hair beside the centroid, in no direction of the mesh's, so that none
    // runs exactly through a vertex or along an edge (the frame's in-plane axis points at the
    // farthest vertex) and every crossing counts once.
    let (lo, hi) = mesh.bounds();
    let hair = (hi - lo).norm() * 1e-7;
    let beside = |d: &Vector3<f64>| {
        let skew = Vector3::new(0.5773, 0.3141, 0.7598);
        let off = skew - d * d.dot(&skew);
        props.centroid + off.normalize() * hair
    };
    let (ahead, behind) = {
        let d = axis(2);
        crossings(mesh, &beside(&d), &d)
    };
    if ahead + behind != 0 {
        return false;
    }
    (0..2).all(|rank| {
        let d = axis(rank);
        let (ahead, behind) = crossings(mesh, &beside(&d), &d);
        ahead > 0 && behind > 0 && ahead % 2 == 0 && behind % 2 == 0
    })
}

/// The crossings of the line `p + t d` with the triangles of `mesh`, for t > 0 and t < 0
/// (Möller–Trumbore).
fn crossings(mesh: &Mesh, p: &Point3<f64>, d: &Vector3<f64>) -> (usize, usize) {
    let (mut ahead, mut behind) = (0, 0);
    for t in 0..mesh.triangles.len() {
        let [a, b, c] = mesh.corners(t);
        let (e1, e2) = (b - a, c - a);
        let h = d.cross(&e2);
        let det = e1.dot(&h);
        if det.abs() <= 1e-12 {
            continue;
        }
        let s = p - a;
        let u = s.dot(&h) / det;
        let q = s.cross(&e1);
        let v = d.dot(&q) / det;
        if u < 0.0 || v < 0.0 || u + v > 1.0 {
            continue;
        }
        let t = e2.dot(&q) / det;
        if t > 0.0 {
            ahead += 1;
        } else if t < 0.0 {
            behind += 1;
        }
    }
    (ahead, behind)
}

/// The arc `which` names (`which.arc`: its direction in degrees from the ring's axis of least
/// moment, about the axis of the largest) and the frame the planner searches it in: the arc's
/// own axis of least moment, in `which`'s sense, aligned as any object is under `rule`.
/// Returns the whole mesh in that frame (for the check: its collider, gravity and the palm's
/// pose) and the arc in it (for the planner). `None` when the arc holds no volume. `axes` are
/// the mesh's [`principal_axes`](super::principal_axes) under `rule`.
pub fn arc_frames(
    mesh: &Mesh,
    props: &MassProperties,
    which: GraspAxis,
    rule: FrameRule,
    axes: &[Vector3<f64>; 3],
) -> Option<(AlignedObject, AlignedObject)> {
    let degrees = f64::from(which.arc?);
    let (least, normal) = (axes[0], axes[2]);
    let (s, c) = degrees.to_radians().sin_cos();
    let dir = least * c + normal.cross(&least) * s;
    let crop = arc_of(mesh, &props.centroid, &normal, &dir, ARC_HALF_DEG)?;
    let crop_props = mass_properties(&crop);
    if crop_props.volume_mm3.is_nan() || crop_props.volume_mm3 <= 0.0 {
        return None;
    }
    let mut planned = align_with_rule(
        &crop,
        &crop_props,
        GraspAxis::principal(0, which.flipped),
        rule,
    );
    planned.axis = which;
    let mut whole_mesh = mesh.clone();
    whole_mesh.map_vertices(|p| planned.to_aligned * p);
    let whole = AlignedObject {
        mesh: whole_mesh,
        to_aligned: planned.to_aligned,
        original: *props,
        principal_moments: planned.principal_moments,
        height_mm: planned.height_mm,
        axis: which,
    };
    Some((whole, planned))
}

/// The triangles of `mesh` whose centroid lies within `half_deg` of `dir` seen from the line
/// through `centre` along `normal`, each cut closed by a fan about its loop's centroid.
fn arc_of(
    mesh: &Mesh,
    centre: &Point3<f64>,
    normal: &Vector3<f64>,
    dir: &Vector3<f64>,
    half_deg: f64,
) -> Option<Mesh> {
    let side = normal.cross(dir);
    let mut index = vec![u32::MAX; mesh.vertices.len()];
    let mut crop = Mesh {
        vertices: Vec::new(),
        triangles: Vec::new(),
    };
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = mesh.corners(t);
        let m = Point3::from((a.coords + b.coords + c.coords) / 3.0) - centre;
        if m.dot(&side).atan2(m.dot(dir)).to_degrees().abs() > half_deg {
            continue;
        }
        let mut kept = [0u32; 3];
        for (k, &v) in tri.iter().enumerate() {
            if index[v as usize] == u32::MAX {
                index[v as usize] = u32::try_from(crop.vertices.len()).ok()?;
                crop.vertices.push(mesh.vertices[v as usize]);
            }
            kept[k] = index[v as usize];
        }
        crop.triangles.push(kept);
    }
    if crop.triangles.is_empty() {
        return None;
    }
    crop.fill_small_holes(f64::INFINITY);
    Some(crop)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::primitives;
    use crate::mesh::principal_axes;

    fn torus(big: f64, small: f64) -> Mesh {
        crate::objects::torus(big, small, 72, 24)
    }

    #[test]
    fn a_torus_is_a_ring_and_no_thesis_or_tuning_object_is() {
        let t = torus(40.0, 12.0);
        let props = mass_properties(&t);
        // Pappus: 2π R · π r².
        let volume = std::f64::consts::TAU * 40.0 * std::f64::consts::PI * 144.0;
        assert!(
            (props.volume_mm3 / volume - 1.0).abs() < 0.02,
            "{}",
            props.volume_mm3
        );
        let axes = |m: &Mesh, p: &MassProperties| principal_axes(m, p, FrameRule::Geometry);
        assert!(is_ring(&t, &props, &axes(&t, &props)));
        let others = crate::objects::thesis_objects()
            .into_iter()
            .chain(crate::objects::training_objects())
            .chain([("ball", primitives::uv_sphere(30.0, 36))]);
        for (name, other) in others {
            let p = mass_properties(&other);
            assert!(!is_ring(&other, &p, &axes(&other, &p)), "{name}");
        }
    }

    #[test]
    fn an_arc_spans_its_angle_is_closed_and_lies_along_the_tube() {
        let t = torus(40.0, 12.0);
        let props = mass_properties(&t);
        let axes = principal_axes(&t, &props, FrameRule::Geometry);
        for arc in [0, 90] {
            let which = GraspAxis::ring_arc(arc);
            let (whole, planned) =
                arc_frames(&t, &props, which, FrameRule::Geometry, &axes).unwrap();
            assert!(planned.mesh.topology().is_closed_manifold());
            // The tube's volume over 100° of the 360°, to the facets' and the fans' error.
            let v = mass_properties(&planned.mesh).volume_mm3;
            assert!((v / props.volume_mm3 - 100.0 / 360.0).abs() < 0.01, "{v}");
            // The arc's axis of least moment is the tube's tangent at its middle: in the
            // ring's plane (the file's XY), and the whole ring is the same mesh moved.
            let z = planned.principal_axis_original();
            assert!(z.z.abs() < 1e-6, "{z}");
            assert_eq!(whole.to_aligned, planned.to_aligned);
            assert_eq!(whole.mesh.vertices.len(), t.vertices.len());
            assert_eq!(whole.axis.name(), format!("arc{arc}"));
            // Along the tangent the arc spans the chord 2 (R + r) sin 50°.
            let chord = 2.0 * 52.0 * ARC_HALF_DEG.to_radians().sin();
            assert!(
                (planned.height_mm - chord).abs() < 4.0,
                "{}",
                planned.height_mm
            );
        }
    }
}

//! The object's convex parts in the physics scene, with their support-point scans in lanes.
//!
//! A profile of a dataset check (BENCHMARKS.md, "Ninth look") puts a tenth to a sixth of its
//! time in parry's `SupportMap::support_point` on the object's hulls: a scalar scan over up to
//! a thousand points for every GJK iteration of every phalanx's contact manifold, every step.
//! [`FastHull`] is parry's [`ConvexPolyhedron`] with that scan (and the face scan of its
//! support feature) done over the points laid out coordinate by coordinate, eight lanes at a
//! time, so that the compiler vectorises it (with AVX where the CPU has it): 2.6 to 3.6 times
//! parry's speed at 256 to 1,024 points (`cargo bench --bench pipeline -- support_scan`). It
//! returns the index parry's scan returns, the first point of the largest dot product, from
//! the same products rounded the same way, so a check gives the same numbers to the bit (the
//! tests below, and the real-object set's JSON in BENCHMARKS.md, "Tenth look"). Every other
//! query is parry's own, on the polyhedron inside.

use rapier3d::parry::bounding_volume::{Aabb, BoundingSphere};
use rapier3d::parry::mass_properties::MassProperties;
use rapier3d::parry::math::{Pose, Real, Vector};
use rapier3d::parry::query::{PointProjection, PointQuery, Ray, RayCast, RayIntersection};
use rapier3d::parry::shape::{
    Compound, ConvexPolyhedron, FeatureId, PackedFeatureId, PolygonalFeature, PolygonalFeatureMap,
    Shape, ShapeType, SharedShape, SubShapeId, SupportMap, TypedShape,
};

/// Lanes of a scan: eight `f32`, two SSE or one AVX register.
const LANES: usize = 8;

/// Unit vectors (or points) laid out coordinate by coordinate, padded to whole lanes with
/// copies of the last one (a copy never wins: it comes later with the same product).
#[derive(Clone, Debug)]
struct Lanes {
    x: Vec<[f32; LANES]>,
    y: Vec<[f32; LANES]>,
    z: Vec<[f32; LANES]>,
    len: usize,
}

impl Lanes {
    fn new(v: &[Vector]) -> Lanes {
        let chunks = v.len().div_ceil(LANES);
        let mut x = vec![[0.0; LANES]; chunks];
        let mut y = vec![[0.0; LANES]; chunks];
        let mut z = vec![[0.0; LANES]; chunks];
        for c in 0..chunks {
            for l in 0..LANES {
                let p = v[(c * LANES + l).min(v.len() - 1)];
                (x[c][l], y[c][l], z[c][l]) = (p.x, p.y, p.z);
            }
        }
        Lanes {
            x,
            y,
            z,
            len: v.len(),
        }
    }

    /// The index of the first vector of the largest dot product with `dir`, as parry's
    /// `point_cloud_support_point_id` finds it: the products are glam's `Vec3::dot`,
    /// `(x·dx + y·dy) + z·dz`, and a later vector wins only with a larger one, so the answer
    /// is the first vector whose product equals the largest. Two passes over the lanes: the
    /// largest product, then the first lane equal to it. A direction with a NaN or an infinity
    /// gives parry's scalar scan, whose answer NaNs decide.
    fn argmax(&self, dir: Vector) -> usize {
        if !(dir.x.is_finite() && dir.y.is_finite() && dir.z.is_finite()) {
            return self.scalar_argmax(dir);
        }
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has AVX (checked just above), all the function asks.
            return unsafe { self.argmax_avx(dir) };
        }
        self.argmax_lanes(dir)
    }

    /// [`Self::argmax_lanes`] compiled for AVX: eight lanes in one register. The same
    /// operations (AVX adds no fused multiply-add), so the same answer.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn argmax_avx(&self, dir: Vector) -> usize {
        self.argmax_lanes(dir)
    }

    /// The two passes of [`Self::argmax`] for a finite direction.
    #[inline(always)]
    fn argmax_lanes(&self, dir: Vector) -> usize {
        let (dx, dy, dz) = (dir.x, dir.y, dir.z);
        let chunks = self.x.iter().zip(&self.y).zip(&self.z);
        let mut best = [f32::NEG_INFINITY; LANES];
        for ((x, y), z) in chunks.clone() {
            for l in 0..LANES {
                let d = (x[l] * dx + y[l] * dy) + z[l] * dz;
                best[l] = if d > best[l] { d } else { best[l] };
            }
        }
        let top = best
            .iter()
            .fold(f32::NEG_INFINITY, |m, &b| if b > m { b } else { m });
        for (c, ((x, y), z)) in chunks.enumerate() {
            let mut hit = [0u32; LANES];
            for l in 0..LANES {
                hit[l] = u32::from((x[l] * dx + y[l] * dy) + z[l] * dz == top);
            }
            if hit.iter().fold(0, |a, &h| a | h) == 0 {
                continue;
            }
            if let Some(l) = hit.iter().position(|&h| h != 0) {
                let i = c * LANES + l;
                if i < self.len {
                    return i;
                }
                break;
            }
        }
        // No product is finite (no finite hull gives that): parry's answer.
        self.scalar_argmax(dir)
    }

    /// The `i`th vector, as it was given.
    fn get(&self, i: usize) -> Vector {
        let (c, l) = (i / LANES, i % LANES);
        Vector::new(self.x[c][l], self.y[c][l], self.z[c][l])
    }

    /// parry's scan, one vector at a time, for what the lanes leave to it.
    fn scalar_argmax(&self, dir: Vector) -> usize {
        let mut best = 0;
        let mut best_dot = self.get(0).dot(dir);
        for i in 1..self.len {
            let d = self.get(i).dot(dir);
            if d > best_dot {
                (best_dot, best) = (d, i);
            }
        }
        best
    }
}

/// A convex polyhedron whose support point and support face are found by lane scans.
#[derive(Clone, Debug)]
pub struct FastHull {
    inner: ConvexPolyhedron,
    points: Lanes,
    normals: Lanes,
}

impl FastHull {
    /// `inner` with its points and face normals laid out in lanes.
    pub fn new(inner: ConvexPolyhedron) -> FastHull {
        let normals: Vec<Vector> = inner.faces().iter().map(|f| f.normal).collect();
        FastHull {
            points: Lanes::new(inner.points()),
            normals: Lanes::new(&normals),
            inner,
        }
    }
}

/// `shape` with each convex polyhedron, alone or as a part of a compound, made a [`FastHull`]
/// at the same pose; any other shape as it is.
pub fn with_fast_hulls(shape: &SharedShape) -> SharedShape {
    if let Some(poly) = shape.as_convex_polyhedron() {
        return SharedShape::new(FastHull::new(poly.clone()));
    }
    if let Some(compound) = shape.as_compound() {
        let parts = compound
            .shapes()
            .iter()
            .map(|(pose, part)| (*pose, with_fast_hulls(part)))
            .collect();
        return SharedShape::new(Compound::new(parts));
    }
    shape.clone()
}

impl SupportMap for FastHull {
    #[inline]
    fn local_support_point(&self, dir: Vector) -> Vector {
        self.inner.points()[self.points.argmax(dir)]
    }
}

impl PolygonalFeatureMap for FastHull {
    /// parry's `ConvexPolyhedron::local_support_feature` with the face scan in lanes.
    fn local_support_feature(&self, dir: Vector, out_feature: &mut PolygonalFeature) {
        let p = &self.inner;
        let best_fid = self.normals.argmax(dir);
        let face = &p.faces()[best_fid];
        let i1 = face.first_vertex_or_edge as usize;
        let num_vertices = face.num_vertices_or_edges.min(4) as usize;
        let i2 = i1 + num_vertices;
        for (i, (vid, eid)) in p.vertices_adj_to_face()[i1..i2]
            .iter()
            .zip(&p.edges_adj_to_face()[i1..i2])
            .enumerate()
        {
            out_feature.vertices[i] = p.points()[*vid as usize];
            out_feature.vids[i] = PackedFeatureId::vertex(*vid);
            out_feature.eids[i] = PackedFeatureId::edge(*eid);
        }
        out_feature.fid = PackedFeatureId::face(best_fid as u32);
        out_feature.num_vertices = num_vertices;
    }

    fn is_convex_polyhedron(&self) -> bool {
        true
    }
}

impl RayCast for FastHull {
    fn cast_local_ray(&self, ray: &Ray, max_toi: Real, solid: bool) -> Option<Real> {
        self.inner.cast_local_ray(ray, max_toi, solid)
    }
    fn cast_local_ray_and_get_normal(
        &self,
        ray: &Ray,
        max_toi: Real,
        solid: bool,
    ) -> Option<RayIntersection> {
        self.inner
            .cast_local_ray_and_get_normal(ray, max_toi, solid)
    }
    fn intersects_local_ray(&self, ray: &Ray, max_toi: Real) -> bool {
        self.inner.intersects_local_ray(ray, max_toi)
    }
    fn cast_ray(&self, m: &Pose, ray: &Ray, max_toi: Real, solid: bool) -> Option<Real> {
        self.inner.cast_ray(m, ray, max_toi, solid)
    }
    fn cast_ray_and_get_normal(
        &self,
        m: &Pose,
        ray: &Ray,
        max_toi: Real,
        solid: bool,
    ) -> Option<RayIntersection> {
        self.inner.cast_ray_and_get_normal(m, ray, max_toi, solid)
    }
    fn intersects_ray(&self, m: &Pose, ray: &Ray, max_toi: Real) -> bool {
        self.inner.intersects_ray(m, ray, max_toi)
    }
}

impl PointQuery for FastHull {
    fn project_local_point_with_max_dist(
        &self,
        pt: Vector,
        solid: bool,
        max_dist: Real,
    ) -> Option<PointProjection> {
        self.inner
            .project_local_point_with_max_dist(pt, solid, max_dist)
    }
    fn project_point_with_max_dist(
        &self,
        m: &Pose,
        pt: Vector,
        solid: bool,
        max_dist: Real,
    ) -> Option<PointProjection> {
        self.inner
            .project_point_with_max_dist(m, pt, solid, max_dist)
    }
    fn project_local_point(&self, pt: Vector, solid: bool) -> PointProjection {
        self.inner.project_local_point(pt, solid)
    }
    fn project_local_point_and_get_feature(&self, pt: Vector) -> (PointProjection, FeatureId) {
        self.inner.project_local_point_and_get_feature(pt)
    }
    fn distance_to_local_point(&self, pt: Vector, solid: bool) -> Real {
        self.inner.distance_to_local_point(pt, solid)
    }
    fn contains_local_point(&self, pt: Vector) -> bool {
        self.inner.contains_local_point(pt)
    }
    fn project_point(&self, m: &Pose, pt: Vector, solid: bool) -> PointProjection {
        self.inner.project_point(m, pt, solid)
    }
    fn distance_to_point(&self, m: &Pose, pt: Vector, solid: bool) -> Real {
        self.inner.distance_to_point(m, pt, solid)
    }
    fn project_point_and_get_feature(&self, m: &Pose, pt: Vector) -> (PointProjection, FeatureId) {
        self.inner.project_point_and_get_feature(m, pt)
    }
    fn contains_point(&self, m: &Pose, pt: Vector) -> bool {
        self.inner.contains_point(m, pt)
    }
}

impl Shape for FastHull {
    fn compute_local_aabb(&self) -> Aabb {
        self.inner.compute_local_aabb()
    }
    fn compute_local_bounding_sphere(&self) -> BoundingSphere {
        self.inner.compute_local_bounding_sphere()
    }
    fn clone_dyn(&self) -> Box<dyn Shape> {
        Box::new(self.clone())
    }
    fn scale_dyn(&self, scale: Vector, num_subdivisions: u32) -> Option<Box<dyn Shape>> {
        let scaled = self.inner.scale_dyn(scale, num_subdivisions)?;
        let poly = scaled.as_shape::<ConvexPolyhedron>()?.clone();
        Some(Box::new(FastHull::new(poly)))
    }
    fn compute_aabb(&self, position: &Pose) -> Aabb {
        self.inner.compute_aabb(position)
    }
    fn compute_bounding_sphere(&self, position: &Pose) -> BoundingSphere {
        self.inner.compute_bounding_sphere(position)
    }
    fn mass_properties(&self, density: Real) -> MassProperties {
        self.inner.mass_properties(density)
    }
    /// A convex polyhedron, as parry's own: rapier's continuous collision detection sweeps a
    /// fast body by its typed shape (parry's `ToiProxy::from_shape` takes a polyhedron's
    /// points and has nothing for a custom shape), and the closing's pushes make the object
    /// fast at times, so a custom type would change a few checks (the knob's and the door
    /// handle's of the real-object set did).
    fn shape_type(&self) -> ShapeType {
        ShapeType::ConvexPolyhedron
    }
    /// The polyhedron inside (see [`Self::shape_type`]).
    fn as_typed_shape(&self) -> TypedShape<'_> {
        TypedShape::ConvexPolyhedron(&self.inner)
    }
    fn ccd_thickness(&self) -> Real {
        self.inner.ccd_thickness()
    }
    fn ccd_angular_thickness(&self) -> Real {
        self.inner.ccd_angular_thickness()
    }
    fn is_convex(&self) -> bool {
        true
    }
    fn as_support_map(&self) -> Option<&dyn SupportMap> {
        Some(self as &dyn SupportMap)
    }
    fn as_polygonal_feature_map(&self) -> Option<(&dyn PolygonalFeatureMap, Real)> {
        Some((self as &dyn PolygonalFeatureMap, 0.0))
    }
    fn feature_normal_at_point(
        &self,
        subshape: SubShapeId,
        feature: FeatureId,
        point: Vector,
    ) -> Option<Vector> {
        self.inner.feature_normal_at_point(subshape, feature, point)
    }
    fn compute_swept_aabb(&self, start_pos: &Pose, end_pos: &Pose) -> Aabb {
        self.inner.compute_swept_aabb(start_pos, end_pos)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic cloud: points on a lumpy sphere, with exact duplicates and ties.
    fn cloud(n: usize) -> Vec<Vector> {
        let mut v = Vec::with_capacity(n);
        let mut s = 0x9e37_79b9_u32;
        let mut r = || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            (s as f32 / u32::MAX as f32) * 2.0 - 1.0
        };
        for i in 0..n {
            let p = if i % 7 == 3 && i > 0 {
                v[i / 2] // a duplicate: ties between lanes
            } else {
                Vector::new(r(), r(), r()) * 0.05
            };
            v.push(p);
        }
        v
    }

    #[test]
    fn the_lanes_find_the_point_parrys_scan_finds() {
        use rapier3d::parry::utils::point_cloud_support_point_id;
        let mut dirs = vec![
            Vector::X,
            -Vector::Y,
            Vector::Z,
            Vector::new(1.0, 1.0, 0.0),
            Vector::ZERO,
            // Left to the scalar scan: NaN and infinite directions.
            Vector::new(f32::NAN, 1.0, 0.0),
            Vector::new(f32::INFINITY, 0.5, -0.5),
            Vector::new(0.0, f32::NEG_INFINITY, 0.0),
        ];
        let mut s = 12345_u32;
        for _ in 0..2000 {
            let mut c = || {
                s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                (s >> 8) as f32 / (1 << 24) as f32 - 0.5
            };
            dirs.push(Vector::new(c(), c(), c()));
        }
        let mut differ = 0;
        for n in [1, 2, 7, 8, 9, 100, 333, 1107] {
            let pts = cloud(n);
            let lanes = Lanes::new(&pts);
            for d in &dirs {
                let parry = point_cloud_support_point_id(*d, &pts);
                // Both builds of the lanes: this CPU's (AVX where it has it) and the baseline.
                if lanes.argmax(*d) != parry || lanes.argmax_lanes(*d) != parry {
                    differ += 1;
                }
            }
        }
        assert_eq!(differ, 0);
        // Axis directions on a box's corners tie four ways: the first wins, as in parry.
        let cube: Vec<Vector> = (0..8)
            .map(|i| Vector::new((i & 1) as f32, ((i >> 1) & 1) as f32, (i >> 2) as f32))
            .collect();
        let lanes = Lanes::new(&cube);
        assert_eq!(lanes.argmax(Vector::X), 1);
        assert_eq!(lanes.argmax(Vector::Z), 4);
        assert_eq!(lanes.argmax(-Vector::X), 0);
        assert_eq!(lanes.argmax(Vector::new(f32::NAN, 0.0, 1.0)), 0);
    }

    #[test]
    fn a_fast_hull_gives_parrys_support_points_and_faces() {
        let pts = cloud(400);
        let poly = ConvexPolyhedron::from_convex_hull(&pts).expect("a hull");
        let fast = FastHull::new(poly.clone());
        let mut s = 777_u32;
        for _ in 0..500 {
            let mut c = || {
                s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                (s >> 8) as f32 / (1 << 24) as f32 - 0.5
            };
            let d = Vector::new(c(), c(), c());
            assert_eq!(fast.local_support_point(d), poly.local_support_point(d));
            let (mut a, mut b) = (PolygonalFeature::default(), PolygonalFeature::default());
            fast.local_support_feature(d, &mut a);
            poly.local_support_feature(d, &mut b);
            assert_eq!(a.fid, b.fid);
            assert_eq!(a.num_vertices, b.num_vertices);
            assert_eq!(a.vertices, b.vertices);
        }
        assert_eq!(fast.mass_properties(500.0), poly.mass_properties(500.0));
        assert!(fast.shape_type() == ShapeType::ConvexPolyhedron && fast.is_convex());
        assert!(
            matches!(fast.as_typed_shape(), TypedShape::ConvexPolyhedron(p) if p.points() == poly.points())
        );
    }
}

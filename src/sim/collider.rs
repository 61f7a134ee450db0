//! The object's collision shape for the physics check: the convex hull of the aligned mesh when
//! the mesh is convex (hull volume within 2 % of the mesh's), rebuilt from its face planes where
//! parry would merge a finely tessellated curved surface into bent faces, and a convex
//! decomposition (V-HACD) otherwise; decompositions and rebuilt hulls are kept in a process-wide
//! cache by the digest of their mesh. Units: metres (the shape), millimetres (the mesh).

use super::convert;
use crate::mesh::Mesh;
use nalgebra::Vector3;
use rapier3d::parry::transformation::vhacd::{VHACDParameters, VHACD};
use rapier3d::prelude::*;

/// How the object's collider was made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColliderKind {
    /// The convex hull of the mesh (the mesh is convex).
    ConvexHull,
    /// A convex decomposition (V-HACD) of the mesh.
    ConvexDecomposition,
}

impl ColliderKind {
    /// The name used in JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            ColliderKind::ConvexHull => "convex_hull",
            ColliderKind::ConvexDecomposition => "convex_decomposition",
        }
    }
}

impl std::fmt::Display for ColliderKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.as_str())
    }
}

/// The object's collision shape, built once per object and shared by every run.
#[derive(Clone)]
pub struct ObjectShape {
    /// The shape in metres, aligned frame.
    pub shape: SharedShape,
    /// How it was made.
    pub kind: ColliderKind,
    /// Number of convex parts.
    pub parts: usize,
    /// True if and only if the object is inertially a body of revolution about its principal
    /// axis (aligned Z): its two transverse principal moments agree within 0.1 %.
    pub is_revolution: bool,
    /// For a convex hull that parry would merge into bent faces, rebuilt from its face planes
    /// (see `coarsened_hull`): the full hull's vertex count.
    pub coarsened_from: Option<usize>,
    /// A mass distribution the check gives the object's body instead of its collider's (see
    /// [`object_mass_properties`]): the hull's own, where parry's polyhedron of it misweighs it
    /// and cannot be rebuilt; `None` (every other collider): the collider's, scaled to the mass.
    pub mesh_mass: Option<MeshMass>,
    /// For a convex decomposition taken in place of the hull of a convex mesh because the hull
    /// lies off a grasp's planned contacts ([`ObjectShape::true_at`]): how far, at most `[mm]`.
    pub hull_off_mm: Option<f64>,
    /// For a convex hull: its face planes, aligned frame, metres (unit outward normal, offset),
    /// from the hull's own triangles ([`ObjectShape::depth_mm`]).
    pub hull_planes: Option<std::sync::Arc<[HullPlane]>>,
}

/// A face plane of a convex hull: unit outward normal and offset (`n · x = d` on the face),
/// aligned frame, metres.
pub type HullPlane = (nalgebra::Vector3<f64>, f64);

/// The face planes of the convex hull `(vertices, triangles)` (metres), each through its
/// triangle and turned to face away from the vertices' centroid (a sliver's winding can come
/// out inwards in single precision); degenerate triangles are left out.
fn hull_planes(vertices: &[Vector], triangles: &[[u32; 3]]) -> Vec<HullPlane> {
    let v64 = |v: &Vector| nalgebra::Vector3::new(f64::from(v.x), f64::from(v.y), f64::from(v.z));
    let points: Vec<nalgebra::Vector3<f64>> = vertices.iter().map(v64).collect();
    let centre = points.iter().sum::<nalgebra::Vector3<f64>>() / points.len().max(1) as f64;
    triangles
        .iter()
        .filter_map(|t| {
            let [a, b, c] = t.map(|i| points.get(i as usize).copied());
            let (a, b, c) = (a?, b?, c?);
            let n = (b - a).cross(&(c - a)).try_normalize(1e-15)?;
            let n = if n.dot(&(centre - a)) > 0.0 { -n } else { n };
            Some((n, n.dot(&a)))
        })
        .collect()
}

/// A solid's mass distribution, aligned frame, unit density, integrated from its triangles
/// in double precision. parry's polyhedron of a hull can carry another than the hull's own:
/// `rs_cereal`'s, a box of 15 hull vertices, weighed 489,308 mm³ in two frames of six against
/// the hull's 449,898 and put the centre of mass 5 mm off (docs/FRAMES.md, issue 30).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshMass {
    /// Enclosed volume `[mm³]`.
    pub volume_mm3: f64,
    /// Centroid, aligned frame `[mm]`.
    pub centroid_mm: nalgebra::Point3<f64>,
    /// Inertia tensor about the centroid, aligned frame, unit density `[mm⁵]`.
    pub inertia_mm5: nalgebra::Matrix3<f64>,
}

/// The object's centre of mass as the check has it, aligned frame `[m]`:
/// [`ObjectShape::mesh_mass`]'s where set, else its collider's.
pub fn object_com_m(object: &ObjectShape) -> Vector {
    match object.mesh_mass {
        Some(m) => {
            let c = m.centroid_mm.coords * convert::M_PER_MM;
            Vector::new(c.x as f32, c.y as f32, c.z as f32)
        }
        None => object.shape.mass_properties(1.0).local_com,
    }
}

/// The mass properties the check gives the object's body, `mass_kg` in all:
/// [`ObjectShape::mesh_mass`]'s where set, else its collider's scaled to the mass.
pub fn object_mass_properties(object: &ObjectShape, mass_kg: f64) -> MassProperties {
    if let Some(m) = object.mesh_mass {
        // kg per mm³, then mm² to m².
        let scale = mass_kg / m.volume_mm3 * 1e-6;
        let i = m.inertia_mm5 * scale;
        let cols: [f32; 9] = std::array::from_fn(|k| i[(k % 3, k / 3)] as f32);
        return MassProperties::with_inertia_matrix(
            object_com_m(object),
            mass_kg as f32,
            rapier3d::math::Matrix::from_cols_array(&cols),
        );
    }
    let unit = object.shape.mass_properties(1.0);
    let density = mass_kg / f64::from(unit.mass()).max(f64::MIN_POSITIVE);
    object.shape.mass_properties(density as f32)
}

/// What the report says of the object's collider (`sim.collider`, written by
/// `report::check::ColliderReport`): how it was made and its part count, and for a hull rebuilt
/// from its face planes, the vertex counts before and after.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColliderReport {
    /// How the collider was made.
    pub kind: ColliderKind,
    /// Number of convex parts.
    pub parts: usize,
    /// For a convex hull rebuilt from its face planes ([`ObjectShape::coarsened_from`]).
    pub rebuilt: Option<RebuiltHull>,
    /// For a decomposition taken because the hull lies off a grasp's planned contacts
    /// ([`ObjectShape::hull_off_mm`]).
    pub hull_off_mm: Option<f64>,
}

/// The vertex counts of a convex hull rebuilt from its face planes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RebuiltHull {
    /// The full hull's vertex count.
    pub from_vertices: usize,
    /// The rebuilt hull's vertex count.
    pub to_vertices: usize,
}

impl ColliderReport {
    /// The report of `shape`.
    pub fn of(shape: &ObjectShape) -> ColliderReport {
        ColliderReport {
            kind: shape.kind,
            parts: shape.parts,
            rebuilt: shape.coarsened_from.map(|from| RebuiltHull {
                from_vertices: from,
                to_vertices: shape
                    .shape
                    .as_convex_polyhedron()
                    .map_or(0, |c| c.points().len()),
            }),
            hull_off_mm: shape.hull_off_mm,
        }
    }
}

/// Convex decompositions made in this process, by the digest of their mesh: the same object
/// in several scenarios of one run (the chapter 4 object and its weak-motor twin, a tuning
/// set) is decomposed once. At most [`SHAPE_CACHE_LEN`], the oldest dropped first.
static SHAPE_CACHE: std::sync::Mutex<Vec<([u8; 32], ObjectShape)>> =
    std::sync::Mutex::new(Vec::new());

/// Convex decompositions kept by [`ObjectShape::cached`].
pub const SHAPE_CACHE_LEN: usize = 16;

/// The shape [`SHAPE_CACHE`] keeps under `key`.
fn cache_get(key: &[u8; 32]) -> Option<ObjectShape> {
    let cache = SHAPE_CACHE.lock().unwrap_or_else(|e| e.into_inner());
    cache.iter().find(|(k, _)| k == key).map(|(_, s)| s.clone())
}

/// Keeps `shape` under `key` in [`SHAPE_CACHE`] unless a shape is kept there already, dropping
/// the oldest when full.
fn cache_put(key: [u8; 32], shape: &ObjectShape) {
    let mut cache = SHAPE_CACHE.lock().unwrap_or_else(|e| e.into_inner());
    if !cache.iter().any(|(k, _)| *k == key) {
        if cache.len() >= SHAPE_CACHE_LEN {
            cache.remove(0);
        }
        cache.push((key, shape.clone()));
    }
}

/// The digest of what [`ObjectShape::from_mesh`] reads: vertices, triangles and volume; without
/// a volume, of what the decomposition alone reads ([`ObjectShape::true_at`]).
fn shape_key(mesh: &Mesh, volume_mm3: Option<f64>) -> [u8; 32] {
    use sha2::{Digest, Sha256};
    let mut h = Sha256::new();
    for p in &mesh.vertices {
        for v in [p.x, p.y, p.z] {
            h.update(v.to_bits().to_le_bytes());
        }
    }
    h.update(b"t");
    for t in &mesh.triangles {
        for i in t {
            h.update(i.to_le_bytes());
        }
    }
    match volume_mm3 {
        Some(v) => h.update(v.to_bits().to_le_bytes()),
        None => h.update(b"decomposition"),
    }
    h.finalize().into()
}

/// The disk cache's key of the convex decomposition of `mesh`: the digest of the mesh and of
/// what makes the decomposition ([`super::collider_cache::MAKER`]).
fn decomposition_key(mesh: &Mesh) -> [u8; 32] {
    use sha2::{Digest, Sha256};
    let mut h = Sha256::new();
    h.update(shape_key(mesh, None));
    h.update(super::collider_cache::MAKER.as_bytes());
    h.finalize().into()
}

/// True if and only if `mesh` (aligned) is inertially a body of revolution about its aligned Z:
/// its two transverse principal moments agree within 0.1 % ([`ObjectShape::is_revolution`]).
pub fn is_revolution(mesh: &Mesh) -> bool {
    let props = crate::mesh::mass_properties(mesh);
    let (ixx, iyy) = (props.inertia[(0, 0)], props.inertia[(1, 1)]);
    (ixx - iyy).abs() <= 1e-3 * ixx.abs().max(iyy.abs())
}

impl ObjectShape {
    /// [`ObjectShape::from_mesh`], with convex decompositions (0.1–0.4 s each) and rebuilt hulls
    /// (tens of milliseconds) kept for the rest of the process: the same mesh gives the same
    /// shape, bit for bit, either way.
    pub fn cached(mesh: &Mesh, volume_mm3: f64) -> ObjectShape {
        let key = shape_key(mesh, Some(volume_mm3));
        if let Some(s) = cache_get(&key) {
            return s;
        }
        let shape = ObjectShape::from_mesh(mesh, volume_mm3);
        if shape.kind == ColliderKind::ConvexDecomposition || shape.coarsened_from.is_some() {
            cache_put(key, &shape);
        }
        shape
    }

    /// The convex hull of `mesh` (aligned, millimetres) if the mesh is convex (hull volume within
    /// 2 % of `volume_mm3`), a convex decomposition otherwise.
    pub fn from_mesh(mesh: &Mesh, volume_mm3: f64) -> ObjectShape {
        let is_revolution = is_revolution(mesh);
        let points: Vec<Vector> = mesh.vertices.iter().map(convert::point_m).collect();
        // The hull once: parry's polyhedron of it (`SharedShape::convex_hull` is this and
        // `convex_mesh`), its own mass, and its planes where it is rebuilt.
        let hull_mesh = rapier3d::parry::transformation::try_convex_hull(&points).ok();
        let polyhedron = hull_mesh
            .as_ref()
            .and_then(|(v, t)| SharedShape::convex_mesh(v.clone(), t).map(|h| (h, v, t)));
        if let Some((hull, vertices, triangles)) = polyhedron {
            let parry_mm3 = f64::from(hull.mass_properties(1.0).mass()) * 1e9;
            // The hull's own volume, from its triangles in double precision: parry's
            // polyhedron of the same hull can carry another (rs_cereal's, a box of 15 hull
            // vertices: 449,764 mm³ in four frames of six, 489,308 in two, its centre of mass
            // 5 mm off; docs/FRAMES.md), so the test takes this one, and a polyhedron whose
            // volume is not it is rebuilt from its planes.
            let own = hull_mass(vertices, triangles);
            let hull_mm3 = own.map_or(parry_mm3, |m| m.volume_mm3);
            if hull_mm3 <= volume_mm3 * 1.02 {
                let misweighed = (parry_mm3 - hull_mm3).abs() > MISWEIGHED_FRACTION * hull_mm3;
                let usable = usable_shape(&hull);
                let rebuilt =
                    (misweighed || !usable || bent_shape_m(&hull) > MERGED_FACE_TOLERANCE_M)
                        .then(|| coarsened_hull(vertices, triangles, usable))
                        .flatten();
                // A polyhedron that misweighs the hull and cannot be rebuilt keeps its contact
                // geometry, and the body takes the hull's own mass distribution.
                let mesh_mass = (misweighed && rebuilt.is_none()).then_some(own).flatten();
                let (shape, coarsened_from) = match rebuilt {
                    Some((coarse, from)) => (coarse, Some(from)),
                    None if usable => (hull, None),
                    // No hull the scene can use: the decomposition, its parts checked.
                    None => return Self::decomposition(mesh, &points, is_revolution),
                };
                return ObjectShape {
                    shape,
                    kind: ColliderKind::ConvexHull,
                    parts: 1,
                    is_revolution,
                    coarsened_from,
                    mesh_mass,
                    hull_off_mm: None,
                    hull_planes: Some(hull_planes(vertices, triangles).into()),
                };
            }
        } else if let Some((vertices, triangles)) = &hull_mesh {
            // parry made no polyhedron of the hull at all (a cylinder of 4000 segments, whose
            // caps' fans it cannot join): of a convex mesh, the hull rebuilt from its planes.
            let convex =
                hull_mass(vertices, triangles).is_some_and(|m| m.volume_mm3 <= volume_mm3 * 1.02);
            if let Some((shape, from)) = convex
                .then(|| coarsened_hull(vertices, triangles, false))
                .flatten()
            {
                return ObjectShape {
                    shape,
                    kind: ColliderKind::ConvexHull,
                    parts: 1,
                    is_revolution,
                    coarsened_from: Some(from),
                    mesh_mass: None,
                    hull_off_mm: None,
                    hull_planes: Some(hull_planes(vertices, triangles).into()),
                };
            }
        }
        Self::decomposition(mesh, &points, is_revolution)
    }

    /// This convex decomposition moved by `motion` (from the aligned frame it was made in to
    /// another aligned frame of the same object, millimetres): the same parts, each placed by
    /// the motion, rather than a decomposition made again in the other frame (V-HACD voxelises
    /// along the frame's axes, so it would be another, and it costs 0.1–1.5 s an object).
    /// `is_revolution` is the other frame's. `None` for any other collider.
    pub fn moved(
        &self,
        motion: &nalgebra::Isometry3<f64>,
        is_revolution: bool,
    ) -> Option<ObjectShape> {
        if self.kind != ColliderKind::ConvexDecomposition {
            return None;
        }
        let by = convert::pose(&motion.translation.vector.into(), &motion.rotation);
        let parts = self
            .shape
            .as_compound()?
            .shapes()
            .iter()
            .map(|(pose, part)| (by * *pose, part.clone()))
            .collect();
        Some(ObjectShape {
            shape: SharedShape::compound(parts),
            is_revolution,
            ..self.clone()
        })
    }

    /// The convex decomposition (V-HACD) of `mesh`, whose vertices in metres are `points`.
    fn decomposition(mesh: &Mesh, points: &[Vector], is_revolution: bool) -> ObjectShape {
        let params = VHACDParameters {
            resolution: 64,
            ..VHACDParameters::default()
        };
        // parry's `SharedShape::convex_decomposition_with_params`, without its panic on a
        // decomposition none of whose parts it makes a polyhedron of (a cylinder of 4000
        // segments), and with each part checked.
        // The parts come from the disk cache where one is named (`--collider-cache`): the
        // same parts, bit for bit, as V-HACD makes.
        let key = decomposition_key(mesh);
        let hulls =
            super::collider_cache::load_or_make(super::collider_cache::folder(), &key, || {
                VHACD::decompose(&params, points, &mesh.triangles, true)
                    .compute_exact_convex_hulls(points, &mesh.triangles)
            });
        let parts: Vec<(Pose, SharedShape)> = hulls
            .into_iter()
            .filter_map(|(v, t)| SharedShape::convex_mesh(v, &t).map(|c| (Pose::IDENTITY, c)))
            .collect();
        let shape = (!parts.is_empty())
            .then(|| usable_parts(&SharedShape::compound(parts)))
            .flatten()
            .or_else(|| {
                // No part: the hull of the whole mesh rebuilt from its planes, else its box.
                let (v, t) = rapier3d::parry::transformation::try_convex_hull(points).ok()?;
                coarsened_hull(&v, &t, false).map(|(h, _)| h)
            })
            .unwrap_or_else(|| bounding_box(points));
        let parts = shape.as_compound().map_or(1, |c| c.shapes().len());
        ObjectShape {
            shape,
            kind: ColliderKind::ConvexDecomposition,
            parts,
            is_revolution,
            coarsened_from: None,
            mesh_mass: None,
            hull_off_mm: None,
            hull_planes: None,
        }
    }

    /// How deep the deepest of `points_mm` (aligned frame) lies inside this shape's hull
    /// `[mm]`: the least distance to its face planes ([`ObjectShape::hull_planes`]), 0 for a
    /// point outside; 0 without points or for a decomposition. The planes are the hull's own
    /// triangles': parry's polyhedron of it can miss faces (rs_cereal's in one frame, which
    /// put a point on the box's face 30 mm inside), its face normals can point inwards, and
    /// its point projection put a point on the Adroit ball's hull 14.9 mm inside it.
    pub fn depth_mm(&self, points_mm: &[nalgebra::Point3<f64>]) -> f64 {
        let Some(planes) = &self.hull_planes else {
            return 0.0;
        };
        points_mm
            .iter()
            .map(|q| {
                let p = q.coords * convert::M_PER_MM;
                let inside = planes
                    .iter()
                    .map(|(n, d)| d - n.dot(&p))
                    .fold(f64::INFINITY, f64::min);
                if inside.is_finite() {
                    inside.max(0.0) / convert::M_PER_MM
                } else {
                    0.0
                }
            })
            .fold(0.0, f64::max)
    }

    /// This collider (`self`, of `mesh`), or where it is the hull of a convex mesh lying more
    /// than `tolerance_mm` outside a body's planned contacts, the mesh's convex decomposition.
    /// `contacts_mm` are the points where a grasp is planned to touch the object (aligned frame),
    /// a group per phalanx; a phalanx counts by its least depth ([`beyond_mesh_mm`]): one whose
    /// other contacts rest on the hull is stopped where planned even if one lies in a groove
    /// narrower than the finger (as the basketball's seams, 1.4 mm deep), which a single point
    /// would count in one frame and not another. The volume
    /// test that takes the hull is global: a bottle whose neck is narrower than its cap is
    /// within 2 % of its hull, yet a grasp at its neck has phalanges all of whose planned contacts
    /// lie 1.6–1.8 mm inside the hull, and each phalanx 1 stopped 6–8° short of its plan
    /// (issue 33).
    /// Decompositions come from the process-wide cache.
    pub fn true_at(
        &self,
        mesh: &Mesh,
        contacts_mm: &[Vec<nalgebra::Point3<f64>>],
        tolerance_mm: f64,
    ) -> ObjectShape {
        if self.kind != ColliderKind::ConvexHull {
            return self.clone();
        }
        let least_depth = |body: &Vec<nalgebra::Point3<f64>>| {
            body.iter()
                .map(|p| self.depth_mm(std::slice::from_ref(p)))
                .fold(f64::INFINITY, f64::min)
        };
        if !contacts_mm
            .iter()
            .any(|body| least_depth(body) > tolerance_mm)
        {
            return self.clone();
        }
        let off = beyond_mesh_mm(self, mesh, contacts_mm);
        if off <= tolerance_mm {
            return self.clone();
        }
        let key = shape_key(mesh, None);
        let parts = cache_get(&key).unwrap_or_else(|| {
            let points: Vec<Vector> = mesh.vertices.iter().map(convert::point_m).collect();
            let made = Self::decomposition(mesh, &points, self.is_revolution);
            cache_put(key, &made);
            made
        });
        ObjectShape {
            hull_off_mm: Some(off),
            ..parts
        }
    }
}

/// How far `hull`, the hull of `mesh`, lies beyond the mesh at the planned contacts `[mm]`:
/// the largest over the bodies (`contacts_mm`, a group per body) of the least over a body's
/// points of the point's depth in the hull less its distance to the mesh's surface, so that a
/// contact the plan presses into the object (an extended rule's phalanx) counts only what the
/// hull adds to the mesh there. 0 where the mesh cannot be made a triangle mesh.
fn beyond_mesh_mm(
    hull: &ObjectShape,
    mesh: &Mesh,
    contacts_mm: &[Vec<nalgebra::Point3<f64>>],
) -> f64 {
    let vertices = mesh.vertices.iter().map(convert::point_m).collect();
    let Ok(surface) = TriMesh::new(vertices, mesh.triangles.clone()) else {
        return 0.0;
    };
    let beyond = |q: &nalgebra::Point3<f64>| {
        let p = convert::point_m(q);
        let to_surface = (surface.project_local_point(p, false).point - p).length();
        hull.depth_mm(std::slice::from_ref(q)) - f64::from(to_surface) / convert::M_PER_MM
    };
    contacts_mm
        .iter()
        .filter(|body| !body.is_empty())
        .map(|body| body.iter().map(beyond).fold(f64::INFINITY, f64::min))
        .fold(0.0, f64::max)
}

/// parry's polyhedron of a hull whose volume differs from the hull's own by more than this
/// fraction is rebuilt from its planes ([`coarsened_hull`]).
const MISWEIGHED_FRACTION: f64 = 1e-3;

/// The mass distribution of a convex hull (`vertices` in metres, aligned frame, and `triangles`, as
/// `try_convex_hull` gives them), from its triangles in double precision
/// ([`crate::mesh::mass_properties`]); `None` where there is no hull with a volume.
fn hull_mass(vertices: &[Vector], triangles: &[[u32; 3]]) -> Option<MeshMass> {
    let mut triangles = triangles.to_vec();
    let mm = |v: &Vector| {
        nalgebra::Point3::new(f64::from(v.x), f64::from(v.y), f64::from(v.z)) / convert::M_PER_MM
    };
    let mut mesh = Mesh {
        vertices: vertices.iter().map(mm).collect(),
        triangles: triangles.clone(),
    };
    let mut props = crate::mesh::mass_properties(&mesh);
    if props.volume_mm3 < 0.0 {
        for t in &mut triangles {
            t.swap(1, 2);
        }
        mesh.triangles = triangles;
        props = crate::mesh::mass_properties(&mesh);
    }
    (props.volume_mm3 > 0.0 && props.volume_mm3.is_finite()).then_some(MeshMass {
        volume_mm3: props.volume_mm3,
        centroid_mm: props.centroid,
        inertia_mm5: props.inertia,
    })
}

/// How far a vertex of a merged hull face may lie off that face's plane `[m]`: rapier's allowed
/// contact error at the check's 1 cm length unit (0.05 mm).
const MERGED_FACE_TOLERANCE_M: f32 = 5e-5;

/// How far the faces of `poly` leave their planes `[m]`. parry builds a hull's faces by merging
/// neighbouring triangles whose unit normals differ by less than √ε of f32 in `1 − n₁·n₂` (about
/// 1.5°; `ConvexPolyhedron::from_convex_mesh`), with the normal of one of them: right for a plane
/// split into triangles, wrong for a finely tessellated curved surface (a cylinder of more than
/// about 240 segments, whose faces meet at under 1.5°), which it chains into one non-planar face.
/// The contacts against that face let a finger sink in: 8.4 mm into a 512-segment cylinder of 60
/// mm, against 0.01 mm at 144 segments.
fn bent_face_m(poly: &rapier3d::parry::shape::ConvexPolyhedron) -> f32 {
    let (points, ids) = (poly.points(), poly.vertices_adj_to_face());
    poly.faces()
        .iter()
        .map(|f| {
            let first = f.first_vertex_or_edge as usize;
            let face = &ids[first..first + f.num_vertices_or_edges as usize];
            let p = points[face[0] as usize];
            face.iter()
                .map(|&i| f.normal.dot(points[i as usize] - p).abs())
                .fold(0.0f32, f32::max)
        })
        .fold(0.0f32, f32::max)
}

/// Returns true if and only if the physics scene can use `poly`: at least four points and four
/// faces, each face with at least three vertices. parry's polyhedron of a hull merges
/// neighbouring triangles whose normals differ by less than about 1.5° ([`bent_face_m`]); on a
/// surface tessellated finer than that everywhere (a UV sphere of 300 × 150 segments, 60 mm)
/// every edge is merged away and no face is left, and the contact queries on it index an
/// empty face list.
fn usable_polyhedron(poly: &rapier3d::parry::shape::ConvexPolyhedron) -> bool {
    poly.points().len() >= 4
        && poly.faces().len() >= 4
        && poly.faces().iter().all(|f| f.num_vertices_or_edges >= 3)
}

/// [`usable_polyhedron`] of a convex polyhedron, or of every part of a compound with parts;
/// true for any other shape.
fn usable_shape(shape: &SharedShape) -> bool {
    if let Some(poly) = shape.as_convex_polyhedron() {
        return usable_polyhedron(poly);
    }
    shape
        .as_compound()
        .is_none_or(|c| !c.shapes().is_empty() && c.shapes().iter().all(|(_, p)| usable_shape(p)))
}

/// A convex decomposition with each part the scene cannot use ([`usable_polyhedron`]) rebuilt
/// from its face planes ([`coarsened_hull`]), or left out where that fails; `None` when no part
/// is left. The decomposition itself when every part is usable.
fn usable_parts(shape: &SharedShape) -> Option<SharedShape> {
    if usable_shape(shape) {
        return Some(shape.clone());
    }
    let compound = shape.as_compound()?;
    let parts: Vec<(Pose, SharedShape)> = compound
        .shapes()
        .iter()
        .filter_map(|(pose, part)| {
            if usable_shape(part) {
                return Some((*pose, part.clone()));
            }
            let points = part.as_convex_polyhedron()?.points();
            let (v, t) = rapier3d::parry::transformation::try_convex_hull(points).ok()?;
            coarsened_hull(&v, &t, false).map(|(h, _)| (*pose, h))
        })
        .collect();
    (!parts.is_empty()).then(|| SharedShape::compound(parts))
}

/// The box bounding `points` `[m]`: the collider of last resort, where neither the hull nor any
/// part of the decomposition is a polyhedron the scene can use (none is known; the collider's
/// report then says `1 parts` of a decomposition).
fn bounding_box(points: &[Vector]) -> SharedShape {
    let first = points.first().copied().unwrap_or(Vector::ZERO);
    let (lo, hi) = points
        .iter()
        .fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let half = ((hi - lo) * 0.5).max(Vector::splat(1e-6));
    SharedShape::compound(vec![(
        Pose::from_translation((lo + hi) * 0.5),
        SharedShape::cuboid(half.x, half.y, half.z),
    )])
}

/// [`bent_face_m`] of a shape that is a convex polyhedron (0 for any other).
fn bent_shape_m(shape: &SharedShape) -> f32 {
    shape.as_convex_polyhedron().map_or(0.0, bent_face_m)
}

/// Neighbouring faces of the hull from [`coarsened_hull`] are at least this far apart in
/// normal: 2°, beyond parry's merge of 1.5°.
const MIN_FACE_ANGLE_RAD: f64 = 2.0 * std::f64::consts::PI / 180.0;

/// A face plane of the hull is a supporting plane if no hull vertex lies further than this
/// outside it `[m]` (0.1 µm; f32 coordinates of a 0.1 m object are good to about 0.01 µm).
const SUPPORT_TOLERANCE_M: f64 = 1e-7;

/// The rebuilt hull may stand off the true one by at most this `[m]` (0.05 mm) or it is not used.
const MAX_OUTER_STANDOFF_M: f64 = 5e-5;

/// The convex hull `vertices` (metres) and `triangles`, rebuilt where parry would merge curved
/// faces into non-planar ones ([`bent_face_m`]): the hull's face planes are taken largest
/// face first, each kept only if its normal is at least [`MIN_FACE_ANGLE_RAD`] from every plane
/// kept (a plane split into triangles is one plane, kept once), and the hull is rebuilt as the
/// intersection of the kept half-spaces (its vertices found through the polar dual: the convex
/// hull of the planes' poles, each of whose triangles is a vertex where its three planes meet).
/// Every kept plane is a plane of the true hull, so the rebuilt one contains it, and stands off
/// it by about r·θ²/8 on a round part of radius r (0.01 mm on a 60 mm cylinder at 2°); any
/// two of its faces meet at 2° or more, so parry keeps them apart. Returns it with the full
/// hull's vertex count, or `None` where the full hull needs no rebuilding (every thesis object)
/// or the rebuilt one would stand off by more than [`MAX_OUTER_STANDOFF_M`].
///
/// `strict`: the rebuilt hull must hold every vertex to [`SUPPORT_TOLERANCE_M`]; otherwise
/// (for a hull parry kept no usable polyhedron of, [`usable_polyhedron`]) to
/// [`MERGED_FACE_TOLERANCE_M`], the contact error the scene allows anyway: a UV sphere of
/// 300 × 150 segments leaves a vertex 0.14 µm outside the rebuilt hull.
fn coarsened_hull(
    vertices: &[Vector],
    triangles: &[[u32; 3]],
    strict: bool,
) -> Option<(SharedShape, usize)> {
    let v64: Vec<Vector3<f64>> = vertices
        .iter()
        .map(|v| Vector3::new(f64::from(v.x), f64::from(v.y), f64::from(v.z)))
        .collect();
    let centre = v64.iter().sum::<Vector3<f64>>() / v64.len() as f64;
    // Each triangle's plane n·(x − centre) = d, with its area.
    let true_planes: Vec<(f64, Vector3<f64>, f64)> = triangles
        .iter()
        .filter_map(|t| {
            let [a, b, c] = t.map(|i| v64[i as usize]);
            let cross = (b - a).cross(&(c - a));
            let area = cross.norm();
            (area > 0.0).then(|| {
                let n = cross / area;
                (area, n, n.dot(&(a - centre)))
            })
        })
        .collect();
    let kept = kept_planes(&true_planes, &v64, &centre);
    let corners = plane_corners(&kept, &true_planes, &centre)?;
    let rebuilt = SharedShape::convex_hull(&corners)?;
    let poly = rebuilt.as_convex_polyhedron()?;
    if !usable_polyhedron(poly) || bent_face_m(poly) > MERGED_FACE_TOLERANCE_M {
        return None;
    }
    let tolerance = if strict {
        SUPPORT_TOLERANCE_M
    } else {
        f64::from(MERGED_FACE_TOLERANCE_M)
    };
    holds_all(poly, &v64, tolerance).then_some((rebuilt, vertices.len()))
}

/// The face planes of the hull `(area, unit normal, offset from the centre)` that
/// [`coarsened_hull`] keeps, largest face first: each only if its normal is at least
/// [`MIN_FACE_ANGLE_RAD`] from every plane kept and the whole hull (`v64`, about `centre`) is on
/// its inner side.
fn kept_planes(
    true_planes: &[(f64, Vector3<f64>, f64)],
    v64: &[Vector3<f64>],
    centre: &Vector3<f64>,
) -> Vec<(Vector3<f64>, f64)> {
    let mut planes: Vec<(f64, Vector3<f64>, f64)> =
        true_planes.iter().copied().filter(|p| p.2 > 0.0).collect();
    planes.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.2.total_cmp(&b.2)));
    let cos_min = MIN_FACE_ANGLE_RAD.cos();
    let mut kept: Vec<(Vector3<f64>, f64)> = Vec::new();
    // The kept normals by cell of side NORMAL_CELL: two unit normals less than 2° apart are
    // less than 0.035 apart, so in the same or a neighbouring cell.
    let mut near: std::collections::HashMap<[i64; 3], Vec<usize>, foldhash::fast::FixedState> =
        Default::default();
    let vertices = Clusters::of_points(v64);
    // A sliver triangle of nearly collinear points (a side's rings, one above the other) has a
    // normal of rounding noise: its plane is kept only if the whole hull is on its inner side.
    let supporting = |n: &Vector3<f64>, d: f64| {
        vertices.all(n, *centre, d + SUPPORT_TOLERANCE_M, |i| {
            n.dot(&(v64[i] - centre)) <= d + SUPPORT_TOLERANCE_M
        })
    };
    for (_, n, d) in planes {
        let cell = normal_cell(&n);
        let apart = neighbours(cell).all(|c| {
            near.get(&c)
                .is_none_or(|ks| ks.iter().all(|&k| kept[k].0.dot(&n) < cos_min))
        });
        if apart && supporting(&n, d) {
            near.entry(cell).or_default().push(kept.len());
            kept.push((n, d));
        }
    }
    kept
}

/// The side of the cells [`kept_planes`] and [`plane_corners`] group unit normals in: more
/// than the 0.035 between two normals 2° apart.
const NORMAL_CELL: f64 = 0.05;

/// The cell of side [`NORMAL_CELL`] that holds the unit normal `n`.
fn normal_cell(n: &Vector3<f64>) -> [i64; 3] {
    [n.x, n.y, n.z].map(|c| (c / NORMAL_CELL).floor() as i64)
}

/// `cell` and its 26 neighbours.
fn neighbours(cell: [i64; 3]) -> impl Iterator<Item = [i64; 3]> {
    (0..27).map(move |k| {
        [
            cell[0] + k % 3 - 1,
            cell[1] + (k / 3) % 3 - 1,
            cell[2] + k / 9 - 1,
        ]
    })
}

/// Vectors grouped in cells for bounding a linear function over each group at once (the
/// convex hull rebuild's tests of every vertex against a plane, and of every plane against a
/// corner, were each a product of two counts: 75 s for a 600 × 300 sphere): a group's members
/// `v` lie within `radius` of its `centre`, so `n·v ≤ n·centre + |n|·radius` (Cauchy–Schwarz),
/// and each carries a value (a plane's offset) of which the group keeps the least. A test of
/// every member then looks only at the groups whose bound does not settle it, so its answer is
/// the test's over every member, exactly.
struct Clusters {
    groups: Vec<Cluster>,
}

/// One group of [`Clusters`].
struct Cluster {
    centre: Vector3<f64>,
    radius: f64,
    least: f64,
    members: Vec<usize>,
}

impl Clusters {
    /// `items` (vector, value) grouped in cubes of side `cell`, in index order within a group.
    fn new(items: &[(Vector3<f64>, f64)], cell: f64) -> Clusters {
        let mut cells: std::collections::BTreeMap<[i64; 3], Vec<usize>> = Default::default();
        for (i, (v, _)) in items.iter().enumerate() {
            let key = [v.x, v.y, v.z].map(|c| {
                let k = (c / cell).floor();
                if k.is_finite() {
                    k as i64
                } else {
                    0
                }
            });
            cells.entry(key).or_default().push(i);
        }
        let groups = cells
            .into_values()
            .map(|members| {
                let centre = members.iter().map(|&i| items[i].0).sum::<Vector3<f64>>()
                    / members.len() as f64;
                let radius = members
                    .iter()
                    .map(|&i| (items[i].0 - centre).norm())
                    .fold(0.0, f64::max);
                let least = members
                    .iter()
                    .map(|&i| items[i].1)
                    .fold(f64::INFINITY, f64::min);
                Cluster {
                    centre,
                    radius,
                    least,
                    members,
                }
            })
            .collect();
        Clusters { groups }
    }

    /// Points grouped in cells of about 16 points of a surface.
    fn of_points(points: &[Vector3<f64>]) -> Clusters {
        let items: Vec<(Vector3<f64>, f64)> = points.iter().map(|p| (*p, 0.0)).collect();
        let (lo, hi) = points.iter().fold(
            (
                Vector3::repeat(f64::INFINITY),
                Vector3::repeat(f64::NEG_INFINITY),
            ),
            |(lo, hi), p| (lo.inf(p), hi.sup(p)),
        );
        let extent = (hi - lo).max();
        let across = (points.len() as f64 / 96.0).sqrt().clamp(1.0, 64.0);
        let cell = if extent.is_finite() && extent > 0.0 {
            extent / across
        } else {
            1.0
        };
        Clusters::new(&items, cell)
    }

    /// Whether `test` holds of every member whose group's bound on `n·(v − origin)` exceeds
    /// `limit` (with a margin for rounding): of every member, when `test` is `n·(v − origin) ≤
    /// limit` or implied by it.
    fn all(
        &self,
        n: &Vector3<f64>,
        origin: Vector3<f64>,
        limit: f64,
        mut test: impl FnMut(usize) -> bool,
    ) -> bool {
        let norm = n.norm();
        self.groups.iter().all(|g| {
            let at = n.dot(&(g.centre - origin));
            let bound = at + norm * g.radius;
            let margin = 1e-12 * (1.0 + at.abs() + norm * g.radius);
            bound + margin <= limit || g.members.iter().all(|&i| test(i))
        })
    }
}

/// The corners of the intersection of the `kept` half-spaces (about `centre`) `[m]`, found
/// through the polar dual: each triangle of the convex hull of the planes' poles is a corner
/// where its three planes meet; a corner that stands off the true hull (`true_planes`) by more
/// than [`MAX_OUTER_STANDOFF_M`] is left out. `None` if the poles have no hull.
fn plane_corners(
    kept: &[(Vector3<f64>, f64)],
    true_planes: &[(f64, Vector3<f64>, f64)],
    centre: &Vector3<f64>,
) -> Option<Vec<Vector>> {
    use rapier3d::parry::transformation::try_convex_hull;
    // The poles n / d; each triangle of their hull is a vertex of the intersection.
    let poles: Vec<Vector> = kept
        .iter()
        .map(|(n, d)| {
            let p = n / *d;
            Vector::new(p.x as f32, p.y as f32, p.z as f32)
        })
        .collect();
    let (dual_points, dual_triangles) = try_convex_hull(&poles).ok()?;
    let by_pole: std::collections::HashMap<[u32; 3], usize> = poles
        .iter()
        .enumerate()
        .map(|(k, p)| (p.to_array().map(f32::to_bits), k))
        .collect();
    // Whether a point (relative to the centre) stands outside the true hull by at most
    // MAX_OUTER_STANDOFF_M: n·x − d ≤ MAX for every plane, so n·x ≤ d + MAX, bounded by each
    // group of normals with its least offset.
    let planes = Clusters::new(
        &true_planes
            .iter()
            .map(|(_, n, d)| (*n, *d))
            .collect::<Vec<_>>(),
        NORMAL_CELL,
    );
    let close = |x: &Vector3<f64>| {
        let norm = x.norm();
        planes.groups.iter().all(|g| {
            let at = g.centre.dot(x);
            let bound = at + g.radius * norm - g.least;
            let margin = 1e-12 * (1.0 + at.abs() + g.radius * norm + g.least.abs());
            bound + margin <= MAX_OUTER_STANDOFF_M
                || g.members.iter().all(|&i| {
                    let (_, n, d) = true_planes[i];
                    n.dot(x) - d <= MAX_OUTER_STANDOFF_M
                })
        })
    };
    let mut corners: Vec<Vector> = Vec::new();
    for t in &dual_triangles {
        let planes = t.map(|i| {
            by_pole
                .get(&dual_points[i as usize].to_array().map(f32::to_bits))
                .map(|&k| kept[k])
        });
        let [Some(p1), Some(p2), Some(p3)] = planes else {
            continue;
        };
        let m =
            nalgebra::Matrix3::from_rows(&[p1.0.transpose(), p2.0.transpose(), p3.0.transpose()]);
        // Three nearly parallel planes (a sliver of the dual hull) meet far off, or nowhere:
        // their corner is another triangle's.
        let Some(x) = m.lu().solve(&Vector3::new(p1.1, p2.1, p3.1)) else {
            continue;
        };
        if x.iter().all(|c| c.is_finite()) && close(&x) {
            let p = x + centre;
            corners.push(Vector::new(p.x as f32, p.y as f32, p.z as f32));
        }
    }
    Some(corners)
}

/// Returns true if and only if `poly` holds every point of `v64` `[m]` (no corner lost to the
/// skips of [`plane_corners`]): every point inside every face plane parry made, to
/// `tolerance` `[m]`.
fn holds_all(
    poly: &rapier3d::parry::shape::ConvexPolyhedron,
    v64: &[Vector3<f64>],
    tolerance: f64,
) -> bool {
    let ids = poly.vertices_adj_to_face();
    let points = Clusters::of_points(v64);
    poly.faces().iter().all(|f| {
        let a = poly.points()[ids[f.first_vertex_or_edge as usize] as usize];
        let a = Vector3::new(f64::from(a.x), f64::from(a.y), f64::from(a.z));
        let n = Vector3::new(
            f64::from(f.normal.x),
            f64::from(f.normal.y),
            f64::from(f.normal.z),
        );
        points.all(&n, a, tolerance, |i| n.dot(&(v64[i] - a)) <= tolerance)
    })
}

/// The object's centre of mass `[m]` and inertia tensor about it `[kg·m²]`, aligned frame, as the
/// rapier check has them ([`object_mass_properties`]).
pub fn collider_inertia(
    object: &ObjectShape,
    mass_kg: f64,
) -> (nalgebra::Vector3<f64>, nalgebra::Matrix3<f64>) {
    let props = object_mass_properties(object, mass_kg);
    let m = props.reconstruct_inertia_matrix();
    let c = props.local_com;
    let cols = m.to_cols_array();
    (
        nalgebra::Vector3::new(f64::from(c.x), f64::from(c.y), f64::from(c.z)),
        nalgebra::Matrix3::from_column_slice(&cols.map(f64::from)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 56: parry merged every hull face of a UV sphere of 300 × 150 segments (89,400
    /// triangles, 60 mm) away, and the scene's support scan indexed an empty face list (a
    /// panic in the physics check). Its collider is now a polyhedron with faces, or another
    /// usable shape, and a point's depth is found on it.
    #[test]
    fn a_finely_divided_sphere_gets_a_collider_with_faces() {
        let mesh = crate::mesh::primitives::uv_sphere(30.0, 300);
        assert_eq!(mesh.triangles.len(), 89_400);
        let volume = crate::mesh::mass_properties(&mesh).volume_mm3;
        let shape = ObjectShape::from_mesh(&mesh, volume);
        assert!(usable_shape(&shape.shape), "{:?}", shape.kind);
        let inside = nalgebra::Point3::new(29.0, 0.0, 0.0);
        let depth = shape.depth_mm(&[inside]);
        assert!((depth - 1.0).abs() < 0.06, "depth {depth} mm, expected 1");
    }

    #[test]
    fn a_hull_that_bridges_a_planned_contact_gives_way_to_the_decomposition() {
        // A bottle: a body 60 mm across and 300 mm tall, a cone to a neck 28 mm across at
        // 330-336 mm, a lip 32 mm across to 338 mm. The hull bridges the neck from the cone's
        // foot (300 mm, r 30) to the lip's top edge (338 mm, r 16); the bridge adds 1.4 % of
        // the volume, so the volume test takes the hull. The neck at 333 mm (r 14) lies inside
        // it by the distance from (33, −16) to the line along (38, −14) in the profile:
        // (16·38 − 33·14) / √(38² + 14²) = 3.605 mm (3.593 on parry's faceted hull).
        let mesh = crate::objects::revolved(&[
            (0.0, 60.0),
            (300.0, 60.0),
            (330.0, 28.0),
            (336.0, 28.0),
            (336.0, 32.0),
            (338.0, 32.0),
        ]);
        let volume = crate::mesh::mass_properties(&mesh).volume_mm3;
        let hull = ObjectShape::from_mesh(&mesh, volume);
        assert_eq!(hull.kind, ColliderKind::ConvexHull);
        let body = nalgebra::Point3::new(30.0, 0.0, 100.0);
        let neck = nalgebra::Point3::new(14.0, 0.0, 333.0);
        let outside = nalgebra::Point3::new(40.0, 0.0, 100.0);
        assert!(hull.depth_mm(&[body, outside]) < 1e-3);
        let depth = hull.depth_mm(&[body, neck]);
        assert!((depth - 3.605).abs() < 0.015, "{depth}");
        // A grasp of the body keeps the hull; one that touches the neck gets the parts.
        let kept = hull.true_at(&mesh, &[vec![body]], 0.5);
        assert_eq!(
            (kept.kind, kept.hull_off_mm),
            (ColliderKind::ConvexHull, None)
        );
        assert_eq!(hull.true_at(&mesh, &[], 0.5).kind, ColliderKind::ConvexHull);
        let taken = hull.true_at(&mesh, &[vec![body], vec![neck]], 0.5);
        assert_eq!(taken.kind, ColliderKind::ConvexDecomposition);
        assert!(taken.parts > 1);
        assert!((taken.hull_off_mm.unwrap() - depth).abs() < 1e-3);
        assert_eq!(ColliderReport::of(&taken).hull_off_mm, taken.hull_off_mm);
        // A contact the plan presses 2 mm into the body is as deep in the mesh as in the
        // hull: the hull adds nothing there and stays.
        let pressed = nalgebra::Point3::new(28.0, 0.0, 100.0);
        assert!((hull.depth_mm(&[pressed]) - 2.0).abs() < 0.01);
        assert_eq!(
            hull.true_at(&mesh, &[vec![body], vec![pressed]], 0.5).kind,
            ColliderKind::ConvexHull
        );
        // Within the tolerance the hull stays.
        assert_eq!(
            hull.true_at(&mesh, &[vec![neck]], 3.7).kind,
            ColliderKind::ConvexHull
        );
        // A body with one contact in the neck and another on the hull rests on the hull.
        assert_eq!(
            hull.true_at(&mesh, &[vec![neck, body]], 0.5).kind,
            ColliderKind::ConvexHull
        );
    }

    #[test]
    fn a_hulls_own_mass_is_parrys_where_parry_weighs_it_right() {
        // The D40 cylinder and the prism: parry's polyhedron weighs their hulls right, so they
        // keep it (no `mesh_mass`), and the hull's own mass distribution, which the body takes
        // where parry's misweighs it, is the same to f32.
        for mesh in [
            crate::objects::cylinder(40.0, 124.0),
            crate::objects::prism(30.0, 40.0, 100.0),
        ] {
            let aligned = crate::mesh::align(&mesh);
            let volume = crate::mesh::mass_properties(&mesh).volume_mm3;
            let mut shape = ObjectShape::from_mesh(&aligned.mesh, volume);
            assert_eq!(shape.kind, ColliderKind::ConvexHull);
            assert_eq!(shape.mesh_mass, None);
            let parrys = object_mass_properties(&shape, 0.2);
            let points: Vec<Vector> = aligned.mesh.vertices.iter().map(convert::point_m).collect();
            let (v, t) = rapier3d::parry::transformation::try_convex_hull(&points).unwrap();
            shape.mesh_mass = hull_mass(&v, &t);
            let own = shape.mesh_mass.expect("a hull");
            assert!((own.volume_mm3 - volume).abs() < 1e-6 * volume, "{own:?}");
            let owns = object_mass_properties(&shape, 0.2);
            assert!((parrys.mass() - owns.mass()).abs() < 1e-6);
            assert!(
                (parrys.local_com - owns.local_com).length() < 1e-6,
                "{parrys:?} {owns:?}"
            );
            let (a, b) = (
                parrys.reconstruct_inertia_matrix(),
                owns.reconstruct_inertia_matrix(),
            );
            let scale = a.to_cols_array().iter().fold(0f32, |m, v| m.max(v.abs()));
            for (x, y) in a.to_cols_array().iter().zip(b.to_cols_array()) {
                assert!((x - y).abs() < 1e-4 * scale, "{a:?} against {b:?}");
            }
        }
    }

    #[test]
    fn a_convex_decomposition_is_made_once_per_mesh() {
        let objects = crate::objects::thesis_objects();
        let mesh = &objects.iter().find(|(n, _)| *n == "chapter4").unwrap().1;
        let mesh = crate::mesh::align(mesh).mesh;
        let volume = crate::mesh::mass_properties(&mesh).volume_mm3;
        let first = ObjectShape::cached(&mesh, volume);
        assert_eq!(first.kind, ColliderKind::ConvexDecomposition);
        // The same mesh again: the same shape, not a new decomposition.
        let again = ObjectShape::cached(&mesh, volume);
        assert!(std::sync::Arc::ptr_eq(&first.shape.0, &again.shape.0));
        // Equal to one made afresh, part for part.
        let fresh = ObjectShape::from_mesh(&mesh, volume);
        assert_eq!(fresh.parts, first.parts);
        let aabb = |s: &ObjectShape| s.shape.compute_local_aabb();
        assert_eq!(aabb(&fresh), aabb(&first));
        // Another mesh (one vertex moved) is another key.
        let mut moved = mesh.clone();
        moved.vertices[0].x += 1e-3;
        assert_ne!(
            shape_key(&moved, Some(volume)),
            shape_key(&mesh, Some(volume))
        );
        // A convex mesh is not kept (its hull is cheap).
        let prism = crate::objects::prism(40.0, 100.0, 80.0);
        let v = crate::mesh::mass_properties(&prism).volume_mm3;
        let a = ObjectShape::cached(&prism, v);
        let b = ObjectShape::cached(&prism, v);
        assert_eq!(a.kind, ColliderKind::ConvexHull);
        assert!(!std::sync::Arc::ptr_eq(&a.shape.0, &b.shape.0));
    }

    #[test]
    fn a_decomposition_moved_into_another_frame_is_its_parts_moved() {
        let objects = crate::objects::thesis_objects();
        let mesh = &objects.iter().find(|(n, _)| *n == "chapter4").unwrap().1;
        let mesh = crate::mesh::align(mesh).mesh;
        let volume = crate::mesh::mass_properties(&mesh).volume_mm3;
        let made = ObjectShape::from_mesh(&mesh, volume);
        assert_eq!(made.kind, ColliderKind::ConvexDecomposition);
        // Every part's vertices where its pose puts them `[m]`.
        let points = |s: &ObjectShape| -> Vec<nalgebra::Point3<f64>> {
            let c = s.shape.as_compound().unwrap();
            c.shapes()
                .iter()
                .flat_map(|(pose, p)| {
                    let poly = p.as_convex_polyhedron().unwrap();
                    poly.points().iter().map(|v| *pose * *v).collect::<Vec<_>>()
                })
                .map(|p| nalgebra::Point3::new(f64::from(p.x), f64::from(p.y), f64::from(p.z)))
                .collect()
        };
        let mass = |s: &ObjectShape| f64::from(s.shape.mass_properties(1.0).mass());
        // A turn of 90° about x: the same parts, where the decomposition made afresh in the
        // turned frame is another (V-HACD voxelises along the frame's axes).
        let turn = nalgebra::Isometry3::new(
            nalgebra::Vector3::zeros(),
            nalgebra::Vector3::x() * std::f64::consts::FRAC_PI_2,
        );
        let moved = made.moved(&turn, false).unwrap();
        assert_eq!((moved.kind, moved.parts), (made.kind, made.parts));
        assert!((mass(&moved) - mass(&made)).abs() <= 1e-5 * mass(&made));
        let mut there = mesh.clone();
        there.map_vertices(|p| turn * p);
        assert_ne!(ObjectShape::from_mesh(&there, volume).parts, made.parts);
        // Any rigid motion: every vertex where the motion puts it, the volume kept.
        let motion = nalgebra::Isometry3::new(
            nalgebra::Vector3::new(12.0, -7.0, 30.0),
            nalgebra::Vector3::new(0.3, -0.5, 0.9),
        );
        let moved = made.moved(&motion, true).unwrap();
        assert!(moved.is_revolution);
        for (a, b) in points(&made).iter().zip(points(&moved)) {
            let want = motion * (a * 1e3) * 1e-3;
            assert!((want - b).norm() < 1e-6, "{want} {b}");
        }
        assert!((mass(&moved) - mass(&made)).abs() <= 1e-5 * mass(&made));
        // A hull is not moved: it is made in each frame.
        let prism = crate::objects::prism(40.0, 100.0, 80.0);
        let v = crate::mesh::mass_properties(&prism).volume_mm3;
        assert!(ObjectShape::from_mesh(&prism, v)
            .moved(&motion, false)
            .is_none());
    }

    /// A cylinder of 60 mm and 120 mm on `segments` facets, with a ring every 10 mm.
    fn fine_cylinder(segments: usize) -> Mesh {
        use crate::objects::{radial_solid, uniform_angles, Ring};
        let rings: Vec<Ring> = (0..=12)
            .map(|k| Ring {
                z: 10.0 * k as f64,
                radii: vec![30.0; segments],
            })
            .collect();
        radial_solid(&uniform_angles(segments), &rings)
    }

    #[test]
    fn a_hull_parry_would_merge_into_curved_faces_is_rebuilt_from_its_planes() {
        let shape = |segments| {
            let mesh = fine_cylinder(segments);
            let v = crate::mesh::mass_properties(&mesh).volume_mm3;
            (ObjectShape::from_mesh(&mesh, v), mesh)
        };
        let hull_of = |s: &ObjectShape| {
            let c = s.shape.as_convex_polyhedron().unwrap();
            rapier3d::parry::transformation::try_convex_hull(c.points()).unwrap()
        };
        // 144 facets meet at 2.5°: parry keeps them apart, and the hull is the plain one, as for
        // every thesis object.
        let (plain, _) = shape(144);
        assert_eq!(plain.coarsened_from, None);
        assert_eq!(plain.kind, ColliderKind::ConvexHull);
        // 512 facets meet at 0.7°, within parry's 1.5° merge: the side would become one face
        // bent round the cylinder, some 30 mm off its own plane.
        let mesh = fine_cylinder(512);
        let points: Vec<Vector> = mesh.vertices.iter().map(convert::point_m).collect();
        let bent = bent_shape_m(&SharedShape::convex_hull(&points).unwrap());
        assert!(bent > 0.02, "{bent} m");
        assert!(bent_shape_m(&plain.shape) <= MERGED_FACE_TOLERANCE_M);
        let (rebuilt, mesh) = shape(512);
        assert_eq!(rebuilt.coarsened_from, Some(1024));
        let (v, t) = hull_of(&rebuilt);
        assert!(bent_shape_m(&rebuilt.shape) <= MERGED_FACE_TOLERANCE_M);
        // Fewer facets, no two within 2° of each other: 512 / (2° of 0.703°) rounds to 148 or so.
        assert!((200..=400).contains(&v.len()), "{} vertices", v.len());
        // It holds the whole mesh (every vertex inside every face plane, to 0.1 µm) and stands
        // off it by under 0.05 mm: every corner within 30 mm + 0.05 mm of the axis and within
        // the caps.
        for tri in &t {
            let [a, b, c] = tri.map(|i| v[i as usize]);
            let n = (b - a).cross(c - a).normalize();
            for p in &mesh.vertices {
                let out = n.dot(convert::point_m(p) - a);
                assert!(out <= 1e-7, "{p:?}: {out} m outside");
            }
        }
        for c in &v {
            let r = (c.x * c.x + c.y * c.y).sqrt();
            assert!((0.0299..=0.030_05).contains(&r), "{r} m");
            assert!(c.z >= -1e-6 && c.z <= 0.120 + 1e-6, "{} m", c.z);
        }
    }
}

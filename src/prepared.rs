//! The object as every pipeline needs it, built once: the mesh loaded and validated, its mass
//! properties, its alignment on the thesis's axis, its mass, and its colliders.
//!
//! `run` (one scenario) and `tune` (a grid of planner settings) both start from a
//! [`PreparedObject`], so loading, aligning, the mass formula and the collider are written once.

use crate::hand::Hand;
use crate::mesh::{self, AlignedObject, GraspAxis, LoadedMesh, MassProperties, Mesh, MeshError};
use crate::plan::timings::ms;
use crate::plan::StageTimings;
use crate::scenario::{ObjectSpec, Scenario};
use crate::sim::{Case, ObjectShape, SimHand};
use std::collections::BTreeMap;
use std::sync::Mutex;
use std::time::Instant;

/// A scenario's object, loaded and aligned, with its mass and its colliders (made on demand,
/// once per axis; a decomposition once per object).
pub struct PreparedObject {
    /// The mesh as loaded (original frame), with what loading found and repaired.
    pub loaded: LoadedMesh,
    /// Mass properties of the loaded mesh (unit density, original frame).
    pub props: MassProperties,
    /// The object aligned on the thesis's axis (least moment of inertia).
    pub aligned: AlignedObject,
    /// Mass `[kg]`, from the scenario's density or mass.
    pub mass_kg: f64,
    /// Colliders by axis, each made the first time it is asked for.
    shapes: Mutex<BTreeMap<GraspAxis, ObjectShape>>,
}

impl PreparedObject {
    /// Loads, validates and aligns `object`'s mesh and computes its mass; `timings` receives
    /// `load` and `align` `[ms]`.
    ///
    /// # Errors
    /// [`MeshError`] for a bad mesh file.
    pub fn load(object: &ObjectSpec, timings: &mut StageTimings) -> Result<Self, MeshError> {
        let t0 = Instant::now();
        let loaded = mesh::load_mesh(&object.mesh, object.units)?;
        timings.load = ms(t0);
        let t1 = Instant::now();
        // An open surface encloses no volume of its own: integrated about the file's bounding
        // box it depends on the frame the file was written in (libero_black_book's was
        // negative in two frames of six, its mass then too, and the physics check met NaN), so
        // it is the covariant fan's, about the surface's own centroid, which also decided its
        // winding (issue 30). So is a surface with edges shared by more than two triangles: its
        // edges do not cancel in pairs either, and rs_bottle's (6 such edges) came out 264,255
        // to 294,271 mm³ in six frames, its mass with it, and its collider a hull in three and
        // a decomposition in the others (the hull test is against this volume). Its shells may
        // still overlap (thirty stacked cubes sharing faces): then the union's, as for any
        // closed surface ([`mesh::mass_properties_from`]).
        let covariant = || mesh::covariant_mass_properties(&loaded.mesh);
        let props = if loaded.topology.boundary_edges > 0 {
            covariant().unwrap_or_else(|| mesh::mass_properties(&loaded.mesh))
        } else if loaded.topology.non_manifold_edges > 0 {
            match covariant() {
                Some(c) => mesh::mass_properties_from(&loaded.mesh, c),
                None => mesh::mass_properties(&loaded.mesh),
            }
        } else {
            mesh::mass_properties(&loaded.mesh)
        };
        let aligned = mesh::align_with_rule(&loaded.mesh, &props, GraspAxis::THESIS, object.frame);
        timings.align = ms(t1);
        let mass_kg = object.mass.mass_kg(props.volume_mm3, loaded.mass_kg);
        Ok(PreparedObject {
            loaded,
            props,
            aligned,
            mass_kg,
            shapes: Mutex::default(),
        })
    }

    /// The mesh as loaded (original frame).
    pub fn mesh(&self) -> &Mesh {
        &self.loaded.mesh
    }

    /// Enclosed volume `[mm³]`.
    pub fn volume_mm3(&self) -> f64 {
        self.props.volume_mm3
    }

    /// The collider of the object aligned as `a` is, whatever the grasp: its convex hull if the
    /// mesh is convex, else its convex decomposition. The decomposition is made once per object,
    /// in the thesis axis's frame ([`Self::aligned`]), and moved into any other axis's frame
    /// ([`ObjectShape::moved`]); a hull, which costs milliseconds, is made in each.
    pub fn own_shape(&self, a: &AlignedObject) -> ObjectShape {
        if let Some(s) = self.shapes_lock().get(&a.axis) {
            return s.clone();
        }
        let thesis = (a.axis != self.aligned.axis).then(|| self.own_shape(&self.aligned));
        let moved = thesis.and_then(|t| {
            let motion = a.to_aligned * self.aligned.to_aligned.inverse();
            t.moved(&motion, crate::sim::collider::is_revolution(&a.mesh))
        });
        let shape = moved.unwrap_or_else(|| ObjectShape::cached(&a.mesh, self.props.volume_mm3));
        self.shapes_lock().entry(a.axis).or_insert(shape).clone()
    }

    /// The colliders made so far, by axis.
    fn shapes_lock(&self) -> std::sync::MutexGuard<'_, BTreeMap<GraspAxis, ObjectShape>> {
        self.shapes.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The collider for a check of `pose` on the object aligned as `a`: [`Self::own_shape`],
    /// but the hull of a convex mesh gives way to its decomposition where it lies more than
    /// the hand's relief (`hand.relief_mm()`, the depth a finger does not feel) outside the
    /// pose's planned contacts ([`ObjectShape::true_at`]).
    pub fn shape(&self, a: &AlignedObject, pose: &SimHand, hand: &Hand) -> ObjectShape {
        self.own_shape(a)
            .true_at(&a.mesh, &pose.planned_contacts_mm, hand.relief_mm())
    }

    /// The physics check's case for `scenario`'s hand, friction and protocol, this object's
    /// mass, `shape` and the hand `pose`.
    pub fn case<'a>(
        &self,
        scenario: &'a Scenario,
        pose: &'a SimHand,
        shape: &'a ObjectShape,
    ) -> Case<'a> {
        Case {
            hand: &scenario.hand,
            pose,
            object: shape,
            mass_kg: self.mass_kg,
            friction: scenario.object.friction,
            params: &scenario.sim,
        }
    }
}

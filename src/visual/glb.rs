//! Binary glTF scenes of a grasp: one node per body (palm, six phalanges, object), metres,
//! under a root node that turns grasp-sim's Z-up frame into glTF's Y-up. The JSON is built with
//! serde_json and packed with the `gltf` crate's GLB writer; tests read it back with its reader.

use crate::hand::{bend, palm_rotation, Hand};
use crate::mesh::Mesh;
use crate::sim::convert::M_PER_MM;
use nalgebra::{Point3, UnitQuaternion, Vector3};

/// One body: a triangle mesh in its own frame and its pose.
pub struct Body {
    /// Node name.
    pub name: String,
    /// Vertices in the body frame `[m]`.
    pub positions: Vec<[f32; 3]>,
    /// Triangles.
    pub indices: Vec<u32>,
    /// RGBA colour.
    pub color: [f32; 4],
    /// Position `[m]`.
    pub translation: Vector3<f64>,
    /// Orientation.
    pub rotation: UnitQuaternion<f64>,
}

fn cuboid(lo: [f64; 3], hi: [f64; 3]) -> (Vec<[f32; 3]>, Vec<u32>) {
    let mut p = Vec::new();
    for k in 0..8 {
        p.push([
            (if k & 1 == 0 { lo[0] } else { hi[0] }) as f32,
            (if k & 2 == 0 { lo[1] } else { hi[1] }) as f32,
            (if k & 4 == 0 { lo[2] } else { hi[2] }) as f32,
        ]);
    }
    let idx = vec![
        0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6,
        1, 3, 5, 3, 7, 5,
    ];
    (p, idx)
}

/// The object's body from its aligned mesh (millimetres), at `translation`/`rotation`.
pub fn object_body(mesh: &Mesh, translation: Vector3<f64>, rotation: UnitQuaternion<f64>) -> Body {
    Body {
        name: "object".to_string(),
        positions: mesh
            .vertices
            .iter()
            .map(|v| {
                [
                    (v.x * M_PER_MM) as f32,
                    (v.y * M_PER_MM) as f32,
                    (v.z * M_PER_MM) as f32,
                ]
            })
            .collect(),
        indices: mesh.triangles.iter().flatten().copied().collect(),
        color: [0.75, 0.75, 0.72, 1.0],
        translation,
        rotation,
    }
}

/// The hand's bodies in their local frames (as in the rapier scene) with the given poses, in
/// the order palm, then phalanx 1 and 2 of each finger.
pub fn hand_bodies(hand: &Hand, poses: &[(Vector3<f64>, UnitQuaternion<f64>)]) -> Vec<Body> {
    let mm = M_PER_MM;
    let o = hand.fingers.offset_mm * mm;
    let [z_lo, z_hi] = hand.palm_z_range_mm();
    let mut bodies = Vec::new();
    let (p, i) = cuboid(
        [0.0, -hand.palm.half_width_mm * mm, z_lo * mm],
        [
            hand.palm.offset_mm * mm,
            hand.palm.half_width_mm * mm,
            z_hi * mm,
        ],
    );
    bodies.push(("palm".to_string(), p, i, [0.2, 0.4, 0.8, 1.0]));
    for f in &hand.finger_list {
        let s = f.side.sign();
        for (j, len) in [(1, hand.phalanx_1.length_mm), (2, hand.phalanx_2.length_mm)] {
            let y = s * len * mm;
            let (p, i) = cuboid([-o, y.min(0.0), -o], [o, y.max(0.0), o]);
            bodies.push((
                format!("{}_phalanx_{j}", f.name),
                p,
                i,
                [0.85, 0.25, 0.2, 1.0],
            ));
        }
    }
    bodies
        .into_iter()
        .zip(poses)
        .map(|((name, positions, indices, color), (t, r))| Body {
            name,
            positions,
            indices,
            color,
            translation: *t,
            rotation: *r,
        })
        .collect()
}

/// The planned poses of the hand's bodies (palm, then phalanx 1 and 2 of each finger), in the
/// aligned frame, metres; `theta_deg` per finger.
pub fn planned_poses(
    hand: &Hand,
    origin_mm: &Point3<f64>,
    axes: &[Vector3<f64>; 3],
    theta_deg: &[[f64; 2]],
) -> Vec<(Vector3<f64>, UnitQuaternion<f64>)> {
    let bends: Vec<[f64; 2]> = theta_deg.iter().map(|t| t.map(bend)).collect();
    hand.body_poses(&(*origin_mm, palm_rotation(axes)), &bends)
        .into_iter()
        .map(|(p, r)| (p.coords * M_PER_MM, r))
        .collect()
}

/// The scene as GLB bytes.
pub fn glb(bodies: &[Body]) -> Vec<u8> {
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut meshes = Vec::new();
    let mut materials = Vec::new();
    let mut nodes = vec![serde_json::Value::Null];
    for (k, b) in bodies.iter().enumerate() {
        let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
        let pos_offset = bin.len();
        for p in &b.positions {
            for c in 0..3 {
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
                bin.extend_from_slice(&p[c].to_le_bytes());
            }
        }
        let pos_len = bin.len() - pos_offset;
        let idx_offset = bin.len();
        for i in &b.indices {
            bin.extend_from_slice(&i.to_le_bytes());
        }
        let idx_len = bin.len() - idx_offset;
        views.push(serde_json::json!({"buffer": 0, "byteOffset": pos_offset, "byteLength": pos_len, "target": 34962}));
        views.push(serde_json::json!({"buffer": 0, "byteOffset": idx_offset, "byteLength": idx_len, "target": 34963}));
        accessors.push(serde_json::json!({"bufferView": 2 * k, "componentType": 5126, "count": b.positions.len(), "type": "VEC3", "min": lo, "max": hi}));
        accessors.push(serde_json::json!({"bufferView": 2 * k + 1, "componentType": 5125, "count": b.indices.len(), "type": "SCALAR"}));
        materials.push(serde_json::json!({"name": b.name, "doubleSided": true,
            "pbrMetallicRoughness": {"baseColorFactor": b.color, "metallicFactor": 0.0, "roughnessFactor": 0.8}}));
        meshes.push(serde_json::json!({"name": b.name, "primitives": [{"attributes": {"POSITION": 2 * k}, "indices": 2 * k + 1, "material": k}]}));
        let q = b.rotation;
        nodes.push(serde_json::json!({"name": b.name, "mesh": k,
            "translation": [b.translation.x, b.translation.y, b.translation.z],
            "rotation": [q.i, q.j, q.k, q.w]}));
    }
    // Z up (grasp-sim) to Y up (glTF): −90° about X.
    let h = std::f64::consts::FRAC_1_SQRT_2;
    nodes[0] = serde_json::json!({"name": "grasp", "rotation": [-h, 0.0, 0.0, h],
        "children": (1..=bodies.len()).collect::<Vec<_>>()});
    let json = serde_json::json!({
        "asset": {"version": "2.0", "generator": "grasp-sim"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}],
    });
    let json = serde_json::to_vec(&json).unwrap_or_default();
    gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: 0,
        },
        json: std::borrow::Cow::Owned(json),
        bin: Some(std::borrow::Cow::Owned(bin)),
    }
    .to_vec()
    .unwrap_or_default()
}

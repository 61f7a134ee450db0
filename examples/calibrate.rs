//! Fits the thesis hand's lost dimensions (DESIGN.md section 3) to the thesis's reported joint
//! angles for the D40 cylinder and the prism — the fitting data — and prints the residuals on
//! the cups, which are validation only.
//!
//!     cargo run --release --example calibrate
//!
//! Fitted: the joint-1 axes' lateral distance and setback, phalanx 1's length (joint to joint)
//! and the length of phalanx 2's thinned tip (its unusable distal length, which decides where
//! its contact line ends and so the tip-contact angle). Kept as stated by the thesis: finger
//! offset 7 mm, phalanx 2 20 mm (18 mm in the variant), joint ranges 45°–135°.
//!
//! The centre ALS of a finger is placed with the planner's own `place_als` on the finger
//! plane's contour, which for these objects at zero pitch does not depend on the hand: the palm
//! surface touches the object at x = 0 (D40: a circle of radius 20 about (−20, 0); the prism at
//! approach 0, palm on its 15 mm face: the rectangle x ∈ [−30, 0], |y| ≤ 7.5).

use grasp_sim::hand::Hand;
use grasp_sim::plan::finger::place_als;
use grasp_sim::slice::{slice, Plane, SliceOptions};
use nalgebra::{Point3, Vector3};
use std::path::Path;

struct Case {
    name: &'static str,
    contour: grasp_sim::slice::Slice,
    phalanx2_mm: f64,
    theta: [f64; 2],
    is_fit: bool,
}

fn object_slice(mesh: &grasp_sim::mesh::Mesh, z: f64, x_front: f64) -> grasp_sim::slice::Slice {
    // The palm plane at height z, x along +X (away from the object) with the palm surface at
    // x = x_front, y along +Y: the planner's finger plane at zero pitch and approach 0.
    slice(
        mesh,
        &Plane {
            origin: Point3::new(x_front, 0.0, z),
            u: Vector3::x(),
            v: Vector3::y(),
        },
        SliceOptions::default(),
    )
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let base = Hand::load(&root.join("assets/hands/thesis.toml"), &[]).unwrap();
    let cyl = grasp_sim::objects::cylinder(40.0, 124.0);
    // The palm on the prism's narrow (15 mm) face: its 30 mm side along X.
    let prism = grasp_sim::objects::prism(30.0, 15.0, 124.0);
    let cup = grasp_sim::objects::frustum(56.0, 80.0, 110.0);
    let cup_r = |z: f64| (56.0 + 24.0 * z / 110.0) / 2.0;
    let cases = vec![
        Case {
            name: "D40",
            contour: object_slice(&cyl, 62.0, 20.0),
            phalanx2_mm: 20.0,
            theta: [72.2, 90.0],
            is_fit: true,
        },
        Case {
            name: "prism",
            contour: object_slice(&prism, 62.0, 15.0),
            phalanx2_mm: 20.0,
            theta: [58.0, 72.2],
            is_fit: true,
        },
        Case {
            name: "prism, phalanx 2 = 18",
            contour: object_slice(&prism, 62.0, 15.0),
            phalanx2_mm: 18.0,
            theta: [58.0, 68.6],
            is_fit: true,
        },
        // Validation (not fitted): the cup's fingers at zero pitch, a close approximation of its
        // 6° pitched grasp: finger_1 at Z 62, finger_2 at 37, finger_3 at 12.
        Case {
            name: "cup finger_1 (validation)",
            contour: object_slice(&cup, 62.0, cup_r(62.0)),
            phalanx2_mm: 20.0,
            theta: [98.3, 117.6],
            is_fit: false,
        },
        Case {
            name: "cup finger_2 (validation)",
            contour: object_slice(&cup, 37.0, cup_r(37.0)),
            phalanx2_mm: 20.0,
            theta: [94.4, 113.1],
            is_fit: false,
        },
        Case {
            name: "cup finger_3 (validation)",
            contour: object_slice(&cup, 12.0, cup_r(12.0)),
            phalanx2_mm: 20.0,
            theta: [89.9, 108.5],
            is_fit: false,
        },
    ];

    let angles = |h: &Hand, c: &Case| -> Option<[f64; 2]> {
        let mut h = h.clone();
        h.phalanx_2.length_mm = c.phalanx2_mm;
        place_als(&c.contour, &h, 1.0)
            .ok()
            .map(|a| [a.theta1_deg, a.theta2_deg])
    };
    let cost = |h: &Hand| -> f64 {
        cases
            .iter()
            .filter(|c| c.is_fit)
            .map(|c| match angles(h, c) {
                Some(a) => (a[0] - c.theta[0]).powi(2) + (a[1] - c.theta[1]).powi(2),
                None => 1e6,
            })
            .sum()
    };
    let with = |lat: f64, sb: f64, l1: f64, tip: f64| {
        let mut h = base.clone();
        h.joints.lateral_mm = lat;
        h.joints.setback_mm = sb;
        h.phalanx_1.length_mm = l1;
        h.phalanx_2.unusable_distal_mm = tip;
        h
    };
    // Coarse grid, then two refinements around the best.
    let mut best = (f64::INFINITY, [36.7, 5.8, 61.0, 0.0]);
    let mut span = [
        [25.0, 45.0, 1.0],
        [0.0, 14.0, 1.0],
        [30.0, 75.0, 1.0],
        [0.0, 6.0, 1.0],
    ];
    for _ in 0..3 {
        let grid = |s: [f64; 3]| {
            let n = ((s[1] - s[0]) / s[2]).round() as usize;
            (0..=n).map(move |i| s[0] + i as f64 * s[2])
        };
        for lat in grid(span[0]) {
            for sb in grid(span[1]) {
                for l1 in grid(span[2]) {
                    for tip in grid(span[3]) {
                        if tip >= 18.0 {
                            continue;
                        }
                        let c = cost(&with(lat, sb, l1, tip));
                        if c < best.0 {
                            best = (c, [lat, sb, l1, tip]);
                        }
                    }
                }
            }
        }
        let p = best.1;
        let step: Vec<f64> = span.iter().map(|s| s[2] / 5.0).collect();
        span = [
            [p[0] - 5.0 * step[0], p[0] + 5.0 * step[0], step[0]],
            [
                (p[1] - 5.0 * step[1]).max(0.0),
                p[1] + 5.0 * step[1],
                step[1],
            ],
            [p[2] - 5.0 * step[2], p[2] + 5.0 * step[2], step[2]],
            [
                (p[3] - 5.0 * step[3]).max(0.0),
                p[3] + 5.0 * step[3],
                step[3],
            ],
        ];
    }
    let [lat, sb, l1, tip] = best.1;
    println!("fit: joints.lateral_mm = {lat:.2}, joints.setback_mm = {sb:.2}, phalanx_1.length_mm = {l1:.2}, phalanx_2.unusable_distal_mm = {tip:.2}");
    println!(
        "sum of squared residuals on the fitting data: {:.3} deg^2",
        best.0
    );
    let fitted = with(lat, sb, l1, tip);
    for (label, h) in [("hand file as committed", &base), ("fitted", &fitted)] {
        println!("\n{label}:");
        println!(
            "{:<28} {:>14} {:>14} {:>14}",
            "case", "theta1 (thesis)", "theta2 (thesis)", "residuals"
        );
        for c in &cases {
            match angles(h, c) {
                Some(a) => println!(
                    "{:<28} {:>6.1} ({:>5.1}) {:>6.1} ({:>5.1}) {:>+6.2} {:>+6.2}",
                    c.name,
                    a[0],
                    c.theta[0],
                    a[1],
                    c.theta[1],
                    a[0] - c.theta[0],
                    a[1] - c.theta[1]
                ),
                None => println!("{:<28} infeasible", c.name),
            }
        }
    }
}

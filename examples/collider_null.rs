//! Issue 30's study of the physics check's object across frames (docs/studies/
//! 2026-12-02-frames-verdicts.md): what the check is given, the volume, mass, collider, and the
//! collider's centre of mass and inertia, for the scenario's mesh as it loads and for each STL
//! given (the same mesh written in other frames, as the frame test dumps them with
//! `GRASP_SIM_FRAMES_DUMP`), with the largest distance of an aligned vertex from the first
//! file's; then, with `--jitter K`, the collider of the scenario's aligned mesh under K null
//! perturbations (every vertex coordinate moved by a uniform ±10⁻⁵ mm).
//!
//!     cargo run --release --example collider_null -- SCENARIO [STL...] [--jitter K]

use grasp_sim::prepared::PreparedObject;
use grasp_sim::scenario::Scenario;
use grasp_sim::sim::{collider_inertia, ColliderReport, ObjectShape};
use nalgebra::Point3;

/// A deterministic pseudo-random number in [0, 1) (SplitMix64 on a counter).
fn unit(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
}

/// The collider's centre of mass `[mm]` and its inertia's diagonal `[kg·mm²]`, aligned frame.
fn com_inertia(shape: &ObjectShape, mass_kg: f64) -> (Point3<f64>, [f64; 3]) {
    let (c, i) = collider_inertia(shape, mass_kg);
    (
        Point3::from(c * 1e3),
        [i[(0, 0)] * 1e6, i[(1, 1)] * 1e6, i[(2, 2)] * 1e6],
    )
}

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let jitter: u64 = match args.iter().position(|a| a == "--jitter") {
        Some(i) => {
            let k = args
                .get(i + 1)
                .and_then(|k| k.parse().ok())
                .expect("--jitter K");
            args.drain(i..i + 2);
            k
        }
        None => 0,
    };
    let Some(scenario) = args.first() else {
        eprintln!("usage: collider_null SCENARIO [STL...] [--jitter K]");
        std::process::exit(2);
    };
    let base = Scenario::load(std::path::Path::new(scenario)).expect("scenario");
    let mut timings = Default::default();
    let own = PreparedObject::load(&base.object, &mut timings).expect("mesh");
    let mut files = vec![(base.object.mesh.clone(), base.object.units)];
    files.extend(
        args[1..]
            .iter()
            .map(|p| (p.into(), grasp_sim::mesh::LengthUnit::Mm)),
    );
    let mut first: Option<Vec<Point3<f64>>> = None;
    for (path, units) in files {
        let mut spec = base.object.clone();
        spec.mesh = path;
        spec.units = units;
        let o = PreparedObject::load(&spec, &mut timings).expect("mesh");
        let shape = o.own_shape(&o.aligned);
        let (c, i) = com_inertia(&shape, o.mass_kg);
        let v = &o.aligned.mesh.vertices;
        let moved = first.as_ref().map_or(0.0, |f| {
            f.iter()
                .zip(v)
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, f64::max)
        });
        first.get_or_insert_with(|| v.clone());
        let t = &o.loaded.topology;
        println!(
            "{}: edges open {} non-manifold {}; volume {:.1} mm3, mass {:.6} kg, {}; centre of mass ({:.4}, {:.4}, {:.4}) mm, inertia diagonal ({:.4}, {:.4}, {:.4}) kg mm2; aligned vertices up to {moved:.1e} mm from the first",
            spec.mesh.display(),
            t.boundary_edges,
            t.non_manifold_edges,
            o.volume_mm3(),
            o.mass_kg,
            grasp_sim::report::ColliderReport::from(&ColliderReport::of(&shape)),
            c.x, c.y, c.z, i[0], i[1], i[2]
        );
    }
    let mut c0 = None;
    for k in (0..=jitter).filter(|_| jitter > 0) {
        let mut m = own.aligned.mesh.clone();
        if k > 0 {
            let mut state = k.wrapping_mul(1_000_003);
            for p in &mut m.vertices {
                for x in p.coords.iter_mut() {
                    *x += (unit(&mut state) * 2.0 - 1.0) * 1e-5;
                }
            }
        }
        let shape = ObjectShape::from_mesh(&m, own.volume_mm3());
        let (c, _) = com_inertia(&shape, own.mass_kg);
        let c0 = *c0.get_or_insert(c);
        println!(
            "{} jitter k={k}: {}; centre of mass ({:.3}, {:.3}, {:.3}) mm, {:.3} mm from k=0's",
            base.name,
            grasp_sim::report::ColliderReport::from(&ColliderReport::of(&shape)),
            c.x,
            c.y,
            c.z,
            (c - c0).norm()
        );
    }
}

//! The vertical closing (`Slice::filled_vertically`, issue 30) on random slices: up to four
//! star-shaped rings (simple by construction, overlapping one another), united as the planner
//! unites a slice of several pieces, then filled with a random finger width. The result has
//! finite, closed contours; it covers the slice (its area is at least the slice's); it stays
//! within the slice's bounding box; and filling it again adds nothing (a closing is idempotent)
//! beyond a sliver of the fill's overlap into the material.
#![no_main]
use grasp_sim::slice::{Contour, Plane, Slice};
use libfuzzer_sys::fuzz_target;
use nalgebra::Point2;

fn area(s: &Slice) -> f64 {
    s.contours.iter().map(Contour::signed_area).sum()
}

fn bounds(s: &Slice) -> (f64, f64, f64, f64) {
    s.contours.iter().flat_map(|c| &c.points).fold(
        (
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ),
        |(a, b, c, d), p| (a.min(p.x), b.min(p.y), c.max(p.x), d.max(p.y)),
    )
}

fuzz_target!(|data: &[u8]| {
    if data.len() < 8 {
        return;
    }
    let w = 1.0 + f64::from(data[0]) / 8.0;
    let rings = 1 + data[1] as usize % 4;
    let mut bytes = data[2..].iter().copied();
    let mut contours = Vec::new();
    for _ in 0..rings {
        let (Some(cx), Some(cy), Some(n)) = (bytes.next(), bytes.next(), bytes.next()) else {
            break;
        };
        let n = 3 + n as usize % 30;
        let radii: Vec<f64> = bytes
            .by_ref()
            .take(n)
            .map(|r| 1.0 + f64::from(r) / 5.0)
            .collect();
        if radii.len() < 3 {
            break;
        }
        let k = radii.len();
        let points = radii
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let a = std::f64::consts::TAU * i as f64 / k as f64;
                Point2::new(f64::from(cx) + r * a.cos(), f64::from(cy) + r * a.sin())
            })
            .collect();
        contours.push(Contour::from_polyline(points, true));
    }
    if contours.is_empty() {
        return;
    }
    let raw = Slice {
        plane: Plane::vertical(0.0),
        contours,
        outermost: Some(0),
    };
    // What the planner fills: the slice with its pieces united (a closing by 1e-9 mm).
    let slice = raw.bridged_prepared(1e-9, 0.0);
    let before = area(&slice);
    let (x0, y0, x1, y1) = bounds(&slice);
    let filled = slice.filled_vertically(w);
    for c in &filled.contours {
        assert!(c.is_closed);
        assert!(c.points.iter().all(|p| p.x.is_finite() && p.y.is_finite()));
    }
    let after = area(&filled);
    let tol = 1e-6 * (1.0 + before.abs());
    assert!(after >= before - tol, "filled {after} < slice {before}");
    let (a0, b0, a1, b1) = bounds(&filled);
    let e = 2e-3;
    assert!(
        a0 >= x0 - e && b0 >= y0 - e && a1 <= x1 + e && b1 <= y1 + e,
        "outside the bounds"
    );
    // Idempotent but for the pieces' 1e-3 mm overlap into the material, which pokes into the
    // air where the material under an edge is thinner than that (a star's thin spike): at most
    // a sliver that thick across the slice.
    let again = area(&filled.filled_vertically(w));
    let sliver = 2e-3 * (x1 - x0);
    assert!(
        (again - after).abs() <= 1e-6 * (1.0 + after) + sliver,
        "{after} then {again}"
    );
});

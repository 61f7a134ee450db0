//! Bounds on the slicer's polygon operations (issue 32): i_overlay 9.1's union of many closed
//! rings that overlap along collinear edges takes time and memory without bound (eight 20 mm
//! squares, each 1 mm above the last and turned 0.3 rad, do not finish in 10 s and grow past
//! 100 MB; thirty, the vertical cut of thirty stacked cubes, pass 4 GB), while the union of two
//! such shapes at a time is a fraction of a millisecond. So a union of more than
//! [`DIRECT_RINGS`] rings is taken as a balanced tree of unions of two shapes each (an outer
//! ring with the holes inside it is one shape), which is the same region: the union is
//! associative, and a hole is kept where no other shape fills it, as in one union by the
//! non-zero rule. Fewer rings go to i_overlay in one call, as before, so every slice of a thesis
//! object is the same bit for bit. The morphological closing grows each shape on its own (the
//! growth of a union is the union of the growths), unites the grown shapes the same way, and
//! shrinks the union; the open-end join is bounded by the number of open ends it pairs.

use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::solver::{Precision, Solver};
use i_overlay::float::simplify::SimplifyShape;
use i_overlay::mesh::float::outline::offset::OutlineOffset;
use i_overlay::mesh::float::style::{LineJoin, OutlineStyle};

/// A closed ring of points `[mm]`, as i_overlay takes it.
pub type Ring = Vec<[f64; 2]>;
/// i_overlay's output: shapes, each an outer ring and its holes.
pub type Shapes = Vec<Vec<Ring>>;

/// The most rings united in one call of i_overlay (measured: four rotated squares stacked 1 mm
/// apart take 50 µs in one call, five take 0.6 s, eight do not finish).
pub const DIRECT_RINGS: usize = 4;

/// The most open contours [`join_allowed`] lets the open-end join pair: it tests every end
/// against every start, so 20,000 ends are 4·10⁸ tests (about a second); a slice with more
/// open pieces is left open (and reported so) rather than joined.
pub const MAX_JOIN_OPEN: usize = 20_000;

/// The thinnest ring the union and the closing take `[mm]`, as its mean width (twice its area
/// over its perimeter). A thinner ring encloses no material a finger can feel: it is the cut of
/// a degenerate or flattened face. Such rings are dropped, since i_overlay's split solver takes
/// time without bound on many of them: a 135-byte OBJ of near-collinear faces gave 500 rings
/// 1e-9 mm wide, whose 7 mm closing took 41 s (fuzz finding, issue 32).
pub const MIN_RING_WIDTH_MM: f64 = 1e-3;

/// `rings` without those thinner than [`MIN_RING_WIDTH_MM`] (see there), in their order.
fn material(mut rings: Vec<Ring>) -> Vec<Ring> {
    rings.retain(|r| area2(r).abs() > MIN_RING_WIDTH_MM * perimeter(r));
    rings
}

/// The length of a closed ring's boundary `[mm]`.
fn perimeter(ring: &Ring) -> f64 {
    let n = ring.len();
    (0..n)
        .map(|i| {
            let (a, b) = (ring[i], ring[(i + 1) % n]);
            (b[0] - a[0]).hypot(b[1] - a[1])
        })
        .sum()
}

/// The union of `rings` by the non-zero rule, bounded: one call of i_overlay for at most
/// [`DIRECT_RINGS`] rings, a balanced tree of unions of two shapes each above that. Rings
/// thinner than [`MIN_RING_WIDTH_MM`] are left out.
pub fn union_rings(rings: Vec<Ring>) -> Shapes {
    let rings = material(rings);
    if rings.len() <= DIRECT_RINGS {
        return unite(&rings);
    }
    let groups: Vec<Vec<Ring>> = shapes_of(rings)
        .into_iter()
        .map(|g| if g.len() > 1 { flat(unite(&g)) } else { g })
        .collect();
    vec![reduce(groups)]
}

/// The morphological closing of `rings` by a bevel-joined polygon of inradius `r` (grown by
/// `r`, then shrunk by `r`), bounded: in one call for at most [`DIRECT_RINGS`] rings, else each
/// shape grown on its own, the grown shapes united as in [`union_rings`], the union's dents
/// filled by `fill_dents`, and the union shrunk. Rings thinner than [`MIN_RING_WIDTH_MM`] are
/// left out.
///
/// The dents matter for the time: the union of many close pieces grown (a vertical cut of a
/// stack of thin plates) has a notch between every two neighbours, and i_overlay's outline of a
/// ring with many small notches overlaps every notch's offset with its neighbours' in one
/// union, in time that grew faster than the square of the plates (issue 56: 100 plates took
/// 3.4 s to plan, 300 took 21 s). A notch a finger does not feel filled before the shrink
/// leaves the outline a few points long; the closing then moves out by at most the notch's
/// depth, which the slice's simplification within the same depth fills anyway.
pub fn close_rings(
    rings: Vec<Ring>,
    r: f64,
    fill_dents: impl FnOnce(Vec<Ring>) -> Vec<Ring>,
) -> Shapes {
    let rings = material(rings);
    let grow = OutlineStyle::new(r).line_join(LineJoin::Bevel);
    let shrink = OutlineStyle::new(-r).line_join(LineJoin::Bevel);
    if rings.len() <= DIRECT_RINGS {
        return rings.outline(&grow).outline(&shrink);
    }
    let grown: Vec<Vec<Ring>> = shapes_of(rings)
        .into_iter()
        .map(|g| flat(g.outline(&grow)))
        .collect();
    vec![fill_dents(reduce(grown))].outline(&shrink)
}

/// Whether the open-end join may pair `open` open contours ([`MAX_JOIN_OPEN`]).
pub fn join_allowed(open: usize) -> bool {
    open <= MAX_JOIN_OPEN
}

/// The most candidate links (an open end within the join tolerance of an open start) the
/// open-end join weighs: past it (ends piled up in one spot, a mesh of slivers) the slice is
/// left open rather than sorted at a cost without bound.
pub const MAX_JOIN_PAIRS: usize = 1_000_000;

/// Every pair (distance, a, b) with the end `ends[a]` within `tol` of the start `starts[b]`,
/// sorted by distance, then a, then b: what testing every end against every start gives, found
/// through a grid of cells `tol` wide, so the cost grows with the pairs rather than with the
/// square of the ends (300 boxes welded into one mesh leave thousands of open pieces per cut).
/// The distance is computed as the slicer's `(start - end).norm()`, bit for bit.
/// `None` past [`MAX_JOIN_PAIRS`] pairs.
pub fn pairs_within(
    ends: &[[f64; 2]],
    starts: &[[f64; 2]],
    tol: f64,
) -> Option<Vec<(f64, usize, usize)>> {
    let cell = |p: [f64; 2]| ((p[0] / tol).floor() as i64, (p[1] / tol).floor() as i64);
    let mut grid: std::collections::HashMap<(i64, i64), Vec<usize>> =
        std::collections::HashMap::new();
    for (b, &p) in starts.iter().enumerate() {
        grid.entry(cell(p)).or_default().push(b);
    }
    let mut pairs = Vec::new();
    for (a, &p) in ends.iter().enumerate() {
        let (cx, cy) = cell(p);
        for dx in -1i64..=1 {
            for dy in -1i64..=1 {
                let key = (cx.saturating_add(dx), cy.saturating_add(dy));
                for &b in grid.get(&key).map(Vec::as_slice).unwrap_or_default() {
                    let q = starts[b];
                    let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
                    let d = (dx * dx + dy * dy).sqrt();
                    if d <= tol {
                        pairs.push((d, a, b));
                    }
                }
            }
            if pairs.len() > MAX_JOIN_PAIRS {
                return None;
            }
        }
    }
    // A saturated cell may be visited twice (coordinates beyond i64 cells): keep each pair once.
    pairs.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
    pairs.dedup_by(|x, y| x.1 == y.1 && x.2 == y.2);
    Some(pairs)
}

/// Unites the shapes two at a time, pairs of neighbours in order, until one is left; returns
/// its rings (none for no shapes).
fn reduce(mut shapes: Vec<Vec<Ring>>) -> Vec<Ring> {
    while shapes.len() > 1 {
        let mut next = Vec::with_capacity(shapes.len().div_ceil(2));
        let mut it = shapes.into_iter();
        while let Some(mut a) = it.next() {
            if let Some(b) = it.next() {
                a.extend(b);
                a = flat(unite(&a));
            }
            next.push(a);
        }
        shapes = next;
    }
    shapes.pop().unwrap_or_default()
}

/// One call of i_overlay's union by the non-zero rule. Its split solver snaps each crossing
/// to the integer grid and, while the snapped segments still cross, goes round again with a
/// snap radius that grows by [`UNION_PRECISION`]'s step. i_overlay's default step (1: the
/// squared radius doubles each round) cascades on near-collinear, overlapping edges: a 6-point
/// self-crossing ring from a 4-triangle STL fuzz input took 16 ms and came out as 899 shapes.
/// Quadrupling (step 2, i_overlay's `MEDIUM`) took 2 ms there, but not on the next fuzz
/// findings (below); the step is now 8. The first round's radius is the default's, so a ring
/// whose crossings settle in one round unites as before.
fn unite(rings: &Vec<Ring>) -> Shapes {
    let solver = Solver {
        precision: UNION_PRECISION,
        ..Solver::AUTO
    };
    rings.simplify_shape_custom(FillRule::NonZero, Default::default(), solver)
}

/// The split solver's snap radius for [`unite`]: the default's first round (so a union that
/// needs one round, every clean slice's, is what the default gives, bit for bit), then the
/// squared radius ×256 a round. i_overlay's default doubles it, and `MEDIUM` (×4) was still
/// not enough: on an 8-point ring crossing itself along near-collinear edges (the cut of a
/// 4-triangle fuzz STL), `MEDIUM` ends after 37 ms in 1552 pieces, ×256 after 0.3 ms in 21, and
/// the area agrees to 1e-8 (test `a_self_crossing_near_collinear_ring_unites_without_a_cascade`).
/// The snap radius after the rounds that such a ring takes stays below 1e-4 mm.
const UNION_PRECISION: Precision = Precision {
    start: 0,
    progression: 8,
};

fn flat(shapes: Shapes) -> Vec<Ring> {
    shapes.into_iter().flatten().collect()
}

/// Twice the signed area of a ring (positive counter-clockwise: an outer ring of the slicer).
fn area2(ring: &Ring) -> f64 {
    let n = ring.len();
    (0..n)
        .map(|i| {
            let (a, b) = (ring[i], ring[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum()
}

/// Whether `p` is inside `ring` (even-odd crossing test).
fn inside(p: [f64; 2], ring: &Ring) -> bool {
    let n = ring.len();
    let mut c = false;
    for i in 0..n {
        let (a, b) = (ring[i], ring[(i + n - 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1])
            && p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0]
        {
            c = !c;
        }
    }
    c
}

/// The rings as shapes: each outer (counter-clockwise) ring with the holes whose first point
/// lies inside it, a hole going to the smallest such outer; a hole inside no outer is a shape
/// of its own. Shapes are in the order of their outer rings, then the lone holes.
fn shapes_of(rings: Vec<Ring>) -> Vec<Vec<Ring>> {
    let areas: Vec<f64> = rings.iter().map(area2).collect();
    let outers: Vec<usize> = (0..rings.len()).filter(|&i| areas[i] > 0.0).collect();
    let mut owner: Vec<Option<usize>> = vec![None; rings.len()];
    for h in (0..rings.len()).filter(|&i| areas[i] <= 0.0) {
        let Some(&p) = rings[h].first() else { continue };
        owner[h] = outers
            .iter()
            .copied()
            .filter(|&o| inside(p, &rings[o]))
            .min_by(|&a, &b| areas[a].total_cmp(&areas[b]).then(a.cmp(&b)));
    }
    let mut slot: Vec<Option<usize>> = vec![None; rings.len()];
    let mut shapes: Vec<Vec<Ring>> = Vec::new();
    for &o in &outers {
        slot[o] = Some(shapes.len());
        shapes.push(Vec::new());
    }
    let mut lone = Vec::new();
    for (i, ring) in rings.into_iter().enumerate() {
        match (slot[i], owner[i]) {
            (Some(s), _) => shapes[s].insert(0, ring),
            (None, Some(o)) => shapes[slot[o].expect("an outer has a slot")].push(ring),
            (None, None) => lone.push(vec![ring]),
        }
    }
    shapes.extend(lone);
    shapes
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 20 mm square, its lower left corner at (0, `z`), turned by `turn` radians about the
    /// origin; counter-clockwise (`hole`: clockwise).
    fn square(z: f64, turn: f64, side: f64, hole: bool) -> Ring {
        let (c, s) = (turn.cos(), turn.sin());
        let mut r: Ring = [[0.0, z], [side, z], [side, z + side], [0.0, z + side]]
            .iter()
            .map(|p| [c * p[0] - s * p[1], s * p[0] + c * p[1]])
            .collect();
        if hole {
            r.reverse();
        }
        r
    }

    fn total_area(shapes: &Shapes) -> f64 {
        shapes.iter().flatten().map(|r| 0.5 * area2(r)).sum()
    }

    /// Thirty turned squares each 1 mm above the last (the cut of thirty stacked cubes): one
    /// outline of 20 × 49 mm, where one call of i_overlay on all thirty does not finish.
    /// The grid finds exactly the pairs the test of every end against every start finds, in
    /// the same order.
    #[test]
    fn pairs_within_match_the_all_pairs_test() {
        let pts: Vec<[f64; 2]> = (0..400)
            .map(|i| {
                let t = i as f64 * 0.731;
                [(t * 7.3).sin() * 10.0, (t * 3.1).cos() * 10.0]
            })
            .collect();
        let (ends, starts) = pts.split_at(200);
        for tol in [0.05, 0.5, 3.0] {
            let mut all = Vec::new();
            for (a, p) in ends.iter().enumerate() {
                for (b, q) in starts.iter().enumerate() {
                    let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
                    let d = (dx * dx + dy * dy).sqrt();
                    if d <= tol {
                        all.push((d, a, b));
                    }
                }
            }
            all.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
            assert_eq!(pairs_within(ends, starts, tol).unwrap(), all, "tol {tol}");
            assert!(!all.is_empty());
        }
        // Ends piled on one spot: refused past the cap instead of sorting 4·10⁶ pairs.
        let pile = vec![[1.0, 1.0]; 2001];
        assert!(pairs_within(&pile, &pile, 0.1).is_none());
    }

    #[test]
    fn a_stack_of_turned_squares_unites_to_one_rectangle() {
        let rings: Vec<Ring> = (0..30)
            .map(|k| square(k as f64, 0.3, 20.0, false))
            .collect();
        let u = union_rings(rings);
        assert!(
            (total_area(&u) - 20.0 * 49.0).abs() < 1e-3,
            "{}",
            total_area(&u)
        );
        assert_eq!(u.iter().flatten().count(), 1);
    }

    /// A hole is kept where no other shape covers it and filled where one does, as by the
    /// non-zero rule: two outers with a hole each, the second's hole under a third outer.
    #[test]
    fn holes_stay_holes_unless_another_shape_fills_them() {
        let rings = vec![
            square(0.0, 0.0, 20.0, false),
            square(5.0, 0.0, 5.0, true),
            [[40.0, 0.0], [60.0, 0.0], [60.0, 20.0], [40.0, 20.0]].to_vec(),
            [[45.0, 5.0], [45.0, 10.0], [50.0, 10.0], [50.0, 5.0]].to_vec(),
            [[44.0, 4.0], [51.0, 4.0], [51.0, 11.0], [44.0, 11.0]].to_vec(),
        ];
        let direct = total_area(&rings.clone().simplify_shape(FillRule::NonZero));
        let bounded = total_area(&union_rings(rings));
        assert!((bounded - (400.0 - 25.0 + 400.0)).abs() < 1e-6, "{bounded}");
        assert!((direct - bounded).abs() < 1e-6);
    }

    /// The closing of many overlapping turned squares is bounded, and bridges a 1 mm gap to a
    /// square beside them (the grown shapes meet): one outline, with most of the 20 mm² gap
    /// filled (the bevelled corners of the bridge keep about 1 mm² of it open).
    /// Rings thinner than a micrometre (the cut of flattened faces, 1e-9 mm wide) are left out of
    /// the union and the closing, whatever their length; a ring 0.01 mm wide is kept, and two
    /// 1 mm × 20 mm strips 10 mm apart are still bridged by a 7 mm closing into one shape
    /// 1 + 10 + 1 mm wide.
    #[test]
    fn rings_thinner_than_a_micrometre_are_no_material() {
        let strip = |x0: f64, w: f64| -> Ring {
            vec![[x0, 0.0], [x0 + w, 0.0], [x0 + w, 20.0], [x0, 20.0]]
        };
        let sliver: Ring = vec![[0.0, 0.0], [30.0, 1e-9], [15.0, 1e-9], [30.0, 2e-9]];
        assert!(union_rings(vec![sliver.clone(); 3]).is_empty());
        assert!(close_rings(vec![sliver.clone(); 500], 7.0, |r| r).is_empty());
        let thin = union_rings(vec![strip(0.0, 0.01)]);
        assert_eq!(thin.len(), 1);
        let a = area2(&thin[0][0]).abs() / 2.0;
        assert!((a - 0.2).abs() < 1e-4, "{a}");
        let mut rings = vec![strip(0.0, 1.0), strip(11.0, 1.0)];
        rings.extend(vec![sliver; 6]);
        let closed = close_rings(rings, 7.0, |r| r);
        assert_eq!(closed.len(), 1, "{closed:?}");
        let xs: Vec<f64> = closed[0][0].iter().map(|p| p[0]).collect();
        let (lo, hi) = xs
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
        assert!(lo.abs() < 1e-6 && (hi - 12.0).abs() < 1e-6, "{lo} {hi}");
    }

    #[test]
    fn the_closing_of_many_shapes_is_bounded_and_bridges_gaps() {
        let mut rings: Vec<Ring> = (0..30)
            .map(|k| square(k as f64, 0.3, 20.0, false))
            .collect();
        rings.push(square(50.0, 0.3, 20.0, false));
        let closed = close_rings(rings, 1.0, |r| r);
        assert_eq!(closed.iter().flatten().count(), 1);
        assert!(
            total_area(&closed) > 20.0 * 69.0 + 15.0,
            "{}",
            total_area(&closed)
        );
    }

    /// A 6-point ring that crosses itself along near-collinear edges (a slice of a 4-triangle
    /// STL the fuzzer found, 0.2 s for `--no-sim`): its union keeps the area (2.7182816 mm², as
    /// i_overlay's default and absolute precisions give) in fewer than 300 pieces, where the
    /// default snap radius cascades into 899 and took 8× the time.
    #[test]
    fn a_self_crossing_near_collinear_ring_unites_without_a_cascade() {
        let ring: Ring = vec![
            [0.09877503769680393, -4.532309191797119],
            [-0.5376296788299302, -1.4989026688085048],
            [0.31302592801495055, -5.553530485998328],
            [-0.7143770640182883, -0.6564408560211312],
            [2.061063219205265, 0.0046916031133212854],
            [-0.32298135982518883, -2.5220182965038433],
        ];
        let united = union_rings(vec![ring.clone()]);
        let a = total_area(&united).abs();
        assert!((a - 2.7182816).abs() < 1e-6, "{a}");
        assert!(united.len() < 300, "{} pieces", united.len());
        let default = vec![ring].simplify_shape(FillRule::NonZero);
        assert!(
            default.len() > 800,
            "i_overlay's default now gives {}",
            default.len()
        );
    }

    #[test]
    fn a_pinched_ring_of_near_overlapping_edges_unites_in_few_pieces() {
        // One of the 400 mass-property slices of a 284-byte, 4-triangle fuzz STL
        // (tests/fuzz_findings/mesh_stl_slow_b9d68fee.stl): 8 points, one of them twice, two
        // edges into it from points 8 µm apart. i_overlay's `MEDIUM` step made 1552 pieces of it
        // in 37 ms (the STL took 4 s); the ×256 step, 21 pieces in 0.3 ms.
        let ring: Ring = vec![
            [0.718413166018712, -1.6996855948534313],
            [-1.4734563500096143, 1.6863494229174307],
            [0.6080041621638516, 2.9950116132758513],
            [-0.6276307640027234, 0.3797045555096943],
            [0.714294350928001, -1.6933227835515334],
            [-1.4734563500096143, 1.6863494229174307],
            [2.069142937503205, -3.7863145079100518],
            [-0.8960779905610662, 0.7944061163932428],
        ];
        let united = union_rings(vec![ring.clone()]);
        let a = total_area(&united).abs();
        assert!((a - 1.9133148582).abs() < 1e-6, "{a}");
        assert!(united.len() < 60, "{} pieces", united.len());
        let medium = Solver {
            precision: Precision::MEDIUM,
            ..Solver::AUTO
        };
        let before =
            vec![ring].simplify_shape_custom(FillRule::NonZero, Default::default(), medium);
        assert!(
            before.len() > 1000,
            "i_overlay's MEDIUM now gives {}",
            before.len()
        );
    }
}

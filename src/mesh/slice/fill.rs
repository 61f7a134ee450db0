//! The vertical closing of a slice: gaps a finger cannot enter, filled (issue 30).
//!
//! In a vertical slice (a plane through the grasp axis) a finger is a band `w` tall: its
//! centreline at the elevation it grips, its contact surface reaching the finger offset above
//! and below (thesis 3.3.2). It cannot enter a gap between material below and material above
//! that is narrower than `w`, so for grading (thesis 3.4.3.1: the curvature around the touch
//! point) such a gap is solid: a gear's teeth, a cap's thread, a knurl, the slots between a
//! cage's hoops when they are close. This is the morphological closing of the slice by a
//! vertical segment of length `w`: on every vertical line, each empty interval shorter than `w`
//! with material at both ends is filled, and nothing else changes. Unlike a closing by a disc,
//! it bevels no corner: under a ridge with nothing below within `w`, the wall keeps its corner,
//! so the thesis's "under a ridge" category (Cat_2) is still seen.
//!
//! The filled region is found by a sweep over the slabs between the vertices' abscissae: within a
//! slab, the edges that span it do not cross, the gaps between them are bounded by two edges each,
//! and a gap's height is linear in `x`, so where it is under `w` is one interval. The pieces
//! (quadrilaterals, merged along a slab boundary where the same two edges go on) are united with
//! the slice ([`super::super::polygon_limits::union_rings`]). A slice with no such gap is returned
//! as it is, bit for bit.

use super::{finish, map_closed, Slice};
use nalgebra::Point2;

/// A non-vertical edge of a closed contour, oriented by increasing `x`.
#[derive(Debug, Clone, Copy)]
struct Edge {
    a: Point2<f64>,
    b: Point2<f64>,
    /// True if the material lies above the edge (the contour travels towards +x along it:
    /// the material is on the left of the travel), false if below.
    material_above: bool,
}

impl Edge {
    fn z_at(&self, x: f64) -> f64 {
        self.a.y + (x - self.a.x) * (self.b.y - self.a.y) / (self.b.x - self.a.x)
    }
}

/// The sweep's table of open pieces (foldhash's fixed-seed hasher, as the mesh code's tables).
type HashMap<K, V> = std::collections::HashMap<K, V, crate::mesh::FastHash>;

/// How far a filling piece reaches into the material it lies between `[mm]`.
const OVERLAP_MM: f64 = 1e-3;

/// Edges whose extent in `x` is below this are vertical for the sweep `[mm]`.
const VERTICAL_MM: f64 = 1e-9;

impl Slice {
    /// The slice with every vertical gap narrower than `w_mm` filled (see the module docs);
    /// unchanged (bit for bit) where it has none, or where it has open contours.
    pub fn filled_vertically(self, w_mm: f64) -> Slice {
        if w_mm.is_nan() || w_mm <= 0.0 || self.contours.iter().any(|c| !c.is_closed) {
            return self;
        }
        let pieces = vertical_gaps(&self, w_mm);
        if pieces.is_empty() {
            return self;
        }
        let plane = self.plane;
        let contours = map_closed(self.contours, |mut rings| {
            rings.extend(pieces);
            super::super::polygon_limits::union_rings(rings)
        });
        finish(plane, contours)
    }
}

/// The quadrilaterals (as rings, counter-clockwise) that fill the vertical gaps of `slice`
/// narrower than `w`.
fn vertical_gaps(slice: &Slice, w: f64) -> Vec<Vec<[f64; 2]>> {
    let mut edges = sweep_edges(slice);
    if edges.len() < 4 {
        return Vec::new();
    }
    edges.sort_by(|e, f| e.a.x.total_cmp(&f.a.x));
    let mut xs: Vec<f64> = edges.iter().flat_map(|e| [e.a.x, e.b.x]).collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    // Filled pieces as (lower edge, upper edge, x from, x to); a piece that continues one of
    // the previous slab with the same two edges is extended.
    let mut pieces: Vec<(usize, usize, f64, f64)> = Vec::new();
    // The pieces that reach the current slab's left end, by their two edges (looked up, never
    // iterated: the pieces' order is their creation's).
    let mut open: HashMap<(usize, usize), usize> = HashMap::default();
    let mut active: Vec<usize> = Vec::new();
    let mut next = 0;
    let mut order: Vec<(f64, usize)> = Vec::new();
    for slab in xs.windows(2) {
        let (x0, x1) = (slab[0], slab[1]);
        while next < edges.len() && edges[next].a.x <= x0 {
            active.push(next);
            next += 1;
        }
        active.retain(|&e| edges[e].b.x >= x1);
        let xm = 0.5 * (x0 + x1);
        order.clear();
        order.extend(active.iter().map(|&e| (edges[e].z_at(xm), e)));
        order.sort_by(|p, q| p.0.total_cmp(&q.0).then(p.1.cmp(&q.1)));
        let mut still_open = HashMap::default();
        let mut winding = 0i32;
        for k in 0..order.len() {
            let e = order[k].1;
            winding += if edges[e].material_above { 1 } else { -1 };
            // An empty interval between this edge and the next, with material below it (the
            // winding was positive just below this edge) and above it (the next edge has
            // material above).
            if winding != 0 || k + 1 == order.len() || edges[e].material_above {
                continue;
            }
            let f = order[k + 1].1;
            if !edges[f].material_above {
                continue;
            }
            let Some((from, to)) = narrow_span(&edges[e], &edges[f], x0, x1, w) else {
                continue;
            };
            let i = match open.get(&(e, f)) {
                Some(&i) if pieces[i].3 == from => {
                    pieces[i].3 = to;
                    i
                }
                _ => {
                    pieces.push((e, f, from, to));
                    pieces.len() - 1
                }
            };
            // Only a piece reaching this slab's right end can go on into the next.
            if to == x1 {
                still_open.insert((e, f), i);
            }
        }
        open = still_open;
    }
    pieces
        .into_iter()
        .map(|(e, f, from, to)| filling_ring(&edges[e], &edges[f], from, to))
        .collect()
}

/// The non-vertical edges of `slice`'s closed contours, each oriented by increasing `x` with
/// the side its material is on, in the contours' order.
fn sweep_edges(slice: &Slice) -> Vec<Edge> {
    let mut edges: Vec<Edge> = Vec::new();
    for c in slice.contours.iter().filter(|c| c.is_closed) {
        for i in 0..c.segment_count() {
            let (p, q) = c.segment(i);
            if (q.x - p.x).abs() <= VERTICAL_MM {
                continue;
            }
            edges.push(if q.x > p.x {
                Edge {
                    a: p,
                    b: q,
                    material_above: true,
                }
            } else {
                Edge {
                    a: q,
                    b: p,
                    material_above: false,
                }
            });
        }
    }
    edges
}

/// Where, within the slab `[x0, x1]`, the gap between the edges `lo` (below) and `hi` (above)
/// is narrower than `w`: `(from, to)`, or `None` where it is nowhere (the gap's height is linear
/// in `x`, so this is one interval).
fn narrow_span(lo: &Edge, hi: &Edge, x0: f64, x1: f64, w: f64) -> Option<(f64, f64)> {
    let (l0, l1) = (hi.z_at(x0) - lo.z_at(x0), hi.z_at(x1) - lo.z_at(x1));
    let (from, to) = match (l0 < w, l1 < w) {
        (true, true) => (x0, x1),
        (true, false) => (x0, x0 + (w - l0) / (l1 - l0) * (x1 - x0)),
        (false, true) => (x1 - (w - l1) / (l0 - l1) * (x1 - x0), x1),
        (false, false) => return None,
    };
    if to <= from {
        return None;
    }
    Some((from, to))
}

/// The quadrilateral (counter-clockwise) that fills the gap between `lo` and `hi` from `x =
/// from` to `to`.
fn filling_ring(lo: &Edge, hi: &Edge, from: f64, to: f64) -> Vec<[f64; 2]> {
    // Reaching OVERLAP_MM into the material below and above, so that the union meets an
    // overlap and not two edges that coincide to round-off (on which i_overlay's snapping
    // leaves slivers and spikes).
    vec![
        [from, lo.z_at(from) - OVERLAP_MM],
        [to, lo.z_at(to) - OVERLAP_MM],
        [to, hi.z_at(to) + OVERLAP_MM],
        [from, hi.z_at(from) + OVERLAP_MM],
    ]
}

#[cfg(test)]
mod tests {
    use super::super::{Contour, Plane};
    use super::*;

    fn ring(points: &[(f64, f64)]) -> Contour {
        Contour::from_polyline(
            points.iter().map(|&(x, y)| Point2::new(x, y)).collect(),
            true,
        )
    }

    fn area(s: &Slice) -> f64 {
        s.contours.iter().map(Contour::signed_area).sum()
    }

    /// A 20 mm wide, 60 mm tall block whose right side has a groove `g` tall and 3 mm deep
    /// from z = 30.
    fn grooved(g: f64) -> Slice {
        finish(
            Plane::vertical(0.0),
            vec![ring(&[
                (0.0, 0.0),
                (20.0, 0.0),
                (20.0, 30.0),
                (17.0, 30.0),
                (17.0, 30.0 + g),
                (20.0, 30.0 + g),
                (20.0, 60.0),
                (0.0, 60.0),
            ])],
        )
    }

    #[test]
    fn a_groove_narrower_than_the_finger_is_filled_and_a_wider_one_kept() {
        // 10 mm tall: filled, the side straight (the block's 1200 mm²).
        let narrow = grooved(10.0).filled_vertically(14.0);
        assert_eq!(narrow.contours.len(), 1);
        assert!((area(&narrow) - 1200.0).abs() < 1e-9, "{}", area(&narrow));
        assert!(
            narrow.contours[0].points.iter().all(|p| p.x != 17.0),
            "{narrow:?}"
        );
        // 14 mm tall (the finger's width exactly): kept, bit for bit.
        let wide = grooved(14.0);
        assert_eq!(wide.clone().filled_vertically(14.0), wide);
    }

    #[test]
    fn a_ridge_with_nothing_below_keeps_its_corner() {
        // A flange 5 mm out at the top of a wall: no material under it within 14 mm, nothing
        // filled (a disc closing would bevel the corner under it).
        let s = finish(
            Plane::vertical(0.0),
            vec![ring(&[
                (0.0, 0.0),
                (20.0, 0.0),
                (20.0, 50.0),
                (25.0, 50.0),
                (25.0, 55.0),
                (0.0, 55.0),
            ])],
        );
        assert_eq!(s.clone().filled_vertically(14.0), s);
    }

    #[test]
    fn sloped_teeth_are_filled_where_the_gap_is_under_the_width() {
        // A side with two V-notches 2 mm deep and 8 mm tall (a gear's teeth seen along its
        // axis): each notch's gap is under 14 mm everywhere, so both fill to the straight side.
        let s = finish(
            Plane::vertical(0.0),
            vec![ring(&[
                (0.0, 0.0),
                (20.0, 0.0),
                (20.0, 10.0),
                (18.0, 14.0),
                (20.0, 18.0),
                (20.0, 30.0),
                (18.0, 34.0),
                (20.0, 38.0),
                (20.0, 50.0),
                (0.0, 50.0),
            ])],
        );
        let filled = s.filled_vertically(14.0);
        assert!((area(&filled) - 1000.0).abs() < 1e-9, "{}", area(&filled));
        // A slot 20 mm tall with 6 mm of it narrower than 14 (a V opening from 0 to 20 mm):
        // filled only near its apex, where the gap is under 14 mm.
        let v = finish(
            Plane::vertical(0.0),
            vec![ring(&[
                (0.0, 0.0),
                (20.0, 0.0),
                (20.0, 10.0),
                (10.0, 20.0),
                (20.0, 30.0),
                (20.0, 40.0),
                (0.0, 40.0),
            ])],
        );
        let before = area(&v);
        let after = area(&v.filled_vertically(14.0));
        // The V's gap at x is 2 (x - 10); under 14 for x < 17: a triangle 7 wide, 14 tall.
        assert!((after - before - 49.0).abs() < 1e-9, "{before} {after}");
    }

    #[test]
    fn two_pieces_closer_than_the_finger_are_joined_and_farther_ones_not() {
        let block = |z0: f64| ring(&[(0.0, z0), (20.0, z0), (20.0, z0 + 10.0), (0.0, z0 + 10.0)]);
        let near = finish(Plane::vertical(0.0), vec![block(0.0), block(20.0)]);
        let joined = near.filled_vertically(14.0);
        assert_eq!(joined.contours.len(), 1);
        assert!((area(&joined) - 600.0).abs() < 1e-9);
        let far = finish(Plane::vertical(0.0), vec![block(0.0), block(25.0)]);
        assert_eq!(far.clone().filled_vertically(14.0), far);
        // 400 plates 1 mm thick, 1 mm apart (a heat sink's fins seen edge-on): one piece.
        let plate = |z0: f64| ring(&[(0.0, z0), (20.0, z0), (20.0, z0 + 1.0), (0.0, z0 + 1.0)]);
        let fins = finish(
            Plane::vertical(0.0),
            (0..400).map(|k| plate(2.0 * k as f64)).collect(),
        );
        let one = fins.filled_vertically(14.0);
        assert_eq!(one.contours.len(), 1);
        assert!((area(&one) - 20.0 * 799.0).abs() < 1e-6, "{}", area(&one));
    }
}

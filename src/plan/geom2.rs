//! Small 2D helpers for the positioning stages: segments against convex outlines.
//!
//! The thesis's penetration checks (3.5.3, 3.6.2.2, 3.6.2.3) test the outline of a body (palm,
//! phalanx, tip) against the object's contour in a slice plane. A contact point lies on the
//! outline by construction, so the test is strict: a contour segment penetrates only if a piece
//! of it longer than zero lies inside the outline shrunk by a tolerance.

use nalgebra::{Point2, Vector2};

/// A convex polygon, counter-clockwise.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvexPolygon {
    /// Corners, counter-clockwise.
    pub corners: Vec<Point2<f64>>,
}

impl ConvexPolygon {
    /// A polygon from corners in either order (made counter-clockwise).
    pub fn new(mut corners: Vec<Point2<f64>>) -> ConvexPolygon {
        let n = corners.len();
        let area: f64 = (0..n)
            .map(|i| {
                let (p, q) = (corners[i], corners[(i + 1) % n]);
                p.x * q.y - q.x * p.y
            })
            .sum();
        if area < 0.0 {
            corners.reverse();
        }
        ConvexPolygon { corners }
    }

    /// The rectangle spanned from `start` along unit `dir` for `length`, from `back` to `front`
    /// along the left normal of `dir` (negative values go right).
    pub fn strip(
        start: Point2<f64>,
        dir: Vector2<f64>,
        length: f64,
        back: f64,
        front: f64,
    ) -> ConvexPolygon {
        let n = Vector2::new(-dir.y, dir.x);
        ConvexPolygon::new(vec![
            start + n * back,
            start + dir * length + n * back,
            start + dir * length + n * front,
            start + n * front,
        ])
    }

    /// Returns true if and only if some piece of segment `a`–`b` lies deeper than `tol` inside.
    pub fn is_penetrated_by(&self, a: Point2<f64>, b: Point2<f64>, tol: f64) -> bool {
        // Cyrus–Beck clipping against each edge's inward half-plane, moved in by tol.
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        let d = b - a;
        let n = self.corners.len();
        for i in 0..n {
            let (p, q) = (self.corners[i], self.corners[(i + 1) % n]);
            let e = q - p;
            let len = e.norm();
            if len == 0.0 {
                continue;
            }
            // Inward normal of a counter-clockwise polygon: left of the edge.
            let inward = Vector2::new(-e.y, e.x) / len;
            let num = (a - p).dot(&inward) - tol;
            let den = d.dot(&inward);
            if den.abs() < 1e-15 {
                if num < 0.0 {
                    return false;
                }
                continue;
            }
            let t = -num / den;
            if den > 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
            if t0 >= t1 {
                return false;
            }
        }
        (t1 - t0) * d.norm() > 1e-9
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_touching_the_boundary_do_not_penetrate() {
        let sq = ConvexPolygon::new(vec![
            Point2::new(0.0, 0.0),
            Point2::new(0.0, 10.0),
            Point2::new(10.0, 10.0),
            Point2::new(10.0, 0.0),
        ]);
        let p = |x, y| Point2::new(x, y);
        assert!(sq.is_penetrated_by(p(-5.0, 5.0), p(15.0, 5.0), 0.01));
        assert!(sq.is_penetrated_by(p(2.0, 2.0), p(3.0, 3.0), 0.01));
        assert!(
            !sq.is_penetrated_by(p(-5.0, 10.0), p(15.0, 10.0), 0.01),
            "along an edge"
        );
        assert!(
            !sq.is_penetrated_by(p(10.0, 5.0), p(20.0, 5.0), 0.01),
            "touching a side"
        );
        assert!(
            !sq.is_penetrated_by(p(-1.0, -1.0), p(-5.0, 5.0), 0.01),
            "outside"
        );
        assert!(
            sq.is_penetrated_by(p(9.9, 5.0), p(20.0, 5.0), 0.01),
            "0.1 mm deep"
        );
        assert!(
            !sq.is_penetrated_by(p(9.995, 5.0), p(20.0, 5.0), 0.01),
            "within tolerance"
        );
    }

    #[test]
    fn a_strip_is_the_rectangle_along_a_direction() {
        let s = ConvexPolygon::strip(Point2::origin(), Vector2::x(), 10.0, -1.0, 2.0);
        let p = |x, y| Point2::new(x, y);
        assert!(s.is_penetrated_by(p(5.0, -5.0), p(5.0, 5.0), 0.01));
        assert!(!s.is_penetrated_by(p(5.0, 2.0), p(5.0, 5.0), 0.01));
        assert!(!s.is_penetrated_by(p(5.0, -5.0), p(5.0, -1.0), 0.01));
    }
}

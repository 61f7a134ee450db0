//! The L∞ wrench space's volume for any number of contacts, by rays from an interior point.
//!
//! `W = Σᵢ Pᵢ`, `Pᵢ = conv({0} ∪ edgesᵢ)`, has too many vertices to hull beyond three contacts
//! ([`super::linf`]), but one ray through it is a small linear programme: the largest `t` with `c +
//! t·u = Σᵢⱼ αᵢⱼ eᵢⱼ`, `αᵢⱼ ≥ 0`, `Σⱼ αᵢⱼ ≤ 1` for every contact `i` (6 + contacts rows). It is
//! solved exactly (to round-off) by the two-phase simplex method, so every ray's exit point lies on
//! `W`'s boundary; the first phase (a basis feasible at the centre) does not depend on the ray and
//! is solved once per wrench space ([`RayCaster`]). The volume is then the integral of the radial
//! function over the sphere, `vol W = (π³/6) · E[ρ(g)⁶]` for `g` uniform on the unit sphere in 6-D,
//! estimated from a fixed set of directions:
//!
//! - **From the centre** `c = Σᵢ centroid(vertices of Pᵢ)`, in `W`'s relative interior whether or
//!   not the origin is (a grasp that is not force closure has a volume too).
//! - **Whitened**: the rays are drawn uniformly in the frame where `W`'s spread (the covariance
//!   of a point `Σᵢ vᵢ` with `vᵢ` uniform over `Pᵢ`'s vertices) is the identity, and the volume
//!   carries the Jacobian `det L` of `Cov = L Lᵀ`, so a body that is thin in some direction is
//!   not sampled as a needle. The programmes are set up in that frame too (`L⁻¹eᵢⱼ`, `L⁻¹c`),
//!   so their entries are of order 1 whatever the wrenches' units and the simplex's
//!   tolerances mean the same for every grasp.
//! - **Antithetic**: the directions come in pairs `±g`; the standard error is that of the pairs'
//!   means, and is reported with the volume (`volume_rel_se`).
//! - **Deterministic**: the directions come from a fixed seed, so the same contacts give the same
//!   volume, bit for bit; the rays run on rayon's threads and are summed in order.
//!
//! A wrench set that spans fewer than 6 dimensions (the covariance is singular) has volume 0.
//!
//! The linear programmes are small (at 17 contacts and 8 cone edges, 23 rows and 160 columns),
//! and a dense tableau solves one in tens of microseconds; a general sparse solver (microlp,
//! measured) took 0.8 ms, which at a thousand rays would cost more than the physics check.

use super::{QualityError, Wrench};
use nalgebra::{Matrix6, Vector6};
use rayon::prelude::*;

/// Rays per volume (in antithetic pairs). docs/QUALITY.md: on three-contact grasps, whose
/// volume the hull gives exactly, the estimate's relative standard error is about 2–4 %, and the
/// exact volume lies within 3 standard errors.
pub const VOLUME_RAYS: usize = 1024;

const DIM: usize = 6;
const SEED: u64 = 0x9E37_79B9_7F4A_7C15;

/// A volume from rays.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayVolume {
    /// The estimate (6-D, in the scaled wrench units).
    pub volume: f64,
    /// Its standard error relative to it (0 when the volume is 0).
    pub rel_se: f64,
    /// Rays shot.
    pub rays: usize,
}

/// The largest `t` with `c + t·u ∈ W`, `W = Σᵢ conv({0} ∪ edgesᵢ)`, where `c` lies in `W` and
/// `u` is a unit vector; an error when the programme is infeasible (`c` outside `W`) or
/// unbounded, which a bounded `W` with `c` inside cannot be.
pub fn ray_exit(per_contact: &[Vec<Wrench>], c: &Wrench, u: &Wrench) -> Result<f64, QualityError> {
    RayCaster::new(per_contact, c)?.exit(u)
}

/// Rays from one centre `c` through `W`: the programme's first phase (a basis feasible at
/// `c`, `t = 0`) is solved once, and each ray continues from a copy of it.
pub struct RayCaster {
    /// The tableau after the first phase, `rows + 1` rows (the last the objective) of
    /// `width` entries; the `t` column is filled per ray.
    tab: Vec<f64>,
    basis: Vec<usize>,
    width: usize,
    rows: usize,
    col_t: usize,
    col_art: usize,
    /// The sign each wrench row was multiplied by (so that its right-hand side is ≥ 0).
    signs: [f64; DIM],
    tol: f64,
}

impl RayCaster {
    /// The first phase for `W` and `c`; an error when `c` is outside `W`.
    pub fn new(per_contact: &[Vec<Wrench>], c: &Wrench) -> Result<RayCaster, QualityError> {
        let contacts: Vec<&Vec<Wrench>> = per_contact.iter().filter(|e| !e.is_empty()).collect();
        let k = contacts.len();
        let n_alpha: usize = contacts.iter().map(|e| e.len()).sum();
        // Columns: α (n_alpha), t, slacks (k), artificials (6), right-hand side.
        let col_t = n_alpha;
        let col_slack = n_alpha + 1;
        let col_art = col_slack + k;
        let cols = col_art + DIM;
        let width = cols + 1;
        let rows = DIM + k;
        let mut tab = vec![0.0; (rows + 1) * width];
        let mut basis = vec![0usize; rows];
        let mut signs = [1.0; DIM];
        for d in 0..DIM {
            signs[d] = if c[d] < 0.0 { -1.0 } else { 1.0 };
            let row = &mut tab[d * width..(d + 1) * width];
            let mut j = 0;
            for edges in &contacts {
                for e in edges.iter() {
                    row[j] = signs[d] * e[d];
                    j += 1;
                }
            }
            row[col_art + d] = 1.0;
            row[cols] = signs[d] * c[d];
            basis[d] = col_art + d;
        }
        let mut j = 0;
        for (i, edges) in contacts.iter().enumerate() {
            let r = DIM + i;
            let row = &mut tab[r * width..(r + 1) * width];
            for _ in edges.iter() {
                row[j] = 1.0;
                j += 1;
            }
            row[col_slack + i] = 1.0;
            row[cols] = 1.0;
            basis[r] = col_slack + i;
        }
        let scale = tab[..rows * width]
            .iter()
            .fold(1.0f64, |m, v| m.max(v.abs()));
        let tol = 1e-11 * scale;
        // Phase 1: maximise −Σ artificials (the objective row holds the reduced costs), `t`
        // barred (its column is empty until a ray fills it).
        let obj = rows * width;
        for d in 0..DIM {
            for j in 0..width {
                tab[obj + j] -= tab[d * width + j];
            }
        }
        for a in col_art..cols {
            tab[obj + a] = 0.0;
        }
        simplex(&mut tab, &mut basis, width, rows, col_art, tol)?;
        if tab[obj + cols] < -1e-9 * scale {
            return Err(QualityError::CentreOutside);
        }
        drive_out_artificials(&mut tab, &mut basis, width, rows, col_art, scale);
        if basis[..DIM].iter().any(|&b| b >= col_art) {
            // A wrench row that no edge reaches: W is not full-dimensional.
            return Err(QualityError::FewerDimensions);
        }
        Ok(RayCaster {
            tab,
            basis,
            width,
            rows,
            col_t,
            col_art,
            signs,
            tol,
        })
    }

    /// The largest `t` with `c + t·u ∈ W`, `u` a unit vector.
    pub fn exit(&self, u: &Wrench) -> Result<f64, QualityError> {
        let (width, rows, col_t, col_art) = (self.width, self.rows, self.col_t, self.col_art);
        let mut tab = self.tab.clone();
        let mut basis = self.basis.clone();
        // The t column in the current basis: B⁻¹ times its column (−u in the wrench rows),
        // B⁻¹'s columns for the wrench rows being the artificials' (an identity at the start).
        let a_t: [f64; DIM] = std::array::from_fn(|d| -self.signs[d] * u[d]);
        for r in 0..rows {
            let row = &tab[r * width..(r + 1) * width];
            let v: f64 = (0..DIM).map(|d| row[col_art + d] * a_t[d]).sum();
            tab[r * width + col_t] = v;
        }
        // Phase 2: maximise t; the reduced costs are −1 for t and 0 elsewhere, since t is not
        // basic; artificials are barred from entering.
        let obj = rows * width;
        for v in &mut tab[obj..obj + width] {
            *v = 0.0;
        }
        tab[obj + col_t] = -1.0;
        simplex(&mut tab, &mut basis, width, rows, col_art, self.tol)?;
        let t = basis
            .iter()
            .position(|&b| b == col_t)
            .map_or(0.0, |r| tab[r * width + width - 1]);
        if t.is_finite() && t >= 0.0 {
            Ok(t)
        } else {
            Err(QualityError::RayEnd { t })
        }
    }
}

/// Moves the artificials still basic after the first phase (at 0, up to round-off) out of the
/// basis, each on its row's largest entry; one whose row has none stays (its wrench row is
/// reached by no edge). Columns `col_art..` are the artificials, the last the right-hand side.
fn drive_out_artificials(
    tab: &mut [f64],
    basis: &mut [usize],
    width: usize,
    rows: usize,
    col_art: usize,
    scale: f64,
) {
    let cols = col_art + DIM;
    for r in 0..DIM {
        if basis[r] >= col_art {
            let row = &tab[r * width..r * width + col_art];
            let (j, a) = row.iter().enumerate().fold((0, 0.0f64), |b, (j, v)| {
                if v.abs() > b.1 {
                    (j, v.abs())
                } else {
                    b
                }
            });
            if a > 1e-9 * scale {
                tab[r * width + cols] = 0.0;
                pivot(tab, basis, width, rows, r, j);
            }
        }
    }
}

/// Pivots row `r` on column `j` (the objective row included).
fn pivot(tab: &mut [f64], basis: &mut [usize], width: usize, rows: usize, r: usize, j: usize) {
    let p = tab[r * width + j];
    for v in &mut tab[r * width..(r + 1) * width] {
        *v /= p;
    }
    tab[r * width + j] = 1.0;
    let (before, rest) = tab.split_at_mut(r * width);
    let (prow, after) = rest.split_at_mut(width);
    let eliminate = |row: &mut [f64]| {
        let f = row[j];
        if f != 0.0 {
            for (a, b) in row.iter_mut().zip(prow.iter()) {
                *a -= f * b;
            }
            row[j] = 0.0;
        }
    };
    before.chunks_mut(width).for_each(eliminate);
    after.chunks_mut(width).take(rows - r).for_each(eliminate);
    basis[r] = j;
}

/// The simplex method on the tableau, maximising: the entering column is the one with the most
/// negative reduced cost among `0..enter_below`, the leaving row the smallest ratio (ties to the
/// smallest basic index); after 50 pivots in a row that do not improve the objective by more
/// than the tolerance, Bland's rule to the end, which cannot cycle.
fn simplex(
    tab: &mut [f64],
    basis: &mut [usize],
    width: usize,
    rows: usize,
    enter_below: usize,
    tol: f64,
) -> Result<(), QualityError> {
    let obj = rows * width;
    let rhs = width - 1;
    let mut stalled = 0;
    let mut bland = false;
    for _ in 0..10_000 {
        bland |= stalled > 50;
        let mut enter = None;
        let mut best = -tol;
        for j in 0..enter_below {
            let cost = tab[obj + j];
            if cost < best {
                enter = Some(j);
                if bland {
                    break;
                }
                best = cost;
            }
        }
        let Some(j) = enter else { return Ok(()) };
        let mut leave: Option<(usize, f64)> = None;
        for r in 0..rows {
            let a = tab[r * width + j];
            if a > tol {
                let ratio = tab[r * width + rhs].max(0.0) / a;
                let better = match leave {
                    None => true,
                    Some((l, q)) => ratio < q || (ratio == q && basis[r] < basis[l]),
                };
                if better {
                    leave = Some((r, ratio));
                }
            }
        }
        let Some((r, ratio)) = leave else {
            return Err(QualityError::UnboundedRay);
        };
        let gain = ratio * -tab[obj + j];
        stalled = if gain > tol { 0 } else { stalled + 1 };
        pivot(tab, basis, width, rows, r, j);
    }
    Err(QualityError::SimplexPivots)
}

/// `W`'s centre: the sum of each `Pᵢ`'s vertex centroid.
pub fn centre(per_contact: &[Vec<Wrench>]) -> Wrench {
    let mut c = [0.0; DIM];
    for edges in per_contact.iter().filter(|e| !e.is_empty()) {
        let n = (edges.len() + 1) as f64;
        for e in edges {
            for (a, b) in c.iter_mut().zip(e) {
                *a += b / n;
            }
        }
    }
    c
}

/// The covariance of `Σᵢ vᵢ` with `vᵢ` uniform over `Pᵢ`'s vertices (`0` and the edges).
fn spread(per_contact: &[Vec<Wrench>]) -> Matrix6<f64> {
    let mut cov = Matrix6::zeros();
    for edges in per_contact.iter().filter(|e| !e.is_empty()) {
        let n = (edges.len() + 1) as f64;
        let mean = edges
            .iter()
            .fold(Vector6::zeros(), |m, e| m + Vector6::from(*e) / n);
        let origin = -mean;
        cov += origin * origin.transpose() / n;
        for e in edges {
            let d = Vector6::from(*e) - mean;
            cov += d * d.transpose() / n;
        }
    }
    cov
}

/// Unit directions in 6-D, in antithetic pairs `g, −g`, from a fixed seed (Gaussian by
/// Box–Muller, normalised).
pub fn directions(rays: usize) -> Vec<Wrench> {
    let mut state = SEED;
    let mut uniform = move || {
        // xorshift64*, the top 53 bits, in (0, 1).
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        let x = state.wrapping_mul(0x2545_F491_4F6C_DD1D);
        ((x >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    let mut out = Vec::with_capacity(rays);
    while out.len() + 1 < rays.max(2) {
        let mut g = [0.0; DIM];
        for pair in g.chunks_mut(2) {
            let (a, b) = (uniform(), uniform());
            let r = (-2.0 * a.ln()).sqrt();
            let phi = 2.0 * std::f64::consts::PI * b;
            pair[0] = r * phi.cos();
            pair[1] = r * phi.sin();
        }
        let norm = g.iter().map(|v| v * v).sum::<f64>().sqrt();
        let g = g.map(|v| v / norm);
        out.push(g);
        out.push(g.map(|v| -v));
    }
    out
}

/// The volume of `W` from `rays` rays (rounded down to pairs, at least one pair).
pub fn volume(per_contact: &[Vec<Wrench>], rays: usize) -> Result<RayVolume, QualityError> {
    let zero = RayVolume {
        volume: 0.0,
        rel_se: 0.0,
        rays: 0,
    };
    if per_contact
        .iter()
        .flatten()
        .flatten()
        .any(|v| !v.is_finite())
    {
        return Err(QualityError::WrenchNotFinite);
    }
    let cov = spread(per_contact);
    if cov.iter().any(|v| !v.is_finite()) {
        return Err(QualityError::SpreadNotFinite);
    }
    let eig = cov.symmetric_eigenvalues();
    let (lo, hi) = eig
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(l, h), v| (l.min(*v), h.max(*v)));
    if hi <= 0.0 || lo <= 1e-12 * hi {
        return Ok(zero);
    }
    let l = cov
        .cholesky()
        .ok_or(QualityError::SpreadNotPositiveDefinite)?
        .l();
    let jacobian: f64 = (0..DIM).map(|i| l[(i, i)]).product();
    // The rays are shot in the whitened frame, `L⁻¹W`, whose spread is the identity: its
    // entries are of order 1 whatever the wrenches' units, so the simplex's tolerances hold.
    let whiten = |w: &Wrench| -> Wrench {
        l.solve_lower_triangular(&Vector6::from(*w))
            .map_or([f64::NAN; DIM], Into::into)
    };
    let whitened: Vec<Vec<Wrench>> = per_contact
        .iter()
        .map(|edges| edges.iter().map(whiten).collect())
        .collect();
    let caster = RayCaster::new(&whitened, &whiten(&centre(per_contact)))?;
    // At least two pairs, for a standard error.
    let dirs = directions(rays.max(4));
    let exits: Vec<Result<f64, QualityError>> = dirs.par_iter().map(|g| caster.exit(g)).collect();
    // The first error in the directions' order, so that the message is the same every run.
    let radii: Vec<f64> = exits.into_iter().collect::<Result<_, _>>()?;
    let pairs: Vec<f64> = radii
        .chunks(2)
        .map(|p| 0.5 * (p[0].powi(6) + p[1].powi(6)))
        .collect();
    let n = pairs.len() as f64;
    let mean = pairs.iter().sum::<f64>() / n;
    let var = pairs.iter().map(|p| (p - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    let ball = std::f64::consts::PI.powi(3) / 6.0;
    let volume = ball * jacobian * mean;
    Ok(RayVolume {
        volume,
        rel_se: if mean > 0.0 {
            (var / n).sqrt() / mean
        } else {
            0.0
        },
        rays: radii.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube_segments() -> Vec<Vec<Wrench>> {
        (0..12)
            .map(|k| {
                let mut w = [0.0; 6];
                w[k % 6] = if k < 6 { 1.0 } else { -1.0 };
                vec![w]
            })
            .collect()
    }

    #[test]
    fn a_ray_leaves_the_cube_where_the_closed_form_says() {
        // The sum of the twelve segments [0, ±e_k] is [−1, 1]^6, centred on 0: a ray along a
        // unit u leaves it at 1 / max|u_k|.
        let w = cube_segments();
        let c = centre(&w);
        assert!(c.iter().all(|v| v.abs() < 1e-15));
        for g in directions(64) {
            let t = ray_exit(&w, &c, &g).unwrap();
            let exact = 1.0 / g.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!((t - exact).abs() < 1e-9 * exact, "{t} vs {exact}");
        }
        // From an off-centre point too.
        let c = [0.5, -0.25, 0.0, 0.1, 0.0, -0.9];
        let u = [0.0, 0.0, 0.0, 0.0, 0.0, -1.0];
        assert!((ray_exit(&w, &c, &u).unwrap() - 0.1).abs() < 1e-12);
        let u = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        assert!((ray_exit(&w, &c, &u).unwrap() - 0.5).abs() < 1e-12);
        // A centre outside is an error, not a number.
        let outside = [1.5, 0.0, 0.0, 0.0, 0.0, 0.0];
        assert!(ray_exit(&w, &outside, &u).is_err());
    }

    #[test]
    fn the_cube_and_a_box_have_their_volumes_within_the_stated_error() {
        let v = volume(&cube_segments(), VOLUME_RAYS).unwrap();
        assert_eq!(v.rays, VOLUME_RAYS);
        assert!(v.rel_se > 0.0 && v.rel_se < 0.05, "{v:?}");
        assert!(
            (v.volume - 64.0).abs() < 3.0 * v.rel_se * v.volume,
            "{v:?} against 64"
        );
        // A box 1 × 10 × 0.1 × 2 × 3 × 0.5 (segments of those lengths): the whitening makes it
        // as easy as the cube.
        let sides = [1.0, 10.0, 0.1, 2.0, 3.0, 0.5];
        let w: Vec<Vec<Wrench>> = (0..6)
            .map(|k| {
                let mut e = [0.0; 6];
                e[k] = sides[k];
                vec![e]
            })
            .collect();
        let exact: f64 = sides.iter().product();
        let v = volume(&w, VOLUME_RAYS).unwrap();
        assert!(
            (v.volume - exact).abs() < 3.0 * v.rel_se * v.volume,
            "{v:?}"
        );
        // Determinism: the same volume, bit for bit.
        assert_eq!(volume(&w, VOLUME_RAYS).unwrap(), v);
        // Five segments span 5 dimensions: no volume.
        let v = volume(&w[..5], VOLUME_RAYS).unwrap();
        assert_eq!(v.volume, 0.0);
    }

    #[test]
    fn the_volume_does_not_depend_on_the_wrenches_units() {
        // Rays are shot in the whitened frame, so scaling the wrenches by 1e5 or 1e-10 scales
        // the volume by the sixth power and nothing else (no tolerance is crossed).
        let base = volume(&cube_segments(), VOLUME_RAYS).unwrap();
        for f in [1e5, 1e-10] {
            let w: Vec<Vec<Wrench>> = cube_segments()
                .into_iter()
                .map(|e| e.into_iter().map(|x| x.map(|v| v * f)).collect())
                .collect();
            let v = volume(&w, VOLUME_RAYS).unwrap();
            let expected = base.volume * f.powi(6);
            assert!(
                (v.volume - expected).abs() < 1e-9 * expected,
                "{v:?} at {f}"
            );
            assert!((v.rel_se - base.rel_se).abs() < 1e-9);
        }
    }

    #[test]
    fn a_wrench_that_is_not_finite_is_an_error() {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut w = cube_segments();
            w[3][0][1] = bad;
            assert!(volume(&w, VOLUME_RAYS).is_err());
        }
        let mut w = cube_segments();
        w[0][0][0] = 1e200;
        assert!(volume(&w, VOLUME_RAYS).is_err(), "the spread overflows");
        // No contacts: no volume.
        assert_eq!(volume(&[], VOLUME_RAYS).unwrap().volume, 0.0);
    }
}

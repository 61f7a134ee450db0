//! Why an L∞ metric could not be computed: the failures of the expanding polytope
//! ([`super::linf::epsilon`]) and of the ray casting ([`super::rays`]).
//!
//! None of them is an outcome of the grasp (a grasp that is not force closure has epsilon 0,
//! with a note): each says the computation stopped, and the quality report carries its text in
//! `linf_note` ("L-infinity epsilon not computed: …"), so the messages are part of the output.

/// A failure of the L∞ epsilon search or of the volume by rays.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum QualityError {
    /// The expanding polytope used up its support points before the bracket closed.
    #[error(
        "not settled after {added} support points (epsilon between {lower:.6} and {upper:.6})"
    )]
    NotSettled {
        /// Support points added.
        added: usize,
        /// Lower bound on epsilon when it stopped.
        lower: f64,
        /// Upper bound on epsilon when it stopped.
        upper: f64,
    },
    /// The next support point was not beyond its facet by more than round-off.
    #[error("round-off stopped the search (epsilon between {lower:.9} and {upper:.9})")]
    RoundOff {
        /// Lower bound on epsilon.
        lower: f64,
        /// Upper bound on epsilon.
        upper: f64,
    },
    /// Hulling the inner polytope's points again (after round-off in an update) failed.
    #[error("the hull failed on the inner polytope (epsilon between {lower:.9} and {upper:.9})")]
    InnerHull {
        /// Lower bound on epsilon.
        lower: f64,
        /// Upper bound on epsilon.
        upper: f64,
    },
    /// The inner polytope had no live facet left to expand.
    #[error("the inner polytope lost its facets")]
    FacetsLost,
    /// The singular value decomposition of the support points gave no left vectors.
    #[error("SVD failed")]
    Svd,
    /// New support directions did not add a point while the points span fewer than 6 dimensions.
    #[error("the support points do not span 6 dimensions")]
    SupportSpan,
    /// The hull of the initial support points failed.
    #[error("the hull failed on the initial polytope")]
    InitialHull,
    /// The initial support points, with the origin inside, make no full-dimensional polytope.
    #[error("the initial polytope is degenerate")]
    InitialDegenerate,
    /// Growing the initial polytope did not put the origin inside within its rounds.
    #[error("no initial polytope around the origin after 200 rounds")]
    NoInitialPolytope,
    /// The ray's centre is not in the wrench space (the first phase is infeasible).
    #[error("the centre is outside the wrench space")]
    CentreOutside,
    /// A wrench row no edge reaches: the wrench space is not full-dimensional.
    #[error("the wrench space spans fewer than 6 dimensions")]
    FewerDimensions,
    /// A ray's programme ended at a negative or non-finite `t`.
    #[error("the ray programme ended at t = {t}")]
    RayEnd {
        /// Where it ended.
        t: f64,
    },
    /// A ray's programme was unbounded, which a bounded wrench space cannot be.
    #[error("unbounded ray")]
    UnboundedRay,
    /// The simplex method used up its pivots.
    #[error("the simplex method did not finish in 10000 pivots")]
    SimplexPivots,
    /// An edge wrench has a non-finite entry.
    #[error("a wrench is not finite")]
    WrenchNotFinite,
    /// The wrenches' covariance has a non-finite entry (it overflowed).
    #[error("the wrench spread is not finite")]
    SpreadNotFinite,
    /// The wrenches' covariance has no Cholesky factor.
    #[error("the wrench spread is not positive definite")]
    SpreadNotPositiveDefinite,
}

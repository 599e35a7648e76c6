//! The cheapest model level: rigid blocks on rigid planes.
//!
//! Owns:
//! - [`wedge`]: Hoek & Bray limit equilibrium of a tetrahedral rock wedge on two joint
//!   planes (geometry, normal reactions, factor of safety, strength-reduction factor,
//!   pseudo-static critical acceleration and the linear sliding coefficients r0, rh, rv);
//! - [`newmark`]: rigid-plastic (Newmark) sliding of a block on an incline or of a wedge
//!   along its line of intersection under base acceleration histories.
//!
//! Inputs: plane orientations (dip / dip direction, degrees), strengths (Pa, degrees),
//! densities (kg/m³), base accelerations sampled at a uniform step (m/s²; records in g
//! are converted elsewhere, once). Outputs: plain serde-serialisable result structs.
//!
//! Conventions (stated once here, used by both files):
//! - Axes x east, y north, z up; SI units; angles in degrees at the API, radians inside.
//! - A plane's orientation is (dip, dip direction); its unit normal is taken pointing up:
//!   n = (sin dip sin dd, sin dip cos dd, cos dip).
//! - Ground acceleration a_h is horizontal (along a stated azimuth or "into the hill"),
//!   a_v is vertical, positive up. The pseudo body force on the block is −m a_ground, so a
//!   ground acceleration into the hill and an upward ground acceleration both push the
//!   block down the slope / add weight. In coefficients, kh = a_h/g and kv = a_v/g.
//! - Relative acceleration of the block is positive *down* the sliding direction.
//!
//! Invariants: nothing here panics on user input; every bad input is a [`RigidError`]
//! naming the quantity and the fix.

pub mod newmark;
pub mod wedge;

use thiserror::Error;

/// Failures of the rigid-block computations.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum RigidError {
    #[error("invalid {what} = {value}: {fix}")]
    InvalidInput { what: String, value: f64, fix: String },
    #[error("joint planes A ({a}) and B ({b}) are parallel: they have no line of intersection, so there is no wedge. Give two joint planes with different orientations.")]
    ParallelPlanes { a: String, b: String },
    #[error("these planes do not form a wedge: {reason}")]
    NotAWedge { reason: String },
    #[error("the wedge is not in contact with plane {plane} under {load} (normal reaction {force:.4e} N <= 0): it would slide on the other plane alone or lift off, which the two-plane limit equilibrium does not cover. Check the plane orientations.")]
    LostContact { plane: char, load: String, force: f64 },
    #[error("tension crack {crack} at L = {distance} m does not cut the wedge: {reason}. Give 0 <= L < {trace_length:.3} m (L is measured from the crest point QA, L = 0, along the trace of plane A on the upper slope to P, L = {trace_length:.3} m), or leave the crack out.")]
    CrackMissesWedge { crack: String, distance: f64, trace_length: f64, reason: String },
    #[error("tension crack {crack} at L = {distance} m cuts off the toe: {reason}, so the crack would split the wedge instead of bounding it behind the crest. A tension crack must run from the upper slope behind the crest down into the wedge and keep the toe O in front of it: give a steeper crack dipping towards the slope face (or a vertical one), or leave the crack out.")]
    CrackCutsOffToe { crack: String, distance: f64, reason: String },
    #[error("tension crack {crack} at L = {distance} m leaves nothing of the wedge in front of it (truncated volume {volume:.3e} m3 of the {full_volume:.3e} m3 tetrahedron): it passes through the toe O with the rest of the wedge behind it. Give a larger L or another crack orientation.")]
    CrackLeavesNothing { crack: String, distance: f64, volume: f64, full_volume: f64 },
    #[error("a tension crack ({crack}) is supported for a dry wedge only (water = \"dry\"): the Hoek & Bray short-solution water pressure (water = \"hoek_bray_short\") assumes the untruncated tetrahedron, and the comprehensive solution with water in the crack is not implemented. Set water to \"dry\" or remove the tension crack.")]
    CrackWithWater { crack: String },
    #[error("strength reduction: no limit state for a reduction factor in [{lo:.3e}, {hi:.3e}] ({reason})")]
    NoLimitState { lo: f64, hi: f64, reason: String },
    #[error("{what}: sample {index} is {value} (not finite). Check the record.")]
    NonFiniteSample { what: String, index: usize, value: f64 },
    #[error("vertical acceleration has {got} samples but the horizontal one has {expected}; both must be sampled at the same times.")]
    LengthMismatch { expected: usize, got: usize },
}

impl RigidError {
    pub(crate) fn invalid(what: &str, value: f64, fix: &str) -> Self {
        RigidError::InvalidInput { what: what.to_string(), value, fix: fix.to_string() }
    }
}

/// `Ok(value)` if `value` is finite and strictly positive, else an [`RigidError::InvalidInput`].
pub(crate) fn positive(what: &str, value: f64) -> Result<f64, RigidError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(RigidError::invalid(what, value, "must be a finite number > 0"))
    }
}

/// `Ok(value)` if `value` is finite and ≥ 0.
pub(crate) fn non_negative(what: &str, value: f64) -> Result<f64, RigidError> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(RigidError::invalid(what, value, "must be a finite number >= 0"))
    }
}

//! The dynamic contact force of one pair in its local frame (design.md §5): Mohr-Coulomb
//! friction with cohesion, tensile strength and tied joints.
//!
//! Sign conventions are those of [`crate::contact`]: the force on the slave node is
//! `R = −r_n n + r_t[0] t1 + r_t[1] t2`, `r_n > 0` compression. With the pair compliance
//! `k = dt² w` (m/N) the pair's own force changes its relative displacement by `k R`, so
//!
//! ```text
//! g[n+1]    = g̃ + k r_n          (closing:  r_n = −g̃ / k  gives g[n+1] = 0)
//! Δd_t[n+1] = Δd̃_t + k r_t       (sticking: r_t = −Δd̃_t / k gives Δd_t = 0)
//! ```
//!
//! where `g̃` is the trial gap and `Δd̃_t` the trial tangential relative displacement increment
//! over the step, both from the contact-free prediction.
//!
//! Decision, in order:
//! 1. `tied`: always bonded: `r_n = −g̃/k` (either sign), `r_t = −Δd̃_t/k`, no limit.
//! 2. A pair is *bonded* when its bond is intact and the law has a tensile strength. Not bonded
//!    and `g̃ ≥ 0`: **open**, `R = 0`.
//! 3. Otherwise `r_n = −g̃/k`. Tension (`r_n < 0`, bonded pairs only) beyond `σ_t A`: the bond
//!    breaks and the pair opens, `R = 0`.
//! 4. Trial `r_t = −Δd̃_t/k`, limit `τ = μ r_n + c A` (`c A` only while intact), clamped at 0
//!    (with an asperity angle, the bilinear envelope `min(tan(φ + i) r_n, μ r_n + c A)`:
//!    [`JointLaw::shear_limit`]). `|r_t| ≤ τ`: **stick** (state `Bonded` for a bonded pair). Else **slip**: `r_t` scaled back
//!    to `τ` along the trial direction (opposite to the trial slip).
//!
//! The bond (cohesion and tensile strength) is lost on the first slip or opening (`g̃ > 0` while
//! not bonded), unless `keep_cohesion`; a tensile rupture (step 3) always ends it, otherwise
//! the pair could never open. When a slip ends the bond of a pair in tension, the pair opens in
//! that same step (the response is that of the pair with its new history).
//!
//! Non-finite inputs propagate into the force (the solver reports non-finite values).

use nalgebra::{Vector2, Vector3};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// The strength of a joint, per pair.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointLaw {
    /// Friction coefficient μ = tan φ (dimensionless, ≥ 0). No default: every joint must state it.
    pub mu: f64,
    /// Cohesion c (Pa, ≥ 0), multiplied by the slave node's tributary area. Default 0: a clean
    /// rock joint; cohesion is a site-specific measured value.
    #[serde(default)]
    pub cohesion: f64,
    /// Tensile strength σ_t (Pa, ≥ 0; 0 = the joint carries no tension). Default 0: rock joints
    /// and dam lift joints are assumed cracked, the conservative choice.
    #[serde(default)]
    pub tensile_strength: f64,
    /// Keep cohesion (and tensile strength) after a pair slips or opens. Default false: the
    /// bond is brittle and lost at the first slip or opening (design §5, as in the paper).
    #[serde(default)]
    pub keep_cohesion: bool,
    /// Tied joint: the two sides are glued (stick always, no opening, no strength limit).
    /// Default false. Used for non-conforming glued blocks (dam on foundation).
    #[serde(default)]
    pub tied: bool,
    /// Gap (m) a pair must exceed to count as *opened*, and slip increment (m) it must exceed to
    /// count as *slipped*, for the loss of its bond. Default 0 in
    /// the pure law; `ContactJoint::build` sets it to the round-off of the joint's positions
    /// ([`OPEN_TOLERANCE_RELATIVE`] × its coordinate scale), so that a pair touching to
    /// round-off keeps its bond: at the first step of a suddenly loaded joint both sides move
    /// together and the trial gap is the initial gap, ±1e-16 m, whose sign is noise.
    #[serde(default)]
    pub open_tolerance: f64,
    /// Softening length d_c (m, ≥ 0): while the bond is intact its cohesion falls linearly from
    /// c A to 0 as the pair's accumulated slip grows from 0 to d_c, where the bond is lost; an
    /// opening beyond d_c also breaks it. Default 0: brittle, lost at the first slip or opening
    /// beyond round-off (design §5). A few millimetres model the breakage of asperities over a
    /// finite shear displacement, and keep a joint's cohesion from being lost all at once by the
    /// elastic creep of its edges, where the loading path concentrates shear.
    #[serde(default)]
    pub softening_slip: f64,
    /// The bilinear (Patton 1966) envelope's first branch, tan(φ + i) [-]: the friction of a
    /// joint riding up its first-order asperities of angle i (the scene's
    /// `joints[].asperity_angle` [deg], converted in `contact::joint`). With it the shear limit
    /// is min(tan(φ + i) r_n, μ r_n + c A) for r_n ≥ 0 ([`JointLaw::shear_limit`]): through the
    /// origin below the knee σ_k = c / (tan(φ + i) − μ), the cohesive Coulomb line above it.
    /// Default `None`: the seed's truncated Mohr–Coulomb cone μ r_n + c A. Must be finite and
    /// above μ ([`JointLaw::validate`]). A pair in tension (a bond with tensile strength) would
    /// carry no shear under it: the scene refuses an asperity angle with a tensile strength,
    /// without cohesion (the envelope is then the Coulomb line) or on a tied joint
    /// (`scene::validate`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub asperity_friction: Option<f64>,
}

/// Round-off scale of a gap, relative to the largest coordinate magnitude of the joint (plus
/// its size): 1e-12, about 5000 × the double-precision epsilon, so far above the round-off of
/// n · (x̄ − x_s) and far below any physical opening.
pub const OPEN_TOLERANCE_RELATIVE: f64 = 1e-12;

impl JointLaw {
    /// Pure Coulomb friction μ: no cohesion, no tension, brittle defaults.
    pub fn coulomb(mu: f64) -> Self {
        JointLaw { mu, cohesion: 0.0, tensile_strength: 0.0, keep_cohesion: false, tied: false, open_tolerance: 0.0, softening_slip: 0.0, asperity_friction: None }
    }

    /// A glued (tied) interface.
    pub fn tied() -> Self {
        JointLaw { tied: true, ..JointLaw::coulomb(0.0) }
    }

    /// Check that every parameter is finite and non-negative, and that an asperity envelope
    /// has what it needs ([`JointLaw::asperity_friction`]); the error names the field.
    pub fn validate(&self) -> Result<(), JointLawError> {
        for (field, value) in
            [("mu", self.mu), ("cohesion", self.cohesion), ("tensile_strength", self.tensile_strength), ("open_tolerance", self.open_tolerance), ("softening_slip", self.softening_slip)]
        {
            if !(value.is_finite() && value >= 0.0) {
                return Err(JointLawError { field, value, rule: NON_NEGATIVE });
            }
        }
        if let Some(s) = self.asperity_friction
            && !(s.is_finite() && s > self.mu)
        {
            return Err(JointLawError { field: "asperity_friction", value: s, rule: "must be finite and above mu (tan(phi + i) of an asperity angle 0 < i < 90 - phi deg)" });
        }
        Ok(())
    }
}

/// The rule of [`JointLawError`] for the numbers that must be finite and non-negative.
const NON_NEGATIVE: &str = "must be a finite number >= 0 (mu dimensionless, cohesion and tensile_strength in Pa, open_tolerance and softening_slip in m)";

/// An invalid joint-law parameter: the field, its value and the rule it breaks.
#[derive(Clone, Debug, PartialEq, Error)]
#[error("joint law: `{field}` = {value} {rule}")]
pub struct JointLawError {
    pub field: &'static str,
    pub value: f64,
    pub rule: &'static str,
}

impl JointLaw {
    /// The limit of the tangential force (N) under normal force `r_n` (N, compressive): the
    /// Mohr-Coulomb line μ r_n + the cohesive force, with an asperity envelope
    /// ([`JointLaw::asperity_friction`] s) the smaller of it and s r_n; not below 0. The floor
    /// by comparison: `f64::max`'s NaN handling cost a thirtieth of a Gauss–Seidel sweep; a NaN
    /// limit gives 0 either way. One definition for the dynamic contact force, the penalty
    /// springs, the static contact and the outputs.
    #[inline(always)]
    pub fn shear_limit(&self, r_n: f64, hist: &PairHistory, area: f64) -> f64 {
        self.shear_limit_with_slope(r_n, hist, area).0
    }

    /// [`JointLaw::shear_limit`] and its derivative with respect to `r_n` (dimensionless): μ
    /// on the Coulomb line, s on the asperity branch, 0 at the floor (the static contact's
    /// tangent).
    #[inline(always)]
    pub fn shear_limit_with_slope(&self, r_n: f64, hist: &PairHistory, area: f64) -> (f64, f64) {
        let mut limit = self.mu * r_n + self.cohesion_force(hist, area);
        let mut slope = self.mu;
        if let Some(s) = self.asperity_friction {
            let asperity = s * r_n;
            if asperity < limit {
                limit = asperity;
                slope = s;
            }
        }
        if limit > 0.0 { (limit, slope) } else { (0.0, 0.0) }
    }

    /// The normal force of the envelope's knee (N) for a pair of area `area` [m²] with its
    /// bond intact, c A / (s − μ); `None` without an asperity envelope.
    pub fn knee_force(&self, area: f64) -> Option<f64> {
        self.asperity_friction.map(|s| self.cohesion * area / (s - self.mu))
    }

    /// The cohesive force of a pair (N): c A while intact, softened linearly with the
    /// accumulated slip over [`JointLaw::softening_slip`]; 0 once the bond is lost.
    pub fn cohesion_force(&self, hist: &PairHistory, area: f64) -> f64 {
        if !hist.intact {
            return 0.0;
        }
        let c = self.cohesion * area;
        if self.softening_slip > 0.0 && !self.keep_cohesion { c * (1.0 - hist.slip / self.softening_slip).max(0.0) } else { c }
    }

    /// Whether a trial gap `g` (m) opens the pair far enough to break its bond.
    fn breaks_by_opening(&self, g: f64) -> bool {
        g > self.open_tolerance.max(self.softening_slip)
    }

    /// Whether a slip increment of norm `d` (m) bringing the accumulated slip to `total` breaks
    /// the bond.
    fn breaks_by_slip(&self, d: f64, total: f64) -> bool {
        if self.softening_slip > 0.0 { total >= self.softening_slip } else { d > self.open_tolerance }
    }
}

/// The state of a pair after a step.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PairState {
    /// Gap open, no force.
    Open,
    /// In contact, no relative tangential motion.
    Stick,
    /// In contact, sliding at the Mohr-Coulomb limit.
    Slip,
    /// Bonded (intact tensile bond or tied): carries tension, sticks.
    Bonded,
}

impl PairState {
    /// Numeric code written to VTU files: open 0, stick 1, slip 2, bonded 3.
    pub fn code(self) -> u8 {
        match self {
            PairState::Open => 0,
            PairState::Stick => 1,
            PairState::Slip => 2,
            PairState::Bonded => 3,
        }
    }
}

/// What a pair remembers from step to step.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PairHistory {
    /// The bond (cohesion, tensile strength) is intact: not yet lost by slip, opening or rupture.
    pub intact: bool,
    /// Accumulated slip path length (m): the sum of `|Δd_t|` over the steps in state `Slip`.
    pub slip: f64,
}

impl Default for PairHistory {
    /// A fresh pair: bond intact, no slip.
    fn default() -> Self {
        PairHistory { intact: true, slip: 0.0 }
    }
}

/// The force of one pair and its new history.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PairResponse {
    /// Normal force magnitude (N): `> 0` compression, `< 0` tension (bonded pairs only).
    pub r_n: f64,
    /// Tangential force on the slave node in `(t1, t2)` (N).
    pub r_t: Vector2<f64>,
    pub state: PairState,
    /// History to store for the next step.
    pub hist: PairHistory,
    /// Tangential relative displacement increment of the step after the force is applied
    /// (m, `(t1, t2)`): zero in stick, along the trial direction in slip.
    pub slip_increment: Vector2<f64>,
}

impl PairResponse {
    fn open(hist: PairHistory, dt_trial: Vector2<f64>) -> Self {
        PairResponse { r_n: 0.0, r_t: Vector2::zeros(), state: PairState::Open, hist, slip_increment: dt_trial }
    }

    /// The force on the slave node in global coordinates, `−r_n n + r_t[0] t1 + r_t[1] t2` (N).
    /// The master nodes receive `−N_I` times it.
    pub fn force_on_slave(&self, n: &Vector3<f64>, t1: &Vector3<f64>, t2: &Vector3<f64>) -> Vector3<f64> {
        -n * self.r_n + t1 * self.r_t.x + t2 * self.r_t.y
    }
}

/// The dynamic contact force of one pair (see the module doc for the decision order).
///
/// - `g_trial`: trial gap `g̃` (m) from the contact-free prediction, positive open.
/// - `dt_trial`: trial relative tangential displacement increment over the step `Δd̃_t` (m), `(t1, t2)`.
/// - `dt2w`: `dt² w` (m/N), must be > 0 (positive masses).
/// - `area`: the slave node's tributary area `A_s` (m²).
#[inline]
pub fn pair_force(
    law: &JointLaw,
    hist: &PairHistory,
    g_trial: f64,
    dt_trial: Vector2<f64>,
    dt2w: f64,
    area: f64,
) -> PairResponse {
    pair_force_with_inverse(law, hist, g_trial, dt_trial, dt2w, 1.0 / dt2w, area)
}

/// [`pair_force`] with `1 / dt2w` given (`inv_dt2w`): the Gauss–Seidel sweeps compute it once
/// per pair and step instead of once per pair update. 1/k depends only on the pair, not on the
/// trial quantities; off the Gauss–Seidel chain (node update → trial gap → force → node update)
/// it costs no latency, but a division per update was still a tenth of a sweep's time.
/// Always inlined: called per pair update, and a call (the response returned through memory)
/// cost the sweeps a fifth of their time where the compiler chose not to inline it.
#[inline(always)]
pub fn pair_force_with_inverse(
    law: &JointLaw,
    hist: &PairHistory,
    g_trial: f64,
    dt_trial: Vector2<f64>,
    dt2w: f64,
    inv_dt2w: f64,
    area: f64,
) -> PairResponse {
    debug_assert!(dt2w > 0.0, "dt² w must be positive, got {dt2w}");
    let k = dt2w;
    let inv_k = inv_dt2w;
    if law.tied {
        return PairResponse {
            r_n: -g_trial * inv_k,
            r_t: -dt_trial * inv_k,
            state: PairState::Bonded,
            hist: *hist,
            slip_increment: Vector2::zeros(),
        };
    }
    let bonded = hist.intact && law.tensile_strength > 0.0;
    if g_trial >= 0.0 && !bonded {
        let intact = hist.intact && (law.keep_cohesion || !law.breaks_by_opening(g_trial));
        return PairResponse::open(PairHistory { intact, ..*hist }, dt_trial);
    }
    let r_n = -g_trial * inv_k;
    if r_n < -law.tensile_strength * area {
        // Tensile rupture (only reachable by a bonded pair): the bond is gone, the pair opens.
        return PairResponse::open(PairHistory { intact: false, ..*hist }, dt_trial);
    }
    let r_trial = -dt_trial * inv_k;
    let limit = law.shear_limit(r_n, hist, area);
    // stick when |r_trial| ≤ limit, compared through the squares (no root when it sticks)
    if r_trial.norm_squared() <= limit * limit {
        let state = if bonded { PairState::Bonded } else { PairState::Stick };
        return PairResponse { r_n, r_t: r_trial, state, hist: *hist, slip_increment: Vector2::zeros() };
    }
    // Slip: back to the limit along the trial direction. As for an opening, a slip within
    // round-off (`open_tolerance`) does not break the bond.
    let r_trial_norm = r_trial.norm();
    let r_t = r_trial * (limit / r_trial_norm);
    let slip_increment = dt_trial + r_t * k;
    // |slip_increment| = |Δd̃_t| − k limit = k (|r_trial| − limit) (slip_increment is Δd̃_t
    // shortened along itself), without a second root
    let d = k * (r_trial_norm - limit);
    let slip = hist.slip + d;
    let intact = hist.intact && (law.keep_cohesion || !law.breaks_by_slip(d, slip));
    if hist.intact && !intact && r_n < 0.0 {
        // The slip broke the bond of a pair in tension: with its new history it is open.
        return PairResponse::open(PairHistory { intact, ..*hist }, dt_trial);
    }
    PairResponse {
        r_n,
        r_t,
        state: PairState::Slip,
        hist: PairHistory { intact, slip },
        slip_increment,
    }
}

/// The penalty variant's pair force: springs instead of the dynamic contact force, with the
/// decisions and strength of [`pair_force`] in the same order (tied; bonded or open; tensile
/// rupture; Mohr-Coulomb with cohesion while intact; bond lost at the first slip or opening
/// beyond `open_tolerance`, unless `keep_cohesion`).
///
/// - `gap`: the gap g (m) at t[n], positive open; the normal spring gives `r_n = −kn_a g`.
/// - `r_t_prev`: the tangential spring force of the previous step (N, `(t1, t2)`; 0 after an
///   open step); `dd_t`: the tangential relative displacement increment of the last step (m).
///   Trial `r_t = r_t_prev − kt_a dd_t`, scaled back to the limit in slip.
/// - `kn_a`, `kt_a`: the pair's spring stiffnesses (N/m: stiffness per unit area × `area`).
///
/// `slip_increment` is `dd_t` (the springs let a sticking pair move elastically).
#[allow(clippy::too_many_arguments)]
pub fn penalty_force(
    law: &JointLaw,
    hist: &PairHistory,
    gap: f64,
    r_t_prev: Vector2<f64>,
    dd_t: Vector2<f64>,
    kn_a: f64,
    kt_a: f64,
    area: f64,
) -> PairResponse {
    let r_trial = r_t_prev - dd_t * kt_a;
    if law.tied {
        return PairResponse { r_n: -kn_a * gap, r_t: r_trial, state: PairState::Bonded, hist: *hist, slip_increment: dd_t };
    }
    let bonded = hist.intact && law.tensile_strength > 0.0;
    if gap >= 0.0 && !bonded {
        let intact = hist.intact && (law.keep_cohesion || !law.breaks_by_opening(gap));
        return PairResponse::open(PairHistory { intact, ..*hist }, dd_t);
    }
    let r_n = -kn_a * gap;
    if r_n < -law.tensile_strength * area {
        return PairResponse::open(PairHistory { intact: false, ..*hist }, dd_t);
    }
    let limit = law.shear_limit(r_n, hist, area);
    let r_trial_norm = r_trial.norm();
    if r_trial_norm <= limit {
        let state = if bonded { PairState::Bonded } else { PairState::Stick };
        return PairResponse { r_n, r_t: r_trial, state, hist: *hist, slip_increment: dd_t };
    }
    // as in `pair_force`: a slip within round-off (`open_tolerance`) does not break the bond
    let d = dd_t.norm();
    let intact = hist.intact && (law.keep_cohesion || !law.breaks_by_slip(d, hist.slip + d));
    if hist.intact && !intact && r_n < 0.0 {
        return PairResponse::open(PairHistory { intact, ..*hist }, dd_t);
    }
    PairResponse {
        r_n,
        r_t: r_trial * (limit / r_trial_norm),
        state: PairState::Slip,
        hist: PairHistory { intact, slip: hist.slip + dd_t.norm() },
        slip_increment: dd_t,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // A pair with dt = 1e-4 s, m_s = 100 kg and one master node of 300 kg (N = 1):
    // w = 1/100 + 1/300, k = dt² w.
    const DT2W: f64 = 1e-8 * (1.0 / 100.0 + 1.0 / 300.0);
    const AREA: f64 = 0.25;

    fn law(mu: f64, c: f64, st: f64) -> JointLaw {
        JointLaw { mu, cohesion: c, tensile_strength: st, keep_cohesion: false, tied: false, open_tolerance: 0.0, softening_slip: 0.0, asperity_friction: None }
    }

    #[test]
    fn open_pair_has_no_force() {
        let r = pair_force(&law(0.6, 0.0, 0.0), &PairHistory::default(), 1e-6, Vector2::new(1e-5, 0.0), DT2W, AREA);
        assert_eq!(r.state, PairState::Open);
        assert_eq!((r.r_n, r.r_t), (0.0, Vector2::zeros()));
        assert_eq!(r.state.code(), 0);
    }

    #[test]
    fn closing_force_closes_the_gap_exactly() {
        // Reference: g[n+1] = g̃ + k r_n = 0 (design §5), to round-off.
        let g = -3e-7;
        let r = pair_force(&law(0.6, 0.0, 0.0), &PairHistory::default(), g, Vector2::zeros(), DT2W, AREA);
        assert_eq!(r.state, PairState::Stick);
        assert!(r.r_n > 0.0, "compression is positive");
        assert!((g + DT2W * r.r_n).abs() < 1e-20);
    }

    #[test]
    fn stick_cancels_the_tangential_increment() {
        // Reference: Δd_t = Δd̃_t + k r_t = 0 below the limit, to round-off.
        let dt = Vector2::new(1e-8, -2e-8);
        let r = pair_force(&law(0.6, 0.0, 0.0), &PairHistory::default(), -1e-6, dt, DT2W, AREA);
        assert_eq!((r.state, r.state.code()), (PairState::Stick, 1));
        assert!((dt + r.r_t * DT2W).norm() < 1e-22);
        assert!(r.r_t.norm() <= 0.6 * r.r_n);
        assert_eq!(r.slip_increment, Vector2::zeros());
        assert_eq!(r.hist, PairHistory::default());
    }

    #[test]
    fn slip_at_the_mohr_coulomb_limit() {
        // Reference: |r_t| = μ r_n + c A exactly (relative 1e-14, round-off of the scaling),
        // direction opposite to the trial slip (cosine −1 to 1e-14).
        let l = law(0.6, 2e5, 0.0);
        let g = -1e-7;
        let dt = Vector2::new(3e-5, 4e-5);
        let r = pair_force(&l, &PairHistory::default(), g, dt, DT2W, AREA);
        assert_eq!((r.state, r.state.code()), (PairState::Slip, 2));
        let expected = 0.6 * (-g / DT2W) + 2e5 * AREA;
        assert!((r.r_t.norm() - expected).abs() <= 1e-14 * expected, "{} vs {expected}", r.r_t.norm());
        let cos = r.r_t.dot(&dt) / (r.r_t.norm() * dt.norm());
        assert!((cos + 1.0).abs() < 1e-14);
        // The slip increment is the trial increment less what the limit force holds back.
        let held = expected * DT2W;
        assert!((r.slip_increment.norm() - (dt.norm() - held)).abs() < 1e-18);
        assert!((r.hist.slip - r.slip_increment.norm()).abs() < 1e-20);
        // Cohesion lost on this first slip.
        assert!(!r.hist.intact);
        // Next step, same trial: the limit is μ r_n only.
        let r2 = pair_force(&l, &r.hist, g, dt, DT2W, AREA);
        assert!((r2.r_t.norm() - 0.6 * (-g / DT2W)).abs() <= 1e-14 * r2.r_t.norm());
        assert!(r2.hist.slip > r.hist.slip);
    }

    #[test]
    fn cohesion_holds_until_first_slip_or_opening() {
        // Without cohesion this trial slips; with c A it sticks and the bond survives.
        let l = law(0.5, 1e5, 0.0);
        let g = -1e-8;
        let r_n = -g / DT2W;
        let dt = Vector2::new(-(0.5 * r_n + 0.5e5 * AREA) * DT2W, 0.0); // trial force halfway into the cohesion
        assert_eq!(pair_force(&law(0.5, 0.0, 0.0), &PairHistory::default(), g, dt, DT2W, AREA).state, PairState::Slip);
        let r = pair_force(&l, &PairHistory::default(), g, dt, DT2W, AREA);
        assert_eq!(r.state, PairState::Stick);
        assert!(r.hist.intact);
        // Opening loses it ...
        let opened = pair_force(&l, &PairHistory::default(), 1e-9, dt, DT2W, AREA);
        assert_eq!(opened.state, PairState::Open);
        assert!(!opened.hist.intact);
        assert_eq!(pair_force(&l, &opened.hist, g, dt, DT2W, AREA).state, PairState::Slip);
        // ... unless keep_cohesion, which also keeps it through slip.
        let keep = JointLaw { keep_cohesion: true, ..l.clone() };
        assert!(pair_force(&keep, &PairHistory::default(), 1e-9, dt, DT2W, AREA).hist.intact);
        let big = dt * 10.0;
        let slip = pair_force(&keep, &PairHistory::default(), g, big, DT2W, AREA);
        assert_eq!(slip.state, PairState::Slip);
        assert!(slip.hist.intact);
        assert!((slip.r_t.norm() - (0.5 * r_n + 1e5 * AREA)).abs() <= 1e-14 * slip.r_t.norm());
        // A pair exactly touching (g̃ = 0) carries no force but is not opened.
        let touch = pair_force(&l, &PairHistory::default(), 0.0, dt, DT2W, AREA);
        assert_eq!(touch.state, PairState::Open);
        assert!(touch.hist.intact);
    }

    #[test]
    fn tension_up_to_strength_then_opening() {
        // σ_t A = 1e6 Pa × 0.25 m² = 2.5e5 N. Reference: a bonded pair closes any trial gap
        // while the tension −g̃/k stays within σ_t A (tolerance: round-off, 1e-20 m).
        let l = law(0.6, 3e5, 1e6);
        let limit = 1e6 * AREA;
        let g_ok = 0.9 * limit * DT2W;
        let r = pair_force(&l, &PairHistory::default(), g_ok, Vector2::zeros(), DT2W, AREA);
        assert_eq!((r.state, r.state.code()), (PairState::Bonded, 3));
        assert!(r.r_n < 0.0 && -r.r_n <= limit);
        assert!((g_ok + DT2W * r.r_n).abs() < 1e-20);
        assert!(r.hist.intact);
        // Beyond σ_t A: rupture, open, bond lost for good (even with keep_cohesion).
        for keep in [false, true] {
            let l = JointLaw { keep_cohesion: keep, ..l.clone() };
            let r = pair_force(&l, &PairHistory::default(), 1.1 * limit * DT2W, Vector2::zeros(), DT2W, AREA);
            assert_eq!(r.state, PairState::Open);
            assert_eq!(r.r_n, 0.0);
            assert!(!r.hist.intact);
            // Once broken, the same trial gap simply opens.
            assert_eq!(pair_force(&l, &r.hist, g_ok, Vector2::zeros(), DT2W, AREA).state, PairState::Open);
        }
        // Shear beyond the (tension-reduced) limit breaks the bond; in tension the pair opens.
        let shear = Vector2::new(1.0, 0.0) * (1e6 * DT2W);
        let r = pair_force(&l, &PairHistory::default(), g_ok, shear, DT2W, AREA);
        assert_eq!(r.state, PairState::Open);
        assert!(!r.hist.intact);
    }

    #[test]
    fn tied_always_sticks_and_never_opens() {
        let l = JointLaw::tied();
        for g in [-1e-6, 0.0, 1e-3] {
            let dt = Vector2::new(1e-2, -3e-3);
            let r = pair_force(&l, &PairHistory::default(), g, dt, DT2W, AREA);
            assert_eq!(r.state, PairState::Bonded);
            // Reference: both the gap and the tangential increment are closed exactly.
            assert!((g + DT2W * r.r_n).abs() < 1e-18);
            assert!((dt + DT2W * r.r_t).norm() < 1e-18);
        }
    }

    #[test]
    fn force_on_slave_signs() {
        // Compression pushes the slave back against n; r_t maps onto (t1, t2).
        let (n, t1, t2) = (Vector3::z(), Vector3::x(), Vector3::y());
        let r = PairResponse {
            r_n: 2.0,
            r_t: Vector2::new(3.0, -1.0),
            state: PairState::Slip,
            hist: PairHistory::default(),
            slip_increment: Vector2::zeros(),
        };
        assert_eq!(r.force_on_slave(&n, &t1, &t2), Vector3::new(3.0, -1.0, -2.0));
    }

    #[test]
    fn validate_names_the_field() {
        assert!(JointLaw::coulomb(0.7).validate().is_ok());
        let e = JointLaw { cohesion: -1.0, ..JointLaw::coulomb(0.7) }.validate().unwrap_err();
        assert_eq!(e.field, "cohesion");
        assert!(JointLaw::coulomb(f64::NAN).validate().is_err());
        // Serde: unknown keys are errors, optional fields default.
        let l: JointLaw = serde_json::from_str(r#"{"mu": 0.6}"#).unwrap();
        assert_eq!(l, JointLaw::coulomb(0.6));
        assert!(serde_json::from_str::<JointLaw>(r#"{"mu": 0.6, "cohesoin": 1}"#).is_err());
        assert_eq!(serde_json::to_string(&PairState::Slip).unwrap(), "\"slip\"");
    }

    #[test]
    fn asperity_envelope_is_bilinear_through_the_origin() {
        // Reference (Patton 1966): τ = min(tan(φ + i) σ, c + σ tan φ) for σ ≥ 0. φ = 30°, i = 15°,
        // c = 48 kPa on A = 0.25 m²: tan 45° = 1, μ = 0.57735, the knee at
        // σ_k A = c A / (1 − μ) = 12 000 / 0.42265 = 28 392 N. Tolerance: round-off (1e-12
        // relative).
        let mu = 30f64.to_radians().tan();
        let s = 45f64.to_radians().tan();
        let l = JointLaw { asperity_friction: Some(s), keep_cohesion: true, ..law(mu, 48e3, 0.0) };
        assert!(l.validate().is_ok());
        let ca = 48e3 * AREA;
        let knee = l.knee_force(AREA).unwrap();
        assert!((knee - ca / (1.0 - mu)).abs() < 1e-9 * knee && (knee - 28_392.0).abs() < 1.0, "knee {knee}");
        let h = PairHistory::default();
        for (r_n, expected) in [(0.0, 0.0), (1e3, s * 1e3), (0.5 * knee, s * 0.5 * knee), (2.0 * knee, mu * 2.0 * knee + ca), (1e6, mu * 1e6 + ca)] {
            let (lim, slope) = l.shear_limit_with_slope(r_n, &h, AREA);
            assert!((lim - expected).abs() <= 1e-12 * expected.max(1.0), "r_n {r_n}: {lim} vs {expected}");
            assert_eq!(lim, l.shear_limit(r_n, &h, AREA));
            let branch = if r_n == 0.0 { 0.0 } else if r_n < knee { s } else { mu };
            assert_eq!(slope, branch, "r_n {r_n}");
        }
        // continuous at the knee, and below the seed's cone everywhere (equal above the knee)
        let at = |r: f64| l.shear_limit(r, &h, AREA);
        assert!((at(knee * (1.0 - 1e-9)) - at(knee * (1.0 + 1e-9))).abs() < 1e-6 * ca);
        let cone = JointLaw { asperity_friction: None, ..l };
        assert!((0..50).map(|k| k as f64 * 1e3).all(|r| at(r) <= cone.shear_limit(r, &h, AREA)));
        // the dynamic force slips at that limit: a closed pair at small r_n carries no more than
        // s r_n (the cone's c A there is what made the force jump at g = 0)
        let g = -1e3 * DT2W; // r_n = 1e3 N
        let r = pair_force(&l, &h, g, Vector2::new(1.0, 0.0), DT2W, AREA);
        assert_eq!(r.state, PairState::Slip);
        assert!((r.r_t.norm() - s * 1e3).abs() < 1e-12 * s * 1e3, "{}", r.r_t.norm());
        assert!(pair_force(&cone, &h, g, Vector2::new(1.0, 0.0), DT2W, AREA).r_t.norm() > ca);
        // once the bond is lost (brittle law) the Coulomb line through the origin is below s r_n
        let lost = PairHistory { intact: false, slip: 1.0 };
        assert_eq!(l.shear_limit(1e3, &lost, AREA), mu * 1e3);
    }

    #[test]
    fn asperity_envelope_validation_names_the_field() {
        let ok = JointLaw { asperity_friction: Some(1.0), ..law(0.6, 1e4, 0.0) };
        assert!(ok.validate().is_ok());
        for bad in [0.5, 0.6, f64::INFINITY, f64::NAN] {
            let e = JointLaw { asperity_friction: Some(bad), ..ok }.validate().unwrap_err();
            assert_eq!(e.field, "asperity_friction");
            assert!(e.to_string().contains("above mu") && e.to_string().contains("`asperity_friction`"), "{e}");
        }
        // the default law has none, and its serialisation does not name it
        assert!(!serde_json::to_string(&law(0.6, 1e4, 0.0)).unwrap().contains("asperity"));
    }

    #[test]
    fn a_round_off_gap_does_not_open_the_bond() {
        // A trial gap below `open_tolerance` carries no force but keeps the bond; above it, it opens.
        let l = JointLaw { open_tolerance: 1e-12, ..law(0.5, 1e5, 0.0) };
        let r = pair_force(&l, &PairHistory::default(), 6e-16, Vector2::zeros(), DT2W, AREA);
        assert_eq!((r.state, r.hist.intact), (PairState::Open, true));
        let r = pair_force(&l, &PairHistory::default(), 2e-12, Vector2::zeros(), DT2W, AREA);
        assert_eq!((r.state, r.hist.intact), (PairState::Open, false));
        let p = penalty_force(&l, &PairHistory::default(), 6e-16, Vector2::zeros(), Vector2::zeros(), 1e9, 1e9, AREA);
        assert_eq!((p.state, p.hist.intact), (PairState::Open, true));
        let p = penalty_force(&l, &PairHistory::default(), 0.0, Vector2::zeros(), Vector2::zeros(), 1e9, 1e9, AREA);
        assert!(p.hist.intact, "an exactly touching penalty pair keeps its bond");
        let p = penalty_force(&l, &PairHistory::default(), 2e-12, Vector2::zeros(), Vector2::zeros(), 1e9, 1e9, AREA);
        assert!(!p.hist.intact);
    }

    #[test]
    fn penalty_slip_within_open_tolerance_keeps_the_bond() {
        // Regression: with softening_slip = 0 the penalty law broke the bond at any slip, while
        // its doc (and `pair_force`) break it only beyond `open_tolerance`. A penalty pair in
        // compression driven past its limit (r_t_prev = 1e6 N against μ r_n + c A ≈ 2.5e4 N)
        // slips; a slip increment of 5e-16 m (round-off) keeps the bond, 2e-12 m breaks it.
        let l = JointLaw { open_tolerance: 1e-12, ..law(0.5, 1e5, 0.0) };
        let (g, r_prev) = (-1e-6, Vector2::new(1e6, 0.0));
        let p = penalty_force(&l, &PairHistory::default(), g, r_prev, Vector2::new(5e-16, 0.0), 1e9, 1e9, AREA);
        assert_eq!((p.state, p.hist.intact), (PairState::Slip, true));
        let p = penalty_force(&l, &PairHistory::default(), g, r_prev, Vector2::new(2e-12, 0.0), 1e9, 1e9, AREA);
        assert_eq!((p.state, p.hist.intact), (PairState::Slip, false));
        // the same decision as the dynamic contact force's law on the same slip increments
        // (trial gap for r_n = 1e3 N; trial tangential increment k limit + d, so that the slip
        // increment is d)
        let k = DT2W;
        let limit = 0.5 * 1e3 + 1e5 * AREA;
        let slip_by = |d: f64| pair_force(&l, &PairHistory::default(), -1e3 * k, Vector2::new(-(k * limit + d), 0.0), k, AREA);
        assert!(slip_by(5e-16).hist.intact && !slip_by(2e-12).hist.intact);
    }

    #[test]
    fn cohesion_softens_linearly_over_the_softening_slip() {
        // Reference: c_eff = c A (1 − s/d_c) while s < d_c, 0 after; the limit is μ r_n + c_eff
        // exactly (relative 1e-12, round-off of the scaling). d_c = 1 mm, c A = 2.5e4 N.
        let l = JointLaw { softening_slip: 1e-3, ..law(0.5, 1e5, 0.0) };
        let g = -1e-8; // closing: r_n = 1e-8 / DT2W
        let r_n = -g / DT2W;
        let push = Vector2::new(1.0, 0.0); // a large trial slip: the pair slips at its limit
        for s in [0.0, 2.5e-4, 5e-4, 9e-4] {
            let h = PairHistory { intact: true, slip: s };
            let r = pair_force(&l, &h, g, push, DT2W, AREA);
            let expected = 0.5 * r_n + 1e5 * AREA * (1.0 - s / 1e-3);
            assert_eq!(r.state, PairState::Slip);
            assert!((r.r_t.norm() - expected).abs() < 1e-12 * expected, "s = {s}: {} vs {expected}", r.r_t.norm());
            // this slip (about 1 m) takes the pair past d_c: the bond is gone
            assert!(!r.hist.intact);
        }
        // a trial slip of 0.1 mm (well above the limit, so the pair slips about 0.097 mm) keeps
        // the total below d_c: the bond stays, softened
        let r = pair_force(&l, &PairHistory::default(), g, Vector2::new(1e-4, 0.0), DT2W, AREA);
        assert_eq!(r.state, PairState::Slip);
        assert!(r.hist.intact && r.hist.slip > 9e-5 && r.hist.slip < 1e-4, "slip {}", r.hist.slip);
        // an opening within d_c keeps the bond, beyond it breaks it
        let r = pair_force(&l, &PairHistory::default(), 5e-4, Vector2::zeros(), DT2W, AREA);
        assert_eq!((r.state, r.hist.intact), (PairState::Open, true));
        let r = pair_force(&l, &PairHistory::default(), 2e-3, Vector2::zeros(), DT2W, AREA);
        assert_eq!((r.state, r.hist.intact), (PairState::Open, false));
        // brittle (d_c = 0) is unchanged: any slip beyond round-off ends the bond
        let b = law(0.5, 1e5, 0.0);
        let r = pair_force(&b, &PairHistory::default(), g, push, DT2W, AREA);
        assert!((r.r_t.norm() - (0.5 * r_n + 1e5 * AREA)).abs() < 1e-12 * r.r_t.norm());
        assert!(!r.hist.intact);
    }

    #[test]
    fn penalty_springs_follow_the_same_law() {
        // kn A = kt A = 1e9 N/m on a penetration of 1e-6 m: r_n = 1e3 N; the cap μ r_n + c A as in
        // `pair_force`, reached along the trial direction; cohesion lost on the first slip.
        let (ka, g) = (1e9, -1e-6);
        let l = law(0.5, 1e3, 0.0); // c A = 250 N, limit 750 N
        let stick = penalty_force(&l, &PairHistory::default(), g, Vector2::zeros(), Vector2::new(-5e-7, 0.0), ka, ka, AREA);
        assert_eq!(stick.state, PairState::Stick);
        assert!((stick.r_n - 1e3).abs() < 1e-9 && (stick.r_t - Vector2::new(500.0, 0.0)).norm() < 1e-9);
        assert!(stick.hist.intact);
        let slip = penalty_force(&l, &PairHistory::default(), g, Vector2::new(500.0, 0.0), Vector2::new(0.0, -1e-6), ka, ka, AREA);
        assert_eq!(slip.state, PairState::Slip);
        assert!((slip.r_t.norm() - 750.0).abs() < 1e-9, "{}", slip.r_t.norm());
        let dir = Vector2::new(500.0, 1000.0).normalize();
        assert!((slip.r_t.normalize() - dir).norm() < 1e-12, "back to the limit along the trial force");
        assert!(!slip.hist.intact && slip.hist.slip > 0.0);
        // without the bond the limit is μ r_n only
        let again = penalty_force(&l, &slip.hist, g, slip.r_t, Vector2::zeros(), ka, ka, AREA);
        assert!((again.r_t.norm() - 500.0).abs() < 1e-9);
        // an open pair carries nothing
        let open = penalty_force(&l, &PairHistory::default(), 1e-6, Vector2::new(100.0, 0.0), Vector2::zeros(), ka, ka, AREA);
        assert_eq!((open.state, open.r_n, open.r_t), (PairState::Open, 0.0, Vector2::zeros()));
    }

    #[test]
    fn penalty_tension_and_tied() {
        let ka = 1e9;
        // σ_t A = 1e6 × 0.25 = 2.5e5 N: a bonded pair 1e-4 m open carries 1e5 N of tension ...
        let l = law(0.6, 0.0, 1e6);
        let r = penalty_force(&l, &PairHistory::default(), 1e-4, Vector2::zeros(), Vector2::zeros(), ka, ka, AREA);
        assert_eq!(r.state, PairState::Bonded);
        assert!((r.r_n + 1e5).abs() < 1e-6);
        // ... and at 3e-4 m (3e5 N > σ_t A) it ruptures and opens for good
        let r = penalty_force(&l, &PairHistory::default(), 3e-4, Vector2::zeros(), Vector2::zeros(), ka, ka, AREA);
        assert_eq!((r.state, r.hist.intact), (PairState::Open, false));
        // tied: both signs, no shear limit
        let t = penalty_force(&JointLaw::tied(), &PairHistory::default(), 1e-3, Vector2::zeros(), Vector2::new(1.0, 0.0), ka, ka, AREA);
        assert_eq!(t.state, PairState::Bonded);
        assert!((t.r_n + 1e6).abs() < 1e-6 && (t.r_t.x + 1e9).abs() < 1e-3);
    }
}

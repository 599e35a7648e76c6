//! Mesh convergence of the dam study's numbers: the observed order of convergence, the
//! Richardson-extrapolated value and its error band from a quantity measured on a sequence of
//! refined meshes, and the verdict on a seed claim (a difference between NTS and NTN) once the
//! discretisation error is known.
//!
//! Method (written once, here): the procedure of Celik et al. (2008), "Procedure for
//! estimation and reporting of uncertainty due to discretization in CFD applications", ASME J.
//! Fluids Eng. 130, 078001, on the three finest meshes with representative sizes h1 < h2 < h3
//! (finest first) and values φ1, φ2, φ3:
//! - ε21 = φ2 − φ1, ε32 = φ3 − φ2, r21 = h2/h1, r32 = h3/h2, s = sign(ε32/ε21);
//! - the observed order p solves p = (ln|ε32/ε21| + q(p)) / ln r21 with
//!   q(p) = ln((r21^p − s)/(r32^p − s)) (fixed-point iteration; q = 0 for a constant ratio);
//! - φ_ext = (r21^p φ1 − φ2)/(r21^p − 1);
//! - error band (Roache's grid convergence index with safety factor 1.25 for three meshes):
//!   GCI = 1.25 |φ1 − φ2| / (r21^p − 1), an absolute band around φ1 (Celik et al. divide by
//!   |φ1| for a relative one; ours is absolute so a value near 0 keeps a finite band).
//!
//! When the sequence is not monotone (s < 0: oscillatory) or the order is not in
//! [`MIN_ORDER`, `MAX_ORDER`], no order is claimed: φ_ext = φ1 and the band is 3 × the largest
//! change between successive meshes of the three (Roache's safety factor for an unverified
//! order). With only two meshes the same: φ_ext = φ1, band 3 |φ1 − φ2|. One mesh: no band
//! (`None`).
//!
//! Verdicts: a seed claim "NTS above NTN by x %" is **not resolved** when |φ_NTS − φ_NTN| is
//! within the combined band √(b_NTS² + b_NTN²); else **agreed** when the sign of φ_NTS − φ_NTN is
//! the claim's, **not agreed** otherwise.

use serde::{Deserialize, Serialize};

/// Safety factor of the grid convergence index with an observed order from three meshes: 1.25
/// (Roache 1998; Celik et al. 2008).
pub const SAFETY_OBSERVED: f64 = 1.25;
/// Safety factor when the order is not observed (two meshes, oscillatory or out-of-range
/// order): 3 (Roache 1998).
pub const SAFETY_UNVERIFIED: f64 = 3.0;
/// Observed orders outside [0.5, 4] are not trusted (dimensionless): below 0.5 the meshes are
/// not in the asymptotic range (or the quantity is singular: a stress at a re-entrant corner),
/// above 4 the three changes are too close to round-off or a lucky cancellation for
/// linear elements of order 1–2.
pub const MIN_ORDER: f64 = 0.5;
pub const MAX_ORDER: f64 = 4.0;

/// How the sequence behaved.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Behaviour {
    /// Monotone with an order in range: Richardson extrapolation.
    Converging,
    /// Changes of alternating sign.
    Oscillating,
    /// Monotone, order outside the trusted range.
    OrderOutOfRange,
    /// Two meshes only.
    TwoMeshes,
    /// One mesh.
    OneMesh,
}

/// The extrapolation of one quantity.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Extrapolation {
    /// The finest mesh's value φ1.
    pub finest: f64,
    /// Observed order p (only when [`Behaviour::Converging`]).
    pub order: Option<f64>,
    /// φ_ext (φ1 when no order).
    pub extrapolated: f64,
    /// Absolute error band around `finest` (the GCI); `None` with one mesh.
    pub band: Option<f64>,
    pub behaviour: Behaviour,
    /// With four meshes or more, how the three next-coarser meshes behaved (the same rule one
    /// mesh coarser; `None` with fewer): information beside the finest three's extrapolation,
    /// which it does not change. A finest triplet that converges while the coarser one
    /// oscillates (the dam's NTS 3× opening: +17, −51, −3 mm) is read as "the two finest agree
    /// to their last change", not as a verified order.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coarser: Option<Behaviour>,
}

/// Observed order, extrapolated value and error band from `(h, value)` per mesh, in any order
/// (sorted by h here; the three finest are used, and with four or more the three next-coarser
/// give [`Extrapolation::coarser`]). Sizes must be positive and distinct.
pub fn richardson(points: &[(f64, f64)]) -> Extrapolation {
    let mut p: Vec<(f64, f64)> = points.iter().copied().filter(|(h, v)| *h > 0.0 && v.is_finite()).collect();
    p.sort_by(|a, b| a.0.total_cmp(&b.0));
    p.dedup_by(|a, b| a.0 == b.0);
    let coarser = (p.len() >= 4).then(|| richardson_finest_three(&p[1..]).behaviour);
    Extrapolation { coarser, ..richardson_finest_three(&p) }
}

/// [`richardson`] on `p`, sorted finest first without repeats: the three finest only.
fn richardson_finest_three(p: &[(f64, f64)]) -> Extrapolation {
    let unverified = |phi1: f64, changes: &[f64], behaviour: Behaviour| Extrapolation {
        finest: phi1,
        order: None,
        extrapolated: phi1,
        band: Some(SAFETY_UNVERIFIED * changes.iter().fold(0.0f64, |a, c| a.max(c.abs()))),
        behaviour,
        coarser: None,
    };
    match p.len() {
        0 => Extrapolation { finest: f64::NAN, order: None, extrapolated: f64::NAN, band: None, behaviour: Behaviour::OneMesh, coarser: None },
        1 => Extrapolation { finest: p[0].1, order: None, extrapolated: p[0].1, band: None, behaviour: Behaviour::OneMesh, coarser: None },
        2 => unverified(p[0].1, &[p[1].1 - p[0].1], Behaviour::TwoMeshes),
        _ => {
            let ((h1, f1), (h2, f2), (h3, f3)) = (p[0], p[1], p[2]);
            let (e21, e32) = (f2 - f1, f3 - f2);
            if e21 == 0.0 && e32 == 0.0 {
                return Extrapolation { finest: f1, order: None, extrapolated: f1, band: Some(0.0), behaviour: Behaviour::Converging, coarser: None };
            }
            if e21 == 0.0 || e32 / e21 < 0.0 {
                return unverified(f1, &[e21, e32], Behaviour::Oscillating);
            }
            let (r21, r32) = (h2 / h1, h3 / h2);
            let ratio = (e32 / e21).abs().ln();
            // p = (ln|ε32/ε21| + q(p)) / ln r21 by fixed-point iteration from p = 1; a
            // non-positive p (the finer change larger than the coarser: diverging) ends it
            let mut order = 1.0;
            for _ in 0..200 {
                let q = ((r21.powf(order) - 1.0) / (r32.powf(order) - 1.0)).ln();
                let next = (ratio + q) / r21.ln();
                if !(next > 0.0) || !next.is_finite() {
                    order = f64::NAN;
                    break;
                }
                let done = (next - order).abs() < 1e-13 * next.max(1.0);
                order = next;
                if done {
                    break;
                }
            }
            if !(MIN_ORDER..=MAX_ORDER).contains(&order) {
                return unverified(f1, &[e21, e32], Behaviour::OrderOutOfRange);
            }
            let rp = r21.powf(order);
            Extrapolation { finest: f1, order: Some(order), extrapolated: (rp * f1 - f2) / (rp - 1.0), band: Some(SAFETY_OBSERVED * e21.abs() / (rp - 1.0)), behaviour: Behaviour::Converging, coarser: None }
        }
    }
}

/// A seed claim judged with the discretisation error.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    Agreed,
    NotAgreed,
    /// The NTS–NTN difference is within the error band (or no band is known).
    NotResolved,
}

impl Verdict {
    /// As the report writes it.
    pub fn label(self) -> &'static str {
        match self {
            Verdict::Agreed => "agreed",
            Verdict::NotAgreed => "**not agreed**",
            Verdict::NotResolved => "not resolved",
        }
    }
}

/// The verdict on the claim "`a` is above `b`" (`above` true) or below, given each value's
/// error band (`None`: unknown, so nothing is resolved).
pub fn verdict_above(a: f64, band_a: Option<f64>, b: f64, band_b: Option<f64>, above: bool) -> Verdict {
    let (Some(ba), Some(bb)) = (band_a, band_b) else { return Verdict::NotResolved };
    let d = a - b;
    if !d.is_finite() || d.abs() <= ba.hypot(bb) {
        return Verdict::NotResolved;
    }
    if (d > 0.0) == above { Verdict::Agreed } else { Verdict::NotAgreed }
}

/// The verdict on the claim "`b` is within `enough` (relative) of `a`", given each value's
/// error band (`None`: unknown, so nothing is resolved): agreed when even the band's worst case
/// keeps the difference within `enough` (|b − a| + √(b_a² + b_b²) ≤ enough |a|), not agreed
/// when even its best case leaves it beyond (|b − a| − √(…) > enough |a|), else not resolved.
pub fn verdict_close(a: f64, band_a: Option<f64>, b: f64, band_b: Option<f64>, enough: f64) -> Verdict {
    let (Some(ba), Some(bb)) = (band_a, band_b) else { return Verdict::NotResolved };
    let (d, band, limit) = ((b - a).abs(), ba.hypot(bb), enough * a.abs());
    if !(d.is_finite() && band.is_finite() && limit.is_finite()) {
        return Verdict::NotResolved;
    }
    if d + band <= limit {
        Verdict::Agreed
    } else if d - band > limit {
        Verdict::NotAgreed
    } else {
        Verdict::NotResolved
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closeness_verdicts_need_the_band_inside_or_outside_the_limit() {
        // limit 10 % of 100 = 10: difference 3 with band 5 (3-4-5) is within at worst (8 ≤ 10);
        // difference 16 with band 5 is beyond at best (11 > 10); difference 8 with band 5 neither
        assert_eq!(verdict_close(100.0, Some(3.0), 103.0, Some(4.0), 0.1), Verdict::Agreed);
        assert_eq!(verdict_close(100.0, Some(3.0), 84.0, Some(4.0), 0.1), Verdict::NotAgreed);
        assert_eq!(verdict_close(100.0, Some(3.0), 108.0, Some(4.0), 0.1), Verdict::NotResolved);
        assert_eq!(verdict_close(100.0, None, 100.0, Some(0.0), 0.1), Verdict::NotResolved);
    }

    #[test]
    fn richardson_recovers_a_known_order_and_limit() {
        // Reference: φ(h) = 10 + 3 h² sampled at h = 1, 2, 4 (and 8, ignored: the three finest
        // are used): observed order 2 and limit 10 exactly (to 1e-10); band = 1.25 |φ1 − φ2|/3
        let f = |h: f64| 10.0 + 3.0 * h * h;
        let e = richardson(&[(8.0, f(8.0)), (2.0, f(2.0)), (1.0, f(1.0)), (4.0, f(4.0))]);
        assert_eq!(e.behaviour, Behaviour::Converging);
        assert!((e.order.unwrap() - 2.0).abs() < 1e-10, "{e:?}");
        assert!((e.extrapolated - 10.0).abs() < 1e-10, "{e:?}");
        assert!((e.band.unwrap() - 1.25 * 9.0 / 3.0).abs() < 1e-10, "{e:?}");
        // the coarser three (h = 2, 4, 8) converge at the same order
        assert_eq!(e.coarser, Some(Behaviour::Converging));
        // the dam's NTS 3× largest opening [mm] (coarse 20 m to h 2.5 m): the finest three
        // converge (p ≈ 3.96, inside [0.5, 4]), the coarser three oscillate; that is recorded
        // beside the extrapolation, which it does not change
        let e = richardson(&[(20.0, 256.0), (10.0, 273.0), (5.0, 222.0), (2.5, 218.7)]);
        assert_eq!((e.behaviour, e.coarser), (Behaviour::Converging, Some(Behaviour::Oscillating)), "{e:?}");
        assert!((e.order.unwrap() - 3.95).abs() < 0.05, "{e:?}");
        assert_eq!(richardson(&[(1.0, f(1.0)), (2.0, f(2.0)), (4.0, f(4.0))]).coarser, None);
        assert!((e.extrapolated - e.finest).abs() <= e.band.unwrap());
    }

    #[test]
    fn richardson_with_unequal_ratios_solves_for_the_order() {
        // φ(h) = 5 − 2 h^1.3 at h = 1, 1.5, 3 (ratios 1.5 and 2): the fixed-point iteration
        // recovers p = 1.3 and the limit 5 (to 1e-8)
        let f = |h: f64| 5.0 - 2.0 * h.powf(1.3);
        let e = richardson(&[(1.0, f(1.0)), (1.5, f(1.5)), (3.0, f(3.0))]);
        assert!((e.order.unwrap() - 1.3).abs() < 1e-8, "{e:?}");
        assert!((e.extrapolated - 5.0).abs() < 1e-8, "{e:?}");
    }

    #[test]
    fn oscillating_and_short_sequences_claim_no_order() {
        // alternating changes (+1, −2): no order, φ_ext = φ1, band 3 × the largest change
        let e = richardson(&[(1.0, 10.0), (2.0, 11.0), (4.0, 9.0)]);
        assert_eq!((e.behaviour, e.order, e.extrapolated, e.band), (Behaviour::Oscillating, None, 10.0, Some(6.0)));
        // the finer change larger than the coarser one (diverging): out of range
        let e = richardson(&[(1.0, 10.0), (2.0, 8.0), (4.0, 7.0)]);
        assert_eq!((e.behaviour, e.band), (Behaviour::OrderOutOfRange, Some(6.0)));
        let e = richardson(&[(2.0, 4.0), (1.0, 5.0)]);
        assert_eq!((e.behaviour, e.extrapolated, e.band), (Behaviour::TwoMeshes, 5.0, Some(3.0)));
        let e = richardson(&[(1.0, 5.0)]);
        assert_eq!((e.behaviour, e.band), (Behaviour::OneMesh, None));
    }

    #[test]
    fn verdicts_need_a_difference_beyond_the_band() {
        // difference 4 against a combined band 5 (3-4-5): not resolved; against 2.5: resolved
        assert_eq!(verdict_above(104.0, Some(3.0), 100.0, Some(4.0), true), Verdict::NotResolved);
        assert_eq!(verdict_above(104.0, Some(1.5), 100.0, Some(2.0), true), Verdict::Agreed);
        assert_eq!(verdict_above(96.0, Some(1.5), 100.0, Some(2.0), true), Verdict::NotAgreed);
        assert_eq!(verdict_above(104.0, None, 100.0, Some(0.0), true), Verdict::NotResolved);
    }
}

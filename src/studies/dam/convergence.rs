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
//! With four meshes or more, the least-squares procedure of Eça & Hoekstra (2014), "A
//! procedure for the estimation of the numerical uncertainty of CFD calculations based on grid
//! refinement studies", J. Comput. Phys. 262, 104–130, uses all of them ([`least_squares`]):
//! - fits by least squares (unweighted; E&H also try weights ∝ 1/h, we do not):
//!   δ_RE: φ = φ0 + α h^p (p free), δ1: φ0 + α h, δ2: φ0 + α h², δ12: φ0 + α1 h + α2 h²; each
//!   fit's standard deviation σ = √(Σ (φ_i − fit_i)² / (n − unknowns));
//! - the observed order p of δ_RE decides: [`MIN_ORDER`] ≤ p < [`LS_MAX_ORDER`]: δ_RE with
//!   F_s = 1.25; p ≥ [`LS_MAX_ORDER`]: whichever of δ2, δ12 has the smaller σ, F_s = 1.25 (an
//!   order above the elements' cannot be credited); p < [`MIN_ORDER`]: whichever of δ1, δ2, δ12
//!   has the smallest σ, F_s = 3;
//! - with ε = |φ1 − φ0| and d = |φ1 − fit(h1)| of the chosen fit and the data range
//!   Δ_M = (max φ − min φ)/(n − 1): U = F_s ε + σ + d when σ < Δ_M (a good fit), else
//!   U = 3 σ/Δ_M (ε + σ + d);
//! - the band then used ([`Extrapolation::band`]) is the larger of the finest three's and U: a
//!   claim is resolved only when both procedures resolve it.
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
/// Least squares: observed orders at or above 2.1 are not credited (dimensionless). Linear
/// elements converge at order 2 in displacement (and 1 in stress); 2.1 leaves E&H's margin
/// for an order estimated from four noisy values.
pub const LS_MAX_ORDER: f64 = 2.1;
/// The free-order fit searches p in [0.05, 8] (dimensionless): wide enough to tell p < 0.5
/// and p ≥ 2.1 apart, which is all the rule needs outside [0.5, 2.1).
const LS_ORDER_SEARCH: (f64, f64) = (0.05, 8.0);

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
    /// Absolute error band around `finest`: the finest three's (the GCI, or 3 × the largest
    /// change without an order), with four meshes or more the larger of that and the
    /// least-squares U ([`Extrapolation::least_squares`]); `None` with one mesh.
    pub band: Option<f64>,
    pub behaviour: Behaviour,
    /// With four meshes or more, how the three next-coarser meshes behaved (the same rule one
    /// mesh coarser; `None` with fewer): information beside the finest three's extrapolation,
    /// which it does not change. A finest triplet that converges while the coarser one
    /// oscillates (the dam's NTS 3× opening: +17, −51, −3 mm) is read as "the two finest agree
    /// to their last change", not as a verified order.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coarser: Option<Behaviour>,
    /// With four meshes or more, the least-squares estimate over all of them ([`least_squares`]);
    /// `band` is then the larger of its uncertainty and the finest three's band.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub least_squares: Option<LeastSquares>,
}

/// Which least-squares fit an uncertainty came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Fit {
    /// φ0 + α h^p, p free.
    FreeOrder,
    /// φ0 + α h.
    First,
    /// φ0 + α h².
    Second,
    /// φ0 + α1 h + α2 h².
    FirstAndSecond,
}

impl Fit {
    /// As the report writes it.
    pub fn label(self) -> &'static str {
        match self {
            Fit::FreeOrder => "α h^p",
            Fit::First => "α h",
            Fit::Second => "α h²",
            Fit::FirstAndSecond => "α1 h + α2 h²",
        }
    }
}

/// The least-squares estimate of Eça & Hoekstra (2014) over four meshes or more.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LeastSquares {
    /// The free-order fit's p (searched in [0.05, 8]; at a bound it means "below" or "above").
    pub order: f64,
    /// The fit the uncertainty came from.
    pub fit: Fit,
    /// Its φ0.
    pub extrapolated: f64,
    /// Its standard deviation σ.
    pub sigma: f64,
    /// The data range Δ_M = (max φ − min φ)/(n − 1).
    pub data_range: f64,
    /// The safety factor F_s (1.25 or 3).
    pub safety: f64,
    /// U, an absolute band around the finest mesh's value.
    pub uncertainty: f64,
    /// The finest three's band (Celik), kept since `band` is the larger of the two.
    pub finest_three_band: Option<f64>,
}

impl LeastSquares {
    /// The free order as the report writes it: "p = 1.52", or "p ≤ 0.05" / "p ≥ 8" at the
    /// search's bounds (the sum of squares still falling there).
    pub fn order_text(&self) -> String {
        let (lo, hi) = LS_ORDER_SEARCH;
        if self.order <= lo * 1.001 {
            format!("p ≤ {lo}")
        } else if self.order >= hi * 0.999 {
            format!("p ≥ {hi}")
        } else {
            format!("p = {:.3}", self.order)
        }
    }
}

/// Observed order, extrapolated value and error band from `(h, value)` per mesh, in any order
/// (sorted by h here; the three finest are used, and with four or more the three next-coarser
/// give [`Extrapolation::coarser`]). Sizes must be positive and distinct.
pub fn richardson(points: &[(f64, f64)]) -> Extrapolation {
    let mut p: Vec<(f64, f64)> = points.iter().copied().filter(|(h, v)| *h > 0.0 && v.is_finite()).collect();
    p.sort_by(|a, b| a.0.total_cmp(&b.0));
    p.dedup_by(|a, b| a.0 == b.0);
    let three = richardson_finest_three(&p);
    let Some(ls) = least_squares(&p) else { return three };
    let band = three.band.map(|b| b.max(ls.uncertainty));
    let coarser = Some(richardson_finest_three(&p[1..]).behaviour);
    Extrapolation { coarser, band, least_squares: Some(LeastSquares { finest_three_band: three.band, ..ls }), ..three }
}

/// One least-squares fit φ0 + Σ α_k h^{q_k} ([`fit_powers`]).
struct Fitted {
    phi0: f64,
    /// The fit at the finest mesh.
    at_finest: f64,
    /// σ = √(Σ residual² / (n − unknowns)), and Σ residual².
    sigma: f64,
    sse: f64,
}

/// The least-squares fit φ0 + Σ α_k h^{q_k} of `p`; `None` with fewer values than unknowns + 1
/// (no σ) or a singular system.
fn fit_powers(p: &[(f64, f64)], powers: &[f64]) -> Option<Fitted> {
    let (n, k) = (p.len(), powers.len() + 1);
    if n <= k {
        return None;
    }
    // h scaled by the finest (the fit is invariant to it; the columns stay of order 1..8^q)
    let h0 = p[0].0;
    let a = nalgebra::DMatrix::from_fn(n, k, |i, j| if j == 0 { 1.0 } else { (p[i].0 / h0).powf(powers[j - 1]) });
    let b = nalgebra::DVector::from_iterator(n, p.iter().map(|x| x.1));
    let c = a.clone().svd(true, true).solve(&b, 1e-13).ok()?;
    let fitted = &a * &c;
    let sse: f64 = (0..n).map(|i| (b[i] - fitted[i]).powi(2)).sum();
    c.iter().all(|x| x.is_finite()).then(|| Fitted { phi0: c[0], at_finest: fitted[0], sigma: (sse / (n - k) as f64).sqrt(), sse })
}

/// The free-order fit's p: the least Σ residual² over p in [`LS_ORDER_SEARCH`] (a scan of 400
/// log-spaced orders, then golden-section search around the best).
fn free_order(p: &[(f64, f64)]) -> f64 {
    let sse = |q: f64| fit_powers(p, &[q]).map_or(f64::INFINITY, |f| f.sse);
    let (lo, hi) = (LS_ORDER_SEARCH.0.ln(), LS_ORDER_SEARCH.1.ln());
    const SCAN: usize = 400;
    let at = |i: usize| (lo + (hi - lo) * i as f64 / SCAN as f64).exp();
    let best = (0..=SCAN).map(|i| (i, sse(at(i)))).min_by(|a, b| a.1.total_cmp(&b.1)).map_or(0, |(i, _)| i);
    let (mut a, mut b) = (at(best.saturating_sub(1)), at((best + 1).min(SCAN)));
    let g = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..60 {
        let (c, d) = (b - g * (b - a), a + g * (b - a));
        if sse(c) <= sse(d) { b = d } else { a = c }
    }
    0.5 * (a + b)
}

/// The least-squares uncertainty of Eça & Hoekstra (2014) from `p` (sorted finest first,
/// distinct sizes); `None` with fewer than four meshes (the h + h² fit then has no σ);
/// `finest_three_band` is left `None` for the caller.
pub fn least_squares(p: &[(f64, f64)]) -> Option<LeastSquares> {
    if p.len() < 4 {
        return None;
    }
    let phi1 = p[0].1;
    let (lo, hi) = p.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| (l.min(x.1), h.max(x.1)));
    let data_range = (hi - lo) / (p.len() - 1) as f64;
    let order = free_order(p);
    let candidates: &[(Fit, &[f64])] = if order < MIN_ORDER {
        &[(Fit::First, &[1.0]), (Fit::Second, &[2.0]), (Fit::FirstAndSecond, &[1.0, 2.0])]
    } else if order >= LS_MAX_ORDER {
        &[(Fit::Second, &[2.0]), (Fit::FirstAndSecond, &[1.0, 2.0])]
    } else {
        &[(Fit::FreeOrder, &[order])]
    };
    let safety = if order < MIN_ORDER { SAFETY_UNVERIFIED } else { SAFETY_OBSERVED };
    let chosen = candidates
        .iter()
        .filter_map(|&(fit, q)| fit_powers(p, q).map(|f| (fit, f)))
        .min_by(|a, b| a.1.sigma.total_cmp(&b.1.sigma));
    let Some((fit, Fitted { phi0, at_finest: at1, sigma, .. })) = chosen else {
        // unreachable with four distinct sizes; kept as the unverified rule, not a panic
        return Some(LeastSquares { order, fit: Fit::FreeOrder, extrapolated: phi1, sigma: f64::NAN, data_range, safety: SAFETY_UNVERIFIED, uncertainty: SAFETY_UNVERIFIED * (hi - lo), finest_three_band: None });
    };
    let (eps, dev) = ((phi1 - phi0).abs(), (phi1 - at1).abs());
    let uncertainty = if data_range == 0.0 {
        0.0 // every mesh gave the same value (σ is then round-off)
    } else if sigma < data_range {
        safety * eps + sigma + dev
    } else {
        3.0 * sigma / data_range * (eps + sigma + dev)
    };
    Some(LeastSquares { order, fit, extrapolated: phi0, sigma, data_range, safety, uncertainty, finest_three_band: None })
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
        least_squares: None,
    };
    match p.len() {
        0 => Extrapolation { finest: f64::NAN, order: None, extrapolated: f64::NAN, band: None, behaviour: Behaviour::OneMesh, coarser: None, least_squares: None },
        1 => Extrapolation { finest: p[0].1, order: None, extrapolated: p[0].1, band: None, behaviour: Behaviour::OneMesh, coarser: None, least_squares: None },
        2 => unverified(p[0].1, &[p[1].1 - p[0].1], Behaviour::TwoMeshes),
        _ => {
            let ((h1, f1), (h2, f2), (h3, f3)) = (p[0], p[1], p[2]);
            let (e21, e32) = (f2 - f1, f3 - f2);
            if e21 == 0.0 && e32 == 0.0 {
                return Extrapolation { finest: f1, order: None, extrapolated: f1, band: Some(0.0), behaviour: Behaviour::Converging, coarser: None, least_squares: None };
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
            Extrapolation { finest: f1, order: Some(order), extrapolated: (rp * f1 - f2) / (rp - 1.0), band: Some(SAFETY_OBSERVED * e21.abs() / (rp - 1.0)), behaviour: Behaviour::Converging, coarser: None, least_squares: None }
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
    fn least_squares_recovers_a_free_order_and_its_limit() {
        // Reference: φ(h) = 10 + 3 h^1.5 at h = 1, 2, 4, 8 (Eça & Hoekstra 2014, exact data):
        // the free-order fit has p = 1.5 and φ0 = 10 (to 1e-6, the order search's precision),
        // σ ≈ 0, so U = 1.25 |φ1 − φ0| = 3.75; the band is the larger of U and the finest
        // three's GCI, equal here (both 1.25 times the true error)
        let f = |h: f64| 10.0 + 3.0 * h.powf(1.5);
        let e = richardson(&[(1.0, f(1.0)), (2.0, f(2.0)), (4.0, f(4.0)), (8.0, f(8.0))]);
        let ls = e.least_squares.clone().unwrap();
        assert_eq!((ls.fit, ls.safety), (Fit::FreeOrder, SAFETY_OBSERVED), "{ls:?}");
        assert!((ls.order - 1.5).abs() < 1e-6 && (ls.extrapolated - 10.0).abs() < 1e-6 && ls.sigma < 1e-6, "{ls:?}");
        assert!((ls.uncertainty - 3.75).abs() < 1e-5, "{ls:?}");
        assert!((e.band.unwrap() - 3.75).abs() < 1e-5 && (ls.finest_three_band.unwrap() - 3.75).abs() < 1e-8, "{e:?}");
    }

    #[test]
    fn least_squares_credits_no_order_outside_its_range() {
        // φ = 10 + h³ at h = 1, 2, 4, 8: the free order is 3 (≥ 2.1), so only the fits with h²
        // may serve, with F_s = 1.25; they cannot follow h³ (σ ≥ 1), so U (58, from the same
        // rule in numpy) must cover the true error |φ1 − 10| = 1 many times
        let f = |h: f64| 10.0 + h.powi(3);
        let ls = least_squares(&[(1.0, f(1.0)), (2.0, f(2.0)), (4.0, f(4.0)), (8.0, f(8.0))]).unwrap();
        assert!((ls.order - 3.0).abs() < 1e-3 && ls.safety == SAFETY_OBSERVED, "{ls:?}");
        assert!(matches!(ls.fit, Fit::Second | Fit::FirstAndSecond) && ls.uncertainty > 10.0, "{ls:?}");
        // the dam's NTS 3× largest opening [mm], coarse 20 m to h 2.5 m: not monotone, so the
        // free order falls below 0.5 and the fixed-order fits serve with F_s = 3; the coarse-to-
        // default reversal leaves σ = 16.8 mm against a data range of 18.1 mm, and U = 138 mm
        // (63 % of φ1; numpy, the same rule, to 0.1 %) is the band, not the finest three's 0.28
        let e = richardson(&[(20.0, 256.0), (10.0, 273.0), (5.0, 222.0), (2.5, 218.7)]);
        let ls = e.least_squares.clone().unwrap();
        assert!(ls.order < MIN_ORDER && ls.safety == SAFETY_UNVERIFIED && ls.fit == Fit::FirstAndSecond, "{ls:?}");
        assert!((ls.sigma - 16.846).abs() < 0.02 && (ls.data_range - 18.1).abs() < 1e-9, "{ls:?}");
        assert!((ls.uncertainty / 138.30 - 1.0).abs() < 1e-3 && e.band == Some(ls.uncertainty), "{e:?}");
        assert!(ls.finest_three_band.unwrap() < 0.3, "{ls:?}");
        // constant values: no uncertainty
        let ls = least_squares(&[(1.0, 5.0), (2.0, 5.0), (4.0, 5.0), (8.0, 5.0)]).unwrap();
        assert_eq!(ls.uncertainty, 0.0, "{ls:?}");
        // fewer than four meshes (or none): no least-squares estimate, no panic
        assert_eq!(least_squares(&[(1.0, 5.0), (2.0, 6.0), (4.0, 8.0)]), None);
        assert_eq!(least_squares(&[]), None);
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

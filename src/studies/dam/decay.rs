//! A mode's frequency and damping from a free-vibration decay (issue 29: "f1 and the first
//! mode's damping of the dam on the radiating rock"; docs/dam_physics.md §4).
//!
//! Method: after a pulse has passed, a history u(t) (the crest's antisymmetric radial motion,
//! say) is fitted in the least-squares sense by a constant plus `modes` damped cosines,
//! u ≈ c + Σ_k e^{−ξ_k ω_k τ} (a_k cos ω_dk τ + b_k sin ω_dk τ), τ = t − t0, ω_dk = ω_k √(1 − ξ_k²),
//! f_k = ω_k / 2π. The amplitudes enter linearly and are solved for exactly at every trial
//! (f_k, ξ_k) (variable projection); the nonlinear pair of each mode is found by a grid search
//! refined three times, one mode at a time with the others held, twice round. The first
//! frequency's start is the largest peak of the window's discrete Fourier amplitude in the band
//! given; the second mode's, the largest peak of what the first leaves. This is the logarithmic
//! decrement done on the whole window at once: it uses every sample, not only the peaks, and
//! a second mode (the next antisymmetric one) is fitted rather than left to bias the first.
//!
//! Units: t [s], u any; f [Hz]; ξ the fraction of critical damping.

use nalgebra::{DMatrix, DVector};

/// One fitted mode.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct DecayMode {
    /// Undamped natural frequency f = ω / 2π [Hz].
    pub frequency: f64,
    /// Damping ratio ξ [-].
    pub damping: f64,
    /// Amplitude √(a² + b²) at t0 [units of u].
    pub amplitude: f64,
}

/// The fit of a window (module doc).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct DecayFit {
    /// The modes, the one of largest amplitude first.
    pub modes: Vec<DecayMode>,
    /// RMS of the residual over the RMS of the signal (both about the window's mean) [-].
    pub residual: f64,
    /// Start and end of the window [s].
    pub t0: f64,
    pub t1: f64,
}

/// Largest damping ratio searched. Default 0.5: a radiating rock gives a few to 20 per cent,
/// and a fit at this bound is reported as such (the window then holds too few cycles).
pub const DAMPING_MAX: f64 = 0.5;

/// Most samples of the window the fit uses (evenly strided). Default 800: over a 3 s window,
/// 267 samples a second, 50 per period of a 5 Hz mode.
pub const MAX_SAMPLES: usize = 800;

/// Fit `modes` (1 or 2) damped modes to u(t) over t ≥ `t0`, the first searched in [f_lo, f_hi]
/// [Hz]. `None` when the window holds fewer than 16 samples or less than one period of f_lo
/// (too short to tell a frequency).
pub fn fit_free_decay(t: &[f64], u: &[f64], t0: f64, f_lo: f64, f_hi: f64, modes: usize) -> Option<DecayFit> {
    let all: Vec<usize> = (0..t.len().min(u.len())).filter(|&i| t[i] >= t0 && u[i].is_finite()).collect();
    // at most MAX_SAMPLES samples: the modes fitted lie below a few Hz, and a history row every
    // millisecond over seconds would make each trial of the search cost thousands of rows
    let stride = all.len().div_ceil(MAX_SAMPLES).max(1);
    let idx: Vec<usize> = all.into_iter().step_by(stride).collect();
    if idx.len() < 16 || !(f_lo > 0.0 && f_hi > f_lo) {
        return None;
    }
    let tau: Vec<f64> = idx.iter().map(|&i| t[i] - t0).collect();
    let y: Vec<f64> = idx.iter().map(|&i| u[i]).collect();
    let span = *tau.last()?;
    if span * f_lo < 1.0 {
        return None;
    }
    let mean = y.iter().sum::<f64>() / y.len() as f64;
    let rms = (y.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / y.len() as f64).sqrt();
    if !(rms > 0.0) {
        return None;
    }
    let modes = modes.clamp(1, 2);
    let mut pars: Vec<(f64, f64)> = vec![(dft_peak(&tau, &y, f_lo, f_hi), 0.02)];
    if modes == 2 {
        let (_, r) = solve(&tau, &y, &pars);
        let f1 = pars[0].0;
        pars.push((dft_peak(&tau, &r, 1.2 * f1, 4.0 * f1), 0.02));
    }
    for _round in 0..2 {
        for k in 0..pars.len() {
            let (lo, hi) = if k == 0 { (f_lo, f_hi) } else { (1.05 * pars[0].0, 6.0 * pars[0].0) };
            pars[k] = refine(&tau, &y, &pars, k, lo, hi);
        }
    }
    let (coef, r) = solve(&tau, &y, &pars);
    let res = (r.iter().map(|v| v * v).sum::<f64>() / r.len() as f64).sqrt() / rms;
    let mut out: Vec<DecayMode> = pars
        .iter()
        .enumerate()
        .map(|(k, &(f, xi))| DecayMode { frequency: f, damping: xi, amplitude: coef[1 + 2 * k].hypot(coef[2 + 2 * k]) })
        .collect();
    out.sort_by(|a, b| b.amplitude.total_cmp(&a.amplitude));
    Some(DecayFit { modes: out, residual: res, t0, t1: t0 + span })
}

/// Frequency [Hz] of the largest |Σ y e^{−iωτ}| on a grid of 400 points in [lo, hi].
fn dft_peak(tau: &[f64], y: &[f64], lo: f64, hi: f64) -> f64 {
    let mean = y.iter().sum::<f64>() / y.len() as f64;
    let n = 400;
    let mut best = (lo, -1.0);
    for j in 0..=n {
        let f = lo + (hi - lo) * j as f64 / n as f64;
        let w = 2.0 * std::f64::consts::PI * f;
        let (mut c, mut s) = (0.0, 0.0);
        for (&t, &v) in tau.iter().zip(y) {
            c += (v - mean) * (w * t).cos();
            s += (v - mean) * (w * t).sin();
        }
        let a = c.hypot(s);
        if a > best.1 {
            best = (f, a);
        }
    }
    best.0
}

/// Mode `k`'s (f, ξ) by a grid search in [lo, hi] × [0, DAMPING_MAX] refined three times about
/// the best point, the other modes held.
fn refine(tau: &[f64], y: &[f64], pars: &[(f64, f64)], k: usize, lo: f64, hi: f64) -> (f64, f64) {
    let mut p = pars.to_vec();
    let (mut f_lo, mut f_hi) = ((p[k].0 * 0.8).max(lo), (p[k].0 * 1.2).min(hi));
    let (mut x_lo, mut x_hi) = (0.0, DAMPING_MAX);
    let mut best = (p[k], f64::INFINITY);
    for _ in 0..4 {
        let n = 16;
        for i in 0..=n {
            for j in 0..=n {
                let f = f_lo + (f_hi - f_lo) * i as f64 / n as f64;
                let xi = x_lo + (x_hi - x_lo) * j as f64 / n as f64;
                p[k] = (f, xi);
                let (_, r) = solve(tau, y, &p);
                let e: f64 = r.iter().map(|v| v * v).sum();
                if e < best.1 {
                    best = ((f, xi), e);
                }
            }
        }
        let (df, dx) = (2.0 * (f_hi - f_lo) / n as f64, 2.0 * (x_hi - x_lo) / n as f64);
        f_lo = (best.0.0 - df).max(lo);
        f_hi = (best.0.0 + df).min(hi);
        x_lo = (best.0.1 - dx).max(0.0);
        x_hi = (best.0.1 + dx).min(DAMPING_MAX);
    }
    best.0
}

/// Least-squares amplitudes (c, a_1, b_1, …) of the modes `pars` and the residual y − fit.
fn solve(tau: &[f64], y: &[f64], pars: &[(f64, f64)]) -> (Vec<f64>, Vec<f64>) {
    let m = 1 + 2 * pars.len();
    let mut a = DMatrix::<f64>::zeros(tau.len(), m);
    for (i, &t) in tau.iter().enumerate() {
        a[(i, 0)] = 1.0;
        for (k, &(f, xi)) in pars.iter().enumerate() {
            let w = 2.0 * std::f64::consts::PI * f;
            let wd = w * (1.0 - xi * xi).max(0.0).sqrt();
            let e = (-xi * w * t).exp();
            a[(i, 1 + 2 * k)] = e * (wd * t).cos();
            a[(i, 2 + 2 * k)] = e * (wd * t).sin();
        }
    }
    // normal equations (m ≤ 5 columns; the columns are scaled alike, well apart in frequency)
    let b = DVector::from_column_slice(y);
    let ata = a.transpose() * &a;
    let atb = a.transpose() * &b;
    let coef: Vec<f64> = ata.lu().solve(&atb).map(|c| c.iter().copied().collect()).unwrap_or_else(|| vec![0.0; m]);
    let fit = &a * DVector::from_column_slice(&coef);
    let r = y.iter().zip(fit.iter()).map(|(v, f)| v - f).collect();
    (coef, r)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reference: a synthetic signal of two damped modes (1.2 Hz at 4 %, 2.9 Hz at 10 %, the
    /// second half as large) plus an offset, sampled at 1 ms over 3 s: the fit returns the first
    /// mode's frequency within 0.5 % and its damping within 0.005 (absolute), residual < 1 %.
    #[test]
    fn two_damped_modes_are_recovered_from_their_sum() {
        let (f1, x1, f2, x2) = (1.2, 0.04, 2.9, 0.10);
        let t: Vec<f64> = (0..3000).map(|i| i as f64 * 1e-3).collect();
        let m = |f: f64, x: f64, a: f64, t: f64| {
            let w = 2.0 * std::f64::consts::PI * f;
            a * (-x * w * t).exp() * (w * (1.0 - x * x).sqrt() * t + 0.3).cos()
        };
        let u: Vec<f64> = t.iter().map(|&t| 0.01 + m(f1, x1, 1.0, t) + m(f2, x2, 0.5, t)).collect();
        let fit = fit_free_decay(&t, &u, 0.0, 0.5, 2.0, 2).unwrap();
        let first = fit.modes[0];
        assert!((first.frequency / f1 - 1.0).abs() < 0.005, "{fit:?}");
        assert!((first.damping - x1).abs() < 0.005, "{fit:?}");
        assert!(fit.residual < 0.01, "{fit:?}");
    }
}

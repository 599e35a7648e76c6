//! Integration of an acceleration record and its intensity measures: PGA, PGV, PGD, Arias
//! intensity, significant duration D5–95 and the predominant period.
//!
//! Integration is exact for an acceleration linear between samples, from rest:
//! v[i+1] = v[i] + (a[i] + a[i+1]) dt/2, d[i+1] = d[i] + v[i] dt + (2a[i] + a[i+1]) dt²/6.
//! Measures are of the record as given (no correction is applied here; see [`super::baseline`]).

use serde::Serialize;

/// Velocity [m/s] and displacement [m] of `accel` [m/s²], from rest.
pub fn integrate(accel: &[f64], dt: f64) -> (Vec<f64>, Vec<f64>) {
    let n = accel.len();
    let mut v = vec![0.0; n];
    let mut d = vec![0.0; n];
    for i in 1..n {
        let (a0, a1) = (accel[i - 1], accel[i]);
        v[i] = v[i - 1] + 0.5 * (a0 + a1) * dt;
        d[i] = d[i - 1] + v[i - 1] * dt + (2.0 * a0 + a1) * dt * dt / 6.0;
    }
    (v, d)
}

/// Intensity measures of one record (SI unless the name says g).
#[derive(Clone, Debug, Serialize)]
pub struct IntensityMeasures {
    /// Peak ground acceleration [g] and its time [s].
    pub pga_g: f64,
    pub t_pga: f64,
    /// Peak ground velocity [m/s] and displacement [m] (of the record as given, from rest).
    pub pgv: f64,
    pub pgd: f64,
    /// Arias intensity I_a = π/(2g) ∫ a² dt [m/s].
    pub arias: f64,
    /// Times at 5 % and 95 % of I_a [s] and the significant duration D5–95 = t95 − t5 [s].
    pub t5: f64,
    pub t95: f64,
    pub d5_95: f64,
    /// Period of the largest 5 % PSA on the given grid [s] (resolution: the grid's spacing).
    pub predominant_period: f64,
    /// Velocity [m/s] and displacement [m] at the last sample: the drift the record carries.
    pub v_end: f64,
    pub d_end: f64,
}

/// Measures of `accel` [m/s²] at `dt` [s], first sample at `t0` [s]; `g` [m/s²] converts to g;
/// `periods` and `psa` (same length, PSA in m/s²) give the predominant period.
pub fn intensity_measures(accel: &[f64], dt: f64, t0: f64, g: f64, periods: &[f64], psa: &[f64]) -> IntensityMeasures {
    let (v, d) = integrate(accel, dt);
    let (mut ipk, mut pk) = (0usize, 0.0f64);
    for (i, a) in accel.iter().enumerate() {
        if a.abs() > pk {
            pk = a.abs();
            ipk = i;
        }
    }
    let absmax = |x: &[f64]| x.iter().fold(0.0f64, |m, y| m.max(y.abs()));
    // cumulative ∫ a² dt, exact for linear a: (a0² + a0 a1 + a1²) dt / 3
    let n = accel.len();
    let mut cum = vec![0.0; n];
    for i in 1..n {
        let (a0, a1) = (accel[i - 1], accel[i]);
        cum[i] = cum[i - 1] + (a0 * a0 + a0 * a1 + a1 * a1) * dt / 3.0;
    }
    let total = cum.last().copied().unwrap_or(0.0);
    let cross = |frac: f64| -> f64 {
        let target = frac * total;
        for i in 1..n {
            if cum[i] >= target {
                let span = cum[i] - cum[i - 1];
                let f = if span > 0.0 { (target - cum[i - 1]) / span } else { 0.0 };
                return t0 + (i as f64 - 1.0 + f) * dt;
            }
        }
        t0 + (n.saturating_sub(1)) as f64 * dt
    };
    let (t5, t95) = if total > 0.0 { (cross(0.05), cross(0.95)) } else { (t0, t0) };
    let mut tp = periods.first().copied().unwrap_or(f64::NAN);
    let mut best = f64::NEG_INFINITY;
    for (&t, &s) in periods.iter().zip(psa) {
        if s > best {
            best = s;
            tp = t;
        }
    }
    IntensityMeasures {
        pga_g: pk / g,
        t_pga: t0 + ipk as f64 * dt,
        pgv: absmax(&v),
        pgd: absmax(&d),
        arias: std::f64::consts::PI / (2.0 * g) * total,
        t5,
        t95,
        d5_95: t95 - t5,
        predominant_period: tp,
        v_end: v.last().copied().unwrap_or(0.0),
        d_end: d.last().copied().unwrap_or(0.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integration_is_exact_for_linear_acceleration() {
        // a = 1 + 2t: v = t + t², d = t²/2 + t³/3
        let dt = 0.1;
        let a: Vec<f64> = (0..11).map(|i| 1.0 + 2.0 * i as f64 * dt).collect();
        let (v, d) = integrate(&a, dt);
        let t = 1.0;
        assert!((v[10] - (t + t * t)).abs() < 1e-13);
        assert!((d[10] - (t * t / 2.0 + t * t * t / 3.0)).abs() < 1e-13);
    }

    #[test]
    fn arias_of_a_sine() {
        // a = A sin(2π t / T) over whole periods: ∫a² = A² D / 2 (to the linear-interpolation
        // error, (ω dt)²/12 relative ≈ 3e-4 here)
        let (amp, dt, per) = (2.0, 0.005, 0.5);
        let a: Vec<f64> = (0..=4000).map(|i| amp * (std::f64::consts::TAU * i as f64 * dt / per).sin()).collect();
        let m = intensity_measures(&a, dt, 0.0, 9.81, &[per], &[1.0]);
        let exact = std::f64::consts::PI / (2.0 * 9.81) * amp * amp * 20.0 / 2.0;
        assert!((m.arias / exact - 1.0).abs() < 1e-3, "{} {}", m.arias, exact);
        // stationary: D5-95 = 0.9 of the duration
        assert!((m.d5_95 - 18.0).abs() < 0.01, "{}", m.d5_95);
    }
}

//! Baseline correction of acceleration records, applied only when asked (a scene's
//! `loads.base[].baseline`, `record correct`, the synthesis), never silently.
//!
//! Methods:
//! - `mean`: subtract the mean acceleration (removes a constant offset; the velocity may still
//!   drift linearly in what the offset hid).
//! - `polynomial` (default degree 5): subtract from the acceleration the second derivative of a
//!   polynomial Σ c_k t^k, k = 2…degree, whose displacement is the least-squares fit of the
//!   record's displacement under the constraint that the corrected velocity and displacement are
//!   zero at the last sample. The polynomial's displacement is integrated with the same exact
//!   rule as the record's ([`super::measures::integrate`]), so a drift in the span of the basis
//!   is removed to round-off, and the correction of an already corrected record is zero.
//! - `highpass`: zero-phase (acausal) Butterworth high-pass of the stated order and corner
//!   [Hz]: the spectrum is multiplied by |H|² = 1 / (1 + (f_c/f)^(2n)), which is what a
//!   forward–backward pass of an order-n Butterworth filter does, on the record padded with
//!   zeros by 1.5 n / f_c seconds in all (Boore & Bommer 2005, Soil Dyn. Earthq. Eng. 25) to
//!   avoid wrap-around. The record's own window is kept; the residual drift is reported.

use super::MotionError;
use super::measures::integrate;
use nalgebra::{DMatrix, DVector};
use rustfft::FftPlannerScalar;
use rustfft::num_complex::Complex;
use serde::{Deserialize, Serialize};

/// A baseline correction, as a scene or the CLI names it.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(tag = "method", rename_all = "lowercase", deny_unknown_fields)]
pub enum Baseline {
    Mean,
    Polynomial {
        /// Highest power of t in the displacement fit (3…10). Default 5.
        #[serde(default = "default_degree")]
        degree: usize,
    },
    #[serde(rename = "highpass")]
    HighPass {
        /// Corner frequency [Hz], > 0 and below the Nyquist frequency.
        corner: f64,
        /// Butterworth order n (1…8), |H|² = 1/(1 + (f_c/f)^(2n)). Default 4.
        #[serde(default = "default_order")]
        order: u32,
    },
}

fn default_degree() -> usize {
    5
}
fn default_order() -> u32 {
    4
}

impl Baseline {
    /// One line saying what the correction is, for notes and file headers.
    pub fn describe(&self) -> String {
        match self {
            Baseline::Mean => "mean removal".into(),
            Baseline::Polynomial { degree } => format!("polynomial displacement fit t^2..t^{degree}, zero end velocity and displacement"),
            Baseline::HighPass { corner, order } => format!("zero-phase Butterworth high-pass, corner {corner} Hz, order {order}"),
        }
    }

    /// Check the parameters against the record's sampling `dt` [s].
    pub fn check(&self, dt: f64) -> Result<(), MotionError> {
        match *self {
            Baseline::Mean => Ok(()),
            Baseline::Polynomial { degree } => {
                if !(3..=10).contains(&degree) {
                    return Err(MotionError::invalid("baseline.degree", format!("{degree} must be in 3..=10 (two coefficients meet the end conditions, the rest fit the displacement)")));
                }
                Ok(())
            }
            Baseline::HighPass { corner, order } => {
                let nyq = 0.5 / dt;
                if !(corner > 0.0 && corner < nyq) {
                    return Err(MotionError::invalid("baseline.corner", format!("{corner} Hz must be positive and below the Nyquist frequency {nyq} Hz (typical: 0.05–0.1 Hz)")));
                }
                if !(1..=8).contains(&order) {
                    return Err(MotionError::invalid("baseline.order", format!("{order} must be in 1..=8")));
                }
                Ok(())
            }
        }
    }
}

/// What a record leaves after double integration from rest.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Drift {
    /// Velocity [m/s] and displacement [m] at the last sample.
    pub v_end: f64,
    pub d_end: f64,
    /// Largest |displacement| [m] over the record.
    pub d_max: f64,
}

impl Drift {
    pub fn describe(&self) -> String {
        format!("end velocity {:.4e} m/s, end displacement {:.4e} m (peak displacement {:.4e} m)", self.v_end, self.d_end, self.d_max)
    }
}

/// The drift of `accel` [m/s²] at `dt` [s].
pub fn drift(accel: &[f64], dt: f64) -> Drift {
    let (v, d) = integrate(accel, dt);
    Drift { v_end: v.last().copied().unwrap_or(0.0), d_end: d.last().copied().unwrap_or(0.0), d_max: d.iter().fold(0.0f64, |m, x| m.max(x.abs())) }
}

/// The corrected acceleration [m/s²].
pub fn correct(accel: &[f64], dt: f64, method: &Baseline) -> Result<Vec<f64>, MotionError> {
    method.check(dt)?;
    if accel.len() < 4 {
        return Err(MotionError::invalid("record", format!("{} samples: a baseline correction needs at least 4", accel.len())));
    }
    match *method {
        Baseline::Mean => {
            let m = accel.iter().sum::<f64>() / accel.len() as f64;
            Ok(accel.iter().map(|a| a - m).collect())
        }
        Baseline::Polynomial { degree } => polynomial(accel, dt, degree),
        Baseline::HighPass { corner, order } => Ok(highpass(accel, dt, corner, order)),
    }
}

fn polynomial(accel: &[f64], dt: f64, degree: usize) -> Result<Vec<f64>, MotionError> {
    let n = accel.len();
    let tend = dt * (n - 1) as f64;
    let nb = degree - 1; // powers 2..=degree
    // acceleration basis ψ_k = d²/dt² (t/T)^k, sampled; its exact displacement φ_k
    let mut psi = Vec::with_capacity(nb);
    let mut phi = Vec::with_capacity(nb);
    let mut vend = Vec::with_capacity(nb);
    for k in 2..=degree {
        let kk = (k * (k - 1)) as f64 / (tend * tend);
        let p: Vec<f64> = (0..n).map(|i| kk * (i as f64 / (n - 1) as f64).powi(k as i32 - 2)).collect();
        let (v, d) = integrate(&p, dt);
        vend.push(*v.last().unwrap());
        psi.push(p);
        phi.push(d);
    }
    let (v, d) = integrate(accel, dt);
    // KKT: [ΦᵀΦ Gᵀ; G 0] [c; λ] = [Φᵀd; g], G = rows (v_end, d_end) of the basis
    let m = nb + 2;
    let mut a = DMatrix::<f64>::zeros(m, m);
    let mut b = DVector::<f64>::zeros(m);
    for i in 0..nb {
        for j in 0..=i {
            let s: f64 = phi[i].iter().zip(&phi[j]).map(|(x, y)| x * y).sum();
            a[(i, j)] = s;
            a[(j, i)] = s;
        }
        b[i] = phi[i].iter().zip(&d).map(|(x, y)| x * y).sum();
        a[(nb, i)] = vend[i];
        a[(i, nb)] = vend[i];
        a[(nb + 1, i)] = *phi[i].last().unwrap();
        a[(i, nb + 1)] = *phi[i].last().unwrap();
    }
    b[nb] = *v.last().unwrap();
    b[nb + 1] = *d.last().unwrap();
    // scale rows/columns for conditioning (equilibration)
    let s: Vec<f64> = (0..m).map(|i| 1.0 / a[(i, i)].abs().max(a.row(i).amax()).max(1e-300).sqrt()).collect();
    let mut as_ = a.clone();
    for i in 0..m {
        for j in 0..m {
            as_[(i, j)] *= s[i] * s[j];
        }
    }
    let bs = DVector::from_iterator(m, (0..m).map(|i| b[i] * s[i]));
    let x = as_.lu().solve(&bs).ok_or_else(|| MotionError::invalid("baseline.degree", format!("the polynomial fit of degree {degree} is singular for this record ({n} samples); use a lower degree")))?;
    let mut out = accel.to_vec();
    for k in 0..nb {
        let c = x[k] * s[k];
        for (o, p) in out.iter_mut().zip(&psi[k]) {
            *o -= c * p;
        }
    }
    Ok(out)
}

fn highpass(accel: &[f64], dt: f64, corner: f64, order: u32) -> Vec<f64> {
    let (pad, full) = highpass_padded(accel, dt, corner, order);
    full[pad..pad + accel.len()].to_vec()
}

/// The zero-phase high-pass of `accel` with its padding kept (Boore 2005: the acausal filter's
/// response before t = 0 and after the end belongs to the filtered record; cutting it off leaves
/// the drift that [`correct`]'s window-only result shows). Returns the number of samples
/// prepended (the record's first sample is at index `pad`) and the whole filtered series.
pub fn highpass_padded(accel: &[f64], dt: f64, corner: f64, order: u32) -> (usize, Vec<f64>) {
    let n = accel.len();
    let pad = ((1.5 * order as f64 / corner / dt) / 2.0).ceil() as usize;
    let nfft = (n + 2 * pad).next_power_of_two();
    let mut buf: Vec<Complex<f64>> = vec![Complex::new(0.0, 0.0); nfft];
    for (i, a) in accel.iter().enumerate() {
        buf[pad + i] = Complex::new(*a, 0.0);
    }
    let mut planner = FftPlannerScalar::new();
    planner.plan_fft_forward(nfft).process(&mut buf);
    let df = 1.0 / (nfft as f64 * dt);
    for (k, z) in buf.iter_mut().enumerate() {
        let kk = k.min(nfft - k);
        let f = kk as f64 * df;
        let h2 = if kk == 0 { 0.0 } else { 1.0 / (1.0 + (corner / f).powi(2 * order as i32)) };
        *z *= h2;
    }
    planner.plan_fft_inverse(nfft).process(&mut buf);
    let s = 1.0 / nfft as f64;
    (pad, (0..(n + 2 * pad)).map(|i| buf[i].re * s).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wiggle(n: usize, dt: f64) -> Vec<f64> {
        (0..n).map(|i| {
            let t = i as f64 * dt;
            (7.0 * t).sin() * (-0.2 * t).exp() + 0.3 * (13.0 * t + 0.4).cos()
        }).collect()
    }

    #[test]
    fn polynomial_ends_at_rest() {
        let dt = 0.01;
        let a: Vec<f64> = wiggle(2001, dt).iter().map(|x| x + 0.02).collect();
        let c = correct(&a, dt, &Baseline::Polynomial { degree: 5 }).unwrap();
        let d = drift(&c, dt);
        assert!(d.v_end.abs() < 1e-10 && d.d_end.abs() < 1e-10, "{d:?}");
        assert!(drift(&a, dt).d_end.abs() > 1.0);
    }

    #[test]
    fn highpass_removes_an_offset() {
        let dt = 0.01;
        let a: Vec<f64> = wiggle(2001, dt).iter().map(|x| x + 0.05).collect();
        let c = correct(&a, dt, &Baseline::HighPass { corner: 0.1, order: 4 }).unwrap();
        let m = c.iter().sum::<f64>() / c.len() as f64;
        assert!(m.abs() < 0.01, "{m}");
    }

    #[test]
    fn bad_parameters_name_the_field() {
        let a = vec![0.0; 100];
        let e = correct(&a, 0.01, &Baseline::HighPass { corner: 80.0, order: 4 }).unwrap_err().to_string();
        assert!(e.contains("baseline.corner") && e.contains("Nyquist"), "{e}");
        let e = correct(&a, 0.01, &Baseline::Polynomial { degree: 2 }).unwrap_err().to_string();
        assert!(e.contains("baseline.degree"), "{e}");
    }
}

//! The 1-D free field of a uniform rock column: deconvolution of a surface record to depth
//! (issue 29, docs/dam_physics.md "Foundation models").
//!
//! Assumptions, stated once here: a vertically incident plane wave (S for a horizontal
//! component, P for the vertical one) in a uniform, linear, viscously damped half-space whose
//! free surface is where the record was taken; no topography. The damping is Rayleigh's, as in
//! the finite-element rock ([`ColumnSpec::alpha`], [`ColumnSpec::beta`]): ρ ü + α ρ u̇ =
//! ∂/∂z (M (∂u/∂z + β ∂u̇/∂z)) with M = G (S) or λ + 2μ (P), so the column and a rock box with
//! the same Rayleigh coefficients carry the same free field.
//!
//! Solution (frequency domain, rustfft; each bin varies as e^{+iωt}, the inverse transform's
//! sign): with k*² = ρ (ω² − iαω) / (M (1 + iωβ)), Re k* > 0 (so Im k* < 0: a wave decays as it
//! travels), the field at depth d below the surface is U(d) = U_s (e^{ik*d} + e^{−ik*d}) / 2:
//! the upgoing (incident) half arrived d/c earlier and is larger, the downgoing (reflected)
//! half is later and smaller. The stress (z up, depth d = z_s − z) is
//! τ = M (1 + iωβ) ∂U/∂z = M (1 + iωβ) k* sin(k*d) U_s.
//!
//! Band: the record is low-passed at [`ColumnSpec::f_max`] (see there why).
//!
//! Time base: the series are delayed by [`ColumnField::delay`] (the travel time from the base
//! to the surface, whole samples) so the incident wave at the base starts after t = 0: the
//! surface record plays at t − delay. The record is padded with zeros in front (the delay) and
//! behind (twice the travel time and 64 samples) so the periodic transform does not wrap.
//! Velocities, displacements and stresses are integrated from rest in time (trapezoid) from
//! the accelerations and stress accelerations of each depth. Inputs and outputs in SI (m/s²,
//! m/s, m, Pa).

use rustfft::num_complex::Complex;
use rustfft::FftPlannerScalar;

/// A uniform damped column.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColumnSpec {
    /// Depth of the base below the free surface [m].
    pub height: f64,
    /// Density [kg/m³].
    pub rho: f64,
    /// Modulus of the wave [Pa]: G for S, λ + 2μ for P.
    pub modulus: f64,
    /// Mass-proportional damping α [1/s].
    pub alpha: f64,
    /// Stiffness-proportional damping β [s].
    pub beta: f64,
    /// Highest frequency carried [Hz]: the field is the record low-passed there (a cosine
    /// taper from 0.8 f_max to f_max). Deconvolving through a damped column multiplies a
    /// frequency by |e^{ik*H}|, which grows exponentially with frequency under β (the record's
    /// noise near its Nyquist frequency would come back amplified by e^{10} and more), and a
    /// finite-element rock carries no more than its mesh resolves anyway.
    pub f_max: f64,
}

impl ColumnSpec {
    /// Wave speed √(M/ρ) [m/s].
    pub fn speed(&self) -> f64 {
        (self.modulus / self.rho).sqrt()
    }

    /// Complex wavenumber k*(ω) (module doc), Re ≥ 0; 0 at ω = 0.
    pub fn wavenumber(&self, omega: f64) -> Complex<f64> {
        let num = Complex::new(self.rho * omega * omega, -self.rho * self.alpha * omega);
        let den = Complex::new(self.modulus, self.modulus * omega * self.beta);
        let k = (num / den).sqrt();
        if k.re < 0.0 { -k } else { k }
    }

    /// The low-pass weight of angular frequency ω (1 below 0.8 f_max, 0 above f_max).
    pub fn pass(&self, omega: f64) -> f64 {
        let f = omega / (2.0 * std::f64::consts::PI);
        let lo = 0.8 * self.f_max;
        if f <= lo {
            1.0
        } else if f >= self.f_max {
            0.0
        } else {
            0.5 * (1.0 + (std::f64::consts::PI * (f - lo) / (self.f_max - lo)).cos())
        }
    }

    /// Complex modulus M (1 + iωβ) [Pa].
    fn complex_modulus(&self, omega: f64) -> Complex<f64> {
        Complex::new(self.modulus, self.modulus * omega * self.beta)
    }
}

/// What the column gives at one depth: series sampled at `dt` from t = 0.
#[derive(Clone, Debug, Default)]
pub struct DepthSeries {
    /// Acceleration [m/s²] (at the surface only; empty below).
    pub accel: Vec<f64>,
    pub vel: Vec<f64>,
    pub disp: Vec<f64>,
    /// Stress on a horizontal plane τ = M (ε + β ε̇) [Pa] (z up: τ_xz for S, σ_zz for P).
    pub stress: Vec<f64>,
}

/// The free field of a column at a set of depths (module doc).
#[derive(Clone, Debug)]
pub struct ColumnField {
    pub spec: ColumnSpec,
    /// Sample interval [s].
    pub dt: f64,
    /// Time at which the surface record's first sample plays [s] (whole samples).
    pub delay: f64,
    /// Depths below the surface [m], ascending from 0, equally spaced.
    pub depths: Vec<f64>,
    pub series: Vec<DepthSeries>,
}

/// Samples of the front pad: the travel time `height / speed` in whole samples (at least 1).
pub fn delay_samples(height: f64, speed: f64, dt: f64) -> usize {
    ((height / speed) / dt).ceil().max(1.0) as usize
}

/// The spectrum of the surface record padded with `front` zeros in front and 2 `travel` + 64
/// behind: (bins 0..=n/2, n).
fn surface_spectrum(surface: &[f64], front: usize, travel: usize) -> (Vec<Complex<f64>>, usize) {
    let n = front + surface.len() + 2 * travel + 64;
    let mut buf: Vec<Complex<f64>> = vec![Complex::new(0.0, 0.0); n];
    for (i, &a) in surface.iter().enumerate() {
        buf[front + i] = Complex::new(a, 0.0);
    }
    FftPlannerScalar::new().plan_fft_forward(n).process(&mut buf);
    buf.truncate(n / 2 + 1);
    (buf, n)
}

/// The real series of the half spectrum `half` (bins 0..=n/2) of length n.
fn inverse_real(half: &[Complex<f64>], n: usize, planner: &mut FftPlannerScalar<f64>) -> Vec<f64> {
    let mut buf = vec![Complex::new(0.0, 0.0); n];
    for (k, z) in half.iter().enumerate() {
        buf[k] = *z;
        if k > 0 && n - k != k && n - k < n {
            buf[n - k] = z.conj();
        }
    }
    planner.plan_fft_inverse(n).process(&mut buf);
    let s = 1.0 / n as f64;
    buf.iter().map(|z| z.re * s).collect()
}

/// ∫ from rest by the trapezoid rule, same length.
pub fn integrate_from_rest(x: &[f64], dt: f64) -> Vec<f64> {
    let mut out = Vec::with_capacity(x.len());
    let mut acc = 0.0;
    for i in 0..x.len() {
        if i > 0 {
            acc += 0.5 * dt * (x[i - 1] + x[i]);
        }
        out.push(acc);
    }
    out
}

/// The angular frequency of bin k of an n-point transform at `dt`.
fn omega_of(k: usize, n: usize, dt: f64) -> f64 {
    2.0 * std::f64::consts::PI * k as f64 / (n as f64 * dt)
}

/// The incident (upgoing) acceleration at the column's base [m/s²] of the surface record
/// `surface` [m/s², sampled at `dt`], delayed by `delay_samples(height, speed, dt)` samples:
/// (series from t = 0, delay [s]). The deconvolution proper: U_in(H) = U_s e^{ik*H} / 2.
pub fn incident_at_base(spec: &ColumnSpec, surface: &[f64], dt: f64) -> (Vec<f64>, f64) {
    let travel = delay_samples(spec.height, spec.speed(), dt);
    let (mut half, n) = surface_spectrum(surface, travel, travel);
    for (k, z) in half.iter_mut().enumerate() {
        let w = omega_of(k, n, dt);
        let kk = spec.wavenumber(w);
        *z *= 0.5 * spec.pass(w) * (Complex::new(0.0, 1.0) * kk * spec.height).exp();
    }
    let mut planner = FftPlannerScalar::new();
    (inverse_real(&half, n, &mut planner), travel as f64 * dt)
}

/// The record `a` [at `dt`] low-passed as `spec` says ([`ColumnSpec::pass`]), same length: the
/// surface motion the field reproduces.
pub fn low_pass(spec: &ColumnSpec, a: &[f64], dt: f64) -> Vec<f64> {
    let (mut half, n) = surface_spectrum(a, 0, 0);
    for (k, z) in half.iter_mut().enumerate() {
        *z *= spec.pass(omega_of(k, n, dt));
    }
    let mut out = inverse_real(&half, n, &mut FftPlannerScalar::new());
    out.truncate(a.len());
    out
}

/// The free field of `spec` under the surface record `surface` [m/s², at `dt`] at `levels`
/// + 1 equally spaced depths from 0 to the base (module doc).
pub fn free_field(spec: &ColumnSpec, surface: &[f64], dt: f64, levels: usize) -> ColumnField {
    let travel = delay_samples(spec.height, spec.speed(), dt);
    let (half, n) = surface_spectrum(surface, travel, travel);
    let levels = levels.max(1);
    let depths: Vec<f64> = (0..=levels).map(|j| spec.height * j as f64 / levels as f64).collect();
    let mut planner = FftPlannerScalar::new();
    let series = depths
        .iter()
        .map(|&d| {
            let mut a = Vec::with_capacity(half.len());
            let mut s = Vec::with_capacity(half.len());
            for (k, z) in half.iter().enumerate() {
                let w = omega_of(k, n, dt);
                let kk = spec.wavenumber(w);
                let z = *z * spec.pass(w);
                a.push(z * (kk * d).cos());
                s.push(z * spec.complex_modulus(w) * kk * (kk * d).sin());
            }
            let accel = inverse_real(&a, n, &mut planner);
            // the stress's second time derivative, integrated twice from rest
            let stress_dd = inverse_real(&s, n, &mut planner);
            let vel = integrate_from_rest(&accel, dt);
            let disp = integrate_from_rest(&vel, dt);
            let stress = integrate_from_rest(&integrate_from_rest(&stress_dd, dt), dt);
            // the acceleration is kept at the surface only (the input, for checks)
            let accel = if d == 0.0 { accel } else { Vec::new() };
            DepthSeries { accel, vel, disp, stress }
        })
        .collect();
    ColumnField { spec: *spec, dt, delay: travel as f64 * dt, depths, series }
}

/// Free-field values at one point: displacement [m], velocity [m/s], stress [Pa].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FieldValue {
    pub disp: f64,
    pub vel: f64,
    pub stress: f64,
}

/// Where a depth falls between the levels of a field: (lower level, weight of the upper one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthWeight {
    pub level: usize,
    pub w: f64,
}

impl ColumnField {
    /// The interpolation weights of depth `d` [m] (clamped to the column).
    pub fn depth_weight(&self, d: f64) -> DepthWeight {
        let last = self.depths.len() - 1;
        if last == 0 {
            return DepthWeight { level: 0, w: 0.0 };
        }
        let s = (d / self.spec.height * last as f64).clamp(0.0, last as f64);
        let level = (s.floor() as usize).min(last - 1);
        DepthWeight { level, w: s - level as f64 }
    }

    /// The field at depth weights `dw` and time `t` [s], linear in depth and time; the last
    /// sample held after the end, rest before t = 0.
    pub fn at(&self, dw: DepthWeight, t: f64) -> FieldValue {
        let n = self.series[0].vel.len();
        let s = (t / self.dt).max(0.0);
        let (i, f) = if s >= (n - 1) as f64 { (n - 2, 1.0) } else { (s.floor() as usize, s - s.floor()) };
        let pick = |x: &DepthSeries| -> [f64; 3] {
            let lerp = |v: &[f64]| v[i] * (1.0 - f) + v[i + 1] * f;
            [lerp(&x.disp), lerp(&x.vel), lerp(&x.stress)]
        };
        let lo = pick(&self.series[dw.level]);
        let hi = if dw.w > 0.0 { pick(&self.series[dw.level + 1]) } else { lo };
        let m = |k: usize| lo[k] * (1.0 - dw.w) + hi[k] * dw.w;
        FieldValue { disp: m(0), vel: m(1), stress: m(2) }
    }

    /// The surface acceleration as it plays in the field's time base (the input, delayed).
    pub fn surface_accel(&self) -> &[f64] {
        &self.series[0].accel
    }
}

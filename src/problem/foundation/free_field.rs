//! The free field of a radiating foundation: the scene's records taken as the motion of the
//! free surface, brought down through uniform 1-D rock columns (`crate::motion::column`):
//! vertically incident S for x and y, P for z.
//!
//! Inputs: the base motions of the scene (`dynamics::loads::BaseMotion`, already scaled and
//! corrected as the scene says), the rock's material, the surface elevation and base depth,
//! and the rock's Rayleigh coefficients (the columns are damped as the finite-element rock is,
//! so the two carry the same free field). Output: at any elevation z and time t the free-field
//! displacement, velocity [3 components] and stress tensor (z up; S: σ_xz, σ_yz; P: σ_zz and
//! σ_xx = σ_yy = λ/(λ+2μ) σ_zz, laterally confined), in the column's time base (the surface
//! record plays at t − delay, [`FreeField::delay`]).

use crate::dynamics::loads::{ground_acceleration_of, BaseMotion};
use crate::model::material::Material;
use crate::motion::column::{free_field, ColumnField, ColumnSpec, DepthWeight};

/// Level spacing of the columns in wavelengths of the shortest S wave the record's sampling
/// carries: c_s dt / 4 (at 100 Hz sampling and c_s = 2200 m/s, 5.5 m). Linear interpolation
/// between levels then errs by at most (k dz)²/8 ≈ 3 % at the Nyquist frequency and far less in
/// the band that carries the energy (below a quarter of it).
const LEVELS_PER_SAMPLE_WAVE: f64 = 4.0;

/// Samples of the free field per record interval. Default 8. The records are linear between
/// their samples (`crate::motion` convention), so the velocity is quadratic and the step reads
/// it, the displacement and the stress by linear interpolation in time: the boundary forces
/// have a kink at every sample, and the kinks excite the rock's highest modes (a 10 m wide
/// box: 110 Hz S, 190 Hz P across), which show in the accelerations though not in the
/// velocities. Measured on the radiating box of `tests/all/foundation.rs` (10 × 10 × 200 m,
/// 2.5 m hexes, DL 5073, 100 Hz records): the top's acceleration misfit against the free field
/// is 7.7 / 7.6 / 7.5 % of peak (x, y, z) at 4 samples per interval, 3.1 / 3.0 / 2.8 % at 8,
/// 0.56 / 0.55 / 0.92 % at 16, while the velocity misfit is below 0.6 % at every rate and
/// 10 × finer depth levels change nothing (7.66 %). 8 meets issue 29's 5 % at twice the
/// memory of 4 (a 630 m column, 116 levels, 20 s record: about 140 MB for the three columns;
/// 16 would hold 280 MB).
pub const SUBSAMPLES: usize = 8;

/// Largest number of levels of a column. Default 500: 3 columns × 500 levels × 4 series of a
/// 30 s record at 100 Hz ([`SUBSAMPLES`] per interval) hold 430 MB (a 630 m dam foundation at
/// c_s = 2200 m/s needs 115 levels, 100 MB; both at 4 samples per interval, twice that at
/// [`SUBSAMPLES`] = 8);
/// beyond it the levels are spaced wider.
pub const MAX_LEVELS: usize = 500;

/// Default highest frequency of the free field [Hz] (`foundation.max_frequency`): 25 Hz, the
/// band of engineering records that carries the energy of arch-dam response (the DL 5073
/// records used here: 95 % of their energy below 30 Hz), and 9 elements per S wavelength of
/// the dam's rock (2214 m/s) at the default mesh's 10 m at the dam.
pub const DEFAULT_MAX_FREQUENCY: f64 = 25.0;

/// The three columns' free field (module doc).
#[derive(Clone, Debug)]
pub struct FreeField {
    /// x (S), y (S), z (P).
    pub columns: [ColumnField; 3],
    /// Elevation of the free surface [m].
    pub surface: f64,
    /// λ / (λ + 2μ) of the rock (the lateral stress of the P column).
    pub lateral_ratio: f64,
    /// When the surface record's first sample plays [s].
    pub delay: f64,
    /// The surface records x, y, z [m/s²] at `dt` (the input, sampled [`SUBSAMPLES`] times per
    /// record interval).
    pub surface_accel: [Vec<f64>; 3],
    pub dt: f64,
}

/// Free-field values at one point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FieldAt {
    pub disp: [f64; 3],
    pub vel: [f64; 3],
    /// σ (xx, yy, zz, xy, yz, zx) [Pa].
    pub stress: [f64; 6],
}

impl FreeField {
    /// The free field of `base` (records, directions, scales) in a rock of `rock` with surface
    /// at `surface` [m] and base `height` [m] below it, Rayleigh α [1/s] (0 when the rock is not
    /// mass-damped) and β [s]. The records are sampled at the smallest record interval.
    pub fn build(base: &[BaseMotion], rock: &Material, surface: f64, height: f64, alpha: f64, beta: f64, f_max: f64) -> FreeField {
        let dt_rec = base.iter().map(|b| b.record.dt).fold(f64::INFINITY, f64::min);
        let dt_rec = if dt_rec.is_finite() { dt_rec } else { 0.01 };
        let dt = dt_rec / SUBSAMPLES as f64;
        let t_end = base.iter().map(|b| b.record.t_end()).fold(0.0, f64::max);
        let n = if base.is_empty() { 0 } else { (t_end / dt).round() as usize + 1 };
        let mut surface_accel: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::with_capacity(n));
        for i in 0..n {
            let a = ground_acceleration_of(base, i as f64 * dt);
            for c in 0..3 {
                surface_accel[c].push(a[c]);
            }
        }
        let g = rock.lame.mu;
        let m = rock.lame.p_modulus();
        let s_spec = ColumnSpec { height, rho: rock.rho, modulus: g, alpha, beta, f_max };
        let p_spec = ColumnSpec { modulus: m, ..s_spec };
        let dz = s_spec.speed() * dt_rec / LEVELS_PER_SAMPLE_WAVE;
        let levels = ((height / dz).ceil() as usize).clamp(8, MAX_LEVELS);
        Self::of_surface(surface_accel, dt, [s_spec, p_spec], levels, surface, rock.lame.lambda / m)
    }

    /// The columns of the S and P specs `sp` under the surface records `surface_accel` [m/s² at
    /// `dt`] at `levels` + 1 depths.
    fn of_surface(surface_accel: [Vec<f64>; 3], dt: f64, sp: [ColumnSpec; 2], levels: usize, surface: f64, lateral_ratio: f64) -> FreeField {
        let columns = [
            free_field(&sp[0], &surface_accel[0], dt, levels),
            free_field(&sp[0], &surface_accel[1], dt, levels),
            free_field(&sp[1], &surface_accel[2], dt, levels),
        ];
        // one time base for all three: the S columns' delay (the longer travel)
        let delay = columns[0].delay;
        let columns = columns.map(|c| realign(c, delay));
        FreeField { columns, surface, lateral_ratio, delay, surface_accel, dt }
    }

    /// The same free field sampled `time_factor` times finer in time (the surface records are
    /// linear between their samples, so the finer samples are exact) at `levels` + 1 depths:
    /// for checks of the field's time and depth interpolation against the defaults
    /// ([`SUBSAMPLES`], [`LEVELS_PER_SAMPLE_WAVE`]).
    pub fn refined(&self, time_factor: usize, levels: usize) -> FreeField {
        let k = time_factor.max(1);
        let fine = self.surface_accel.clone().map(|a| {
            let mut out = Vec::with_capacity(a.len() * k);
            for w in a.windows(2) {
                out.extend((0..k).map(|j| w[0] + (w[1] - w[0]) * j as f64 / k as f64));
            }
            out.extend(a.last());
            out
        });
        let sp = [self.columns[0].spec, self.columns[2].spec];
        Self::of_surface(fine, self.dt / k as f64, sp, levels.max(1), self.surface, self.lateral_ratio)
    }

    /// Levels of the columns (depths − 1).
    pub fn levels(&self) -> usize {
        self.columns[0].depths.len() - 1
    }

    /// The depth weights of elevation `z` in the columns (all three share their levels).
    pub fn depth_weight(&self, z: f64) -> DepthWeight {
        self.columns[0].depth_weight(self.surface - z)
    }

    /// The free field at depth weights `dw` and time `t` [s].
    pub fn at(&self, dw: DepthWeight, t: f64) -> FieldAt {
        let [x, y, z] = [0, 1, 2].map(|c| self.columns[c].at(dw, t));
        let r = self.lateral_ratio;
        FieldAt {
            disp: [x.disp, y.disp, z.disp],
            vel: [x.vel, y.vel, z.vel],
            stress: [r * z.stress, r * z.stress, z.stress, 0.0, y.stress, x.stress],
        }
    }

    /// The free field's surface acceleration of component `c` at time `t` [m/s²] (the record
    /// low-passed at f_max, delayed by [`Self::delay`]; linear between samples, 0 outside).
    pub fn surface_accel_at(&self, c: usize, t: f64) -> f64 {
        let s = t / self.dt;
        let a = self.columns[c].surface_accel();
        if !(s >= 0.0) || s >= (a.len().saturating_sub(1)) as f64 {
            return 0.0;
        }
        let i = s.floor() as usize;
        let f = s - i as f64;
        a[i] * (1.0 - f) + a[i + 1] * f
    }
}

/// The column `c` shifted so that its surface record plays at `delay` [s] (a P column's own
/// delay is shorter than the S columns'; whole samples, padding with rest in front).
fn realign(mut c: ColumnField, delay: f64) -> ColumnField {
    let shift = ((delay - c.delay) / c.dt).round() as usize;
    if shift > 0 {
        for s in &mut c.series {
            for v in [&mut s.accel, &mut s.vel, &mut s.disp, &mut s.stress] {
                v.splice(0..0, std::iter::repeat_n(0.0, shift));
            }
        }
        c.delay += shift as f64 * c.dt;
    }
    c
}

/// The frame every reported displacement is measured in (docs/dam_physics.md "Foundation
/// models", "Displacement reference"): the free field. The massless and massed_fixed models
/// integrate displacements relative to the rigid base motion, which is their free field at every
/// depth; the radiating model integrates total displacements, so its peaks and monitor
/// displacements have the 1-D free field at each node's elevation taken off (the surface one
/// above the rock, the dam's nodes). Without that, a radiating run reports the record's own
/// ground displacement (the DL 5073 records at 3×: up to 2.1 m by 6 s, drift included) as the
/// dam's motion. Velocities and accelerations are left as integrated.
#[derive(Clone, Debug)]
pub struct Frame {
    weights: Vec<DepthWeight>,
}

impl Frame {
    /// The depth weights of every mesh node (`elevations`: the nodes' z [m]).
    pub fn new(field: &FreeField, elevations: impl Iterator<Item = f64>) -> Frame {
        Frame { weights: elevations.map(|z| field.depth_weight(z)).collect() }
    }

    /// The free-field displacement [m] of `node` at time `t` [s] of the run.
    pub fn displacement(&self, field: &FreeField, node: usize, t: f64) -> [f64; 3] {
        field.at(self.weights[node], t).disp
    }
}

//! Rigid-plastic (Newmark) sliding of a rigid block on a rigid base.
//!
//! The block moves along one line (down an incline, or down the line of intersection of
//! a wedge). While it slides, its relative acceleration along the line is linear in the
//! ground-acceleration coefficients kh = a_h/g and kv = a_v/g:
//!
//! ```text
//! sliding down (v > 0):  s'' = r_down = r0 + rh kh + rv kv    starts from rest when r_down > 0
//! sliding up   (v < 0):  s'' = r_up   = u0 + uh kh + uv kv    starts from rest when r_up   < 0
//! ```
//!
//! (s positive down the slope; `r_up` has friction and cohesion reversed, so r_down ≤ r_up
//! whenever the normal force is ≥ 0). One-way sliding ([`Direction::OneWay`], as
//! `slide_1way` in refs/analytic.py) ignores `r_up`: the upslope resistance is assumed
//! never exceeded. Two-way ([`Direction::TwoWay`]) lets the block slide both ways with
//! its two yield accelerations. Signs of the ground accelerations: see [`crate::rigid`]
//! (for an incline a_h is positive *into* the hill, a_v positive up).
//!
//! Integration: the samples a[i] at t = i dt are joined linearly, so r is linear inside
//! each step and v, s are integrated in closed form; starts and stops (v = 0, the first
//! root of a quadratic) are located exactly inside the step, and a block that stops may
//! start again in the same step. The result is exact for piecewise-linear input. After
//! the last sample the ground acceleration ramps to 0 over one dt and stays 0; a block
//! still sliding then decelerates at the constant r0 and stops in closed form, or, if
//! r0 does not oppose the motion (statically unstable), is reported `still_sliding`.
//!
//! Not covered: rotation/toppling, changes of geometry with displacement, loss of contact
//! (counted in `lift_off_samples` where the model provides its normal forces).

use super::RigidError;
use super::wedge::WedgeSeismicCoeffs;
use serde::Serialize;

/// A quantity linear in the ground-acceleration coefficients: c0 + ch kh + cv kv.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Linear3 {
    /// Value at rest (kh = kv = 0).
    pub c0: f64,
    /// Per g of horizontal ground acceleration.
    pub ch: f64,
    /// Per g of vertical (upward) ground acceleration.
    pub cv: f64,
}

impl Linear3 {
    pub const fn new(c0: f64, ch: f64, cv: f64) -> Self {
        Linear3 { c0, ch, cv }
    }
    fn at(&self, kh: f64, kv: f64) -> f64 {
        self.c0 + self.ch * kh + self.cv * kv
    }
}

/// Which ways the block may slide.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub enum Direction {
    /// Down only (default; the classic Newmark analysis of a slope).
    #[default]
    OneWay,
    /// Down and up, each with its own yield acceleration.
    TwoWay,
}

/// The sliding law of one block along its line.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SlidingModel {
    /// Relative acceleration [m/s²] while sliding down.
    pub down: Linear3,
    /// Relative acceleration [m/s²] while sliding up; `None` = one-way.
    pub up: Option<Linear3>,
    /// Normal forces [N] whose sign is checked at every sample (contact lost when < 0).
    pub normals: Vec<Linear3>,
    /// Gravity [m/s²] used to turn the accelerations into kh, kv.
    pub g: f64,
}

/// A block on an incline: angle β, Mohr-Coulomb contact (φ, c over `area`), mass.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Incline {
    /// Incline angle β [deg], 0 ≤ β < 90.
    pub beta: f64,
    /// Friction angle φ [deg].
    pub phi: f64,
    /// Cohesion [Pa] (default 0 in the references).
    pub cohesion: f64,
    /// Contact area [m²] carrying the cohesion.
    pub area: f64,
    /// Block mass [kg].
    pub mass: f64,
    /// Gravity [m/s²].
    pub g: f64,
}

impl Incline {
    /// Cohesionless block of unit mass, g = 9.81 m/s².
    pub fn frictional(beta: f64, phi: f64) -> Self {
        Incline { beta, phi, cohesion: 0.0, area: 0.0, mass: 1.0, g: 9.81 }
    }

    /// The sliding law. With μ = tan φ, b = β, ca = c A / m:
    /// down r = g(sin b − μ cos b) − ca + g(cos b + μ sin b) kh + g(sin b − μ cos b) kv,
    /// up   r = g(sin b + μ cos b) + ca + g(cos b − μ sin b) kh + g(sin b + μ cos b) kv,
    /// normal force N = m g [(1 + kv) cos b − kh sin b].
    pub fn model(&self, direction: Direction) -> Result<SlidingModel, RigidError> {
        if !(self.beta.is_finite() && (0.0..90.0).contains(&self.beta)) {
            return Err(RigidError::invalid("incline angle beta [deg]", self.beta, "must be in 0..90"));
        }
        if !(self.phi.is_finite() && (0.0..90.0).contains(&self.phi)) {
            return Err(RigidError::invalid("friction angle phi [deg]", self.phi, "must be in 0..90"));
        }
        super::non_negative("cohesion [Pa]", self.cohesion)?;
        super::non_negative("contact area [m2]", self.area)?;
        super::positive("block mass [kg]", self.mass)?;
        let g = super::positive("g [m/s2]", self.g)?;
        let (sb, cb) = self.beta.to_radians().sin_cos();
        let mu = self.phi.to_radians().tan();
        let ca = self.cohesion * self.area / self.mass;
        let down = Linear3::new(g * (sb - mu * cb) - ca, g * (cb + mu * sb), g * (sb - mu * cb));
        let up = Linear3::new(g * (sb + mu * cb) + ca, g * (cb - mu * sb), g * (sb + mu * cb));
        let mg = self.mass * g;
        Ok(SlidingModel {
            down,
            up: (direction == Direction::TwoWay).then_some(up),
            normals: vec![Linear3::new(mg * cb, -mg * sb, mg * cb)],
            g,
        })
    }

    /// Horizontal ground acceleration into the hill [m/s²] at which down-slope sliding
    /// starts (kv = 0): g tan(φ − β) without cohesion.
    pub fn yield_acceleration_down(&self) -> Result<f64, RigidError> {
        let m = self.model(Direction::OneWay)?;
        Ok(-m.down.c0 / m.down.ch * m.g)
    }

    /// Horizontal ground acceleration *out of* the hill [m/s², > 0] at which up-slope
    /// sliding starts (kv = 0): g tan(φ + β) without cohesion. `None` if it never starts
    /// (β + φ ≥ 90°).
    pub fn yield_acceleration_up(&self) -> Result<Option<f64>, RigidError> {
        let m = self.model(Direction::TwoWay)?;
        Ok(m.up.filter(|up| up.ch > 0.0).map(|up| up.c0 / up.ch * m.g))
    }
}

impl WedgeSeismicCoeffs {
    /// The sliding law of the wedge along its line of intersection (cohesion as chosen
    /// when the coefficients were made); contact checked on both planes.
    pub fn sliding_model(&self, direction: Direction) -> SlidingModel {
        let l = |c: [f64; 3]| Linear3::new(c[0], c[1], c[2]);
        SlidingModel {
            down: l(self.down),
            up: (direction == Direction::TwoWay).then(|| l(self.up)),
            normals: vec![l(self.normal_a), l(self.normal_b)],
            g: self.g,
        }
    }
}

/// Outcome of one sliding analysis. Displacements positive down the slope.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NewmarkResult {
    /// Displacement [m] when the block has come to rest after the record (or at the end
    /// of the record if `still_sliding`).
    pub residual_displacement: f64,
    /// Largest |relative velocity| [m/s].
    pub max_velocity: f64,
    /// Number of sliding episodes (starts from rest), both directions.
    pub n_episodes: usize,
    /// Of these, episodes up the slope (two-way only).
    pub n_episodes_up: usize,
    /// True if the block never stops (statically unstable without shaking).
    pub still_sliding: bool,
    /// Velocity [m/s] at the end of the record (before the free run-out).
    pub velocity_at_end_of_record: f64,
    /// Samples at which a normal force of the model is negative (the block would lift off;
    /// the rigid sliding model is not valid there).
    pub lift_off_samples: usize,
    /// Displacement [m] at each sample time t = i dt (if requested).
    pub history: Option<Vec<f64>>,
}

/// Integration options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewmarkOptions {
    /// Sample interval of the records [s].
    pub dt: f64,
    /// Keep the displacement at every sample (default false).
    pub keep_history: bool,
}

impl NewmarkOptions {
    pub fn new(dt: f64) -> Self {
        NewmarkOptions { dt, keep_history: false }
    }
    pub fn with_history(mut self) -> Self {
        self.keep_history = true;
        self
    }
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum Mode {
    Rest,
    Down,
    Up,
}

struct Slider {
    v: f64,
    d: f64,
    mode: Mode,
    vmax: f64,
    n_episodes: usize,
    n_up: usize,
}

/// Smallest root s in (0, len] of v + b s + a s² = 0 (len·(1 + 1e-12) accepted).
fn first_zero(v: f64, b: f64, a: f64, len: f64) -> Option<f64> {
    let lim = len * (1.0 + 1e-12);
    let mut best: Option<f64> = None;
    let mut consider = |s: f64| {
        if s > 0.0 && s <= lim && best.is_none_or(|b| s < b) {
            best = Some(s.min(len));
        }
    };
    if a == 0.0 || (a * len * len).abs() <= 1e-14 * (v.abs() + (b * len).abs()) {
        if b != 0.0 {
            consider(-v / b);
        }
        return best;
    }
    let disc = b * b - 4.0 * a * v;
    if disc < 0.0 {
        return None;
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    if q != 0.0 {
        consider(q / a);
        consider(v / q);
    } else {
        // b = 0 and disc = 0: v = 0, double root at 0; or b = 0, −4 a v ≥ 0 handled below.
        let r = (-v / a).max(0.0).sqrt();
        consider(r);
    }
    best
}

impl Slider {
    /// Advance over one interval of length h on which the down/up accelerations vary
    /// linearly from (da, ua) to (db, ub).
    fn advance(&mut self, h: f64, da: f64, db: f64, up: Option<(f64, f64)>) {
        let mut tau = 0.0;
        // Each pass either reaches h or changes mode at a strictly later time (a stop
        // needs a root s > 0), or starts sliding; 16 passes is far more than one step needs.
        for _ in 0..16 {
            if tau >= h {
                return;
            }
            let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t / h;
            match self.mode {
                Mode::Rest => {
                    let dc = lerp(da, db, tau);
                    let t_down = if dc > 0.0 {
                        Some(tau)
                    } else if db > 0.0 {
                        Some(tau + (h - tau) * (-dc) / (db - dc))
                    } else {
                        None
                    };
                    let t_up = up.and_then(|(ua, ub)| {
                        let uc = lerp(ua, ub, tau);
                        if uc < 0.0 {
                            Some(tau)
                        } else if ub < 0.0 {
                            Some(tau + (h - tau) * uc / (uc - ub))
                        } else {
                            None
                        }
                    });
                    let (mode, t) = match (t_down, t_up) {
                        (Some(td), Some(tu)) if tu < td => (Mode::Up, tu),
                        (Some(td), _) => (Mode::Down, td),
                        (None, Some(tu)) => (Mode::Up, tu),
                        (None, None) => return,
                    };
                    self.mode = mode;
                    if mode == Mode::Up {
                        self.n_up += 1;
                    }
                    tau = t;
                    self.n_episodes += 1;
                }
                Mode::Down | Mode::Up => {
                    let (ra, rb) = match (self.mode, up) {
                        (Mode::Up, Some(u)) => u,
                        _ => (da, db),
                    };
                    let mut rc = lerp(ra, rb, tau);
                    // A start located at a zero crossing of r must not stop at once on the
                    // round-off sign of r there.
                    if self.v == 0.0 {
                        rc = if self.mode == Mode::Down { rc.max(0.0) } else { rc.min(0.0) };
                    }
                    let a2 = (rb - ra) / (2.0 * h);
                    let len = h - tau;
                    // v(s) = v + rc s + a2 s²; its extremum where r = 0 may be inside.
                    let stop = first_zero(self.v, rc, a2, len);
                    let s_end = stop.unwrap_or(len);
                    if a2 != 0.0 {
                        let s_ext = -rc / (2.0 * a2);
                        if s_ext > 0.0 && s_ext < s_end {
                            self.vmax = self.vmax.max((self.v + rc * s_ext + a2 * s_ext * s_ext).abs());
                        }
                    }
                    self.d += self.v * s_end + rc * s_end * s_end / 2.0 + a2 * s_end.powi(3) / 3.0;
                    if stop.is_some() {
                        self.v = 0.0;
                        self.mode = Mode::Rest;
                    } else {
                        self.v += rc * s_end + a2 * s_end * s_end;
                        // Guard against round-off carrying v through 0 without a root.
                        if (self.mode == Mode::Down && self.v < 0.0) || (self.mode == Mode::Up && self.v > 0.0) {
                            self.v = 0.0;
                            self.mode = Mode::Rest;
                        }
                        self.vmax = self.vmax.max(self.v.abs());
                    }
                    tau += s_end;
                }
            }
        }
    }
}

fn check_record(what: &str, a: &[f64]) -> Result<(), RigidError> {
    match a.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(RigidError::NonFiniteSample { what: what.to_string(), index: i, value: a[i] }),
        None => Ok(()),
    }
}

/// Slide a block with the law `model` under horizontal and (optional) vertical ground
/// accelerations `a_h`, `a_v` [m/s²] sampled every `opts.dt` from t = 0.
pub fn slide(model: &SlidingModel, a_h: &[f64], a_v: Option<&[f64]>, opts: &NewmarkOptions) -> Result<NewmarkResult, RigidError> {
    slide_impl(model, None, a_h, a_v, opts)
}

/// [`slide`] for a brittle bond: the block follows `intact` until it first starts to slide
/// and `residual` (e.g. the law without cohesion) from that instant on. The start is located
/// exactly inside its interval (where the intact rate crosses zero), so the result stays exact
/// for piecewise-linear input.
pub fn slide_with_bond_loss(
    intact: &SlidingModel,
    residual: &SlidingModel,
    a_h: &[f64],
    a_v: Option<&[f64]>,
    opts: &NewmarkOptions,
) -> Result<NewmarkResult, RigidError> {
    if residual.up.is_some() != intact.up.is_some() {
        return Err(RigidError::invalid("bond-loss sliding: residual law direction (1 = two-way)", residual.up.is_some() as u8 as f64, "must match the intact law's"));
    }
    slide_impl(intact, Some(residual), a_h, a_v, opts)
}

fn check_law(model: &SlidingModel) -> Result<(), RigidError> {
    for (name, l) in [("down", Some(model.down)), ("up", model.up)] {
        if let Some(l) = l
            && !(l.c0.is_finite() && l.ch.is_finite() && l.cv.is_finite())
        {
            return Err(RigidError::invalid(&format!("sliding law ({name}) coefficient"), l.c0 + l.ch + l.cv, "must be finite"));
        }
    }
    Ok(())
}

fn slide_impl(intact: &SlidingModel, residual: Option<&SlidingModel>, a_h: &[f64], a_v: Option<&[f64]>, opts: &NewmarkOptions) -> Result<NewmarkResult, RigidError> {
    let (dt, g) = check_slide_input(intact, residual, a_h, a_v, opts)?;
    let rec = GroundRecord { a_h, a_v, g };
    // lift-off is checked on the law in force after the bond is lost (if it is lost at all,
    // that is the law of the sliding phase; the normal forces of both laws are the same).
    let model = residual.unwrap_or(intact);
    let lift_off_samples = (0..a_h.len())
        .filter(|&i| {
            let (kh, kv) = rec.k(i);
            model.normals.iter().any(|n| n.at(kh, kv) < 0.0)
        })
        .count();

    let mut s = Slider { v: 0.0, d: 0.0, mode: Mode::Rest, vmax: 0.0, n_episodes: 0, n_up: 0 };
    let mut history = opts.keep_history.then(|| Vec::with_capacity(a_h.len()));
    let n = a_h.len();
    let mut velocity_at_end = 0.0;
    for i in 0..n {
        // Interval [t_i, t_{i+1}]; for i = n − 1 it is the ramp to zero after the record.
        if let Some(h) = history.as_mut() {
            h.push(s.d);
        }
        if i == n - 1 {
            velocity_at_end = s.v;
        }
        match residual {
            Some(res) if s.n_episodes == 0 => s.advance_bonded(dt, intact, res, &rec, i),
            _ => {
                let m = if s.n_episodes > 0 { residual.unwrap_or(intact) } else { intact };
                let (da, ua) = rec.rates(m, i);
                let (db, ub) = rec.rates(m, i + 1);
                s.advance(dt, da, db, ua.zip(ub));
            }
        }
    }
    // Free run-out with zero ground acceleration: constant r = c0.
    let model = if s.n_episodes > 0 { residual.unwrap_or(intact) } else { intact };
    let still_sliding = s.run_out(model);
    Ok(NewmarkResult {
        residual_displacement: s.d,
        max_velocity: s.vmax,
        n_episodes: s.n_episodes,
        n_episodes_up: s.n_up,
        still_sliding,
        velocity_at_end_of_record: velocity_at_end,
        lift_off_samples,
        history,
    })
}

/// The record step dt [s] and g [m/s²] of a slide, after checking the laws and the records
/// (finite, at least one sample, the vertical as long as the horizontal).
fn check_slide_input(intact: &SlidingModel, residual: Option<&SlidingModel>, a_h: &[f64], a_v: Option<&[f64]>, opts: &NewmarkOptions) -> Result<(f64, f64), RigidError> {
    let dt = super::positive("record time step dt [s]", opts.dt)?;
    let g = super::positive("g [m/s2]", intact.g)?;
    check_law(intact)?;
    if let Some(r) = residual {
        check_law(r)?;
    }
    if a_h.is_empty() {
        return Err(RigidError::invalid("number of record samples", 0.0, "give at least one sample"));
    }
    check_record("horizontal acceleration", a_h)?;
    if let Some(av) = a_v {
        if av.len() != a_h.len() {
            return Err(RigidError::LengthMismatch { expected: a_h.len(), got: av.len() });
        }
        check_record("vertical acceleration", av)?;
    }
    Ok((dt, g))
}

/// The ground accelerations of a slide [m/s²] and g [m/s²].
struct GroundRecord<'a> {
    a_h: &'a [f64],
    a_v: Option<&'a [f64]>,
    g: f64,
}

impl GroundRecord<'_> {
    /// (k_h, k_v) = (a_h, a_v) / g at sample `i`; 0 after the record.
    fn k(&self, i: usize) -> (f64, f64) {
        if i < self.a_h.len() { (self.a_h[i] / self.g, self.a_v.map_or(0.0, |av| av[i] / self.g)) } else { (0.0, 0.0) }
    }

    /// The down and (two-way laws) up rates of law `m` at sample `i`.
    fn rates(&self, m: &SlidingModel, i: usize) -> (f64, Option<f64>) {
        let (kh, kv) = self.k(i);
        (m.down.at(kh, kv), m.up.map(|u| u.at(kh, kv)))
    }
}

impl Slider {
    /// Interval `i` (of length `dt`) while the bond holds: with the `intact` law; when the
    /// block starts inside it, the interval is redone, intact up to the start time t* (at
    /// rest), then with the `residual` law from t*.
    fn advance_bonded(&mut self, dt: f64, intact: &SlidingModel, res: &SlidingModel, rec: &GroundRecord, i: usize) {
        let (da, ua) = rec.rates(intact, i);
        let (db, ub) = rec.rates(intact, i + 1);
        let before = (self.v, self.d, self.mode, self.vmax);
        self.advance(dt, da, db, ua.zip(ub));
        if self.n_episodes == 0 {
            return;
        }
        // The bond broke inside this interval: redo it.
        (self.v, self.d, self.mode, self.vmax) = before;
        self.n_episodes = 0;
        self.n_up = 0;
        let t_star = |a: f64, b: f64, up: bool| -> Option<f64> {
            let (a, b) = if up { (-a, -b) } else { (a, b) };
            if a > 0.0 {
                Some(0.0)
            } else if b > 0.0 {
                Some(dt * (-a) / (b - a))
            } else {
                None
            }
        };
        let ts = [t_star(da, db, false), ua.zip(ub).and_then(|(x, y)| t_star(x, y, true))].into_iter().flatten().fold(dt, f64::min);
        let (ra, rua) = rec.rates(res, i);
        let (rb, rub) = rec.rates(res, i + 1);
        let lerp = |a: f64, b: f64| a + (b - a) * ts / dt;
        let up_res = rua.zip(rub).map(|(x, y)| (lerp(x, y), y));
        self.advance(dt - ts, lerp(ra, rb), rb, up_res);
        if self.n_episodes == 0 {
            // round-off at t*: the residual law is weaker, so the block does start
            self.n_episodes = 1;
        }
    }

    /// The free run-out after the record under law `model` (zero ground acceleration:
    /// constant r = c0). Returns whether the block is still sliding (it would never stop).
    fn run_out(&mut self, model: &SlidingModel) -> bool {
        let mut still_sliding = false;
        match self.mode {
            Mode::Down if model.down.c0 < 0.0 => {
                self.d += self.v * self.v / (2.0 * -model.down.c0);
                self.v = 0.0;
            }
            Mode::Up if model.up.is_some_and(|u| u.c0 > 0.0) => {
                self.d -= self.v * self.v / (2.0 * model.up.map_or(1.0, |u| u.c0));
                self.v = 0.0;
            }
            Mode::Rest => {
                if model.down.c0 > 0.0 || model.up.is_some_and(|u| u.c0 < 0.0) {
                    still_sliding = true;
                }
            }
            _ => still_sliding = true,
        }
        still_sliding
    }
}

/// Newmark sliding of a block on an incline; `a_h` positive into the hill, `a_v` up [m/s²].
pub fn slide_block(
    incline: &Incline,
    direction: Direction,
    a_h: &[f64],
    a_v: Option<&[f64]>,
    opts: &NewmarkOptions,
) -> Result<NewmarkResult, RigidError> {
    slide(&incline.model(direction)?, a_h, a_v, opts)
}

/// Newmark sliding of a wedge along its line of intersection; `a_h` [m/s²] along the
/// azimuth of `coeffs`, `a_v` up. Displacement positive down the line of intersection.
pub fn slide_wedge(
    coeffs: &WedgeSeismicCoeffs,
    direction: Direction,
    a_h: &[f64],
    a_v: Option<&[f64]>,
    opts: &NewmarkOptions,
) -> Result<NewmarkResult, RigidError> {
    slide(&coeffs.sliding_model(direction), a_h, a_v, opts)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_zero_picks_the_first_positive_root() {
        // v + b s + a s^2: linear, two roots, start at zero, no root, beyond the interval.
        assert_eq!(first_zero(1.0, -1.0, 0.0, 2.0), Some(1.0));
        assert!((first_zero(1.0, -3.0, 2.0, 2.0).unwrap() - 0.5).abs() < 1e-15);
        assert!((first_zero(0.0, 1.0, -1.0, 2.0).unwrap() - 1.0).abs() < 1e-15);
        assert_eq!(first_zero(0.0, 0.0, 1.0, 2.0), None);
        assert_eq!(first_zero(1.0, 0.0, 1.0, 2.0), None);
        assert_eq!(first_zero(1.0, -1.0, 0.0, 0.5), None);
        // v = 0 with r rising: no stop (the start of an episode).
        assert_eq!(first_zero(0.0, 2.0, 1.0, 1.0), None);
    }

    #[test]
    fn stop_and_restart_inside_one_interval() {
        // Down law r = -1 + 2 kh (g = 1); kh ramps 1 -> 0 -> 1 over two unit steps.
        // Sliding starts at t = 0 (r = 1), r falls linearly to -1 at t = 1: v = t - t^2,
        // stops at t = 1 exactly; rises again from r = -1 to 1, restarts at t = 1.5.
        let m = SlidingModel { down: Linear3::new(-1.0, 2.0, 0.0), up: None, normals: vec![], g: 1.0 };
        let r = slide(&m, &[1.0, 0.0, 1.0], None, &NewmarkOptions::new(1.0).with_history()).unwrap();
        let h = r.history.unwrap();
        // d(1) = int_0^1 (t - t^2) dt = 1/6.
        assert!((h[1] - 1.0 / 6.0).abs() < 1e-14, "{}", h[1]);
        assert_eq!(r.n_episodes, 2);
        // Episode 2: v = (t - 1.5)^2 to t = 2 (d 1/24), then the ramp to zero after the
        // record (r from 1 to -1 over [2, 3]): v = 1/4 + s - s^2, peak 1/2 at t = 2.5,
        // d 5/12; run-out at r0 = -1 from v = 1/4: d 1/32.
        assert!((r.max_velocity - 0.5).abs() < 1e-14, "{}", r.max_velocity);
        let d = 1.0 / 6.0 + 1.0 / 24.0 + 5.0 / 12.0 + 1.0 / 32.0;
        assert!((r.residual_displacement - d).abs() < 1e-14, "{}", r.residual_displacement);
        assert!(!r.still_sliding);
    }
}

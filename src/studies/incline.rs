//! The incline study: a block on an incline under a base record, friction angle × PGA, the
//! FEM's residual slip against the rigid Newmark block ([`crate::rigid::newmark::slide_block`])
//! under the same records (the run scene's own, through
//! [`crate::dynamics::loads::base_motions`]).
//!
//! Its runs are plain study-file data (`pipelines/incline_study.json`: a `joints.phi` axis and
//! a `pga` axis); this module is only its metrics, table and chart.
//!
//! Quantities: residual slip [m] = the slider monitor's displacement at the end of the run
//! minus its first sample (after gravity), along the down-slope direction
//! −(cos β u_h, sin β) (u_h the horizontal direction in which the plane rises, `uphill`);
//! Newmark: one-way, the ground acceleration along `uphill` (positive into the hill) and the
//! vertical component, φ of the run's joint (its `phi`, or atan μ), cohesionless.

use crate::dynamics::loads::base_motions;
use crate::error::{Error, OutputError, StudyError};
use crate::report::{fmt_percent, fmt_sig, Chart, Series, Table};
use crate::rigid::newmark::{slide_block, Direction, Incline, NewmarkOptions};
use crate::scene::Scene;
use crate::studies::wedge::rigid_level::sample_ground_motion;
use crate::study::{kind_params, KindReport, RunResult, Study, StudyKind, StudyResults};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// The incline study's parameters: the study file's `report` object (`"kind": "incline"`).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct InclineParams {
    /// Incline angle β [deg] of the scene's geometry (30 for `tests/fixtures/incline_hex.msh`).
    pub beta: f64,
    /// Horizontal direction (x, y) in which the plane rises. Default [1, 0] (east, as
    /// `geo/incline.geo`).
    #[serde(default = "east")]
    pub uphill: [f64; 2],
    /// The monitor on the slider.
    pub monitor: String,
    /// The joint under the slider (its friction angle is the Newmark block's).
    pub joint: String,
    /// Relative difference to the Newmark slip above which a run is flagged. Default 0.05 (the
    /// tolerance of the validation test `el_centro_incline_matches_rigid_newmark_…`).
    #[serde(default = "five_percent")]
    pub tolerance: f64,
}

fn east() -> [f64; 2] {
    [1.0, 0.0]
}
fn five_percent() -> f64 {
    0.05
}

pub struct InclineKind {
    pub params: InclineParams,
}

/// One run against its rigid block.
#[derive(Clone, Debug, Serialize)]
pub struct InclineRun {
    pub id: String,
    /// Friction angle [deg] and PGA [g] of the run.
    pub phi: f64,
    pub pga: f64,
    /// Yield acceleration into the hill [g]: tan(φ − β).
    pub yield_acceleration: f64,
    pub fem_slip: f64,
    pub newmark_slip: f64,
    pub newmark_episodes: usize,
    /// (FEM − Newmark) / Newmark (none when Newmark does not slide).
    pub difference: Option<f64>,
}

impl InclineKind {
    pub fn new(study: &Study) -> Result<InclineKind, Error> {
        let params: InclineParams = kind_params(study)?;
        let k = InclineKind { params };
        k.check(study)?;
        Ok(k)
    }

    fn phi_of(&self, scene: &Scene) -> Result<f64, String> {
        let j = scene.joints.iter().find(|j| j.name == self.params.joint).ok_or_else(|| format!("its scene has no joint \"{}\"", self.params.joint))?;
        if j.cohesion.is_some_and(|c| c != 0.0) {
            return Err(format!("joint \"{}\" has cohesion: the Newmark reference here is cohesionless", j.name));
        }
        Ok(j.friction().phi_deg())
    }

    fn down_slope(&self) -> [f64; 3] {
        let (sb, cb) = self.params.beta.to_radians().sin_cos();
        let [x, y] = self.params.uphill;
        let n = (x * x + y * y).sqrt();
        [-cb * x / n, -cb * y / n, -sb]
    }

    fn run(&self, r: &RunResult) -> Result<InclineRun, Error> {
        let scene = r.scene.as_ref().ok_or_else(|| OutputError::read(&r.dir, "its scene cannot be read"))?;
        let phi = self.phi_of(scene).map_err(|m| OutputError::read(&r.dir, m))?;
        let pga = r.spec.pga.ok_or_else(|| OutputError::read(&r.dir, "the run sets no `pga`"))?;
        // FEM: the slider's displacement along the slope, from its first sample
        let h = r.history(&self.params.monitor)?;
        let u = h.vectors(["ux", "uy", "uz"])?;
        let (first, last) = match (u.first(), u.last()) {
            (Some(a), Some(b)) => (*a, *b),
            _ => return Err(OutputError::read(&h.path, "no history rows").into()),
        };
        let d = self.down_slope();
        let fem_slip: f64 = (0..3).map(|k| (last[k] - first[k]) * d[k]).sum();
        // the rigid block under the same records
        let (motions, _) = base_motions(scene)?;
        let dt = motions.iter().map(|b| b.record.dt).fold(f64::INFINITY, f64::min);
        let a = sample_ground_motion(&motions, dt, scene.time.duration);
        let [x, y] = self.params.uphill;
        let n = (x * x + y * y).sqrt();
        let a_h: Vec<f64> = a.iter().map(|v| (v[0] * x + v[1] * y) / n).collect();
        let a_v: Vec<f64> = a.iter().map(|v| v[2]).collect();
        let incline = Incline { g: scene.g, ..Incline::frictional(self.params.beta, phi) };
        let vertical = a_v.iter().any(|&v| v != 0.0).then_some(a_v.as_slice());
        let nm = slide_block(&incline, Direction::OneWay, &a_h, vertical, &NewmarkOptions::new(dt))?;
        let ky = incline.yield_acceleration_down()? / scene.g;
        let difference = (nm.residual_displacement > 1e-6).then(|| fem_slip / nm.residual_displacement - 1.0);
        Ok(InclineRun {
            id: r.spec.id.clone(),
            phi,
            pga,
            yield_acceleration: ky,
            fem_slip,
            newmark_slip: nm.residual_displacement,
            newmark_episodes: nm.n_episodes,
            difference,
        })
    }
}

impl StudyKind for InclineKind {
    fn check(&self, study: &Study) -> Result<(), Error> {
        let p = &self.params;
        let invalid = |message: String| -> Error { StudyError::Invalid { path: study.path.clone(), message: format!("`report` (kind \"incline\"): {message}") }.into() };
        if !(p.beta.is_finite() && p.beta > 0.0 && p.beta < 90.0) {
            return Err(invalid(format!("`beta` = {} must be an angle in (0, 90) [deg]", p.beta)));
        }
        if !(p.uphill[0].is_finite() && p.uphill[1].is_finite()) || p.uphill[0].hypot(p.uphill[1]) == 0.0 {
            return Err(invalid(format!("`uphill` = {:?} must be a non-zero horizontal direction", p.uphill)));
        }
        if p.tolerance.is_nan() || p.tolerance <= 0.0 {
            return Err(invalid(format!("`tolerance` = {} must be positive", p.tolerance)));
        }
        let base = Scene::load(&study.scene)?;
        if !base.output.monitor.iter().any(|m| m.name == p.monitor) {
            return Err(invalid(format!("`monitor`: the base scene has no monitor \"{}\"", p.monitor)));
        }
        self.phi_of(&base).map_err(|m| invalid(format!("`joint`: {m}")))?;
        Ok(())
    }

    fn report(&self, results: &StudyResults) -> Result<KindReport, Error> {
        let mut rows = Vec::new();
        let mut unreadable = Vec::new();
        let mut stopped = Vec::new();
        for r in results.runs.iter().filter(|r| r.has_results()) {
            match (r.failed(), self.run(r)) {
                (Some(e), _) => stopped.push((r.spec.id.clone(), e.to_string())),
                (None, Ok(x)) => rows.push(x),
                (None, Err(e)) => unreadable.push((r.spec.id.clone(), e.to_string())),
            }
        }
        rows.sort_by(|a, b| a.phi.total_cmp(&b.phi).then(a.pga.total_cmp(&b.pga)));
        let m = |x: f64| fmt_sig(x, 4);
        let p = &self.params;
        let mut md = String::new();
        let _ = writeln!(md, "# Incline study: a block on a {}° incline, friction angle × PGA\n", m(p.beta));
        let _ = writeln!(md, "Generated by `jointquake study report` from `{}`; base scene `{}`. Units SI; slip in m, down the slope.\n", results.plan.study.display(), results.study.scene.display());
        let _ = writeln!(md, "FEM: residual slip of the slider monitor `{}` along the slope. Reference: the rigid Newmark block (one-way, cohesionless) with the run's friction angle under the run's own records (horizontal component along the uphill direction {:?}, positive into the hill, and the vertical one), yield acceleration g tan(φ − β). A run more than {} off the reference is flagged.\n", p.monitor, p.uphill, fmt_percent(p.tolerance, 0));
        let mut t = Table::new(["φ [deg]", "PGA [g]", "yield acc. [g]", "FEM slip", "Newmark slip", "Newmark episodes", "FEM − Newmark", "run"]);
        let mut flagged = Vec::new();
        for r in &rows {
            let diff = match r.difference {
                Some(d) => {
                    if d.abs() > p.tolerance {
                        flagged.push(r.id.clone());
                        format!("{} (outside {})", fmt_percent(d, 1), fmt_percent(p.tolerance, 0))
                    } else {
                        fmt_percent(d, 1)
                    }
                }
                None => format!("Newmark: no slip (FEM {})", m(r.fem_slip)),
            };
            let _ = t.push_row([m(r.phi), m(r.pga), m(r.yield_acceleration), m(r.fem_slip), m(r.newmark_slip), r.newmark_episodes.to_string(), diff, format!("`{}`", r.id)]);
        }
        md.push_str(&t.to_markdown());
        if !stopped.is_empty() {
            let _ = writeln!(md, "\nRuns stopped by an error (left out of the table):\n");
            for (id, e) in &stopped {
                let _ = writeln!(md, "- `{id}`: {e}");
            }
        }
        // chart: slip against PGA, one FEM series and one Newmark series per friction angle
        let mut phis: Vec<f64> = rows.iter().map(|r| r.phi).collect();
        phis.dedup();
        let mut c = Chart::new(format!("Residual slip against PGA, {}° incline", m(p.beta)), "PGA [g]", "residual slip down the slope [m]");
        for &phi in &phis {
            let of = |f: &dyn Fn(&InclineRun) -> f64| rows.iter().filter(|r| r.phi == phi).map(|r| (r.pga, f(r))).collect::<Vec<_>>();
            c.series.push(Series::markers(format!("FEM, φ = {}°", m(phi)), of(&|r| r.fem_slip)));
            c.series.push(Series::line(format!("rigid Newmark, φ = {}°", m(phi)), of(&|r| r.newmark_slip)));
        }
        let mut charts = Vec::new();
        if !rows.is_empty() {
            charts.push(c.write_png_svg(&results.plan.out.join("charts").join("slip_vs_pga"))?.png);
            let _ = writeln!(md, "\n![slip against PGA](charts/slip_vs_pga.svg)");
        }
        let worst = rows.iter().filter_map(|r| r.difference.map(|d| (d, &r.id))).max_by(|a, b| a.0.abs().total_cmp(&b.0.abs()));
        let mut lines = vec![format!("{} runs against the rigid Newmark block", rows.len())];
        if let Some((d, id)) = worst {
            lines.push(format!("largest difference {} ({id})", fmt_percent(d, 1)));
        }
        if !flagged.is_empty() {
            lines.push(format!("outside {}: {}", fmt_percent(p.tolerance, 0), flagged.join(", ")));
        }
        Ok(KindReport { markdown: md, json: serde_json::json!({ "runs": rows, "stopped": stopped }), charts, lines, unreadable, lists_failed: true })
    }
}

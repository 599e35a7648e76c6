//! The dam report's table of models (issues 28 and 29): one row per (reservoir, foundation)
//! model of the study's runs on the main mesh with NTS joints, the seed's model (Westergaard
//! added mass on a massless rock) first; columns f1, its drop from the empty reservoir and the
//! first mode's damping (from the model's free-vibration run after a pulse, [`super::decay`]),
//! then per level the largest joint opening, the largest net slip and the faces' largest σ1
//! and most compressive σ3. A headline computed from the table says what the seed's
//! conservatism costs in mm and MPa against the best-practice model present.
//!
//! Inputs: the report's runs ([`super::report::DamReport::all`]). Output: a Markdown section
//! (nothing when the study has only the seed's model) and [`ModelRow`]s for the report's JSON.
//! Conventions: lengths in mm, stresses in MPa (tension positive), f in Hz, ξ and drops in %.

use super::decay::{fit_free_decay, DecayFit};
use super::report::{DamReport, Doc};
use super::{DamRun, Method, SEED_FOUNDATION, SEED_RESERVOIR};
use std::fmt::Write;

/// The reservoir models a current dam engineer would choose, best first (compressible water,
/// then incompressible potential flow on the meshed valley), and the foundation model.
const BEST_RESERVOIRS: [&str; 2] = ["acoustic", "fe_incompressible"];
const BEST_FOUNDATION: &str = "radiating";

/// One level's numbers of a model: largest opening and net slip [m], largest σ1 and most
/// compressive σ3 over both faces [Pa] (`None` when the run stopped before the envelope).
#[derive(Clone, Debug, serde::Serialize)]
pub struct LevelCells {
    pub level: f64,
    pub opening: f64,
    pub slip: f64,
    pub tension: Option<f64>,
    pub compression: Option<f64>,
    /// The run stopped (its numbers cover the record up to there).
    pub stopped: bool,
}

/// One model's row.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ModelRow {
    pub reservoir: String,
    pub foundation: String,
    /// The fit of its pulse run's crest decay (first mode first).
    pub decay: Option<DecayFit>,
    /// 1 − f1 / f1(empty reservoir, same foundation) [-].
    pub drop: Option<f64>,
    pub levels: Vec<LevelCells>,
}

impl ModelRow {
    fn is_seed(&self) -> bool {
        self.reservoir == SEED_RESERVOIR && self.foundation == SEED_FOUNDATION
    }
    fn f1(&self) -> Option<f64> {
        self.decay.as_ref().and_then(|d| d.modes.first()).map(|m| m.frequency)
    }
    fn at(&self, level: f64) -> Option<&LevelCells> {
        self.levels.iter().find(|c| (c.level - level).abs() < 1e-6)
    }
}

/// The table's rows (module doc), the seed's first, then by reservoir and foundation.
pub fn model_rows(r: &DamReport) -> Vec<ModelRow> {
    let p = r.params();
    let main: Vec<&DamRun> = r.all.iter().filter(|x| x.is_main(p)).collect();
    let mut keys: Vec<(String, String)> = main.iter().filter(|x| x.pulse || x.method == Method::Nts).map(|x| (x.reservoir.clone(), x.foundation.clone())).collect();
    keys.sort();
    keys.dedup();
    let fit = |res: &str, fnd: &str| -> Option<DecayFit> {
        let pp = p.pulse.as_ref()?;
        let run = main.iter().find(|x| x.pulse && x.reservoir == res && x.foundation == fnd && x.failed.is_none())?;
        // the crown's cross-stream motion: the first mode is antisymmetric (docs/dam.md "Modes"),
        // so the cross-stream pulse drives it and it moves the crown along the crest, where the
        // symmetric modes do not move it (at the quarter points the 4th mode, antisymmetric too,
        // dominates: measured on the coarse dam)
        let (t, u): (Vec<f64>, Vec<f64>) = run.crown_x.iter().copied().unzip();
        fit_free_decay(&t, &u, pp.start, pp.band[0], pp.band[1], 2)
    };
    // the empty reservoir's rows too: their f1 and ξ1 are the dam's own on each rock (no
    // earthquake run: their level cells are –)
    let mut rows: Vec<ModelRow> = keys
        .iter()
        .map(|(res, fnd)| {
            let decay = fit(res, fnd);
            let empty = fit("empty", fnd).and_then(|d| d.modes.first().map(|m| m.frequency));
            let drop = match (decay.as_ref().and_then(|d| d.modes.first()), empty) {
                (Some(m), Some(fe)) if fe > 0.0 => Some(1.0 - m.frequency / fe),
                _ => None,
            };
            let mut levels: Vec<LevelCells> = main
                .iter()
                .filter(|x| !x.pulse && x.method == Method::Nts && x.reservoir == *res && x.foundation == *fnd)
                .map(|x| LevelCells {
                    level: x.level,
                    opening: x.max_opening().1,
                    slip: x.max_slip().1,
                    tension: x.stress.as_ref().map(|s| s.tension()),
                    compression: x.stress.as_ref().map(|s| s.compression()),
                    stopped: x.failed.is_some(),
                })
                .collect();
            levels.sort_by(|a, b| a.level.total_cmp(&b.level));
            ModelRow { reservoir: res.clone(), foundation: fnd.clone(), decay, drop, levels }
        })
        .collect();
    rows.sort_by_key(|x| !x.is_seed());
    rows
}

/// The best-practice row present (module doc: [`BEST_RESERVOIRS`] on [`BEST_FOUNDATION`]).
fn best(rows: &[ModelRow]) -> Option<&ModelRow> {
    BEST_RESERVOIRS.iter().find_map(|b| rows.iter().find(|x| x.reservoir == *b && x.foundation == BEST_FOUNDATION))
}

fn cell(x: Option<f64>, scale: f64, digits: usize) -> String {
    x.map(|v| format!("{:.*}", digits, v * scale)).unwrap_or_else(|| "–".into())
}

/// The headline: what the seed's model costs against the best-practice one, per level both
/// have (or why it cannot be said).
fn headline(rows: &[ModelRow], levels: &[f64]) -> String {
    let mut s = String::from(
        "The seed used the generalised Westergaard added mass (7/8 ρw √(H (z_w − z)) per unit area) on a massless rock shaken rigidly at its far boundary: the conservative textbook model of the 1970s. A current dam engineer would model the water as a fluid on the meshed valley (compressible `acoustic`, or `fe_incompressible` where compressibility is not at stake) and the rock with its mass, absorbing far boundaries and the free-field input (`radiating`: the direct finite-element method of Løkke & Chopra), because the Westergaard mass cannot see the narrow valley or the 3-D flow around the curved face, and a massless rock can neither resonate nor carry energy away. ",
    );
    let (Some(seed), Some(b)) = (rows.iter().find(|x| x.is_seed()), best(rows)) else {
        s.push_str("The study has not both the seed's model and a best-practice model (fe_incompressible or acoustic water on the radiating rock) among its runs: the cost of the seed's conservatism is not measured here.");
        return s;
    };
    let name = format!("{} + {}", b.reservoir, b.foundation);
    if let (Some(f0), Some(f1)) = (seed.f1(), b.f1()) {
        let _ = write!(s, "Against {name}, the seed's model has f1 {f0:.3} Hz against {f1:.3} Hz. ");
    }
    let mut any = false;
    for &l in levels {
        let (Some(a), Some(c)) = (seed.at(l), b.at(l)) else { continue };
        any = true;
        let d_open = a.opening - c.opening;
        let verb = |d: f64| if d >= 0.0 { "more" } else { "less" };
        let _ = write!(
            s,
            "At {} the seed's model opens the joints by {:.1} mm against {:.1} mm ({:.1} mm {}, {:+.0} %)",
            super::report::lvl(l),
            a.opening * 1e3,
            c.opening * 1e3,
            d_open.abs() * 1e3,
            verb(d_open),
            100.0 * d_open / c.opening.max(1e-12)
        );
        if let (Some(ta), Some(tc), Some(ca), Some(cc)) = (a.tension, c.tension, a.compression, c.compression) {
            let _ = write!(s, ", with a largest tension of {:.1} against {:.1} MPa ({:+.1} MPa) and compression {:.1} against {:.1} MPa ({:+.1} MPa)", ta / 1e6, tc / 1e6, (ta - tc) / 1e6, ca / 1e6, cc / 1e6, (ca - cc) / 1e6);
        }
        if a.stopped || c.stopped {
            s.push_str(" (a run stopped: its numbers cover the record up to there)");
        }
        s.push_str(". ");
    }
    if !any {
        let _ = write!(s, "The seed's model and {name} share no level among their earthquake runs: the cost in mm and MPa is not measured here.");
    }
    s
}

/// The section (nothing when only the seed's model ran).
pub fn models_table_section(r: &DamReport, doc: &mut Doc) {
    let rows = model_rows(r);
    if rows.len() < 2 && rows.iter().all(|x| x.decay.is_none()) {
        return;
    }
    let mut levels: Vec<f64> = rows.iter().flat_map(|x| x.levels.iter().map(|c| c.level)).collect();
    levels.sort_by(f64::total_cmp);
    levels.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
    let md = &mut doc.md;
    let _ = writeln!(md, "\n## Models: reservoir × foundation\n");
    let _ = writeln!(md, "{}\n", headline(&rows, &levels));
    let _ = writeln!(
        md,
        "Main mesh, NTS joints. f1 and ξ1: the first mode's frequency and damping ratio, fitted to the crown's cross-stream motion in free vibration after a cross-stream pulse (joints bonded; two damped modes by least squares, src/studies/dam/decay.rs); drop: 1 − f1 / f1 with the reservoir empty on the same rock. Per level: largest joint opening, largest net slip [mm], the faces' largest σ1 and most compressive σ3 [MPa]. – : no run. Displacements of every foundation model are relative to the free field (the rigid base motion for massless and massed_fixed; for radiating the 1-D free field at each node's elevation taken off its total motion). massed_fixed is the reflecting check: a closed rock box whose waves cannot leave, its numbers an upper bound, not a design model.\n"
    );
    let mut head = String::from("| reservoir | foundation | f1 [Hz] | drop [%] | ξ1 [%] |");
    let mut rule = String::from("|---|---|---|---|---|");
    for &l in &levels {
        let x = super::report::lvl(l);
        let _ = write!(head, " opening {x} | slip {x} | σ1 {x} | σ3 {x} |");
        rule.push_str("---|---|---|---|");
    }
    let _ = writeln!(md, "{head}\n{rule}");
    for row in &rows {
        let first = row.decay.as_ref().and_then(|d| d.modes.first());
        let tag = if row.is_seed() { " (the seed's)" } else if best(&rows).is_some_and(|b| std::ptr::eq(b, row)) { " (best practice)" } else { "" };
        let _ = write!(
            md,
            "| {}{tag} | {} | {} | {} | {} |",
            row.reservoir,
            row.foundation,
            cell(first.map(|m| m.frequency), 1.0, 3),
            cell(row.drop, 100.0, 1),
            cell(first.map(|m| m.damping), 100.0, 2)
        );
        for &l in &levels {
            match row.at(l) {
                Some(c) => {
                    let st = if c.stopped { " (stopped)" } else { "" };
                    let _ = write!(md, " {:.1}{st} | {:.1} | {} | {} |", c.opening * 1e3, c.slip * 1e3, cell(c.tension, 1e-6, 1), cell(c.compression, 1e-6, 1));
                }
                None => md.push_str(" – | – | – | – |"),
            }
        }
        md.push('\n');
    }
}

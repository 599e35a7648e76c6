//! The dam study's report: tables and charts from the runs read by [`super::DamKind::run`].
//! Every number in a table comes from a run or from the study file's `seed` (the paper's
//! values, quoted as such); a run without results is left out and named.
//!
//! [`report`] is a list of section calls: a section is one table or chart (or a family of them,
//! one per level) with its text, a function `fn(&DamReport, &mut Doc)` that reads the runs
//! ([`DamReport`], read once) and appends to the document ([`Doc`]: the Markdown and the charts
//! written). A new section is a function (in its own file under `studies/dam/` if it is large)
//! and one call here.

use super::convergence::{verdict_above, verdict_close};
use super::reference::{DamReference, Quantity as Q};
use super::{DamKind, DamParams, DamRun, Method};
use crate::error::Error;
use crate::report::{Axis, Chart, Series, Table, fmt_percent, fmt_sig, pareto_front};
use crate::study::{KindReport, StudyResults};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::PathBuf;

/// A seed claim checked against our numbers.
#[derive(Clone, Debug, Serialize)]
pub struct Claim {
    pub claim: String,
    /// What we measured.
    pub ours: String,
    /// `Some(true)` agreed, `Some(false)` not agreed, `None` not checkable (runs missing).
    pub agreed: Option<bool>,
    /// The difference is within the discretisation error band (the reference's): neither
    /// agreed nor not agreed, whatever the sign (`agreed` keeps the sign for the record).
    pub not_resolved: bool,
    /// The error band the verdict used, in words (empty for a claim without one).
    pub band: String,
}

impl Claim {
    /// As the report writes the verdict.
    pub fn verdict(&self) -> &'static str {
        match (self.not_resolved, self.agreed) {
            (true, _) => "not resolved",
            (false, Some(true)) => "agreed",
            (false, Some(false)) => "**not agreed**",
            (false, None) => "not checked (a run is missing or stopped)",
        }
    }
}

/// A cheaper run against its level's reference.
#[derive(Clone, Debug, Serialize)]
pub struct Accuracy {
    pub id: String,
    pub level: f64,
    pub reference: String,
    pub wall_time: f64,
    pub error_opening: f64,
    pub error_slip: f64,
    pub error_tension: Option<f64>,
    pub error_compression: Option<f64>,
    /// The largest of the errors.
    pub error: f64,
}

pub(super) fn mm(x: f64) -> String {
    fmt_sig(1e3 * x, 4)
}
pub(super) fn mpa(x: f64) -> String {
    fmt_sig(1e-6 * x, 4)
}
/// A level as `1×`, `0.1×`, `2.5×` (3 decimals at most).
pub(super) fn lvl(x: f64) -> String {
    format!("{}×", lvl_num(x))
}
pub(super) fn lvl_num(x: f64) -> f64 {
    (1e3 * x).round() / 1e3
}
/// " (stopped at t = … s)" for a run that stopped, else nothing: its maxima are up to there.
fn stopped(r: &DamRun) -> String {
    if r.failed.is_some() {
        format!(" (stopped at t = {} s)", fmt_sig(r.t_end, 3))
    } else {
        String::new()
    }
}
fn rel(a: f64, b: f64) -> f64 {
    if b != 0.0 { a / b - 1.0 } else { f64::NAN }
}
fn same(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-6 * b.abs().max(1e-12)
}

/// The runs the report reads, sorted by level, method, mesh, and the levels they cover.
pub struct DamReport<'a> {
    pub kind: &'a DamKind,
    pub results: &'a StudyResults<'a>,
    pub runs: Vec<DamRun>,
    /// Every run read, the other reservoir and foundation models and the pulse runs too (the
    /// models table's); `runs` holds the seed's model only.
    pub all: Vec<DamRun>,
    /// Runs whose results could not be read: (id, why).
    pub unreadable: Vec<(String, String)>,
    /// Distinct levels, ascending.
    pub levels: Vec<f64>,
    /// The highest level.
    pub top: Option<f64>,
    /// The extrapolated reference (`report.reference`), or why there is none.
    pub reference: Result<DamReference, String>,
}

impl<'a> DamReport<'a> {
    /// Reads every run with results through [`DamKind::run`].
    pub fn read(kind: &'a DamKind, results: &'a StudyResults<'a>) -> DamReport<'a> {
        let mut all: Vec<DamRun> = Vec::new();
        let mut unreadable = Vec::new();
        for r in results.runs.iter().filter(|r| r.has_results()) {
            match kind.run(r) {
                Ok(x) => all.push(x),
                Err(e) => unreadable.push((r.spec.id.clone(), e.to_string())),
            }
        }
        let mut runs: Vec<DamRun> = all.iter().filter(|x| x.is_seed_model()).cloned().collect();
        runs.sort_by(|a, b| {
            a.level
                .total_cmp(&b.level)
                .then(a.method.cmp(&b.method))
                .then(a.mesh.cmp(&b.mesh))
        });
        let mut levels: Vec<f64> = runs.iter().map(|r| r.level).collect();
        levels.dedup_by(|a, b| same(*a, *b));
        let top = levels.last().copied();
        let reference = match &kind.reference_path {
            None => Err("the study file names no `report.reference`".to_string()),
            Some(path) if !path.exists() => Err(format!("{} is absent (`make dam-convergence` writes it)", path.display())),
            Some(path) => DamReference::read(path).map_err(|e| e.to_string()),
        };
        DamReport {
            reference,
            kind,
            results,
            runs,
            all,
            unreadable,
            levels,
            top,
        }
    }

    pub fn params(&self) -> &DamParams {
        &self.kind.params
    }

    /// The run at `level` with method `m`, on the main mesh (`main`) or another.
    pub fn find(&self, level: f64, m: Method, main: bool) -> Option<&DamRun> {
        let p = self.params();
        self.runs
            .iter()
            .find(|r| same(r.level, level) && r.method == m && r.is_main(p) == main)
    }
}

/// The report being written: its Markdown and the charts written so far.
pub struct Doc {
    pub md: String,
    pub charts: Vec<PathBuf>,
    /// Where the charts go (`<out>/charts`).
    pub charts_dir: PathBuf,
}

impl Doc {
    /// Writes `c` as `charts/<stem>.png` and `.svg` and embeds the SVG.
    pub fn chart(&mut self, c: &Chart, stem: &str) -> Result<(), Error> {
        self.charts
            .push(c.write_png_svg(&self.charts_dir.join(stem))?.png);
        let _ = writeln!(self.md, "\n![{}](charts/{stem}.svg)\n", c.title);
        Ok(())
    }
}

pub fn report(kind: &DamKind, results: &StudyResults) -> Result<KindReport, Error> {
    let r = DamReport::read(kind, results);
    let mut doc = Doc {
        md: String::new(),
        charts: Vec::new(),
        charts_dir: results.plan.out.join("charts"),
    };
    heading_section(&r, &mut doc);
    runs_section(&r, &mut doc);
    per_joint_section(&r, &mut doc, Quantity::Opening)?;
    per_joint_section(&r, &mut doc, Quantity::Slip)?;
    largest_opening_section(&r, &mut doc);
    largest_slip_section(&r, &mut doc);
    stress_section(&r, &mut doc);
    objective_stress_section(&r, &mut doc);
    linearised_stress_section(&r, &mut doc);
    stress_against_seed_section(&r, &mut doc);
    super::face_maps::face_maps_section(&r, &mut doc)?;
    super::joint_maps::joint_maps_section(&r, &mut doc)?;
    super::paraview_state::paraview_state_section(&r, &mut doc)?;
    super::joint_maps::lost_nodes_section(&r, &mut doc);
    super::models_table::models_table_section(&r, &mut doc);
    histories_section(&r, &mut doc)?;
    reference_section(&r, &mut doc);
    let claims = claims(kind, &r.runs, &r.levels, r.reference.as_ref().ok());
    claims_section(&claims, &mut doc);
    let acc = accuracy(&r);
    speed_table_section(&r, &acc, &mut doc);
    speed_chart_section(&r, &acc, &mut doc)?;
    ntn_error_section(&r, &mut doc)?;
    search_section(&r, &mut doc);
    stopped_section(&r, &mut doc);

    let mut lines = vec![format!(
        "{} runs read at {} levels",
        r.runs.len(),
        r.levels.len()
    )];
    for c in &claims {
        lines.push(format!(
            "{}: {}",
            match (c.not_resolved, c.agreed) {
                (true, _) => "not resolved",
                (false, Some(true)) => "agreed",
                (false, Some(false)) => "NOT agreed",
                (false, None) => "not checked",
            },
            c.claim
        ));
    }
    let json = serde_json::json!({ "runs": r.runs, "claims": claims, "accuracy": acc, "models": super::models_table::model_rows(&r) });
    Ok(KindReport {
        markdown: doc.md,
        json,
        charts: doc.charts,
        lines,
        unreadable: r.unreadable,
        lists_failed: true,
    })
}

/// Title and what the numbers are.
fn heading_section(r: &DamReport, doc: &mut Doc) {
    let p = r.params();
    let md = &mut doc.md;
    let _ = writeln!(
        md,
        "# Arch dam study: contraction joints at 1×, 2×, 3× the design PGA, NTS against NTN\n"
    );
    let _ = writeln!(
        md,
        "Generated by `jointquake study report` from `{}`; base scene `{}`. Design PGA {} g; a run's level is its PGA over it. Main mesh `{}`. Opening and slip are the largest over each joint's slave nodes and over the record (`histories/joint_<J>.csv`), in mm; stresses are the envelopes over time of the principal stresses of the elements under the faces (`envelope.json`, `envelope.vtu` per run), in MPa, tension positive. The seed's values (`seed` in the study file: {}) are for its own dam, whose shape it does not publish (docs/dam.md): compare trends and orders of magnitude, not digits.\n",
        r.results.plan.study.display(),
        r.results.study.scene.display(),
        fmt_sig(p.design_pga, 4),
        p.main_mesh,
        p.seed.source
    );
}

/// The runs read: method, level, mesh, status, time reached, wall time.
fn runs_section(r: &DamReport, doc: &mut Doc) {
    let _ = writeln!(doc.md, "## Runs\n");
    let mut t = Table::new([
        "run",
        "method",
        "level",
        "mesh",
        "status",
        "record reached [s]",
        "wall time [s]",
    ]);
    for r in &r.runs {
        let status = match &r.failed {
            Some(e) => format!("**failed**: {e}"),
            None => "finished".into(),
        };
        let _ = t.push_row([
            format!("`{}`", r.id),
            r.method.name().into(),
            lvl(r.level),
            r.mesh.clone(),
            status,
            fmt_sig(r.t_end, 4),
            r.wall_time.map_or("–".into(), |w| fmt_sig(w, 4)),
        ]);
    }
    doc.md.push_str(&t.to_markdown());
}

/// A joint quantity of the per-joint charts.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Quantity {
    Opening,
    Slip,
}

impl Quantity {
    fn name(self) -> &'static str {
        match self {
            Quantity::Opening => "opening",
            Quantity::Slip => "slip",
        }
    }
    /// Per joint [m].
    fn of(self, r: &DamRun) -> &[f64] {
        match self {
            Quantity::Opening => &r.opening,
            Quantity::Slip => &r.slip,
        }
    }
    /// The seed's figure of it.
    fn seed_figure(self) -> &'static str {
        match self {
            Quantity::Opening => "13",
            Quantity::Slip => "14",
        }
    }
    /// (joint index, value) of the largest over the joints.
    fn max(self, r: &DamRun) -> (usize, f64) {
        match self {
            Quantity::Opening => r.max_opening(),
            Quantity::Slip => r.max_slip(),
        }
    }
}

/// The largest opening (or slip) of each joint, one chart per level (the seed's figure 13 / 14).
fn per_joint_section(r: &DamReport, doc: &mut Doc, q: Quantity) -> Result<(), Error> {
    let what = q.name();
    let _ = writeln!(
        doc.md,
        "\n## Largest {what} of each joint (the seed's figure {})\n",
        q.seed_figure()
    );
    for &l in &r.levels {
        let mut c = Chart::new(
            format!("Largest joint {what} over the record, {}", lvl(l)),
            "joint number (1 = left bank) [-]",
            format!("largest {what} [mm]"),
        );
        for m in [Method::Nts, Method::Ntn, Method::NtsLayer2] {
            if let Some(run) = r.find(l, m, true) {
                c.series.push(Series::line_markers(
                    m.name(),
                    q.of(run)
                        .iter()
                        .enumerate()
                        .map(|(i, x)| ((i + 1) as f64, 1e3 * x)),
                ));
            }
        }
        if !c.series.is_empty() {
            doc.chart(&c, &format!("{what}_per_joint_{}x", lvl_num(l)))?;
        }
    }
    Ok(())
}

/// NTS's and NTN's (value with "stopped at", joint) of the largest `q` at level `l`, and
/// NTS / NTN − 1 when both finished.
fn nts_ntn_cells(r: &DamReport, l: f64, q: Quantity) -> [String; 5] {
    let (nts, ntn) = (r.find(l, Method::Nts, true), r.find(l, Method::Ntn, true));
    let cell = |x: Option<&DamRun>| {
        x.map_or(("–".to_string(), "–".to_string()), |x| {
            (
                format!("{}{}", mm(q.max(x).1), stopped(x)),
                x.joints[q.max(x).0].clone(),
            )
        })
    };
    let (a, ja) = cell(nts);
    let (b, jb) = cell(ntn);
    let d = match (nts, ntn) {
        (Some(x), Some(y)) if x.failed.is_none() && y.failed.is_none() => {
            fmt_percent(rel(q.max(x).1, q.max(y).1), 1)
        }
        _ => "–".into(),
    };
    [a, ja, b, jb, d]
}

/// The largest opening over all joints per level, NTS and NTN, ours and the seed's.
fn largest_opening_section(r: &DamReport, doc: &mut Doc) {
    let p = r.params();
    let _ = writeln!(doc.md, "\n### Largest opening over all joints [mm]\n");
    let mut t = Table::new([
        "level",
        "NTS (ours)",
        "joint",
        "NTN (ours)",
        "joint",
        "NTS / NTN − 1",
        "NTS (seed)",
        "NTN (seed)",
    ]);
    for &l in &r.levels {
        let [a, ja, b, jb, d] = nts_ntn_cells(r, l, Quantity::Opening);
        let k = p.seed.levels.iter().position(|&s| same(s, l));
        let s = |v: &Vec<f64>| k.map_or("–".to_string(), |k| fmt_sig(v[k], 4));
        let _ = t.push_row([
            lvl(l),
            a,
            ja,
            b,
            jb,
            d,
            s(&p.seed.opening_nts_mm),
            s(&p.seed.opening_ntn_mm),
        ]);
    }
    doc.md.push_str(&t.to_markdown());
}

/// The largest slip over all joints per level, NTS and NTN, and the seed's NTS / NTN.
fn largest_slip_section(r: &DamReport, doc: &mut Doc) {
    let p = r.params();
    let _ = writeln!(doc.md, "\n### Largest slip over all joints [mm]\n");
    let mut t = Table::new([
        "level",
        "NTS (ours)",
        "joint",
        "NTN (ours)",
        "joint",
        "NTS / NTN − 1 (ours)",
        "NTS / NTN − 1 (seed)",
    ]);
    for &l in &r.levels {
        let [a, ja, b, jb, d] = nts_ntn_cells(r, l, Quantity::Slip);
        let seed = if Some(l) == r.top && p.seed.levels.last().is_some_and(|&s| same(s, l)) {
            fmt_percent(p.seed.slip_nts_over_ntn, 1)
        } else {
            "–".into()
        };
        let _ = t.push_row([lvl(l), a, ja, b, jb, d, seed]);
    }
    doc.md.push_str(&t.to_markdown());
}

/// The face stress extremes of every run with an envelope (the seed's figures 15–16).
fn stress_section(r: &DamReport, doc: &mut Doc) {
    let p = r.params();
    let md = &mut doc.md;
    let _ = writeln!(
        md,
        "\n## Face stresses: envelopes of the principal stresses (the seed's figures 15–16)\n"
    );
    let _ = writeln!(
        md,
        "Each run writes `envelope.vtu` (in its run directory): per face of `{}` and `{}` the largest σ1 (`max_principal`) and smallest σ3 (`min_principal`) over the record, and when; open it in ParaView and colour by either field. The table gives the extremes over each face.\n",
        p.faces.upstream, p.faces.downstream
    );
    let mut t = Table::new([
        "level",
        "run",
        "tension upstream",
        "tension downstream",
        "compression upstream",
        "compression downstream",
        "largest tension: where (x, y, z) [m], t [s]",
    ]);
    for r in r.runs.iter().filter(|r| r.stress.is_some()) {
        let s = r.stress.as_ref().expect("filtered");
        let w = if s.upstream_tension.value >= s.downstream_tension.value {
            &s.upstream_tension
        } else {
            &s.downstream_tension
        };
        let _ = t.push_row([
            lvl(r.level),
            format!("{} {}", r.method.name(), r.mesh),
            mpa(s.upstream_tension.value),
            mpa(s.downstream_tension.value),
            mpa(s.upstream_compression.value),
            mpa(s.downstream_compression.value),
            format!(
                "({:.0}, {:.0}, {:.0}), {}",
                w.position[0],
                w.position[1],
                w.position[2],
                fmt_sig(w.t, 3)
            ),
        ]);
    }
    md.push_str(&t.to_markdown());
}

/// The largest tension and compression at the highest level, NTS, NTN and monolithic against
/// the seed's (quoted only when the seed's stresses are at that level).
fn stress_against_seed_section(r: &DamReport, doc: &mut Doc) {
    let Some(l) = r.top else { return };
    let p = r.params();
    let md = &mut doc.md;
    // the seed's stresses are at its highest level: quoted only against ours at that level
    let seed_here = p.seed.levels.last().is_some_and(|&s| same(s, l));
    let sd = |x: f64| {
        if seed_here {
            fmt_sig(x, 4)
        } else {
            "–".to_string()
        }
    };
    let _ = writeln!(
        md,
        "\nAt {} against the seed [MPa]{}:\n",
        lvl(l),
        if seed_here {
            ""
        } else {
            " (the seed's values are at another level: not quoted)"
        }
    );
    let mut t = Table::new([
        "",
        "NTS (ours)",
        "NTN (ours)",
        "monolithic (ours)",
        "NTS (seed)",
        "NTN (seed)",
    ]);
    let g = |m: Method, f: &dyn Fn(&super::FaceStress) -> f64| {
        r.find(l, m, true)
            .and_then(|r| r.stress.as_ref())
            .map_or("–".to_string(), |s| mpa(f(s)))
    };
    let _ = t.push_row([
        "largest tension".to_string(),
        g(Method::Nts, &|s| s.tension()),
        g(Method::Ntn, &|s| s.tension()),
        g(Method::Monolithic, &|s| s.tension()),
        sd(p.seed.tension_nts_mpa),
        sd(p.seed.tension_ntn_mpa),
    ]);
    let _ = t.push_row([
        "largest compression".to_string(),
        g(Method::Nts, &|s| s.compression()),
        g(Method::Ntn, &|s| s.compression()),
        g(Method::Monolithic, &|s| s.compression()),
        sd(p.seed.compression_nts_mpa),
        sd(p.seed.compression_ntn_mpa),
    ]);
    md.push_str(&t.to_markdown());
    if let (Some(j), Some(mo)) = (
        r.find(l, Method::Nts, true).and_then(|r| r.stress.as_ref()),
        r.find(l, Method::Monolithic, true)
            .and_then(|r| r.stress.as_ref()),
    ) {
        let _ = writeln!(
            md,
            "\nThe joints release arch tension: NTS's largest tension is {} of the monolithic dam's ({} against {} MPa).",
            fmt_percent(j.tension() / mo.tension(), 0),
            mpa(j.tension()),
            mpa(mo.tension())
        );
    }
}

/// Crest radial displacement and the worst joint's opening over time, per level, with the
/// crest peaks.
fn histories_section(r: &DamReport, doc: &mut Doc) -> Result<(), Error> {
    let p = r.params();
    let _ = writeln!(doc.md, "\n## Histories\n");
    let _ = writeln!(
        doc.md,
        "Crest radial displacement (positive downstream, relative to the base, from the static state) at the crown (`{}`) and the quarter points (`{}`, `{}`), and the largest opening of the joint with the largest opening.\n",
        p.monitors.crown, p.monitors.quarter_left, p.monitors.quarter_right
    );
    for &l in &r.levels {
        histories_charts(r, l, doc)?;
        crest_peaks_table(r, l, doc);
    }
    Ok(())
}

/// The crest and worst-joint histories at level `l` (NTS and NTN on the main mesh).
fn histories_charts(r: &DamReport, l: f64, doc: &mut Doc) -> Result<(), Error> {
    let mut c = Chart::new(
        format!("Crest radial displacement, {}", lvl(l)),
        "t [s]",
        "radial displacement [mm]",
    );
    let mut o = Chart::new(
        format!("Opening of the worst joint, {}", lvl(l)),
        "t [s]",
        "largest opening [mm]",
    );
    for m in [Method::Nts, Method::Ntn] {
        if let Some(r) = r.find(l, m, true) {
            for (name, h) in &r.crest {
                c.series.push(Series::line(
                    format!("{} {name}", m.name()),
                    h.iter().map(|&(t, u)| (t, 1e3 * u)),
                ));
            }
            let (k, _) = r.max_opening();
            o.series.push(Series::line(
                format!("{} {}", m.name(), r.joints[k]),
                r.worst_joint_history.iter().map(|&(t, u)| (t, 1e3 * u)),
            ));
        }
    }
    if !c.series.is_empty() {
        doc.chart(&c, &format!("crest_{}x", lvl_num(l)))?;
        doc.chart(&o, &format!("worst_joint_{}x", lvl_num(l)))?;
    }
    Ok(())
}

/// The largest crest radial displacements at level `l`.
fn crest_peaks_table(r: &DamReport, l: f64, doc: &mut Doc) {
    let mut t = Table::new([
        "run",
        "crown: largest |u_r| [mm]",
        "left quarter",
        "right quarter",
    ]);
    for m in [Method::Nts, Method::Ntn] {
        if let Some(r) = r.find(l, m, true) {
            let peak = |h: &Vec<(f64, f64)>| mm(h.iter().map(|x| x.1.abs()).fold(0.0, f64::max));
            let _ = t.push_row([
                format!("`{}`{}", r.id, stopped(r)),
                peak(&r.crest[0].1),
                peak(&r.crest[1].1),
                peak(&r.crest[2].1),
            ]);
        }
    }
    if !t.rows().is_empty() {
        doc.md.push_str(&t.to_markdown());
    }
}

/// The mesh-objective face stresses (outside the band at the rock) and the face areas above
/// the tension thresholds, per run.
fn objective_stress_section(r: &DamReport, doc: &mut Doc) {
    use crate::output::envelope::{OBJECTIVE_BAND, TENSION_THRESHOLDS};
    let md = &mut doc.md;
    let _ = writeln!(md, "\n## Face stresses outside the band at the rock, and the area above a tension\n");
    let _ = writeln!(
        md,
        "The raw element peaks above sit in the elements along the dam–rock contact and the abutments' re-entrant corners, where the elastic stress is singular and grows under refinement. Here the faces whose centre is within {} m of the face's contact line with the rock (its boundary except the crest and the joints' traces: `FaceEnvelope::objective`, src/output/envelope.rs) are left out; and, as USACE EM 1110-2-6053 plots demand against capacity, the area of each face whose largest σ1 exceeded {} MPa (`FaceEnvelope::area_above`).\n",
        fmt_sig(OBJECTIVE_BAND, 3),
        TENSION_THRESHOLDS.map(|t| fmt_sig(t * 1e-6, 2)).join(", ")
    );
    let mut head = vec!["level".to_string(), "run".into(), "tension up / down [MPa]".into(), "compression up / down [MPa]".into(), "faces kept / in band".into()];
    head.extend(TENSION_THRESHOLDS.iter().map(|t| format!("area > {} MPa up / down [m²]", fmt_sig(t * 1e-6, 2))));
    let mut t = Table::new(head);
    for x in r.runs.iter().filter(|x| x.stress.is_some()) {
        let s = x.stress.as_ref().expect("filtered");
        let (Some(u), Some(d)) = (&s.upstream_objective, &s.downstream_objective) else { continue };
        let mut row = vec![
            lvl(x.level),
            format!("{} {}", x.method.name(), x.mesh),
            format!("{} / {}", mpa(u.max_tension), mpa(d.max_tension)),
            format!("{} / {}", mpa(u.max_compression), mpa(d.max_compression)),
            format!("{} / {}", u.kept + d.kept, u.excluded + d.excluded),
        ];
        row.extend(s.areas_above.iter().map(|(_, a, b)| format!("{} / {}", fmt_sig(*a, 3), fmt_sig(*b, 3))));
        let _ = t.push_row(row);
    }
    md.push_str(&t.to_markdown());
}

/// The arch and cantilever stresses linearised through the thickness, per run: the largest
/// tension and compression at the upstream and downstream surface, over all cuts and outside the
/// band at the rock.
fn linearised_stress_section(r: &DamReport, doc: &mut Doc) {
    use crate::output::envelope::OBJECTIVE_BAND;
    use crate::output::linearise::LinearisedExtremes;
    let runs: Vec<&DamRun> = r.runs.iter().filter(|x| x.stress.as_ref().is_some_and(|s| s.linearised.is_some())).collect();
    if runs.is_empty() {
        return;
    }
    let md = &mut doc.md;
    let _ = writeln!(md, "\n## Stresses linearised through the thickness (arch and cantilever)\n");
    let _ = writeln!(
        md,
        "As USACE EM 1110-2-6053 evaluates a 3-D model (and ASME VIII-2 5.A a stress classification line): a straight cut from each upstream face's centre to the nearest point of the downstream face; along it the arch stress (horizontal, tangential to the faces) and the cantilever stress (in the faces' vertical plane) are linearised, membrane σ_m = mean through the thickness t, bending σ_b = 6/t² ∫σ (x − t/2) dx, surface values σ_m ∓ σ_b upstream / downstream, each enveloped over the record at the envelope's samples (`output::linearise`). It integrates the element stresses (each element's centre value over its stretch of the cut), so a single element's peak at a re-entrant corner weighs by its share of the thickness only; with n elements through the thickness a linear bending stress is read as (1 − 1/n²) of itself. Upstream / downstream, MPa, tension positive; \"outside band\": the cuts whose upstream face is more than {} m from the rock.\n",
        fmt_sig(OBJECTIVE_BAND, 3)
    );
    let mut t = Table::new(["level", "run", "cuts (dropped)", "arch tension up / down", "arch compression up / down", "cantilever tension up / down", "cantilever compression up / down", "outside band: arch tension / compression, cantilever tension / compression"]);
    let tc = |e: &LinearisedExtremes| [format!("{} / {}", mpa(e.tension_start), mpa(e.tension_end)), format!("{} / {}", mpa(e.compression_start), mpa(e.compression_end))];
    for x in runs {
        let l = x.stress.as_ref().and_then(|s| s.linearised.as_ref()).expect("filtered");
        let band = match (&l.arch_outside_band, &l.cantilever_outside_band) {
            (Some(a), Some(c)) => format!("{} / {}, {} / {}", mpa(a.tension()), mpa(a.compression()), mpa(c.tension()), mpa(c.compression())),
            _ => "–".into(),
        };
        let (a, c) = (tc(&l.arch), tc(&l.cantilever));
        let _ = t.push_row([lvl(x.level), format!("{} {}", x.method.name(), x.mesh), format!("{} ({})", l.cuts, l.dropped), a[0].clone(), a[1].clone(), c[0].clone(), c[1].clone(), band]);
    }
    md.push_str(&t.to_markdown());
}

/// What the verdicts and the speed-against-accuracy chart are judged against.
fn reference_section(r: &DamReport, doc: &mut Doc) {
    let md = &mut doc.md;
    let _ = writeln!(md, "\n## Reference: the extrapolated values\n");
    let rf = match &r.reference {
        Ok(rf) => rf,
        Err(why) => {
            let _ = writeln!(md, "**No extrapolated reference**: {why}. The verdicts below are judged on the main mesh's numbers without an error band, and the speed-against-accuracy table takes NTS-Layer2 (else NTS) on the main mesh as its reference: both as if the main mesh were exact.");
            return;
        }
    };
    let _ = writeln!(
        md,
        "From `{}` (study `{}`, runs built at {}): meshes {}. {}.\n",
        r.kind.reference_path.as_ref().map_or(String::new(), |p| p.display().to_string()),
        rf.study,
        rf.commits.join(", "),
        rf.meshes.iter().map(|m| format!("{} (h {} m)", m.label, fmt_sig(m.h, 3))).collect::<Vec<_>>().join(", "),
        rf.note
    );
    let mut t = Table::new(["level", "method", "quantity", "per mesh (coarsest first)", "finest three: behaviour, order, band", "least squares, four meshes or more: fit, p, φ0, U", "value ± band"]);
    for v in &rf.values {
        let f = |x: f64| match v.unit.as_str() {
            "Pa" => format!("{} MPa", mpa(x)),
            "m2" => format!("{} m²", fmt_sig(x, 3)),
            _ => format!("{} mm", mm(x)),
        };
        let e = &v.extrapolation;
        let _ = t.push_row([
            lvl(v.level),
            v.method.name().into(),
            v.quantity.name().0.into(),
            v.values.iter().map(|m| f(m.value)).collect::<Vec<_>>().join(" / "),
            format!(
                "{:?}{}{}{}",
                e.behaviour,
                e.order.map_or(String::new(), |p| format!(", p = {}", fmt_sig(p, 3))),
                e.least_squares.as_ref().and_then(|l| l.finest_three_band).map_or(String::new(), |b| format!(", ± {}", f(b))),
                e.coarser.map_or(String::new(), |c| format!("; coarser three: {c:?}"))
            ),
            e.least_squares.as_ref().map_or("–".into(), |l| format!("{}, {}, {} ± {} (F_s {})", l.fit.label(), l.order_text(), f(l.extrapolated), f(l.uncertainty), l.safety)),
            format!("{} ± {}", f(e.extrapolated), e.band.map_or("–".into(), f)),
        ]);
    }
    md.push_str(&t.to_markdown());
}

/// The seed's claims with our numbers and the verdicts.
fn claims_section(claims: &[Claim], doc: &mut Doc) {
    let _ = writeln!(doc.md, "\n## The seed's claims against our numbers\n");
    let _ = writeln!(doc.md, "A claim that NTS is above NTN is **not resolved** when the NTS − NTN difference of the extrapolated reference is within the combined error band √(b_NTS² + b_NTN²) (src/studies/dam/convergence.rs); without a reference it is judged on the main mesh's numbers alone, as the band column says.\n");
    let mut t = Table::new(["claim (seed)", "ours", "error band", "verdict"]);
    for c in claims {
        let _ = t.push_row([c.claim.clone(), c.ours.clone(), c.band.clone(), c.verdict().into()]);
    }
    doc.md.push_str(&t.to_markdown());
}

/// The values a run's errors are taken against at one level.
struct RefPoint {
    label: String,
    opening: f64,
    slip: f64,
    tension: Option<f64>,
    compression: Option<f64>,
    /// Stresses outside the band at the rock (the extrapolated reference's), else raw peaks.
    objective: bool,
}

impl RefPoint {
    /// The extrapolated NTS values at level `l` of the reference.
    fn extrapolated(rf: &DamReference, l: f64) -> Option<RefPoint> {
        let v = |q: Q| rf.get(q, Method::Nts, l).map(|v| v.extrapolation.extrapolated);
        Some(RefPoint { label: "extrapolated NTS".into(), opening: v(Q::Opening)?, slip: v(Q::Slip)?, tension: v(Q::ObjectiveTension), compression: v(Q::ObjectiveCompression), objective: true })
    }
    /// A run's own values (the fallback without a reference).
    fn of_run(x: &DamRun) -> RefPoint {
        RefPoint { label: x.id.clone(), opening: x.max_opening().1, slip: x.max_slip().1, tension: x.stress.as_ref().map(|s| s.tension()), compression: x.stress.as_ref().map(|s| s.compression()), objective: false }
    }
}

/// Every finished run against its level's reference: the extrapolated NTS values of
/// `report.reference`, else NTS-Layer2 on the main mesh, else NTS (whose own row is then left
/// out).
fn accuracy(r: &DamReport) -> Vec<Accuracy> {
    let mut acc: Vec<Accuracy> = Vec::new();
    for &l in &r.levels {
        let extrapolated = r.reference.as_ref().ok().and_then(|rf| RefPoint::extrapolated(rf, l));
        let main = r.find(l, Method::NtsLayer2, true).or(r.find(l, Method::Nts, true)).filter(|r| r.failed.is_none());
        let (rf, own) = match (extrapolated, main) {
            (Some(p), _) => (p, None),
            (None, Some(m)) => (RefPoint::of_run(m), Some(m.id.clone())),
            (None, None) => continue,
        };
        for x in r.runs.iter().filter(|x| same(x.level, l) && Some(&x.id) != own.as_ref() && x.failed.is_none()) {
            acc.push(accuracy_of(x, &rf, l));
        }
    }
    acc
}

/// Run `x`'s errors against reference `rf` at level `l`.
fn accuracy_of(x: &DamRun, rf: &RefPoint, l: f64) -> Accuracy {
    let eo = rel(x.max_opening().1, rf.opening).abs();
    let es = rel(x.max_slip().1, rf.slip).abs();
    let s = x.stress.as_ref();
    let (xt, xc) = match rf.objective {
        true => (s.and_then(|s| s.objective_tension()), s.and_then(|s| s.objective_compression())),
        false => (s.map(|s| s.tension()), s.map(|s| s.compression())),
    };
    let et = xt.zip(rf.tension).map(|(a, b)| rel(a, b).abs());
    let ec = xc.zip(rf.compression).map(|(a, b)| rel(a, b).abs());
    let error = [Some(eo), Some(es), et, ec].into_iter().flatten().filter(|e| e.is_finite()).fold(0.0, f64::max);
    Accuracy {
        id: x.id.clone(),
        level: l,
        reference: rf.label.clone(),
        wall_time: x.wall_time.unwrap_or(f64::NAN),
        error_opening: eo,
        error_slip: es,
        error_tension: et,
        error_compression: ec,
        error,
    }
}

/// The errors of every cheaper run and the cheapest within `enough` per level.
fn speed_table_section(r: &DamReport, acc: &[Accuracy], doc: &mut Doc) {
    let p = r.params();
    let md = &mut doc.md;
    let _ = writeln!(md, "\n## Speed against accuracy\n");
    let _ = writeln!(
        md,
        "Error of a run: the largest relative difference to its level's reference of the largest opening, the largest slip, the largest tension and the largest compression. The reference is the extrapolated NTS value of each (section \"Reference\"; stresses outside the band at the rock, the run's too) where the study has one, else NTS-Layer2 on the main mesh where it was run, else NTS (raw peaks; the main mesh taken as exact). \"Enough\": within {}.\n",
        fmt_percent(p.enough, 0)
    );
    let mut t = Table::new([
        "level",
        "run",
        "reference",
        "wall time [s]",
        "opening",
        "slip",
        "tension",
        "compression",
        "error",
    ]);
    let o = |x: Option<f64>| x.map_or("–".into(), |v| fmt_percent(v, 1));
    for a in acc {
        let _ = t.push_row([
            lvl(a.level),
            format!("`{}`", a.id),
            a.reference.clone(),
            fmt_sig(a.wall_time, 4),
            fmt_percent(a.error_opening, 1),
            fmt_percent(a.error_slip, 1),
            o(a.error_tension),
            o(a.error_compression),
            fmt_percent(a.error, 1),
        ]);
    }
    md.push_str(&t.to_markdown());
    let _ = writeln!(md);
    for &l in &r.levels {
        let best = acc
            .iter()
            .filter(|a| same(a.level, l) && a.error <= p.enough && a.wall_time.is_finite())
            .min_by(|a, b| a.wall_time.total_cmp(&b.wall_time));
        match best {
            Some(a) => {
                let _ = writeln!(
                    md,
                    "- {}: cheapest within {}: `{}` ({} s, error {})",
                    lvl(l),
                    fmt_percent(p.enough, 0),
                    a.id,
                    fmt_sig(a.wall_time, 3),
                    fmt_percent(a.error, 1)
                );
            }
            None if acc.iter().any(|a| same(a.level, l)) => {
                let _ = writeln!(
                    md,
                    "- {}: no cheaper run is within {} of the reference",
                    lvl(l),
                    fmt_percent(p.enough, 0)
                );
            }
            None => {}
        }
    }
}

/// Wall time against error at the highest level, with the Pareto front (log-log).
fn speed_chart_section(r: &DamReport, acc: &[Accuracy], doc: &mut Doc) -> Result<(), Error> {
    let Some(l) = r.top else { return Ok(()) };
    let pts: Vec<&Accuracy> = acc
        .iter()
        .filter(|a| same(a.level, l) && a.wall_time.is_finite() && a.wall_time > 0.0 && a.error > 0.0)
        .collect();
    if pts.is_empty() {
        return Ok(());
    }
    let xy: Vec<(f64, f64)> = pts.iter().map(|a| (a.wall_time, a.error)).collect();
    let front = pareto_front(&xy);
    let mut c = Chart::new(
        format!("Speed against accuracy at {}", lvl(l)),
        "wall time [s]",
        "relative error against the reference [-]",
    );
    c.x_axis = Axis::Log;
    c.y_axis = Axis::Log;
    for (i, a) in pts.iter().enumerate() {
        c.series.push(Series::markers(a.id.clone(), [xy[i]]));
    }
    c.series
        .push(Series::line("Pareto front", front.iter().map(|&i| xy[i])));
    doc.chart(&c, "speed_accuracy")?;
    let dropped = acc.iter().filter(|a| same(a.level, l)).count() - pts.len();
    if dropped > 0 {
        let _ = writeln!(
            doc.md,
            "({dropped} run(s) with zero error or no wall time are in the table but cannot be drawn on log axes.)"
        );
    }
    Ok(())
}

/// NTN − NTS per joint against the joint's NTS slip (where node-to-node fails).
fn ntn_error_section(r: &DamReport, doc: &mut Doc) -> Result<(), Error> {
    let _ = writeln!(doc.md, "\n## Where methods fail\n");
    let _ = writeln!(
        doc.md,
        "NTN against NTS per joint: the difference of the largest opening and slip against the joint's largest NTS slip (a node-to-node pair is exact only while the nodes stay facing each other).\n"
    );
    let mut c = Chart::new(
        "NTN − NTS per joint against the joint's NTS slip",
        "largest NTS slip [mm]",
        "NTN − NTS largest opening [mm]",
    );
    let mut cs = Chart::new(
        "NTN − NTS slip per joint against the joint's NTS slip",
        "largest NTS slip [mm]",
        "NTN − NTS largest slip [mm]",
    );
    for &l in &r.levels {
        if let (Some(a), Some(b)) = (r.find(l, Method::Nts, true), r.find(l, Method::Ntn, true)) {
            // both over the whole record: a stopped run's maxima end earlier
            if a.joints == b.joints && a.failed.is_none() && b.failed.is_none() {
                c.series.push(Series::markers(
                    lvl(l),
                    (0..a.joints.len())
                        .map(|k| (1e3 * a.slip[k], 1e3 * (b.opening[k] - a.opening[k]))),
                ));
                cs.series.push(Series::markers(
                    lvl(l),
                    (0..a.joints.len()).map(|k| (1e3 * a.slip[k], 1e3 * (b.slip[k] - a.slip[k]))),
                ));
            }
        }
    }
    if !c.series.is_empty() {
        doc.chart(&c, "ntn_error_opening")?;
        doc.chart(&cs, "ntn_error_slip")?;
    }
    Ok(())
}

/// Search and Gauss–Seidel diagnostics per joint at the highest level, one column per run.
fn search_section(r: &DamReport, doc: &mut Doc) {
    let Some(l) = r.top else { return };
    let cols: Vec<&DamRun> = r
        .runs
        .iter()
        .filter(|r| same(r.level, l) && r.diagnostics.is_some() && r.method != Method::Monolithic)
        .collect();
    let Some(first) = cols.first() else { return };
    let _ = writeln!(
        doc.md,
        "Search and Gauss–Seidel per joint at {} (node-steps lost beyond the master's free edge + lost inside its outline / Layer2 widenings / fresh searches / largest sweeps / unconverged steps; never silent):\n",
        lvl(l)
    );
    let mut head = vec!["joint".to_string()];
    head.extend(
        cols.iter()
            .map(|r| format!("{} {}", r.method.name(), r.mesh)),
    );
    let mut t = Table::new(head);
    for j in &first.joints {
        let mut row = vec![j.clone()];
        for r in &cols {
            let d = r
                .diagnostics
                .as_ref()
                .and_then(|d| r.joints.iter().position(|x| x == j).map(|i| &d[i]));
            row.push(d.map_or("–".into(), |d| {
                format!(
                    "{} + {} / {} / {} / {} / {}",
                    d.lost_beyond_edge, d.lost - d.lost_beyond_edge, d.widened_layer2, d.fresh_searches, d.max_sweeps, d.unconverged_steps
                )
            }));
        }
        let _ = t.push_row(row);
    }
    doc.md.push_str(&t.to_markdown());
}

/// The runs that stopped, with where and why.
fn stopped_section(r: &DamReport, doc: &mut Doc) {
    let failed: Vec<&DamRun> = r.runs.iter().filter(|r| r.failed.is_some()).collect();
    if failed.is_empty() {
        return;
    }
    let _ = writeln!(
        doc.md,
        "\nRuns that stopped (their joint maxima above are up to where they stopped; no stress envelope):\n"
    );
    for r in failed {
        let _ = writeln!(
            doc.md,
            "- `{}` at t = {} s: {}",
            r.id,
            fmt_sig(r.t_end, 4),
            r.failed.as_deref().unwrap_or("")
        );
    }
}

/// The seed's qualitative claims, each with the rule that decides it.
fn claims(kind: &DamKind, runs: &[DamRun], levels: &[f64], reference: Option<&DamReference>) -> Vec<Claim> {
    let c = ClaimRuns {
        p: &kind.params,
        runs,
        levels,
        reference,
    };
    let mut out = vec![c.nts_near_ntn_below_top()];
    if let Some(t) = levels.last().copied() {
        out.push(c.openings_grow_faster(t));
        out.push(c.openings_more_uniform(t));
        out.push(c.largest_opening_left(t));
        out.extend(c.nts_above_ntn(t));
    }
    out
}

/// The finished main-mesh runs the claims read.
struct ClaimRuns<'a> {
    p: &'a DamParams,
    runs: &'a [DamRun],
    levels: &'a [f64],
    reference: Option<&'a DamReference>,
}

impl ClaimRuns<'_> {
    fn find(&self, level: f64, m: Method) -> Option<&DamRun> {
        self.runs.iter().find(|r| {
            same(r.level, level) && r.method == m && r.is_main(self.p) && r.failed.is_none()
        })
    }

    /// The levels below the highest.
    fn low(&self) -> Vec<f64> {
        let top = self.levels.last().copied();
        self.levels
            .iter()
            .copied()
            .filter(|&l| Some(l) != top)
            .collect()
    }

    /// NTS ≈ NTN below the top level: each low level on the extrapolated reference with its
    /// bands where it has both methods' opening and net slip there ([`verdict_close`]), else on
    /// the main mesh's numbers alone; not agreed if a level is, else not resolved if a level is.
    fn nts_near_ntn_below_top(&self) -> Claim {
        use super::convergence::Verdict::*;
        let mut c = self.nts_near_ntn_on_the_main_mesh();
        let Some(rf) = self.reference else { return c };
        let mut verdicts = Vec::new();
        let mut texts = Vec::new();
        for l in self.low() {
            let (Some(a), Some(b)) = (self.find(l, Method::Nts), self.find(l, Method::Ntn)) else { return c };
            let mut on_ref = Vec::new();
            for q in [Q::Opening, Q::Slip] {
                if let (Some(x), Some(y)) = (rf.get(q, Method::Nts, l), rf.get(q, Method::Ntn, l)) {
                    let (ex, ey) = (&x.extrapolation, &y.extrapolation);
                    on_ref.push(verdict_close(ex.extrapolated, ex.band, ey.extrapolated, ey.band, self.p.enough));
                    let band = |v: Option<f64>| v.map_or("no band".into(), |v| format!("{} mm", mm(v)));
                    texts.push(format!("{} {}: NTS {} mm ± {}, NTN {} mm ± {}", lvl(l), q.name().0, mm(ex.extrapolated), band(ex.band), mm(ey.extrapolated), band(ey.band)));
                }
            }
            if on_ref.len() == 2 {
                verdicts.extend(on_ref);
            } else {
                let close = rel(b.max_opening().1, a.max_opening().1).abs() <= self.p.enough && rel(b.max_slip().1, a.max_slip().1).abs() <= self.p.enough;
                verdicts.push(if close { Agreed } else { NotAgreed });
                texts.push(format!("{}: no reference, the main mesh's", lvl(l)));
            }
        }
        if texts.is_empty() {
            return c;
        }
        let v = if verdicts.contains(&NotAgreed) { NotAgreed } else if verdicts.contains(&NotResolved) { NotResolved } else { Agreed };
        c.ours = format!("{} (main mesh); reference: {}", c.ours, texts.join("; "));
        c.agreed = Some(v == Agreed);
        c.not_resolved = v == NotResolved;
        c.band = format!("per level on the reference: agreed when |NTN − NTS| + √(b_NTS² + b_NTN²) ≤ {} of NTS, not agreed when |NTN − NTS| − √(…) exceeds it, else not resolved", fmt_percent(self.p.enough, 0));
        c
    }

    /// NTS ≈ NTN below the top level, on the main mesh's numbers.
    fn nts_near_ntn_on_the_main_mesh(&self) -> Claim {
        let low = self.low();
        let mut ours = Vec::new();
        let mut ok = Some(true);
        for &l in &low {
            match (self.find(l, Method::Nts), self.find(l, Method::Ntn)) {
                (Some(a), Some(b)) => {
                    let (eo, es) = (
                        rel(b.max_opening().1, a.max_opening().1),
                        rel(b.max_slip().1, a.max_slip().1),
                    );
                    ours.push(format!(
                        "{}: NTN − NTS opening {}, slip {}",
                        lvl(l),
                        fmt_percent(eo, 1),
                        fmt_percent(es, 1)
                    ));
                    if eo.abs() > self.p.enough || es.abs() > self.p.enough {
                        ok = ok.map(|_| false);
                    }
                }
                _ => ok = None,
            }
        }
        if low.is_empty() {
            ok = None;
        }
        Claim {
            claim: format!(
                "NTS ≈ NTN below the highest level (rule: largest opening and slip within {})",
                fmt_percent(self.p.enough, 0)
            ),
            ours: ours.join("; "),
            agreed: ok, not_resolved: false, band: String::new(),
        }
    }

    /// Openings grow faster than the input from the level below the top to the top.
    fn openings_grow_faster(&self, t: f64) -> Claim {
        let prev = self.low().last().copied();
        match (
            prev.and_then(|l| self.find(l, Method::Nts).map(|r| (l, r))),
            self.find(t, Method::Nts),
        ) {
            (Some((l, a)), Some(b)) => {
                let g = b.max_opening().1 / a.max_opening().1;
                Claim { claim: "at the highest level openings grow faster than the input (rule: NTS largest opening ratio > PGA ratio)".into(), ours: format!("{} → {}: opening × {}, input × {}", lvl(l), lvl(t), fmt_sig(g, 3), fmt_sig(t / l, 3)), agreed: Some(g > t / l), not_resolved: false, band: String::new() }
            }
            _ => Claim {
                claim: "at the highest level openings grow faster than the input".into(),
                ours: String::new(),
                agreed: None, not_resolved: false, band: String::new(),
            },
        }
    }

    /// Openings more uniform across joints at the top level than at the lowest.
    fn openings_more_uniform(&self, t: f64) -> Claim {
        let cv = |r: &DamRun| {
            let n = r.opening.len() as f64;
            let mean = r.opening.iter().sum::<f64>() / n;
            (r.opening.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt() / mean
        };
        let lowest = self.levels.first().copied();
        match (lowest.filter(|&l| l != t).and_then(|l| self.find(l, Method::Nts).map(|r| (l, r))), self.find(t, Method::Nts)) {
            (Some((l, a)), Some(b)) => Claim { claim: "at the highest level openings are more uniform across joints (rule: smaller coefficient of variation of the NTS openings than at the lowest level)".into(), ours: format!("CoV {} at {}, {} at {}", fmt_sig(cv(a), 3), lvl(l), fmt_sig(cv(b), 3), lvl(t)), agreed: Some(cv(b) < cv(a)), not_resolved: false, band: String::new() },
            _ => Claim { claim: "at the highest level openings are more uniform across joints".into(), ours: String::new(), agreed: None, not_resolved: false, band: String::new() },
        }
    }

    /// The largest opening near the left abutment (the left third of the joints).
    fn largest_opening_left(&self, t: f64) -> Claim {
        match self.find(t, Method::Nts) {
            Some(r) => {
                let (k, _) = r.max_opening();
                let third = r.opening.len().div_ceil(3);
                Claim {
                    claim: format!(
                        "the largest opening is near the left abutment (rule: NTS at the highest level, in joints 1–{third}, the left third)"
                    ),
                    ours: format!("{} (joint {} of {})", r.joints[k], k + 1, r.opening.len()),
                    agreed: Some(k < third), not_resolved: false, band: String::new(),
                }
            }
            None => Claim {
                claim: "the largest opening is near the left abutment".into(),
                ours: String::new(),
                agreed: None, not_resolved: false, band: String::new(),
            },
        }
    }

    /// NTS above NTN at the top level: opening, slip, tension, compression. With the
    /// reference: its extrapolated NTS and NTN values and bands decide (stresses: outside the
    /// band at the rock, the raw peak has no limit); without: the main mesh's numbers.
    fn nts_above_ntn(&self, t: f64) -> Vec<Claim> {
        let q: [(&str, Q, Q, f64); 4] = [
            ("largest opening", Q::Opening, Q::Opening, 1.0),
            ("largest slip", Q::Slip, Q::Slip, 1.0),
            ("largest tension", Q::Tension, Q::ObjectiveTension, 1.0),
            ("largest compression (magnitude)", Q::Compression, Q::ObjectiveCompression, -1.0),
        ];
        q.iter().map(|&(name, raw, judged, sign)| self.nts_above_ntn_in(t, name, raw, judged, sign)).collect()
    }

    /// One quantity of [`Self::nts_above_ntn`]: `raw` on the main mesh, `judged` in the
    /// reference; `sign` −1 for a compression (its magnitude is compared).
    fn nts_above_ntn_in(&self, t: f64, name: &str, raw: Q, judged: Q, sign: f64) -> Claim {
        let claim = format!("NTS above NTN at {}: {name}", lvl(t));
        let (a, b) = (self.find(t, Method::Nts), self.find(t, Method::Ntn));
        let main = match (a.and_then(|r| raw.of(r)), b.and_then(|r| raw.of(r))) {
            (Some(x), Some(y)) => Some((sign * x, sign * y)),
            _ => None,
        };
        let main_text = |(x, y): (f64, f64)| format!("NTS / NTN − 1 = {} (main mesh)", fmt_percent(rel(x, y), 1));
        let refs = self.reference.and_then(|rf| Some((rf.get(judged, Method::Nts, t)?, rf.get(judged, Method::Ntn, t)?)));
        let Some((rn, rt)) = refs else {
            return match main {
                Some((x, y)) => Claim { claim, ours: main_text((x, y)), agreed: Some(x > y), not_resolved: false, band: "none: no reference for it (section \"Reference\")".into() },
                None => Claim { claim, ours: String::new(), agreed: None, not_resolved: false, band: String::new() },
            };
        };
        let (x, y) = (sign * rn.extrapolation.extrapolated, sign * rt.extrapolation.extrapolated);
        let (bx, by) = (rn.extrapolation.band, rt.extrapolation.band);
        let unit = |v: f64| if rn.unit == "Pa" { format!("{} MPa", mpa(v)) } else { format!("{} mm", mm(v)) };
        let band = |b: Option<f64>| b.map_or("no band".into(), unit);
        Claim {
            claim,
            ours: format!(
                "{}; reference, {}: NTS {} ± {}, NTN {} ± {}",
                main.map_or("main mesh: –".into(), main_text),
                judged.name().0,
                unit(x),
                band(bx),
                unit(y),
                band(by)
            ),
            agreed: Some(x > y),
            not_resolved: verdict_above(x, bx, y, by, true) == super::convergence::Verdict::NotResolved,
            band: format!("|NTS − NTN| {} against √(b_NTS² + b_NTN²) {}", unit((x - y).abs()), bx.zip(by).map_or("unknown".into(), |(p, q)| unit(p.hypot(q)))),
        }
    }
}

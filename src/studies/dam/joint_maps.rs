//! The dam report's joint maps (issue 32; the seed's figures 13–14 resolved along the height):
//! joint number × elevation, each cell coloured by the largest opening (one map) or the largest
//! net slip |d_t| (another) over the record of the joint's slave nodes at that elevation, in mm;
//! NTS and NTN side by side on one colour scale, per level.
//!
//! Cells: joint k (1… in the report's natural order) spans k ± 0.4 on the x axis; the height
//! from the lowest to the highest slave node of all the map's joints is cut into
//! [`ELEVATION_BANDS`] equal bands, and a cell holds the largest value of the joint's nodes in
//! its band (a band with no node of the joint is left white: the joint is shorter there, near
//! the abutments). Data: `joint_envelope.json` of each run (`output::joint_envelope`, one value
//! per slave node, sampled at the joint-history rows); a run without it (written before it
//! existed, or stopped) is named and left out.

use super::report::{DamReport, Doc, lvl, lvl_num, mm};
use super::{DamRun, Method};
use crate::error::Error;
use crate::output::joint_envelope::{JOINT_ENVELOPE_FILE, JointEnvelope, JointNodeEnvelope};
use crate::report::{Map, MapPanel};
use std::fmt::Write as _;

/// Elevation bands of a joint map: 24, about 10 m on the 250 m dam (a cell per two to three
/// coarse-mesh node rows, a few default-mesh rows), fine enough to see where along the height a
/// joint opens and coarse enough that every band of a full-height joint holds nodes.
pub const ELEVATION_BANDS: usize = 24;

/// Half the width of a joint's column on the joint-number axis [-].
const HALF_WIDTH: f64 = 0.4;

/// Which per-node envelope a map shows.
#[derive(Clone, Copy)]
pub enum JointQuantity {
    Opening,
    NetSlip,
}

impl JointQuantity {
    fn of(self, e: &JointNodeEnvelope) -> &[f64] {
        match self {
            JointQuantity::Opening => &e.max_opening,
            JointQuantity::NetSlip => &e.max_net_slip,
        }
    }
    fn what(self) -> &'static str {
        match self {
            JointQuantity::Opening => "largest opening",
            JointQuantity::NetSlip => "largest net slip |d_t|",
        }
    }
    fn stem(self) -> &'static str {
        match self {
            JointQuantity::Opening => "opening",
            JointQuantity::NetSlip => "slip",
        }
    }
}

/// Per elevation band of `z_range` cut in `bands`: the largest of `values` at `points` in it
/// (`None` where no point lies).
pub fn band_maxima(points: &[[f64; 3]], values: &[f64], z_range: (f64, f64), bands: usize) -> Vec<Option<f64>> {
    let mut out = vec![None; bands];
    let h = (z_range.1 - z_range.0).max(f64::MIN_POSITIVE);
    for (p, &v) in points.iter().zip(values) {
        let b = (((p[2] - z_range.0) / h) * bands as f64).floor().clamp(0.0, (bands - 1) as f64) as usize;
        out[b] = Some(out[b].map_or(v, |x: f64| x.max(v)));
    }
    out
}

/// One panel: per joint of `run` (in its order, numbered from 1) a column of band cells [mm],
/// the largest value marked.
fn panel(run: &DamRun, env: &JointEnvelope, q: JointQuantity, z_range: (f64, f64)) -> MapPanel {
    let dz = (z_range.1 - z_range.0) / ELEVATION_BANDS as f64;
    let mut polygons = Vec::new();
    let mut best: Option<(f64, (f64, f64), &str)> = None;
    for (k, name) in run.joints.iter().enumerate() {
        let Some(e) = env.joint(name) else { continue };
        let x = (k + 1) as f64;
        for (b, v) in band_maxima(&e.points, q.of(e), z_range, ELEVATION_BANDS).into_iter().enumerate() {
            let Some(v) = v else { continue };
            let (z0, z1) = (z_range.0 + b as f64 * dz, z_range.0 + (b + 1) as f64 * dz);
            polygons.push((vec![(x - HALF_WIDTH, z0), (x + HALF_WIDTH, z0), (x + HALF_WIDTH, z1), (x - HALF_WIDTH, z1)], 1e3 * v));
            if best.is_none_or(|m| v > m.0) {
                best = Some((v, (x, 0.5 * (z0 + z1)), name));
            }
        }
    }
    MapPanel {
        title: format!("{} ({})", run.method.name(), run.id),
        polygons,
        lines: Vec::new(),
        marks: best.map(|(v, at, name)| vec![(at, format!("max {} mm ({name})", mm(v)))]).unwrap_or_default(),
    }
}

/// Joint maps of the largest opening and net slip at every level, NTS and NTN side by side.
pub fn joint_maps_section(r: &DamReport, doc: &mut Doc) -> Result<(), Error> {
    let _ = writeln!(doc.md, "\n## Joint maps: opening and net slip along the height (the seed's figures 13–14 resolved)\n");
    let _ = writeln!(
        doc.md,
        "Joint number (from the left bank) against elevation; a cell's colour is the largest value over the record of the joint's slave nodes in that elevation band ({ELEVATION_BANDS} bands from the lowest to the highest joint node; white: no node of that joint there), in mm; NTS and NTN on one scale; the cross marks the largest value. Opening = max(gap, 0); net slip = |d_t|, the accumulated tangential relative displacement (not the path).\n"
    );
    let mut missing = Vec::new();
    for &l in &r.levels {
        let mut runs: Vec<(&DamRun, JointEnvelope)> = Vec::new();
        for m in [Method::Nts, Method::Ntn] {
            let Some(run) = r.find(l, m, true) else { continue };
            let Some(res) = r.results.run(&run.id) else { continue };
            if !res.dir.join(JOINT_ENVELOPE_FILE).exists() {
                missing.push(run.id.clone());
                continue;
            }
            runs.push((run, JointEnvelope::read(&res.dir)?));
        }
        let zs = runs.iter().flat_map(|(_, e)| e.joints.iter().flat_map(|j| j.points.iter().map(|p| p[2])));
        let Some(z_range) = zs.fold(None, |a: Option<(f64, f64)>, z| Some(a.map_or((z, z), |(lo, hi)| (lo.min(z), hi.max(z))))) else { continue };
        for q in [JointQuantity::Opening, JointQuantity::NetSlip] {
            let mut map = Map::new(format!("Joints: {} over the record along the height, {}", q.what(), lvl(l)), "joint number from the left bank [-]", "elevation z [m]", format!("{} [mm]", q.what()));
            map.panels = runs.iter().map(|(run, env)| panel(run, env, q, z_range)).collect();
            if map.panels.iter().all(|p| p.polygons.is_empty()) {
                continue;
            }
            let stem = format!("joint_{}_{}x", q.stem(), lvl_num(l));
            doc.charts.push(map.write_png_svg(&doc.charts_dir.join(&stem))?.png);
            let _ = writeln!(doc.md, "\n![{}](charts/{stem}.svg)\n", map.title);
        }
    }
    if !missing.is_empty() {
        let _ = writeln!(doc.md, "\nNo joint map of {} (no `{JOINT_ENVELOPE_FILE}`: the run stopped, or was made before the file existed: run it again).", missing.join(", "));
    }
    Ok(())
}

/// Per run, the lost slave node-steps split as the run's summary splits them (issue 32): beyond
/// the master's free edge (an edge node slid past a face's curved edge: a note) and lost inside
/// its outline (a warning when above `LOST_WARN_FRACTION` of a joint's slave node-steps), with
/// the joints over that limit.
pub fn lost_nodes_section(r: &DamReport, doc: &mut Doc) {
    let runs: Vec<&DamRun> = r.runs.iter().filter(|x| x.diagnostics.is_some() && x.method != Method::Monolithic).collect();
    if runs.is_empty() {
        return;
    }
    let limit = crate::output::recorder::LOST_WARN_FRACTION;
    let _ = writeln!(
        doc.md,
        "\nLost slave nodes per run (node-steps without a master face, force-free that step): beyond the master's free edge (the node slid past the edge of the face it rests on: expected, a note in the run's summary) and lost inside the master's outline (the dangerous case: a WARNING when above {:.0} % of a joint's slave node-steps):\n",
        100.0 * limit
    );
    let mut t = crate::report::Table::new(vec!["run".into(), "beyond the free edge (note)".into(), "lost inside (warning)".into(), format!("joints above {:.0} % inside", 100.0 * limit)]);
    for run in runs {
        let d = run.diagnostics.as_ref().expect("filtered");
        let steps = r.results.run(&run.id).and_then(|x| x.summary.as_ref()).map_or(0, |s| s.steps).max(1) as f64;
        let beyond: u64 = d.iter().map(|j| j.lost_beyond_edge).sum();
        let inside: u64 = d.iter().map(|j| j.lost - j.lost_beyond_edge).sum();
        let warned: Vec<&str> = d.iter().zip(&run.joints).filter(|(j, _)| (j.lost - j.lost_beyond_edge) as f64 > limit * j.slave_nodes.max(1) as f64 * steps).map(|(_, n)| n.as_str()).collect();
        let _ = t.push_row(vec![run.id.clone(), beyond.to_string(), inside.to_string(), if warned.is_empty() { "none".into() } else { warned.join(", ") }]);
    }
    doc.md.push_str(&t.to_markdown());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn band_maxima_keep_the_largest_value_of_each_band_and_leave_empty_bands_empty() {
        // 4 bands over z in [0, 4]: points at z 0.5 (1 and 3), 3.9 (2) and 4.0 (the top edge,
        // in the last band) (5); bands 1 and 2 hold nothing
        let p = [[0.0, 0.0, 0.5], [0.0, 0.0, 0.5], [0.0, 0.0, 3.9], [0.0, 0.0, 4.0]];
        let got = band_maxima(&p, &[1.0, 3.0, 2.0, 5.0], (0.0, 4.0), 4);
        assert_eq!(got, vec![Some(3.0), None, None, Some(5.0)]);
    }
}

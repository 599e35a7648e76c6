//! The dam study's ParaView state (issue 32): `<out>/dam.pvsm`, written with the report, that
//! opens the frames of the one run of the study that wrote them (the study file's run selection
//! whose `with` sets `/output/frames`: `nts-default-3x` in `pipelines/dam_study.json`) with the
//! rock hidden, the dam warped by its displacement and coloured by |u|, and the joints coloured
//! by opening (`output::pvsm`).
//!
//! Which run: of the finished runs whose scene asks for frames and that wrote at least two, the
//! one with the most frames (the frames run writes one every 0.05 s, against the others' start
//! and end when a study asks for those), then the highest level. The rock: the block of volume group `rock` (the study file's
//! `report.rock`, default `block:rock`; the run summary's `blocks` give each `block_id`'s group);
//! none found: nothing hidden, and the report says so.
//! Warp factor: the 1-2-5 value at or below 5 % of the joints' height over the run's peak |u|
//! (a 250 m dam with 50 mm at the crest: 200), at least 1: the motion reads without the dam
//! leaving its outline. Colour ranges: |u| over [0, the run's peak |u|]; opening over [0, the
//! largest opening of any joint node] (`joint_envelope.json`).

use super::report::{DamReport, Doc, mm};
use crate::error::Error;
use crate::output::joint_envelope::JointEnvelope;
use crate::output::pvsm::{Camera, PvsmScene, write_pvsm};
use crate::report::fmt_sig;
use crate::study::RunResult;
use std::fmt::Write as _;

/// File name of the state in the study's output directory.
pub const PVSM_FILE: &str = "dam.pvsm";

/// The largest 1-2-5 value ≤ `x` (1 for x < 1).
pub fn warp_factor(x: f64) -> f64 {
    if !(x.is_finite() && x >= 1.0) {
        return 1.0;
    }
    let d = 10f64.powf(x.log10().floor());
    [5.0, 2.0, 1.0].into_iter().map(|m| m * d).find(|&v| v <= x * (1.0 + 1e-12)).unwrap_or(d)
}

/// The run whose frames the state opens.
fn frames_run<'a>(r: &'a DamReport) -> Option<&'a RunResult> {
    let mut runs: Vec<&RunResult> = r
        .results
        .runs
        .iter()
        .filter(|x| x.failed().is_none() && x.scene.as_ref().is_some_and(|s| s.output.frames) && x.summary.as_ref().is_some_and(|s| s.frames >= 2 && s.pvd.is_some()))
        .collect();
    let level = |x: &RunResult| r.runs.iter().find(|d| d.id == x.spec.id).map_or(0.0, |d| d.level);
    let frames = |x: &RunResult| x.summary.as_ref().map_or(0, |s| s.frames);
    runs.sort_by(|a, b| frames(b).cmp(&frames(a)).then(level(b).total_cmp(&level(a))));
    runs.first().copied()
}

/// Writes `<out>/dam.pvsm` for the run with frames, and says how to open it.
pub fn paraview_state_section(r: &DamReport, doc: &mut Doc) -> Result<(), Error> {
    let Some(run) = frames_run(r) else { return Ok(()) };
    let summary = run.summary.as_ref().expect("filtered");
    let rock = summary.blocks.iter().position(|g| *g == r.params().rock);
    let env = JointEnvelope::read(&run.dir).ok();
    // the joints' bounding box (the dam's, without the rock)
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let mut opening = 0.0f64;
    for j in env.iter().flat_map(|e| &e.joints) {
        for p in &j.points {
            for k in 0..3 {
                (lo[k], hi[k]) = (lo[k].min(p[k]), hi[k].max(p[k]));
            }
        }
        opening = j.max_opening.iter().copied().fold(opening, f64::max);
    }
    let peak = summary.peak_displacement.value;
    let height = if hi[2] > lo[2] { hi[2] - lo[2] } else { 0.0 };
    let warp = warp_factor(0.05 * height / peak);
    // from downstream (+y, the crest's radial direction at the crown) and a little above, at
    // twice the box's largest side: the whole downstream face in view
    let camera = (height > 0.0).then(|| {
        let c = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])];
        let size = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
        let d = [0.0, 0.958, 0.287]; // (0, 1, 0.3) normalised
        Camera { position: [c[0] + 2.0 * size * d[0], c[1] + 2.0 * size * d[1], c[2] + 2.0 * size * d[2]], focal_point: c, view_up: [0.0, 0.0, 1.0] }
    });
    let pvd = run.dir.join(summary.pvd.as_ref().and_then(|p| p.file_name()).expect("filtered"));
    let joints = summary.joint_series.iter().filter_map(|p| p.file_name()).map(|n| run.dir.join("joints").join(n)).collect();
    let state = PvsmScene {
        volume: pvd,
        hide_blocks: rock.map(|k| vec![k as i32]).unwrap_or_default(),
        warp_scale: warp,
        displacement_max: if peak > 0.0 { peak } else { 1e-3 },
        joints,
        opening_max: if opening > 0.0 { opening } else { 1e-3 },
        camera,
    };
    let path = r.results.plan.out.join(PVSM_FILE);
    write_pvsm(&path, &state)?;
    let _ = writeln!(doc.md, "\n## The quake in ParaView\n");
    let _ = writeln!(
        doc.md,
        "Run `{}` wrote {} frames; open them with `paraview --state {}`: {}the dam warped by its displacement × {} and coloured by |u| (0 to its peak {} mm), the {} joint surfaces coloured by opening (0 to {} mm, the largest of any joint node); the time bar steps through the frames.\n",
        run.spec.id,
        summary.frames,
        path.display(),
        match rock {
            Some(_) => format!("the rock (`{}`) hidden, ", r.params().rock),
            None => format!("(no material `{}` in the run's scene: nothing hidden) ", r.params().rock),
        },
        fmt_sig(warp, 3),
        mm(peak),
        state.joints.len(),
        mm(opening)
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warp_factor_is_the_1_2_5_value_at_or_below() {
        let got: Vec<f64> = [0.3, 1.0, 1.9, 2.0, 4.99, 5.0, 9.9, 250.0, 1234.0, f64::NAN].iter().map(|&x| warp_factor(x)).collect();
        assert_eq!(got, vec![1.0, 1.0, 1.0, 2.0, 2.0, 5.0, 5.0, 200.0, 1000.0, 1.0]);
    }
}

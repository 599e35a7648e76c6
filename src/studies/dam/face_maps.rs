//! The dam report's face maps (issue 32; the seed's figures 15–16): each face of the dam,
//! upstream and downstream, unrolled onto (arc length along the crest axis, elevation), the
//! elevation view dam engineers read, with the envelope over the record of σ1 (largest tension)
//! or σ3 (largest compression) of the element under each face cell, in MPa, tension positive;
//! NTS and NTN side by side on one colour scale, per level.
//!
//! Unrolling: a point (x, y, z) maps to (s(x), z), s the arc length from the crown along the
//! upstream crest arch y = x² / (2 Rc) (`crest_radius`), s(x) = x/2 √(1 + (x/Rc)²) + Rc/2 asinh(x/Rc),
//! negative towards the left bank. Exact on the crest arch; below it the faces' horizontal
//! arches are flatter, so lengths there read slightly long (a developed view, not a true
//! surface length). Outlines: the edges of the face cells that belong to one cell only: the
//! monoliths' edges, that is the joint traces, the crest, the abutments and the foundation line.
//! Data: `envelope.json` of each run (per face cell its corners and values, written by
//! `output::envelope`); a run whose file predates the corners is named and left out.

use super::report::{DamReport, Doc, lvl, lvl_num, mpa};
use super::{DamRun, Method};
use crate::error::Error;
use crate::output::envelope::{FaceEnvelope, StressEnvelope};
use crate::report::{Map, MapPanel};
use std::collections::HashMap;
use std::fmt::Write as _;

/// Arc length [m] from the crown along y = x² / (2 rc) to the point above `x`.
pub fn crest_arc_length(x: f64, rc: f64) -> f64 {
    let u = x / rc;
    0.5 * x * (1.0 + u * u).sqrt() + 0.5 * rc * u.asinh()
}

/// The edges of `corners`' cells that belong to one cell only, as unrolled segments.
fn outline(corners: &[Vec<[f64; 3]>], unroll: &impl Fn(&[f64; 3]) -> (f64, f64)) -> Vec<Vec<(f64, f64)>> {
    let key = |p: &[f64; 3]| p.map(f64::to_bits);
    let mut count: HashMap<([u64; 3], [u64; 3]), (usize, [f64; 3], [f64; 3])> = HashMap::new();
    for c in corners {
        for k in 0..c.len() {
            let (a, b) = (c[k], c[(k + 1) % c.len()]);
            let (ka, kb) = (key(&a), key(&b));
            let e = count.entry(if ka <= kb { (ka, kb) } else { (kb, ka) }).or_insert((0, a, b));
            e.0 += 1;
        }
    }
    let mut edges: Vec<_> = count.into_iter().filter(|(_, v)| v.0 == 1).collect();
    // deterministic drawing order
    edges.sort_by(|a, b| a.0.cmp(&b.0));
    edges.into_iter().map(|(_, (_, a, b))| vec![unroll(&a), unroll(&b)]).collect()
}

/// Which envelope quantity a map shows.
#[derive(Clone, Copy)]
enum Stress {
    /// σ1, largest over the record.
    S1,
    /// σ3, smallest over the record.
    S3,
}

/// One panel of face `f` of run `r`: its cells coloured by σ1 or σ3 [MPa], the outline, the
/// extreme marked.
fn panel(r: &DamRun, f: &FaceEnvelope, q: Stress, rc: f64) -> MapPanel {
    let unroll = |p: &[f64; 3]| (crest_arc_length(p[0], rc), p[2]);
    let values = match q {
        Stress::S1 => &f.max_principal,
        Stress::S3 => &f.min_principal,
    };
    let polygons: Vec<(Vec<(f64, f64)>, f64)> = f.corners.iter().zip(values).map(|(c, v)| (c.iter().map(unroll).collect(), 1e-6 * v)).collect();
    let ext = match q {
        Stress::S1 => &f.max_tension,
        Stress::S3 => &f.max_compression,
    };
    let name = match q {
        Stress::S1 => "max",
        Stress::S3 => "min",
    };
    MapPanel {
        title: format!("{} ({})", r.method.name(), r.id),
        polygons,
        lines: outline(&f.corners, &unroll),
        marks: vec![(unroll(&ext.position), format!("{name} {} MPa", mpa(ext.value)))],
    }
}

/// Face maps of σ1 and σ3 on both faces at every level, NTS and NTN side by side.
pub fn face_maps_section(r: &DamReport, doc: &mut Doc) -> Result<(), Error> {
    let p = r.params();
    let _ = writeln!(doc.md, "\n## Face maps: envelopes of σ1 and σ3 over the faces (the seed's figures 15–16)\n");
    let _ = writeln!(
        doc.md,
        "Each face unrolled onto the arc length along the upstream crest arch (from the crown, negative towards the left bank) and the elevation; a cell's colour is the envelope over the record of the principal stress of the element under it (σ1 the largest, tension positive; σ3 the smallest, compression negative), in bands over the colour bar; NTS and NTN on one scale. Black lines: the monoliths' outlines (the joint traces, the crest, the abutments, the foundation line); the cross marks the extreme with its value.\n"
    );
    let mut missing = Vec::new();
    for &l in &r.levels {
        // (run, envelope) of NTS and NTN on the main mesh with a face-map envelope
        let mut runs: Vec<(&DamRun, StressEnvelope)> = Vec::new();
        for m in [Method::Nts, Method::Ntn] {
            let Some(run) = r.find(l, m, true).filter(|x| x.stress.is_some()) else { continue };
            let Some(res) = r.results.run(&run.id) else { continue };
            let env = StressEnvelope::read(&res.dir)?;
            match (env.face(&p.faces.upstream), env.face(&p.faces.downstream)) {
                (Some(u), Some(d)) if !u.corners.is_empty() && !d.corners.is_empty() => runs.push((run, env)),
                _ => missing.push(run.id.clone()),
            }
        }
        if runs.is_empty() {
            continue;
        }
        for (q, qn, what) in [(Stress::S1, "s1", "σ1 (largest tension)"), (Stress::S3, "s3", "σ3 (largest compression)")] {
            for (face, fname) in [(&p.faces.upstream, "upstream"), (&p.faces.downstream, "downstream")] {
                let mut map = Map::new(
                    format!("Envelope of {what} on the {fname} face, {}", lvl(l)),
                    "arc length along the crest axis from the crown [m]",
                    "elevation z [m]",
                    format!("{} [MPa]", &what[..what.find(' ').unwrap_or(what.len())]),
                );
                for (run, env) in &runs {
                    let f = env.face(face).expect("checked above");
                    map.panels.push(panel(run, f, q, p.crest_radius));
                }
                let stem = format!("face_{qn}_{fname}_{}x", lvl_num(l));
                doc.charts.push(map.write_png_svg(&doc.charts_dir.join(&stem))?.png);
                let _ = writeln!(doc.md, "\n![{}](charts/{stem}.svg)\n", map.title);
            }
        }
    }
    if !missing.is_empty() {
        let _ = writeln!(doc.md, "\nNo face map of {} (their `envelope.json` predates the face corners: run them again).", missing.join(", "));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crest_arc_length_is_the_parabola_length() {
        // against the chord sum of the parabola y = x²/(2 Rc) from 0 to x, 10⁵ chords (error
        // of order (Δx)² x / Rc², far below 1e-6 m)
        let rc = 270.0;
        for x in [-250.0, 10.0, 200.0] {
            let n = 100_000;
            let y = |x: f64| x * x / (2.0 * rc);
            let chord: f64 = (0..n).map(|k| {
                let (a, b) = (x * k as f64 / n as f64, x * (k + 1) as f64 / n as f64);
                ((b - a).powi(2) + (y(b) - y(a)).powi(2)).sqrt()
            }).sum::<f64>() * x.signum();
            assert!((crest_arc_length(x, rc) - chord).abs() < 1e-6, "{x}: {} {chord}", crest_arc_length(x, rc));
        }
    }

    #[test]
    fn outline_keeps_the_edges_of_one_cell() {
        // two triangles sharing the diagonal of the unit square: the 4 sides remain
        let c = vec![vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 1.0]], vec![[0.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 0.0, 1.0]]];
        let o = outline(&c, &|p: &[f64; 3]| (p[0], p[2]));
        assert_eq!(o.len(), 4);
        assert!(o.iter().all(|e| (e[0].0 - e[1].0).abs() + (e[0].1 - e[1].1).abs() == 1.0), "{o:?}");
    }
}

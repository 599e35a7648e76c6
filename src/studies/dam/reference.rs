//! The extrapolated reference of the dam study (issue 30 §3, §5): for each reported quantity,
//! method (NTS, NTN) and level, the value on each mesh of the convergence study, the observed
//! order, the extrapolated value and its error band ([`super::convergence::richardson`]), with
//! the meshes used and the commits of the runs. Written by `jointquake study extrapolate`
//! (`make dam-convergence` → `pipelines/dam_reference.json`), read back by [`DamReference::read`]
//! for `make dam`'s verdicts and speed-against-accuracy chart.
//!
//! Units: SI as the runs report them (m for opening, slip, slip path and crest displacement;
//! Pa for stresses, tension positive, compression negative).

use super::convergence::{Extrapolation, richardson};
use super::report::lvl_num;
use super::{DamParams, DamRun, Method};
use crate::error::OutputError;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A reported quantity of the convergence table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// Largest opening over the joints [m].
    Opening,
    /// Largest net slip |d_t| over the joints [m].
    Slip,
    /// Largest slip path Σ|Δd_t| over the joints [m].
    SlipPath,
    /// Largest σ1 of the faces' elements (raw peak) [Pa].
    Tension,
    /// Most compressive σ3 of the faces' elements (raw peak) [Pa].
    Compression,
    /// Largest σ1 outside the band at the rock ([`crate::output::envelope::OBJECTIVE_BAND`]) [Pa].
    ObjectiveTension,
    /// Most compressive σ3 outside the band [Pa].
    ObjectiveCompression,
    /// Largest |u_r| of the crest monitors [m].
    Crest,
    /// Largest arch tension linearised through the thickness, over all cuts and both faces
    /// ([`crate::output::linearise`]) [Pa].
    ArchTension,
    /// Most compressive linearised arch stress [Pa].
    ArchCompression,
    /// Largest linearised cantilever tension [Pa].
    CantileverTension,
    /// Most compressive linearised cantilever stress [Pa].
    CantileverCompression,
    /// Area of both faces whose σ1 exceeded 3, 5, 10 MPa ([`crate::output::envelope::TENSION_THRESHOLDS`]) [m²].
    AreaAbove3,
    AreaAbove5,
    AreaAbove10,
}

impl Quantity {
    pub const ALL: [Quantity; 15] = [
        Quantity::Opening,
        Quantity::Slip,
        Quantity::SlipPath,
        Quantity::Tension,
        Quantity::Compression,
        Quantity::ObjectiveTension,
        Quantity::ObjectiveCompression,
        Quantity::Crest,
        Quantity::ArchTension,
        Quantity::ArchCompression,
        Quantity::CantileverTension,
        Quantity::CantileverCompression,
        Quantity::AreaAbove3,
        Quantity::AreaAbove5,
        Quantity::AreaAbove10,
    ];

    /// The quantity of a run (`None`: the run has no stress envelope, or no face corners).
    pub fn of(self, r: &DamRun) -> Option<f64> {
        let s = r.stress.as_ref();
        match self {
            Quantity::Opening => Some(r.max_opening().1),
            Quantity::Slip => Some(r.max_slip().1),
            Quantity::SlipPath => Some(r.max_slip_path().1),
            Quantity::Tension => s.map(|s| s.tension()),
            Quantity::Compression => s.map(|s| s.compression()),
            Quantity::ObjectiveTension => s.and_then(|s| s.objective_tension()),
            Quantity::ObjectiveCompression => s.and_then(|s| s.objective_compression()),
            Quantity::Crest => (!r.crest.is_empty()).then(|| r.max_crest()),
            Quantity::ArchTension => s.and_then(|s| s.linearised.as_ref()).map(|l| l.arch.tension()),
            Quantity::ArchCompression => s.and_then(|s| s.linearised.as_ref()).map(|l| l.arch.compression()),
            Quantity::CantileverTension => s.and_then(|s| s.linearised.as_ref()).map(|l| l.cantilever.tension()),
            Quantity::CantileverCompression => s.and_then(|s| s.linearised.as_ref()).map(|l| l.cantilever.compression()),
            Quantity::AreaAbove3 => Self::area(s, 0),
            Quantity::AreaAbove5 => Self::area(s, 1),
            Quantity::AreaAbove10 => Self::area(s, 2),
        }
    }

    /// Both faces' area above threshold `k` [m²]; `None` without face areas (no corners).
    fn area(s: Option<&super::FaceStress>, k: usize) -> Option<f64> {
        let s = s.filter(|s| s.upstream_objective.is_some())?;
        s.areas_above.get(k).map(|&(_, u, d)| u + d)
    }

    /// As the tables name it, and its SI unit.
    pub fn name(self) -> (&'static str, &'static str) {
        match self {
            Quantity::Opening => ("largest opening", "m"),
            Quantity::Slip => ("largest net slip", "m"),
            Quantity::SlipPath => ("largest slip path", "m"),
            Quantity::Tension => ("largest tension (raw element peak)", "Pa"),
            Quantity::Compression => ("largest compression (raw element peak)", "Pa"),
            Quantity::ObjectiveTension => ("largest tension outside the band", "Pa"),
            Quantity::ObjectiveCompression => ("largest compression outside the band", "Pa"),
            Quantity::Crest => ("largest crest displacement |u_r|", "m"),
            Quantity::ArchTension => ("largest arch tension, linearised", "Pa"),
            Quantity::ArchCompression => ("largest arch compression, linearised", "Pa"),
            Quantity::CantileverTension => ("largest cantilever tension, linearised", "Pa"),
            Quantity::CantileverCompression => ("largest cantilever compression, linearised", "Pa"),
            Quantity::AreaAbove3 => ("face area above 3 MPa", "m2"),
            Quantity::AreaAbove5 => ("face area above 5 MPa", "m2"),
            Quantity::AreaAbove10 => ("face area above 10 MPa", "m2"),
        }
    }
}

/// A mesh of the sequence.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MeshSize {
    pub label: String,
    /// Representative element size h [m].
    pub h: f64,
}

/// One mesh's value of a quantity.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MeshValue {
    pub mesh: String,
    pub h: f64,
    pub value: f64,
}

/// One quantity of one method at one level.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReferenceValue {
    pub quantity: Quantity,
    pub unit: String,
    pub method: Method,
    /// PGA over the design PGA.
    pub level: f64,
    /// Per mesh, coarsest first.
    pub values: Vec<MeshValue>,
    pub extrapolation: Extrapolation,
}

/// What `dam_reference.json` holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DamReference {
    /// The study file the runs came from.
    pub study: String,
    /// The commits the runs were built from (their summaries' provenance), distinct.
    pub commits: Vec<String>,
    /// The meshes with at least one finished run, coarsest first.
    pub meshes: Vec<MeshSize>,
    /// What the bands are, in words (two meshes: "band = 3 × change").
    pub note: String,
    pub values: Vec<ReferenceValue>,
}

impl DamReference {
    /// From the finished seed-model NTS and NTN runs of a study; `commits` are the runs' builds.
    /// Errors when a run's mesh has no size in `mesh_sizes`.
    pub fn from_runs(p: &DamParams, study: &str, runs: &[DamRun], commits: Vec<String>) -> Result<DamReference, String> {
        let used: Vec<&DamRun> = runs
            .iter()
            .filter(|r| r.is_seed_model() && r.failed.is_none() && matches!(r.method, Method::Nts | Method::Ntn))
            .collect();
        let mut meshes: Vec<MeshSize> = Vec::new();
        for r in &used {
            let h = *p.mesh_sizes.get(&r.mesh).ok_or_else(|| format!("run {}: mesh \"{}\" has no size in `report.mesh_sizes` (sizes: {:?})", r.id, r.mesh, p.mesh_sizes))?;
            if !meshes.iter().any(|m| m.label == r.mesh) {
                meshes.push(MeshSize { label: r.mesh.clone(), h });
            }
        }
        meshes.sort_by(|a, b| b.h.total_cmp(&a.h));
        let mut levels: Vec<f64> = used.iter().map(|r| lvl_num(r.level)).collect();
        levels.sort_by(f64::total_cmp);
        levels.dedup();
        let mut values = Vec::new();
        for &level in &levels {
            for method in [Method::Nts, Method::Ntn] {
                for q in Quantity::ALL {
                    let vals: Vec<MeshValue> = meshes
                        .iter()
                        .filter_map(|m| {
                            let r = used.iter().find(|r| r.mesh == m.label && r.method == method && lvl_num(r.level) == level)?;
                            Some(MeshValue { mesh: m.label.clone(), h: m.h, value: q.of(r)? })
                        })
                        .collect();
                    if vals.is_empty() {
                        continue;
                    }
                    let extrapolation = richardson(&vals.iter().map(|v| (v.h, v.value)).collect::<Vec<_>>());
                    values.push(ReferenceValue { quantity: q, unit: q.name().1.into(), method, level, values: vals, extrapolation });
                }
            }
        }
        let note = match meshes.len() {
            0 => "no finished NTS or NTN run".to_string(),
            1 => "one mesh: no error band".to_string(),
            2 => format!("two meshes ({}): no observed order; value = the finer mesh's, band = 3 × the change between them (Roache's factor for an unverified order)", meshes.iter().map(|m| format!("{} h {} m", m.label, m.h)).collect::<Vec<_>>().join(", ")),
            3 => "three meshes: Richardson extrapolation (Celik et al. 2008), band = GCI with safety factor 1.25; 3 × the largest change where the order is not observed".to_string(),
            _ => "three or more meshes: Richardson extrapolation from the three finest (Celik et al. 2008), band = GCI with safety factor 1.25, 3 × the largest change where the order is not observed; where a quantity has four meshes or more, the band is the larger of that and the least-squares uncertainty U over all of them (Eça & Hoekstra 2014)".to_string(),
        };
        Ok(DamReference { study: study.into(), commits, meshes, note, values })
    }

    /// The reference of `q` for `method` at `level`.
    pub fn get(&self, q: Quantity, method: Method, level: f64) -> Option<&ReferenceValue> {
        self.values.iter().find(|v| v.quantity == q && v.method == method && lvl_num(v.level) == lvl_num(level))
    }

    /// Read a reference file.
    pub fn read(path: &Path) -> Result<DamReference, OutputError> {
        let text = std::fs::read_to_string(path).map_err(|e| OutputError::read(path, e))?;
        serde_json::from_str(&text).map_err(|e| OutputError::read(path, format!("not a dam reference: {e}")))
    }

    /// Write it (pretty JSON, atomically).
    pub fn write(&self, path: &Path) -> Result<(), crate::Error> {
        let text = serde_json::to_string_pretty(self).map_err(|e| OutputError::read(path, e))?;
        crate::report::file::write_atomic(path, format!("{text}\n").as_bytes())?;
        Ok(())
    }
}

/// `jointquake study extrapolate`: read a dam study's runs (as `study report` does) and write
/// the reference to `out`. Returns it.
pub fn extrapolate(study: &crate::study::Study, kind: &super::DamKind, out: &Path) -> Result<DamReference, crate::Error> {
    let results = crate::study::StudyResults::read(study)?;
    let mut runs = Vec::new();
    let mut commits: Vec<String> = Vec::new();
    for r in results.runs.iter().filter(|r| r.has_results() && r.failed().is_none()) {
        runs.push(kind.run(r)?);
        if let Some(c) = r.summary.as_ref().and_then(|s| s.provenance.as_ref()).map(|p| p.commit.clone()) {
            if !commits.contains(&c) {
                commits.push(c);
            }
        }
    }
    let name = study.path.file_name().map(|f| f.to_string_lossy().into_owned()).unwrap_or_default();
    let reference = DamReference::from_runs(&kind.params, &name, &runs, commits)
        .map_err(|m| crate::error::StudyError::Invalid { path: study.path.clone(), message: m })?;
    reference.write(out)?;
    Ok(reference)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(mesh: &str, method: Method, level: f64, opening: f64) -> DamRun {
        DamRun {
            id: format!("{}-{mesh}", method.name()),
            method,
            reservoir: super::super::SEED_RESERVOIR.into(),
            foundation: super::super::SEED_FOUNDATION.into(),
            pulse: false,
            level,
            mesh: mesh.into(),
            wall_time: Some(1.0),
            failed: None,
            t_end: 6.0,
            joints: vec!["J01".into(), "J02".into()],
            opening: vec![opening, 0.5 * opening],
            slip: vec![0.01, 0.02],
            slip_path: vec![0.1, 0.2],
            diagnostics: None,
            stress: None,
            crest: vec![("crest_crown".into(), vec![(0.0, 0.0), (1.0, -0.3)])],
            crown_x: vec![],
            worst_joint_history: vec![],
        }
    }

    #[test]
    fn two_meshes_give_the_finer_value_and_a_band_of_three_changes_and_read_back() {
        // Reference (convergence.rs, Roache): with two meshes the value is the finer mesh's and
        // the band 3 |φ_default − φ_coarse|: openings 0.30 → 0.26 m gives 0.26 ± 0.12 m (to
        // 1e-12); a mesh without a size is an error naming it; a failed run is not used.
        let p: DamParams = serde_json::from_value(serde_json::json!({"main_mesh": "default", "seed": {"source": "", "levels": [], "opening_nts_mm": [], "opening_ntn_mm": [], "slip_nts_over_ntn": 0.0, "tension_nts_mpa": 0.0, "tension_ntn_mpa": 0.0, "compression_nts_mpa": 0.0, "compression_ntn_mpa": 0.0}, "mesh_sizes": {"coarse": 20, "default": 10}})).unwrap();
        let mut failed = run("fine", Method::Nts, 3.0, 9.0);
        failed.failed = Some("stopped".into());
        let runs = [run("coarse", Method::Nts, 3.0, 0.30), run("default", Method::Nts, 3.0, 0.26), run("default", Method::Ntn, 3.0, 0.20), failed];
        let r = DamReference::from_runs(&p, "s.json", &runs, vec!["abc".into()]).unwrap();
        assert_eq!(r.meshes.iter().map(|m| m.label.as_str()).collect::<Vec<_>>(), ["coarse", "default"]);
        let o = r.get(Quantity::Opening, Method::Nts, 3.0).unwrap();
        assert_eq!(o.values.len(), 2);
        assert_eq!(o.extrapolation.behaviour, super::super::convergence::Behaviour::TwoMeshes);
        assert!((o.extrapolation.extrapolated - 0.26).abs() < 1e-12 && (o.extrapolation.band.unwrap() - 0.12).abs() < 1e-12, "{o:?}");
        // NTN on one mesh: no band; the crest's largest |u_r| is 0.3 m; no stress without envelopes
        let n = r.get(Quantity::Opening, Method::Ntn, 3.0).unwrap();
        assert_eq!(n.extrapolation.band, None);
        assert_eq!(r.get(Quantity::Crest, Method::Nts, 3.0).unwrap().extrapolation.finest, 0.3);
        assert!(r.get(Quantity::Tension, Method::Nts, 3.0).is_none());
        assert!(r.note.starts_with("two meshes"), "{}", r.note);
        let dir = std::env::temp_dir().join(format!("jq_reference_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("ref.json");
        r.write(&f).unwrap();
        assert_eq!(DamReference::read(&f).unwrap(), r);
        let _ = std::fs::remove_dir_all(&dir);
        let bad = [run("h7", Method::Nts, 3.0, 0.3)];
        let e = DamReference::from_runs(&p, "s.json", &bad, vec![]).unwrap_err();
        assert!(e.contains("\"h7\""), "{e}");
    }

    #[test]
    fn a_reference_file_written_before_the_linearised_stresses_and_areas_reads_and_the_new_quantities_round_trip() {
        // Backward compatibility (issue 30 §4): a file of the 4 December format (eight
        // quantities, no linearised stress, no areas) reads; its new quantities are absent.
        let old = r#"{"study": "s.json", "commits": ["aad97b6"], "meshes": [{"label": "coarse", "h": 20.0}],
            "note": "one mesh: no error band", "values": [{"quantity": "objective_tension", "unit": "Pa",
            "method": "NTS", "level": 3.0, "values": [{"mesh": "coarse", "h": 20.0, "value": 5.66e7}],
            "extrapolation": {"behaviour": "one_mesh", "order": null, "extrapolated": 5.66e7, "band": null, "finest": 5.66e7}}]}"#;
        let dir = std::env::temp_dir().join(format!("jq_reference_old_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("old.json");
        std::fs::write(&f, old).unwrap();
        let r = DamReference::read(&f).unwrap();
        assert_eq!(r.get(Quantity::ObjectiveTension, Method::Nts, 3.0).unwrap().extrapolation.finest, 5.66e7);
        assert!(r.get(Quantity::ArchTension, Method::Nts, 3.0).is_none() && r.get(Quantity::AreaAbove3, Method::Nts, 3.0).is_none());
        // a run with linearised stresses and areas: 2 + 1 m² above 3 MPa (the sum of both
        // faces), the linearised arch tension the larger surface value 4 MPa
        use crate::output::linearise::LinearisedExtremes;
        let x = |t: f64| LinearisedExtremes { tension_start: t, tension_end: 0.5 * t, compression_start: -t, compression_end: -2.0 * t, membrane_tension: 0.0, membrane_compression: 0.0, tension_at: [0.0; 3] };
        let o = crate::output::envelope::ObjectiveStress { band: 20.0, max_tension: 1.0, max_tension_at: [0.0; 3], max_compression: -1.0, max_compression_at: [0.0; 3], kept: 1, excluded: 0 };
        let mut a = run("coarse", Method::Nts, 3.0, 0.3);
        a.stress = Some(super::super::FaceStress {
            upstream_tension: Default::default(),
            upstream_compression: Default::default(),
            downstream_tension: Default::default(),
            downstream_compression: Default::default(),
            upstream_objective: Some(o.clone()),
            downstream_objective: Some(o),
            areas_above: vec![(3e6, 2.0, 1.0), (5e6, 1.0, 0.0), (10e6, 0.0, 0.0)],
            linearised: Some(super::super::LinearisedStress { arch: x(4e6), cantilever: x(1e6), arch_outside_band: None, cantilever_outside_band: None, cuts: 1, dropped: 0 }),
        });
        let p: DamParams = serde_json::from_value(serde_json::json!({"main_mesh": "coarse", "seed": {"source": "", "levels": [], "opening_nts_mm": [], "opening_ntn_mm": [], "slip_nts_over_ntn": 0.0, "tension_nts_mpa": 0.0, "tension_ntn_mpa": 0.0, "compression_nts_mpa": 0.0, "compression_ntn_mpa": 0.0}, "mesh_sizes": {"coarse": 20}})).unwrap();
        let r = DamReference::from_runs(&p, "s.json", &[a], vec![]).unwrap();
        let v = |q| r.get(q, Method::Nts, 3.0).unwrap().extrapolation.finest;
        assert_eq!((v(Quantity::AreaAbove3), v(Quantity::AreaAbove5), v(Quantity::AreaAbove10)), (3.0, 1.0, 0.0));
        assert_eq!((v(Quantity::ArchTension), v(Quantity::ArchCompression), v(Quantity::CantileverTension)), (4e6, -8e6, 1e6));
        // the areas' names follow the thresholds they read
        assert_eq!(crate::output::envelope::TENSION_THRESHOLDS, [3e6, 5e6, 10e6]);
        r.write(&f).unwrap();
        assert_eq!(DamReference::read(&f).unwrap(), r);
        let _ = std::fs::remove_dir_all(&dir);
    }
}

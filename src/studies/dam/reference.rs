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
}

impl Quantity {
    pub const ALL: [Quantity; 8] = [
        Quantity::Opening,
        Quantity::Slip,
        Quantity::SlipPath,
        Quantity::Tension,
        Quantity::Compression,
        Quantity::ObjectiveTension,
        Quantity::ObjectiveCompression,
        Quantity::Crest,
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
        }
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
            _ => "three or more meshes: Richardson extrapolation from the three finest (Celik et al. 2008), band = GCI with safety factor 1.25; 3 × the largest change where the order is not observed".to_string(),
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
}

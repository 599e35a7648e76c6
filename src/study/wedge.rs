//! The wedge study of the seed paper (Hoek & Bray wedge): static factor of safety, seismic slip
//! against PGA with NTS, NTN and the rigid-block level, sensitivity to the rock's stiffness, and
//! speed against accuracy.
//!
//! Owns: the study file ([`WedgeStudy`], `pipelines/wedge_study.json`), the list of runs it
//! implies ([`plan_runs`]), the variant scenes and the Makefile fragment that runs them in
//! parallel ([`write_plan`]), and the reading of their results ([`RunResult`]). The report
//! (tables, charts, `report.md`) is in [`super::wedge_report`]. It owns no physics: every FEM
//! run is an ordinary scene run by `jointquake run`; the rigid level is
//! [`super::rigid_level`]; the strength reduction is [`super::ssr`].
//!
//! Conventions: PGA [g] is the peak of the *first* base record of the base scene (the
//! horizontal one); every record of the scene is scaled by the same factor, so the vertical
//! record keeps its ratio to the horizontal (2/3 in `pipelines/wedge.json`). Slip is the
//! relative displacement of the wedge and rock nodes at P2 (middle of the line of
//! intersection) along the line of intersection, positive down it, from its value at the end
//! of gravity equilibrium.

use crate::dynamics::loads::base_motions;
use crate::error::{Error, ModelError, OutputError, SceneError};
use crate::rigid::wedge::WedgeInput;
use crate::scene::Scene;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A mesh level: a name and the `-setnumber` values merged into the base scene's geometry.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MeshLevel {
    pub name: String,
    pub set: BTreeMap<String, f64>,
}

/// The reference run of each PGA: the finest mesh with NTS.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSpec {
    /// Mesh level name. Default: the last (finest) level.
    #[serde(default)]
    pub mesh: Option<String>,
    /// Candidate layer of the reference NTS runs. Default 2 (the wider set cannot lose a node
    /// that Layer1 keeps).
    #[serde(default = "two")]
    pub layer: u8,
}

fn two() -> u8 {
    2
}

impl Default for ReferenceSpec {
    fn default() -> Self {
        ReferenceSpec { mesh: None, layer: 2 }
    }
}

/// Strength-reduction settings of the study (see [`super::ssr::SsrOptions`]).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SsrSpec {
    /// Mesh level. Default: the first (coarsest) level.
    #[serde(default)]
    pub mesh: Option<String>,
    /// Initial bracket [F_low, F_high]. Default [1.0, 3.0] (the seed values lie in 1.6–1.9).
    #[serde(default = "ssr_bracket")]
    pub bracket: [f64; 2],
    /// Bracket width at which bisection stops. Default 0.01 (0.5 % of F ≈ 2).
    #[serde(default = "ssr_tol")]
    pub tolerance: f64,
    /// Slip [m] of any slave node above which a trial has failed. Default 0.05 m: far above the
    /// elastic relative displacement of a stable wedge (≈ 1e-4 m) and far below a sliding one.
    #[serde(default = "ssr_slip")]
    pub slip_limit: f64,
    /// Relaxation steps per trial. Default 60 000.
    #[serde(default = "ssr_steps")]
    pub max_steps: usize,
}

fn ssr_bracket() -> [f64; 2] {
    [1.0, 3.0]
}
fn ssr_tol() -> f64 {
    0.01
}
fn ssr_slip() -> f64 {
    0.05
}
fn ssr_steps() -> usize {
    60_000
}

impl Default for SsrSpec {
    fn default() -> Self {
        SsrSpec { mesh: None, bracket: ssr_bracket(), tolerance: ssr_tol(), slip_limit: ssr_slip(), max_steps: ssr_steps() }
    }
}

/// The study file (`pipelines/wedge_study.json`). Paths are relative to the study file.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct WedgeStudy {
    /// Name of the study; output under `out/<name>` unless `out` is given. Default "wedge".
    #[serde(default)]
    pub name: Option<String>,
    /// The base scene: geometry, materials, joints, gravity, base records at any PGA.
    pub scene: PathBuf,
    /// Output directory. Default `out/<name>`.
    #[serde(default)]
    pub out: Option<PathBuf>,
    /// Horizontal PGAs of the seismic sweep [g]. Default the seed's 0.2, 0.5, 0.8, 1.0, 1.5.
    #[serde(default = "default_pgas")]
    pub pga: Vec<f64>,
    /// Mesh levels, coarsest first.
    pub meshes: Vec<MeshLevel>,
    /// Mesh level of the NTS/NTN sweep over PGA. Default: the middle level.
    #[serde(default)]
    pub sweep_mesh: Option<String>,
    /// The finest run of each PGA (the accuracy reference).
    #[serde(default)]
    pub reference: ReferenceSpec,
    /// PGA of the speed-against-accuracy chart [g]. Default 1.0.
    #[serde(default = "one")]
    pub accuracy_pga: f64,
    /// Factors on the Young's modulus of every material for the stiffness sensitivity (run at
    /// `accuracy_pga`, sweep mesh, NTS). Default [0.5, 2.0].
    #[serde(default = "default_factors")]
    pub stiffness_factors: Vec<f64>,
    /// The rock of the main runs: "rigid" (default: the rock nodes are fixed, so the FEM wedge
    /// slides on its joints under the base motion itself, as on a stiff massless foundation) or
    /// "elastic" (the rock mass with its mass and stiffness, fixed at its bottom and sides).
    /// Why rigid by default: the elastic rock box of `geo/wedge.geo` has no absorbing boundaries,
    /// so it rings — alone, without the wedge, it amplifies El Centro at 0.2 g to 1.7 g under the
    /// wedge (8×) — and its response, not the joints, then decides the slip.
    #[serde(default = "rigid")]
    pub rock: String,
    /// Also run the sweep (NTS-L1 and NTN on the sweep mesh, every PGA) with the other rock
    /// model. Default true.
    #[serde(default = "yes")]
    pub other_rock_sweep: bool,
    /// Strength reduction.
    #[serde(default)]
    pub ssr: SsrSpec,
    /// The wedge for limit equilibrium and the rigid level. Default: the seed wedge, which is
    /// what `geo/wedge.geo` builds with its defaults.
    #[serde(default)]
    pub wedge: WedgeInput,
    /// Names of the monitored points in the base scene: P1 on the wedge, P2 on the wedge and
    /// on the rock. Default "P1", "P2w", "P2r".
    #[serde(default)]
    pub monitors: MonitorNames,
    /// Fraction of the reference slip within which a cheaper level "is enough". Default 0.10.
    #[serde(default = "ten_percent")]
    pub enough: f64,
}

/// Names of the monitored points the report reads.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MonitorNames {
    pub p1: String,
    pub p2_wedge: String,
    pub p2_rock: String,
    /// A rock node inside the rock mass under the wedge (off the joint, whose master nodes
    /// carry the contact impulses): the motion the rock delivers to the wedge. Optional in the
    /// scene; default "R".
    #[serde(default = "default_rock_monitor")]
    pub rock: String,
}

fn default_rock_monitor() -> String {
    "R".into()
}

impl Default for MonitorNames {
    fn default() -> Self {
        MonitorNames { p1: "P1".into(), p2_wedge: "P2w".into(), p2_rock: "P2r".into(), rock: default_rock_monitor() }
    }
}

fn default_pgas() -> Vec<f64> {
    vec![0.2, 0.5, 0.8, 1.0, 1.5]
}
fn one() -> f64 {
    1.0
}
fn yes() -> bool {
    true
}
fn rigid() -> String {
    "rigid".into()
}
fn default_factors() -> Vec<f64> {
    vec![0.5, 2.0]
}
fn ten_percent() -> f64 {
    0.10
}

/// What a FEM run of the study varies.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunSpec {
    /// File-safe identifier, e.g. `nts1-medium-pga1.00`.
    pub id: String,
    pub mesh: String,
    /// "nts" or "ntn".
    pub method: String,
    /// Candidate layer (NTS): 1 or 2.
    pub layer: u8,
    /// Horizontal PGA [g].
    pub pga: f64,
    /// Factor on every Young's modulus.
    pub e_factor: f64,
    /// Rock nodes fixed (FEM wedge on a rigid rock).
    pub rigid_rock: bool,
    /// Write VTU frames (only the run shown in ParaView).
    pub frames: bool,
    /// Relative cost estimate used to start the expensive runs first (elements / dt ∝).
    pub cost_rank: usize,
}

impl RunSpec {
    /// Short label of the model level, e.g. "NTS-L1 medium".
    pub fn level(&self) -> String {
        let m = if self.method == "nts" { format!("NTS-L{}", self.layer) } else { "NTN".into() };
        format!("{m} {}", self.mesh)
    }
}

impl WedgeStudy {
    /// Read a study file; paths are made relative to the current directory.
    pub fn load(path: &Path) -> Result<WedgeStudy, Error> {
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io { path: path.to_path_buf(), source })?;
        let mut s: WedgeStudy = serde_json::from_str(&text)
            .map_err(|e| SceneError::Parse { path: path.to_path_buf(), message: format!("{e} (study file; see docs/wedge.md)") })?;
        let base = path.parent().unwrap_or(Path::new("."));
        if s.scene.is_relative() {
            s.scene = base.join(&s.scene);
        }
        if let Some(o) = s.out.as_mut()
            && o.is_relative()
        {
            *o = base.join(&*o);
        }
        s.validate().map_err(|message| SceneError::Invalid { path: path.to_path_buf(), message })?;
        Ok(s)
    }

    fn validate(&self) -> Result<(), String> {
        if self.meshes.is_empty() {
            return Err("`meshes` must list at least one mesh level (name and gmsh numbers)".into());
        }
        for (i, m) in self.meshes.iter().enumerate() {
            if self.meshes[..i].iter().any(|o| o.name == m.name) {
                return Err(format!("mesh level \"{}\" is given twice", m.name));
            }
            if m.name.is_empty() || !m.name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
                return Err(format!("mesh level name \"{}\": use letters, digits and _ only (it goes into file names)", m.name));
            }
        }
        for name in [&self.sweep_mesh, &self.reference.mesh, &self.ssr.mesh].into_iter().flatten() {
            if !self.meshes.iter().any(|m| &m.name == name) {
                let known: Vec<&str> = self.meshes.iter().map(|m| m.name.as_str()).collect();
                return Err(format!("mesh level \"{name}\" is not in `meshes` ({})", known.join(", ")));
            }
        }
        if self.pga.is_empty() || self.pga.iter().any(|p| !(p.is_finite() && *p > 0.0)) {
            return Err(format!("`pga` must be a non-empty list of positive accelerations [g], got {:?}", self.pga));
        }
        if !(self.accuracy_pga.is_finite() && self.accuracy_pga > 0.0) {
            return Err(format!("`accuracy_pga` = {} must be a positive acceleration [g]", self.accuracy_pga));
        }
        if self.stiffness_factors.iter().any(|f| !(f.is_finite() && *f > 0.0)) {
            return Err(format!("`stiffness_factors` must be positive, got {:?}", self.stiffness_factors));
        }
        if !(1..=2).contains(&self.reference.layer) {
            return Err(format!("reference.layer = {} must be 1 or 2", self.reference.layer));
        }
        if !matches!(self.rock.as_str(), "rigid" | "elastic") {
            return Err(format!("`rock` = \"{}\" must be \"rigid\" or \"elastic\"", self.rock));
        }
        if !(self.enough > 0.0 && self.enough < 1.0) {
            return Err(format!("`enough` = {} must be a fraction in (0, 1)", self.enough));
        }
        Ok(())
    }

    pub fn name(&self) -> &str {
        self.name.as_deref().unwrap_or("wedge")
    }

    /// Whether the main runs have a rigid rock.
    pub fn main_rigid_rock(&self) -> bool {
        self.rock == "rigid"
    }

    pub fn out_dir(&self) -> PathBuf {
        self.out.clone().unwrap_or_else(|| PathBuf::from("out").join(self.name()))
    }

    pub fn sweep_mesh(&self) -> &str {
        self.sweep_mesh.as_deref().unwrap_or(&self.meshes[self.meshes.len() / 2].name)
    }

    pub fn reference_mesh(&self) -> &str {
        self.reference.mesh.as_deref().unwrap_or(&self.meshes[self.meshes.len() - 1].name)
    }

    pub fn ssr_mesh(&self) -> &str {
        self.ssr.mesh.as_deref().unwrap_or(&self.meshes[0].name)
    }

    /// The limit-equilibrium / rigid-block wedge of `scene`: the study's `wedge` geometry with
    /// the strength of the scene's joints "A" and "B" and the density of `block:wedge`.
    pub fn wedge_of(&self, scene: &Scene) -> WedgeInput {
        super::rigid_level::wedge_input_from_scene(&self.wedge, scene, "A", "B", "block:wedge")
    }

    pub fn mesh_level(&self, name: &str) -> &MeshLevel {
        self.meshes.iter().find(|m| m.name == name).expect("validated mesh level name")
    }

    fn mesh_index(&self, name: &str) -> usize {
        self.meshes.iter().position(|m| m.name == name).expect("validated mesh level name")
    }
}

/// Every FEM run of the study, without duplicates, in a fixed order (most expensive first, so
/// that `make -j` starts the long runs early).
///
/// - the sweep: NTS-Layer1 and NTN on the sweep mesh at every PGA (the NTS run at
///   `accuracy_pga` writes frames: it is the one to look at in ParaView);
/// - the levels of every PGA: NTS-Layer1 and NTN on every mesh coarser than the reference,
///   and the reference (finest mesh, NTS with `reference.layer`);
/// - at `accuracy_pga` also NTS-Layer1, NTS-Layer2 and NTN on every mesh (the
///   speed-against-accuracy chart);
/// - at `accuracy_pga`: the stiffness factors (sweep mesh, NTS-L1);
/// - with `other_rock_sweep`: the sweep again with the other rock model (`rock`).
pub fn plan_runs(study: &WedgeStudy) -> Vec<RunSpec> {
    let mut runs: Vec<RunSpec> = Vec::new();
    let mut add = |mesh: &str, method: &str, layer: u8, pga: f64, e_factor: f64, rigid_rock: bool, frames: bool| {
        let layer = if method == "ntn" { 1 } else { layer };
        let m = if method == "ntn" { "ntn".to_string() } else { format!("nts{layer}") };
        let mut id = format!("{m}-{mesh}-pga{pga:.2}");
        if e_factor != 1.0 {
            id.push_str(&format!("-E{e_factor}"));
        }
        id.push_str(if rigid_rock { "-rigidrock" } else { "-elasticrock" });
        if let Some(r) = runs.iter_mut().find(|r| r.id == id) {
            r.frames |= frames;
            return;
        }
        let mi = study.mesh_index(mesh);
        runs.push(RunSpec {
            id,
            mesh: mesh.to_string(),
            method: method.to_string(),
            layer,
            pga,
            e_factor,
            rigid_rock,
            frames,
            cost_rank: mi,
        });
    };
    let sweep = study.sweep_mesh().to_string();
    let reference = study.reference_mesh().to_string();
    let rr = study.main_rigid_rock();
    for &pga in &study.pga {
        for method in ["nts", "ntn"] {
            add(&sweep, method, 1, pga, 1.0, rr, method == "nts" && pga == study.accuracy_pga);
        }
        // the cheaper levels of every PGA: every mesh coarser than the reference
        for m in study.meshes.iter().take_while(|m| m.name != reference) {
            for method in ["nts", "ntn"] {
                add(&m.name, method, 1, pga, 1.0, rr, false);
            }
        }
        add(&reference, "nts", study.reference.layer, pga, 1.0, rr, false);
    }
    let acc = study.accuracy_pga;
    for m in &study.meshes {
        for method in ["nts", "ntn"] {
            add(&m.name, method, 1, acc, 1.0, rr, false);
        }
        add(&m.name, "nts", 2, acc, 1.0, rr, false);
    }
    add(&reference, "nts", study.reference.layer, acc, 1.0, rr, false);
    for &f in &study.stiffness_factors {
        add(&sweep, "nts", 1, acc, f, rr, false);
    }
    if study.other_rock_sweep {
        for &pga in &study.pga {
            for method in ["nts", "ntn"] {
                add(&sweep, method, 1, pga, 1.0, !rr, false);
            }
        }
    }
    // finest meshes first; stable within a level
    runs.sort_by(|a, b| b.cost_rank.cmp(&a.cost_rank));
    runs
}

/// Canonical absolute form of a path that exists (else the path joined to the current directory).
fn absolute(p: &Path) -> PathBuf {
    std::fs::canonicalize(p).unwrap_or_else(|_| std::env::current_dir().map(|d| d.join(p)).unwrap_or_else(|_| p.to_path_buf()))
}

/// Factor that brings the first base record of `scene` to `pga` [g] (all records get it).
fn pga_factor(scene: &Scene, pga: f64) -> Result<f64, Error> {
    let (base, _) = base_motions(scene)?;
    let first = base.first().ok_or_else(|| ModelError::Invalid("the study's base scene has no `loads.base` record to scale to the PGAs".into()))?;
    let peak = first.record.peak() * first.scale; // m/s²
    if peak <= 0.0 {
        return Err(ModelError::Invalid(format!("record {} is all zeros: cannot scale it to {pga} g", first.record.path.display())).into());
    }
    Ok(pga * scene.g / peak)
}

/// The scene of one run: the base scene with the run's mesh numbers, PGA, moduli, contact method
/// and layer, its own name and output directory; paths absolute.
pub fn variant_scene(base: &Scene, study: &WedgeStudy, run: &RunSpec) -> Result<Scene, Error> {
    let mut s = base.clone();
    s.name = Some(run.id.clone());
    if let Some(g) = s.geometry.geo.as_mut() {
        *g = absolute(g);
    }
    if let Some(m) = s.geometry.msh.as_mut() {
        *m = absolute(m);
    }
    for (k, v) in &study.mesh_level(&run.mesh).set {
        s.geometry.set.insert(k.clone(), *v);
    }
    let f = pga_factor(base, run.pga)?;
    for b in &mut s.loads.base {
        let peak_scale = match (b.scale, b.pga) {
            (_, Some(p)) => {
                let r = crate::dynamics::record::Record::read(&b.record, base.g)?;
                p * base.g / r.peak()
            }
            (Some(sc), None) => sc,
            (None, None) => 1.0,
        };
        b.scale = Some(peak_scale * f);
        b.pga = None;
        b.record = absolute(&b.record);
    }
    for m in &mut s.materials {
        m.e *= run.e_factor;
    }
    for j in &mut s.joints {
        j.method = Some(run.method.parse().map_err(crate::error::ModelError::Invalid)?);
        j.layer = Some(run.layer);
    }
    // The rock model: every volume that carries no weight (the rock) is fixed in the rigid
    // model and free in the elastic one, whatever the base scene says.
    let wedge_groups = s.loads.gravity.as_ref().and_then(|g| g.groups.clone()).ok_or_else(|| {
        ModelError::Invalid("study: the base scene's gravity must name the sliding blocks in `loads.gravity.groups` (the other volumes are the rock)".into())
    })?;
    let rock_groups: Vec<String> = base.materials.iter().filter(|m| !wedge_groups.contains(&m.group)).map(|m| m.group.clone()).collect();
    s.boundary.retain(|b| !rock_groups.contains(&b.group));
    if run.rigid_rock {
        for g in rock_groups {
            s.boundary.push(crate::scene::BoundarySpec { group: g, fix: vec!["x".into(), "y".into(), "z".into()] });
        }
    }
    s.output.frames = run.frames;
    s.output.dir = None;
    Ok(s)
}

/// Files written by [`write_plan`].
#[derive(Clone, Debug, Serialize)]
pub struct PlanFiles {
    pub plan: PathBuf,
    pub makefile: PathBuf,
    pub scenes: Vec<PathBuf>,
    pub meshes: Vec<PathBuf>,
}

/// The plan as written to `plan.json` (read back by the report).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Plan {
    pub study: PathBuf,
    pub out: PathBuf,
    pub runs: Vec<RunSpec>,
}

/// Write `<out>/scenes/<id>.json` for every run, `<out>/plan.json` and `<out>/runs.mk` (a
/// Makefile with one target per run and the strength reduction, for `make -j`), and mesh every
/// distinct geometry once now, so that parallel runs never mesh the same `.geo` at the same time.
pub fn write_plan(study_path: &Path, study: &WedgeStudy, mesh_cache: &Path, bin: &str) -> Result<PlanFiles, Error> {
    let base = Scene::load(&study.scene)?;
    let out = study.out_dir();
    let scenes_dir = out.join("scenes");
    std::fs::create_dir_all(&scenes_dir).map_err(|e| OutputError::write(&scenes_dir, e))?;
    let runs = plan_runs(study);
    let mut scenes = Vec::new();
    let mut meshes: Vec<PathBuf> = Vec::new();
    for r in &runs {
        let s = variant_scene(&base, study, r)?;
        if let Some(geo) = &s.geometry.geo {
            let m = crate::gmsh::mesh_geo(geo, &s.geometry.set, mesh_cache)?;
            if !meshes.contains(&m) {
                meshes.push(m);
            }
        }
        let p = scenes_dir.join(format!("{}.json", r.id));
        let text = serde_json::to_string_pretty(&s).expect("scene serialises");
        std::fs::write(&p, text).map_err(|e| OutputError::write(&p, e))?;
        scenes.push(p);
    }
    let plan = Plan { study: absolute(study_path), out: out.clone(), runs: runs.clone() };
    let plan_path = out.join("plan.json");
    std::fs::write(&plan_path, serde_json::to_string_pretty(&plan).expect("plan serialises")).map_err(|e| OutputError::write(&plan_path, e))?;

    let mk = out.join("runs.mk");
    let mut t = String::new();
    t.push_str("# Generated by `jointquake study plan`: one target per run of the wedge study.\n");
    t.push_str("# Run with `make -f runs.mk -j2 all` (the top-level `make wedge` does this).\n");
    t.push_str(&format!("BIN ?= {bin}\nOUT := {}\nSTUDY := {}\nCACHE := {}\n", out.display(), study_path.display(), mesh_cache.display()));
    t.push_str("RUNS :=");
    for r in &runs {
        t.push_str(&format!(" \\\n  {}", r.id));
    }
    t.push_str("\n\n.PHONY: all\nall: $(OUT)/ssr.json $(RUNS:%=$(OUT)/runs/%/summary.json)\n\n");
    // A run that stops with an error (e.g. the energy check when a wedge slides out of its bed)
    // leaves `failed.txt` with the error, and a `summary.json` stub so that the other runs go
    // on; the report lists it with the error and the slip reached.
    t.push_str("$(OUT)/runs/%/summary.json: $(OUT)/scenes/%.json\n");
    t.push_str("\t@mkdir -p $(OUT)/runs/$*\n");
    t.push_str("\t@rm -f $(OUT)/runs/$*/failed.txt\n");
    t.push_str("\t@echo \"run $*\"\n");
    t.push_str("\t@$(BIN) run $< --out $(OUT)/runs/$* --cache $(CACHE) --threads 1 --quiet > $(OUT)/runs/$*.log 2>&1 || { grep '^error' $(OUT)/runs/$*.log > $(OUT)/runs/$*/failed.txt || tail -n 5 $(OUT)/runs/$*.log > $(OUT)/runs/$*/failed.txt; echo \"run $* FAILED: $$(cat $(OUT)/runs/$*/failed.txt)\"; echo '{\"failed\": true}' > $@; }\n\n");
    t.push_str("$(OUT)/ssr.json:\n\t@echo \"strength reduction\"\n");
    t.push_str("\t@$(BIN) study ssr $(STUDY) --cache $(CACHE) --threads 1 > $(OUT)/ssr.log 2>&1 || { tail -n 5 $(OUT)/ssr.log; exit 1; }\n");
    std::fs::write(&mk, t).map_err(|e| OutputError::write(&mk, e))?;
    Ok(PlanFiles { plan: plan_path, makefile: mk, scenes, meshes })
}

/// The study's FEM strength reduction (`<out>/ssr.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StudySsr {
    /// Mesh level and its size.
    pub mesh: String,
    pub nodes: usize,
    pub elements: usize,
    pub result: super::ssr::SsrResult,
    /// Limit equilibrium of the same wedge (the study's `wedge`), and with H read as the crest
    /// height on plane A (the reading that reproduces the seed's quoted 1.68).
    pub le_fs: f64,
    pub le_fs_crest_on_a: f64,
    pub wall_time: f64,
}

/// Strength reduction of the study's wedge: the base scene on the SSR mesh level, without its
/// base records (gravity only), bisection on F (see [`super::ssr`] for the failure criterion).
pub fn run_ssr(study: &WedgeStudy, mesh_cache: &Path) -> Result<StudySsr, Error> {
    use crate::rigid::wedge::{analyse_wedge, HeightDef};
    let t0 = std::time::Instant::now();
    let base = Scene::load(&study.scene)?;
    let level = study.ssr_mesh().to_string();
    let spec = RunSpec {
        id: format!("ssr-{level}"),
        mesh: level.clone(),
        method: "nts".into(),
        layer: 1,
        pga: study.accuracy_pga,
        e_factor: 1.0,
        rigid_rock: false,
        frames: false,
        cost_rank: 0,
    };
    let mut scene = variant_scene(&base, study, &spec)?;
    scene.loads.base.clear();
    let opts = crate::pipeline::RunOptions { mesh_cache: Some(mesh_cache.to_path_buf()), ..Default::default() };
    let mesh = crate::pipeline::load_mesh(&scene, &opts)?;
    let p1 = scene.output.monitor.iter().find(|m| m.name == study.monitors.p1).map(|m| m.point);
    let ssr_opts = super::ssr::SsrOptions {
        bracket: study.ssr.bracket,
        tolerance: study.ssr.tolerance,
        max_steps: study.ssr.max_steps,
        residual: 1e-5,
        slip_limit: study.ssr.slip_limit,
        monitor: p1,
    };
    let (nodes, elements) = (mesh.nodes.len(), mesh.cells.iter().filter(|c| c.kind.dim() == 3).count());
    let result = super::ssr::strength_reduction(&mesh, &scene, &ssr_opts)?;
    let le_wedge = study.wedge_of(&scene);
    let le_fs = analyse_wedge(&le_wedge)?.fs;
    let le_fs_crest_on_a = analyse_wedge(&WedgeInput { height_def: HeightDef::CrestOnA, ..le_wedge })?.fs;
    Ok(StudySsr { mesh: level, nodes, elements, result, le_fs, le_fs_crest_on_a, wall_time: t0.elapsed().as_secs_f64() })
}

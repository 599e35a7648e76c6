//! The recipe: the only function that sequences the stages (scene → mesh → problem (model,
//! joints, loads) → simulation: equilibrium → dynamic run with a recorder → summary). Each stage
//! is timed into `summary.json`.

use crate::error::{Error, ModelError};
use crate::mesh::Mesh;
use crate::output::recorder::Recorder;
use crate::problem::Problem;
use crate::scene::Scene;
use crate::simulation::Simulation;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

pub use crate::output::recorder::snap_monitors;
pub use crate::output::summary::{Peak, RunSummary};

/// Where gmsh meshes are cached when no cache is given [path]: `build/mesh` under the working
/// directory (the Makefile's and the CLI's default; `make clean` removes it). Meshes are keyed
/// by the `.geo` text and its `set` numbers, so a shared cache is never stale.
pub const DEFAULT_MESH_CACHE: &str = "build/mesh";

/// Options of a run that are not part of the scene.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Override the output directory.
    pub out_dir: Option<PathBuf>,
    /// Where gmsh meshes are cached. Default [`DEFAULT_MESH_CACHE`].
    pub mesh_cache: Option<PathBuf>,
    /// Show a progress bar (only drawn when stderr is a terminal). Default false.
    pub progress: bool,
    /// Replace the scene's `time.duration` [s]. Default: the scene's.
    pub duration: Option<f64>,
    /// Threads of the run. Default `None`: [`default_threads`] (one thread below
    /// [`SERIAL_BELOW_ELEMENTS`] elements, else all of rayon's pool).
    pub threads: Option<usize>,
}

/// Produce the mesh of a scene (gmsh for a `.geo`, cached under `mesh_cache`, default
/// [`DEFAULT_MESH_CACHE`]; or the given `.msh`) and read it, as it is: the scene's group
/// patterns are not expanded (`jointquake mesh` lists the groups; every caller that builds a
/// problem uses [`load_scene_mesh`]).
pub fn load_mesh(scene: &Scene, mesh_cache: Option<&Path>) -> Result<Mesh, Error> {
    let path = match (&scene.geometry.geo, &scene.geometry.msh) {
        (Some(geo), _) => crate::gmsh::mesh_geo(geo, &scene.geometry.set, mesh_cache.unwrap_or(Path::new(DEFAULT_MESH_CACHE)))?,
        (None, Some(msh)) => msh.clone(),
        (None, None) => return Err(crate::error::SceneError::Invalid { path: PathBuf::from(scene.name()), message: "geometry: give `geo` (a Gmsh script) or `msh` (a mesh file)".into() }.into()),
    };
    Ok(Mesh::from_msh(path)?)
}

/// The mesh of a scene and the scene made ready for it, the one way every caller loads a
/// scene's mesh (the run, `tag`, `modes`, the wedge's strength reduction, the tests): the mesh
/// as [`load_mesh`] makes it, then the scene's group patterns expanded against it and the
/// expanded scene checked again ([`expand_patterns`]). Errors name `scene_path` (the scene's
/// file, or for a scene built in memory the file it came from).
pub fn load_scene_mesh(scene: &mut Scene, scene_path: &Path, mesh_cache: Option<&Path>) -> Result<Mesh, Error> {
    let mesh = load_mesh(scene, mesh_cache)?;
    interrupt_phase("meshing")?;
    expand_patterns(scene, &mesh, scene_path)?;
    interrupt_phase("the expansion of group patterns")?;
    Ok(mesh)
}

/// Ends a run between its phases when SIGINT/SIGTERM arrived (`crate::interrupt`), naming the
/// phase that had finished.
fn interrupt_phase(name: &str) -> Result<(), Error> {
    Ok(crate::interrupt::check(name)?)
}

/// Expand the scene's group patterns against the mesh ([`crate::scene::patterns`]) and check
/// the expanded scene again (names and joint pairs); errors name the scene file. The second
/// half of [`load_scene_mesh`], for a caller that has the mesh already (a benchmark that reuses
/// one mesh for several scenes). Must run right after the mesh is read, before any group lookup.
pub fn expand_patterns(scene: &mut Scene, mesh: &Mesh, scene_path: &Path) -> Result<Vec<crate::scene::patterns::PatternUse>, Error> {
    let invalid = |message: String| -> Error { crate::error::SceneError::Invalid { path: scene_path.to_path_buf(), message }.into() };
    let uses = scene.expand_group_patterns(&crate::scene::patterns::mesh_group_names(mesh)).map_err(|e| invalid(e.to_string()))?;
    if !uses.is_empty() {
        scene.validate().map_err(invalid)?;
    }
    Ok(uses)
}

/// Run a scene file end to end: the recipe.
pub fn run(scene_path: &Path, opts: &RunOptions) -> Result<RunSummary, Error> {
    run_inspect(scene_path, opts, &mut |_, _| Ok(()))
}

/// [`run`], with `inspect` called on the simulation and the output directory after the static
/// state (the equilibrium), before the dynamic stage (e.g. the dam's static table).
///
/// Ctrl-C or SIGTERM (`crate::interrupt`) in any phase ends the run with `Ok` and a
/// `summary.json` marked `interrupted`: in the time loop at its next output (the recorder's
/// summary, outputs whole up to there); before it (meshing, pattern expansion, the model's build,
/// the static state) at the phase's next check, with a summary naming the phase
/// ([`RunSummary::interrupted_before`]). The CLI exits with `crate::interrupt::EXIT_STATUS`
/// for both. A run whose joints penetrate beyond the stated fraction of their element size
/// ([`crate::output::recorder::penetration_excess`]) writes its outputs and summary, then is an
/// error unless the scene sets `output.allow_penetration`.
pub fn run_inspect(scene_path: &Path, opts: &RunOptions, inspect: &mut (dyn FnMut(&Simulation<'_>, &Path) -> Result<(), Error> + Send)) -> Result<RunSummary, Error> {
    let t_all = Instant::now();
    let mut laps = Laps::start();
    let mut scene = Scene::load(scene_path)?;
    if let Some(d) = opts.duration {
        if !(d.is_finite() && d >= 0.0) {
            return Err(crate::error::SceneError::Invalid { path: scene_path.to_path_buf(), message: format!("--duration {d}: must be a finite time ≥ 0 [s]") }.into());
        }
        scene.time.duration = d;
    }
    let (name, out_dir, allow_penetration) = (scene.name().to_string(), opts.out_dir.clone().unwrap_or_else(|| scene.output_dir()), scene.output.allow_penetration);
    match run_phases(scene, scene_path, opts, inspect, &mut laps, t_all) {
        Err(e) if e.interrupted().is_some() => {
            let phase = e.interrupted().map(|i| i.phase.clone()).unwrap_or_default();
            laps.lap(&format!("interrupted during {phase}"));
            let summary = RunSummary::interrupted_before(&name, &out_dir, &phase, laps.timings.clone(), t_all.elapsed().as_secs_f64());
            std::fs::create_dir_all(&out_dir).map_err(|e| crate::error::OutputError::write(&out_dir, e))?;
            summary.write(&out_dir)?;
            Ok(summary)
        }
        Ok(summary) if !allow_penetration && summary.interrupted.is_none() => match crate::output::recorder::penetration_excess(&summary.joints) {
            Some(m) => Err(crate::error::StepError::Contact(format!("{m}; the outputs and summary.json are in {} (set `output.allow_penetration: true` in the scene to accept such a run)", out_dir.display())).into()),
            None => Ok(summary),
        },
        r => r,
    }
}

/// The phases of [`run_inspect`] after the scene is read: mesh, problem, static state, time loop.
fn run_phases(mut scene: Scene, scene_path: &Path, opts: &RunOptions, inspect: &mut (dyn FnMut(&Simulation<'_>, &Path) -> Result<(), Error> + Send), laps: &mut Laps, t_all: Instant) -> Result<RunSummary, Error> {
    let mesh = load_scene_mesh(&mut scene, scene_path, opts.mesh_cache.as_deref())?;
    let mesh_path = mesh.source.clone();
    laps.lap("mesh");
    let problem = Problem::build(scene, mesh)?;
    interrupt_phase("the model's build (records, reservoir, joints)")?;
    laps.lap("model");
    let threads = opts.threads.unwrap_or_else(|| default_threads(problem.model.n_elements(), rayon::current_num_threads()));
    let simulate = || -> Result<RunSummary, Error> {
        let mut sim = Simulation::new(&problem)?;
        let out_dir = opts.out_dir.clone().unwrap_or_else(|| problem.scene.output_dir());
        crate::output::recorder::check_outputs(&sim, &out_dir)?;
        sim.equilibrate()?;
        interrupt_phase("the static state")?;
        laps.lap("equilibrium");
        inspect(&sim, &out_dir)?;
        let mut recorder = Recorder::create(&sim, &out_dir, opts.progress)?;
        // the time loop with the pool's other workers kept awake between the step's parallel
        // regions (`par::with_awake_workers`: why, and what it costs)
        crate::par::with_awake_workers(|| sim.run(&mut recorder))?;
        laps.lap("dynamic");
        let summary = recorder.summary(&sim, mesh_path, laps.timings.clone(), t_all.elapsed().as_secs_f64());
        summary.write(&out_dir)?;
        Ok(summary)
    };
    // The run on a worker of a pool of `threads`, also when that is as many as rayon's global
    // pool has: the step's parallel regions (about 50 a step on the dam, docs/performance.md §7)
    // then start on a worker, which runs its own part and lets the others steal the rest. Called
    // from outside a pool (the main thread), each region was injected into the pool while the
    // main thread slept until a worker had run it: two wake-ups a region, and one thread fewer.
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| ModelError::Invalid(format!("cannot start {threads} threads: {e}")))?;
    pool.install(simulate)
}

/// Wall time of a run's stages [s], in order.
struct Laps {
    timings: Vec<(String, f64)>,
    t: Instant,
}

impl Laps {
    fn start() -> Laps {
        Laps { timings: Vec::new(), t: Instant::now() }
    }

    /// Close the stage `name` and start the next.
    fn lap(&mut self, name: &str) {
        self.timings.push((name.to_string(), self.t.elapsed().as_secs_f64()));
        self.t = Instant::now();
    }
}

/// Below this many elements a run uses one thread unless told otherwise (`RunOptions::threads`,
/// `jointquake run --threads`). Measured on the 2-core machine (docs/performance.md §1, Two
/// threads): the wedge's medium mesh (13 941 tet4, two joints) stepped 12 s of El Centro in
/// 24.1 s on one thread and 28.2 s on two; the fine mesh (26 849 tet4) 46.0 s and 45.6 s. The
/// contact correction is serial and a model this small does not pay for the threads' start.
pub const SERIAL_BELOW_ELEMENTS: usize = 30_000;

/// The thread count of a run when none is given: one below [`SERIAL_BELOW_ELEMENTS`], else all
/// of rayon's (`available`).
pub fn default_threads(elements: usize, available: usize) -> usize {
    if elements < SERIAL_BELOW_ELEMENTS { 1 } else { available }
}

// ---------------------------------------------------------------------------------------------
// `jointquake tag`: tag the joints of a scene and write them for inspection (no time stepping).

pub use crate::contact::joint::DEFAULT_JOINT_TOLERANCE_RELATIVE;

/// What `tag` found for one joint (lengths in m, areas in m²).
#[derive(Clone, Debug, Serialize)]
pub struct JointTagSummary {
    pub name: String,
    /// Group that became the slave / master (after `auto`).
    pub slave_group: String,
    pub master_group: String,
    /// `auto` as written in the scene, and whether it exchanged the named roles.
    pub auto: bool,
    pub swapped: bool,
    /// Tolerance used [m] and where it came from ("scene" or "default").
    pub tolerance: f64,
    pub tolerance_source: String,
    pub slave_nodes: usize,
    pub slave_faces: usize,
    pub master_nodes: usize,
    pub master_faces: usize,
    pub slave_area: f64,
    pub master_area: f64,
    /// Mean number of master faces in Layer1 / Layer2 per slave node.
    pub layer1_mean: f64,
    pub layer2_mean: f64,
    /// Largest slave-node-to-O distance [m] (the NTN error) and the Gmsh tag of that slave node.
    pub ntn_max_distance: f64,
    pub ntn_max_node_tag: u64,
    /// Slave nodes whose O coincides with them (within 1e-9 × joint size).
    pub ntn_conforming: usize,
    /// Largest slave-node-to-master-surface distance [m].
    pub max_surface_distance: f64,
    /// The joint's VTU file.
    pub vtu: PathBuf,
}

/// What `tag` reports (also written as `<out>/tagging/summary.json`).
#[derive(Clone, Debug, Serialize)]
pub struct TagSummary {
    pub scene: String,
    pub mesh: PathBuf,
    pub nodes: usize,
    /// Mesh bounding-box diagonal [m] (scale of the default tolerance).
    pub model_size: f64,
    pub joints: Vec<JointTagSummary>,
    /// `joints.json` (all joints, layout in docs/tagger.md).
    pub json: PathBuf,
    pub out_dir: PathBuf,
    pub wall_time: f64,
}

/// A joint name made safe for a file name: characters other than letters, digits, `-`, `_` and
/// `.` become `_`.

/// Tag every joint of a scene: load the scene, mesh it, tag `scene.joints` in order (tolerance:
/// the joint's `tolerance`, else [`DEFAULT_JOINT_TOLERANCE_RELATIVE`] × the mesh bounding-box
/// diagonal), and write `<out>/tagging/joints.json`, one `<out>/tagging/<joint>.vtu` per joint and
/// `<out>/tagging/summary.json`. `<out>` is `opts.out_dir`, else the scene's output directory.
pub fn tag(scene_path: &Path, opts: &RunOptions) -> Result<TagSummary, Error> {
    use crate::interface::{tag_joint_in, write_joint_json, write_joint_vtu, JointSpec};
    let t_all = Instant::now();
    let mut scene = Scene::load(scene_path)?;
    if scene.joints.is_empty() {
        return Err(crate::error::SceneError::Invalid {
            path: scene_path.to_path_buf(),
            message: "no joints to tag: add a `joints` list with `name`, `master` and `slave` face groups (see docs/scenes.md)".into(),
        }
        .into());
    }
    // Joint names (non-empty, distinct file stems) are checked by `Scene::validate`, again after
    // the patterns are expanded.
    let mesh = load_scene_mesh(&mut scene, scene_path, opts.mesh_cache.as_deref())?;
    let model_size = mesh.diagonal();
    let out_dir = opts.out_dir.clone().unwrap_or_else(|| scene.output_dir());
    let dir = out_dir.join("tagging");
    std::fs::create_dir_all(&dir).map_err(|e| crate::error::OutputError::write(&dir, e))?;

    let blocks = crate::mesh::topology::Blocks::of(&mesh);
    let mut joints = Vec::with_capacity(scene.joints.len());
    let mut rows = Vec::with_capacity(scene.joints.len());
    let stems: Vec<String> = scene.joints.iter().map(|j| crate::files::file_stem(&j.name)).collect();
    for (j, stem) in scene.joints.iter().zip(&stems) {
        let spec = JointSpec { name: j.name.clone(), master: j.master.clone(), slave: j.slave.clone(), auto: j.auto };
        let (tolerance, source) = crate::contact::joint::joint_tolerance(j.tolerance, model_size);
        let joint = tag_joint_in(&mesh, &blocks, &spec, tolerance)?;
        let vtu = dir.join(format!("{stem}.vtu"));
        write_joint_vtu(&vtu, &mesh, &joint)?;
        let n = joint.n_slave().max(1) as f64;
        rows.push(JointTagSummary {
            name: joint.name.clone(),
            slave_group: joint.slave.group.clone(),
            master_group: joint.master.group.clone(),
            auto: j.auto,
            swapped: joint.swapped,
            tolerance,
            tolerance_source: source.to_string(),
            slave_nodes: joint.n_slave(),
            slave_faces: joint.slave.faces.len(),
            master_nodes: joint.master.nodes.len(),
            master_faces: joint.master.faces.len(),
            slave_area: joint.slave.area,
            master_area: joint.master.area,
            layer1_mean: joint.layer1.items.len() as f64 / n,
            layer2_mean: joint.layer2.items.len() as f64 / n,
            ntn_max_distance: joint.ntn_max_distance,
            ntn_max_node_tag: joint.slave.nodes.get(joint.ntn_max_slave).map(|&m| mesh.node_tags[m]).unwrap_or(0),
            ntn_conforming: joint.ntn_conforming_count(),
            max_surface_distance: joint.surface_distance.iter().copied().fold(0.0, f64::max),
            vtu,
        });
        joints.push(joint);
    }
    let json = dir.join("joints.json");
    write_joint_json(&json, &mesh, &joints)?;
    let summary = TagSummary {
        scene: scene.name().to_string(),
        mesh: mesh.source.clone(),
        nodes: mesh.nodes.len(),
        model_size,
        joints: rows,
        json,
        out_dir: dir.clone(),
        wall_time: t_all.elapsed().as_secs_f64(),
    };
    let sp = dir.join("summary.json");
    std::fs::write(&sp, serde_json::to_string_pretty(&summary).expect("tag summary serialises"))
        .map_err(|e| crate::error::OutputError::write(&sp, e))?;
    Ok(summary)
}

impl TagSummary {
    /// A per-joint table for the terminal.
    pub fn to_text(&self) -> String {
        use std::fmt::Write as _;
        let mut s = String::new();
        let plural = if self.joints.len() == 1 { "" } else { "s" };
        let _ = writeln!(s, "scene {}: {} joint{plural} tagged on {} ({} nodes, model size {:.4} m)", self.scene, self.joints.len(), self.mesh.display(), self.nodes, self.model_size);
        for j in &self.joints {
            let _ = writeln!(s, "joint {}", j.name);
            let choice = match (j.auto, j.swapped) {
                (false, _) => "as named (auto off)".to_string(),
                (true, false) => "auto: kept the named roles (the named slave is the finer side, or a tie)".to_string(),
                (true, true) => "auto: swapped the named roles (the named master is the finer side)".to_string(),
            };
            let _ = writeln!(s, "  slave           \"{}\": {} nodes, {} faces, {:.4} m²", j.slave_group, j.slave_nodes, j.slave_faces, j.slave_area);
            let _ = writeln!(s, "  master          \"{}\": {} nodes, {} faces, {:.4} m²", j.master_group, j.master_nodes, j.master_faces, j.master_area);
            let _ = writeln!(s, "  roles           {choice}");
            let _ = writeln!(s, "  tolerance       {:.3e} m ({})", j.tolerance, if j.tolerance_source == "scene" { "from the scene".to_string() } else { format!("default: {DEFAULT_JOINT_TOLERANCE_RELATIVE:e} × model size") });
            let _ = writeln!(s, "  candidates      Layer1 {:.2}, Layer2 {:.2} master faces per slave node (mean)", j.layer1_mean, j.layer2_mean);
            let _ = writeln!(
                s,
                "  NTN             max distance to O {:.4e} m (slave node {}); {} of {} slave nodes conforming",
                j.ntn_max_distance, j.ntn_max_node_tag, j.ntn_conforming, j.slave_nodes
            );
            let _ = writeln!(s, "  surface gap     max {:.4e} m", j.max_surface_distance);
            let _ = writeln!(s, "  VTU             {}", j.vtu.display());
        }
        let _ = writeln!(s, "joints.json     {}", self.json.display());
        let _ = writeln!(s, "summary         {}", self.out_dir.join("summary.json").display());
        s
    }
}

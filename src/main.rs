//! jointquake command line: parses arguments, calls the library, adds `anyhow` context.
//!
//! Every subcommand is documented with examples in `docs/cli.md`. Errors are printed as
//! `error: <context>: <cause>` on stderr with exit status 1; the library's typed errors name
//! the file, group, element or line to fix.
use anyhow::{Context, Result};
use clap::{Parser, Subcommand, ValueEnum};
use jointquake::pipeline::RunOptions;
use jointquake::rigid::wedge::{
    analyse_wedge, critical_horizontal_acceleration, strength_reduction_factor, wedge_fs_report, HeightDef, PlaneOrientation, TensionCrack, WedgeInput, WedgeResult,
};
use std::path::{Path, PathBuf};

/// `println!` that ends the process quietly when stdout is closed (`jointquake … | head`): the
/// standard macro panics on a broken pipe.
macro_rules! say {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        if writeln!(std::io::stdout(), $($t)*).is_err() {
            std::process::exit(0);
        }
    }};
}

/// `print!` with the same behaviour as [`say!`].
macro_rules! say_raw {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        if write!(std::io::stdout(), $($t)*).is_err() {
            std::process::exit(0);
        }
    }};
}

#[derive(Parser)]
#[command(
    name = "jointquake",
    version,
    about = "Gmsh geometry to seismic simulation of jointed rock and dam structures",
    after_help = "Scene files: docs/scenes.md. Subcommands and outputs: docs/cli.md."
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Mesh a scene's .geo with gmsh (cached by content) and print the .msh path and its groups.
    ///
    /// For a scene with `geometry.msh` the file is only read and its groups listed.
    Mesh {
        #[command(flatten)]
        scene: SceneFile,
        #[command(flatten)]
        cache: MeshCache,
    },
    /// Run a scene: gravity equilibrium, dynamic stage, ParaView series, histories, summary.json.
    ///
    /// Scenes with `joints` run with the dynamic contact force (docs/contact.md); `jointquake tag`
    /// checks their joints without running.
    Run {
        #[command(flatten)]
        io: SceneOut,
        #[command(flatten)]
        threads: Threads,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
        /// Override the scene's `time.duration` [s] (e.g. a short check of a long scene).
        #[arg(long)]
        duration: Option<f64>,
    },
    /// Natural frequencies and mode shapes of a scene's model: massless blocks condensed, the
    /// reservoir's added mass included (docs/dam_physics.md). Writes <out>/modes/modes.pvd,
    /// mode_NNN.vtu and modes.json.
    Modes {
        #[command(flatten)]
        io: SceneOut,
        /// Number of modes (lowest first).
        #[arg(short = 'n', long = "count", default_value_t = 6)]
        count: usize,
        /// Print the report as JSON instead of the table.
        #[arg(long)]
        json: bool,
    },
    /// The arch dam's static state (docs/dam.md): the scene's static sequence
    /// (`equilibrium.sequence`, e.g. "construction"), written as a zero-length run (frames with
    /// stress, principal stresses, displacement; joint surfaces with opening and normal traction)
    /// plus the table of crest radial displacements and crown stresses (<out>/static_table.md,
    /// .json). Needs the groups of geo/arch_dam.geo.
    DamStatic {
        #[command(flatten)]
        io: SceneOut,
    },
    /// Tag the joints of a scene (slave/master, normals, Layer1/Layer2, NTN pairs) and write
    /// <out>/tagging/joints.json, one <joint>.vtu per joint and summary.json.
    ///
    /// Tolerance per joint: its `tolerance` [m], else 1e-6 × the mesh bounding-box diagonal.
    Tag {
        /// Scene file with a `joints` list (see docs/scenes.md).
        scene: PathBuf,
        /// Output directory; files go to <out>/tagging/ (default: the scene's output.dir, else out/<name>).
        #[arg(long)]
        out: Option<PathBuf>,
        #[command(flatten)]
        cache: MeshCache,
        /// Print the summary as JSON instead of the table.
        #[arg(long)]
        json: bool,
    },
    /// Hoek & Bray limit equilibrium of a rigid tetrahedral wedge (default: the seed-paper wedge).
    ///
    /// Prints geometry, reactions, FS, FS with c = 0, the strength-reduction factor and the
    /// pseudo-static critical horizontal acceleration (ground acceleration towards north).
    #[command(name = "wedge-fs")]
    WedgeFs {
        /// Wedge description (JSON, fields of `WedgeInput`; missing fields take the seed values).
        #[arg(long)]
        input: Option<PathBuf>,
        /// What H measures: the vertical rise of the line of intersection, or the height of the
        /// crest point on plane A above the toe.
        #[arg(long, value_enum)]
        height_def: Option<HeightDefArg>,
        /// Wedge height H [m] (default 39.624, the seed wedge).
        #[arg(long = "H", visible_alias = "height", value_name = "METRES", allow_negative_numbers = true)]
        h: Option<f64>,
        /// Tension crack orientation, dip/dip direction [deg] (e.g. 70/165); needs
        /// --crack-distance unless the input file has a crack. Overrides the file.
        #[arg(long, value_name = "DIP/DIPDIR", value_parser = parse_orientation)]
        crack: Option<PlaneOrientation>,
        /// Tension crack position L [m]: distance behind the crest point QA along the trace of
        /// plane A on the upper slope, towards P. Overrides the file.
        #[arg(long, value_name = "METRES", allow_negative_numbers = true)]
        crack_distance: Option<f64>,
        /// Print the full result (input, geometry, forces, FS) as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Studies: a base scene varied over axes, its runs in parallel with make, its report
    /// (`plan`, `step`, `report`, `chart`; docs/studies.md).
    Study {
        #[command(subcommand)]
        action: StudyCmd,
    },
    /// Ground motions: `info`, `correct`, `synth`, `match` (docs/motion.md).
    Record {
        #[command(subcommand)]
        action: RecordCmd,
    },
    /// A generated joint test with its exact reference (patch, slide, impact): writes
    /// <out>/case.msh, scene.json, reference.json; with --run solves it and prints the error
    /// (and writes result.json). Options and defaults: docs/cli.md.
    Testcase(TestcaseArgs),
}

// `jointquake testcase`: the options of a generated joint test. Serialised with serde into the
// library's `testcase::CaseSpec` (the study file's form of a case: one parser and one set of
// checks); `out`, `run` and `json` are the command's own. (No doc comment: the subcommand's
// help is the `Cmd::Testcase` variant's.)
#[derive(clap::Args, serde::Serialize)]
struct TestcaseArgs {
    /// patch (uniform pressure/shear through the joint, static), slide (block on an
    /// incline), newmark (the block under a base record against rigid Newmark), impact (two bars).
    kind: String,
    /// Lower side ELEMENT:N[:LAYERS], e.g. hex8:4, tet4:3:2, mixed:4 (ELEMENT hex8, tet4 or mixed).
    #[arg(long)]
    #[serde(skip_serializing_if = "Option::is_none")]
    lower: Option<String>,
    /// Upper side ELEMENT:N[:LAYERS].
    #[arg(long)]
    #[serde(skip_serializing_if = "Option::is_none")]
    upper: Option<String>,
    /// Slave side: lower or upper (default the finer side).
    #[arg(long)]
    #[serde(skip_serializing_if = "Option::is_none")]
    slave: Option<String>,
    /// Contact method: nts, ntn, penalty or mortar.
    #[arg(long)]
    #[serde(skip_serializing_if = "Option::is_none")]
    method: Option<String>,
    /// Penalty factor k (kn = k E/h of the slave), with --method penalty.
    #[arg(long)]
    #[serde(skip_serializing_if = "Option::is_none")]
    penalty: Option<f64>,
    /// Candidate layer 1 or 2.
    #[arg(long)]
    #[serde(skip_serializing_if = "Option::is_none")]
    layer: Option<u8>,
    /// Friction coefficient.
    #[arg(long)]
    #[serde(skip_serializing_if = "Option::is_none")]
    mu: Option<f64>,
    /// Bonded joint.
    #[arg(long)]
    tied: bool,
    /// Patch: pressure p [Pa].
    #[arg(long)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pressure: Option<f64>,
    /// Patch: shear τ along the joint's x [Pa].
    #[arg(long, allow_negative_numbers = true)]
    #[serde(skip_serializing_if = "Option::is_none")]
    shear: Option<f64>,
    /// Joint inclination β [deg] about y.
    #[arg(long, allow_negative_numbers = true)]
    #[serde(skip_serializing_if = "Option::is_none")]
    inclination: Option<f64>,
    /// Patch: the lower block massless (condensed).
    #[arg(long)]
    massless_lower: bool,
    /// Patch: load path p first (relaxed), then τ at full p (default: p and τ together).
    #[arg(long)]
    pressure_first: bool,
    /// Slide: simulated time [s].
    #[arg(long)]
    #[serde(skip_serializing_if = "Option::is_none")]
    duration: Option<f64>,
    /// Patch: relaxation residual at which the static solve stops.
    #[arg(long)]
    #[serde(skip_serializing_if = "Option::is_none")]
    residual: Option<f64>,
    /// Newmark: base record (t [s], a [g]).
    #[arg(long)]
    #[serde(skip_serializing_if = "Option::is_none")]
    record: Option<PathBuf>,
    /// Newmark: PGA of the record [g].
    #[arg(long)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pga: Option<f64>,
    /// The joint's edge_tolerance (fraction of the master face size).
    #[arg(long)]
    #[serde(skip_serializing_if = "Option::is_none")]
    edge_tolerance: Option<f64>,
    /// Shift of the upper side's interior grid lines in the joint plane, as a fraction of
    /// its element (|s| < 1).
    #[arg(long, allow_negative_numbers = true)]
    #[serde(skip_serializing_if = "Option::is_none")]
    offset: Option<f64>,
    /// Turn of the upper side's mesh about the joint normal [deg] (inner half rigid, blended
    /// to 0 at the outline; |θ| ≤ 45).
    #[arg(long, allow_negative_numbers = true)]
    #[serde(skip_serializing_if = "Option::is_none")]
    rotate: Option<f64>,
    /// Patch: a cylindrical joint of radius R [m] (axis along y; R > 0 the lower block
    /// bulges up, R < 0 a trough; |R| > 0.5); μ must exceed the steepest slope.
    #[arg(long, allow_negative_numbers = true)]
    #[serde(skip_serializing_if = "Option::is_none")]
    curvature: Option<f64>,
    /// Patch with --curvature: the slave's joint nodes on the exact cylinder too (default: on
    /// the master's facets); the joint is then grouted whatever its method.
    #[arg(long)]
    slave_on_cylinder: bool,
    /// Output directory.
    #[arg(long)]
    #[serde(skip)]
    out: PathBuf,
    /// Run the case and print its error against the reference.
    #[arg(long)]
    #[serde(skip)]
    run: bool,
    /// Print the result as JSON (with --run).
    #[arg(long)]
    #[serde(skip)]
    json: bool,
}

/// Ground-motion stages (docs/motion.md).
#[derive(Subcommand)]
enum RecordCmd {
    /// PGA, PGV, PGD, Arias intensity, D5-95, predominant period, the 5 % PSA on 0.02-10 s, and
    /// charts of a(t), v(t), d(t) and the spectrum, in <out>/<stem>_*.
    Info {
        /// Records: two-column (t [s], a [g]) or PEER .AT2.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        #[arg(long, default_value = "out/records")]
        out: PathBuf,
        /// Standard gravity [m/s²] converting g.
        #[arg(long, default_value_t = 9.81)]
        g: f64,
    },
    /// Baseline-correct a record and report the residual end velocity and displacement.
    Correct {
        file: PathBuf,
        #[command(flatten)]
        baseline: BaselineArgs,
        /// Output file (two columns, t [s], a [g]).
        #[arg(long)]
        out: PathBuf,
        #[arg(long, default_value_t = 9.81)]
        g: f64,
    },
    /// Spectrum-compatible synthetic components (h1, h2, v) from random phases.
    Synth {
        #[command(flatten)]
        target: TargetArgs,
        /// Horizontal PGA [g].
        #[arg(long)]
        pga: f64,
        #[arg(long, default_value_t = 20.0)]
        duration: f64,
        #[arg(long, default_value_t = 0.01)]
        dt: f64,
        #[arg(long, default_value_t = 1)]
        seed: u64,
        #[arg(long, default_value_t = 3)]
        components: usize,
        /// Vertical as a fraction of the horizontal (target and PGA). Default 2/3.
        #[arg(long)]
        vertical_ratio: Option<f64>,
        /// Envelope rise, strong part and decay [s], end level (default 2, 8, 10, 0.05).
        #[arg(long)]
        rise: Option<f64>,
        #[arg(long)]
        strong: Option<f64>,
        #[arg(long)]
        decay: Option<f64>,
        #[arg(long)]
        end_level: Option<f64>,
        #[command(flatten)]
        fit: FitArgs,
        #[arg(long, default_value = "out/records")]
        out: PathBuf,
        /// File name prefix: <out>/<name>_s<seed>_<component>.txt.
        #[arg(long, default_value = "synth")]
        name: String,
    },
    /// Match a recorded motion to a target spectrum (spectral scaling, phases kept).
    Match {
        file: PathBuf,
        #[command(flatten)]
        target: TargetArgs,
        /// PGA of the matched record [g] (and of the code spectrum).
        #[arg(long)]
        pga: f64,
        #[command(flatten)]
        fit: FitArgs,
        #[arg(long)]
        out: PathBuf,
        #[arg(long, default_value_t = 9.81)]
        g: f64,
    },
}

/// The scene file of a command (a positional argument).
#[derive(clap::Args)]
struct SceneFile {
    /// Scene file (JSON, see docs/scenes.md).
    scene: PathBuf,
}

/// `--out`: the output directory of a scene command.
#[derive(clap::Args)]
struct OutDir {
    /// Output directory (default: the scene's output.dir, else out/<name>).
    #[arg(long)]
    out: Option<PathBuf>,
}

/// The scene a command reads, its output directory and the mesh cache (`run`, `modes`,
/// `dam-static`).
#[derive(clap::Args)]
struct SceneOut {
    #[command(flatten)]
    scene: SceneFile,
    #[command(flatten)]
    out: OutDir,
    #[command(flatten)]
    cache: MeshCache,
}

/// `--cache`: where gmsh meshes are cached (one default for every command:
/// `pipeline::DEFAULT_MESH_CACHE`).
#[derive(clap::Args)]
struct MeshCache {
    /// Mesh cache directory (meshes are keyed by the .geo text and the `set` numbers).
    #[arg(long = "cache", default_value = jointquake::pipeline::DEFAULT_MESH_CACHE)]
    cache: PathBuf,
}

/// `--threads`: the thread count of a command that runs simulations.
#[derive(clap::Args)]
struct Threads {
    /// Threads (default: one below 30 000 elements, else all cores). Results are bit-identical whatever the count.
    #[arg(long)]
    threads: Option<usize>,
}

impl Threads {
    /// The thread setup, once for every command: `--threads N` within what the machine has
    /// ([`capped_threads`]) becomes rayon's global pool; the count, or `None` when not given.
    fn install(&self) -> Result<Option<usize>> {
        let threads = self.threads.map(capped_threads).transpose()?;
        if let Some(n) = threads {
            rayon::ThreadPoolBuilder::new().num_threads(n).build_global().context("setting the thread count")?;
        }
        Ok(threads)
    }
}

/// The baseline correction options (`record correct`; every iterate of `synth` and `match`).
#[derive(clap::Args)]
struct BaselineArgs {
    /// mean | polynomial | highpass
    #[arg(long = "method", visible_alias = "baseline", default_value = "polynomial")]
    method: String,
    /// Polynomial degree (3..10).
    #[arg(long, default_value_t = 5)]
    degree: usize,
    /// High-pass corner [Hz].
    #[arg(long)]
    corner: Option<f64>,
    /// High-pass Butterworth order.
    #[arg(long, default_value_t = 4)]
    order: u32,
}

#[derive(clap::Args)]
struct TargetArgs {
    /// Code spectrum: "DL 5073-2000" or "GB 51247-2018".
    #[arg(long)]
    code: Option<String>,
    /// arch | gravity | earth-rock | other.
    #[arg(long)]
    structure: Option<String>,
    /// Site class (DL 5073-2000: I-IV; GB 51247-2018: I0, I1, II-IV).
    #[arg(long)]
    site: Option<String>,
    #[arg(long)]
    basic_tg: Option<f64>,
    #[arg(long)]
    tg: Option<f64>,
    #[arg(long)]
    beta_max: Option<f64>,
    /// User table (T [s], Sa [g]) file.
    #[arg(long)]
    table: Option<PathBuf>,
    /// Uniform hazard spectrum points (T [s], Sa [g]) file.
    #[arg(long)]
    uhs: Option<PathBuf>,
}

#[derive(clap::Args)]
struct FitArgs {
    /// Largest relative shortfall below the target at any check period (SRP 3.7.1: 0.10).
    #[arg(long, default_value_t = 0.10)]
    tolerance: f64,
    /// Check band [s] as LO,HI. Default 0.04,3.0 (match: the lower end at least 4 dt).
    #[arg(long)]
    band: Option<String>,
    #[arg(long, default_value_t = 100)]
    max_iterations: usize,
    /// Baseline correction of every iterate (`--baseline` or `--method`).
    #[command(flatten)]
    baseline: BaselineArgs,
}

/// Stages of a study (a study file, docs/studies.md).
#[derive(Subcommand)]
enum StudyCmd {
    /// Write the run scenes, `plan.json` and the Makefile `runs.mk` under the study's output
    /// directory, and mesh every distinct geometry once.
    Plan {
        study: PathBuf,
        #[command(flatten)]
        cache: MeshCache,
        /// The jointquake binary the generated Makefile calls.
        #[arg(long, default_value = "target/release/jointquake")]
        bin: String,
    },
    /// Run a step of the study that is not a scene run (the wedge's `ssr`: FEM strength
    /// reduction) and write its result file under the study's output directory.
    Step {
        study: PathBuf,
        /// The step's name (the plan lists the study's steps).
        name: String,
        #[command(flatten)]
        cache: MeshCache,
        #[command(flatten)]
        threads: Threads,
    },
    /// Plan the study (as `plan`) and submit its runs to Slurm: a job array (one task per run
    /// not done yet) and a report job after it (docs/cluster.md).
    Submit {
        study: PathBuf,
        /// Submit to Slurm (`sbatch`); the only scheduler `submit` knows.
        #[arg(long, required = true)]
        slurm: bool,
        /// Partition of the jobs (default: the cluster's default partition).
        #[arg(long)]
        partition: Option<String>,
        /// Time limit of each run's task and of the report job, HH:MM:SS or D-HH:MM:SS (default: the partition's).
        #[arg(long)]
        time: Option<String>,
        /// Cores of each run's task, and its `--threads`.
        #[arg(long, default_value_t = 1)]
        cpus_per_run: usize,
        /// At most this many runs at once (the array's `%K`; default: no limit).
        #[arg(long)]
        max_parallel: Option<usize>,
        /// Write the scripts and print the sbatch commands without submitting.
        #[arg(long)]
        dry_run: bool,
        #[command(flatten)]
        cache: MeshCache,
        /// The jointquake binary the tasks run (default: this one; the nodes must see it).
        #[arg(long)]
        bin: Option<PathBuf>,
    },
    /// Read every run and step, write `<out>/report.md`, `report.json` and `charts/`. Exits
    /// with status 1 (after writing) when runs or steps have no results, naming them.
    Report { study: PathBuf },
    /// A dam study's extrapolated reference (docs/dam.md, "Convergence"): per quantity, method
    /// and level the values on each mesh, the observed order, the extrapolated value and its
    /// error band, the meshes and the runs' commits, as JSON (the `report.reference` of
    /// pipelines/dam_study.json reads it).
    Extrapolate {
        study: PathBuf,
        /// The JSON to write.
        #[arg(long)]
        out: PathBuf,
    },
    /// Charts of one run of the study's model in `<run>/charts/` (the wedge: slip at P2 with
    /// the rigid block, P1 displacement).
    Chart {
        study: PathBuf,
        /// The scene that was run.
        #[arg(long)]
        scene: PathBuf,
        /// Its output directory.
        #[arg(long)]
        run: PathBuf,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum HeightDefArg {
    Intersection,
    CrestOnA,
}

/// `DIP/DIPDIR` in degrees, e.g. `70/165` (range checks are the library's).
fn parse_orientation(s: &str) -> std::result::Result<PlaneOrientation, String> {
    let bad = || format!("expected DIP/DIPDIR in degrees, e.g. 70/165, got {s:?}");
    let (d, a) = s.split_once('/').ok_or_else(bad)?;
    let num = |x: &str| x.trim().parse::<f64>().map_err(|_| bad());
    Ok(PlaneOrientation::new(num(d)?, num(a)?))
}

/// `wedge-fs --json`: the limit-equilibrium result plus the two derived numbers of the table.
#[derive(serde::Serialize)]
struct WedgeFsJson {
    #[serde(flatten)]
    result: WedgeResult,
    strength_reduction_factor: f64,
    /// Pseudo-static critical horizontal acceleration [g] for ground acceleration towards
    /// azimuth 0 (north); null when that direction does not destabilise the wedge.
    critical_kh_azimuth_0: Option<f64>,
}

fn main() {
    if let Err(e) = real_main() {
        if interrupted_error(&e) {
            eprintln!("{}", error_text(&e));
            std::process::exit(jointquake::interrupt::EXIT_STATUS);
        }
        eprintln!("error: {}", error_text(&e));
        std::process::exit(1);
    }
}

/// Whether Ctrl-C or SIGTERM (not the input) ended the command: exit status
/// `interrupt::EXIT_STATUS` (130) instead of 1, as for an interrupted `run`.
fn interrupted_error(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.downcast_ref::<jointquake::interrupt::Interrupted>().is_some() || c.downcast_ref::<jointquake::Error>().is_some_and(|e| e.interrupted().is_some()))
}

/// Make Ctrl-C and SIGTERM end the commands whose phases check the flag (`run`, `mesh`, `tag`,
/// `dam-static`, `study plan`, `study submit`) at the next check, with exit status 130; the
/// other commands keep the signals' default action (they end at once).
fn honour_interrupts() -> Result<()> {
    jointquake::output::recorder::install_interrupt_handler().map_err(anyhow::Error::msg)
}

/// The context chain joined by ": ", leaving out a cause whose text the messages before it
/// already quote (the library's I/O errors print their `source`, which is also the next link).
fn error_text(e: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in e.chain() {
        let s = cause.to_string();
        if s.is_empty() || out.contains(&s) {
            continue;
        }
        if !out.is_empty() {
            out.push_str(": ");
        }
        out.push_str(&s);
    }
    out
}

fn real_main() -> Result<()> {
    let cli = Cli::parse();
    match cli.cmd {
        Cmd::Mesh { scene, cache } => {
            honour_interrupts()?;
            cmd_mesh(&scene.scene, &cache.cache)
        }
        Cmd::Run { io, threads, quiet, duration } => {
            let threads = threads.install()?;
            let scene = io.scene.scene;
            let opts = RunOptions { out_dir: io.out.out, mesh_cache: Some(io.cache.cache), progress: !quiet, duration, threads };
            honour_interrupts()?;
            let summary = jointquake::pipeline::run(&scene, &opts).with_context(|| format!("running scene {}", scene.display()))?;
            say_raw!("{}", summary.to_text());
            if summary.interrupted.is_some() {
                std::process::exit(jointquake::interrupt::EXIT_STATUS);
            }
            Ok(())
        }
        Cmd::Modes { io, count, json } => cmd_modes(&io.scene.scene, count, io.out.out, &io.cache.cache, json),
        Cmd::DamStatic { io } => {
            honour_interrupts()?;
            cmd_dam_static(&io.scene.scene, io.out.out, io.cache.cache)
        }
        Cmd::Tag { scene, out, cache, json } => {
            honour_interrupts()?;
            let opts = RunOptions { out_dir: out, mesh_cache: Some(cache.cache), progress: false, duration: None, threads: None };
            let summary = jointquake::pipeline::tag(&scene, &opts).with_context(|| format!("tagging the joints of scene {}", scene.display()))?;
            if json {
                say!("{}", serde_json::to_string_pretty(&summary).context("serialising the tag summary")?);
            } else {
                say_raw!("{}", summary.to_text());
            }
            Ok(())
        }
        Cmd::WedgeFs { input, height_def, h, crack, crack_distance, json } => cmd_wedge_fs(input, height_def, h, crack, crack_distance, json),
        Cmd::Study { action } => study_cmd(action),
        Cmd::Record { action } => record_cmd(action),
        Cmd::Testcase(args) => cmd_testcase(args),
    }
}

/// `jointquake mesh`: mesh the scene (no pattern expansion: the groups as the mesh has them).
fn cmd_mesh(scene: &Path, cache: &Path) -> Result<()> {
    let s = jointquake::scene::Scene::load(scene).with_context(|| format!("loading scene {}", scene.display()))?;
    let mesh = jointquake::pipeline::load_mesh(&s, Some(cache)).with_context(|| format!("meshing scene {}", scene.display()))?;
    say!("{}", mesh.source.display());
    say!("  {} nodes, {} cells", mesh.nodes.len(), mesh.cells.len());
    for g in &mesh.groups {
        say!("  group \"{}\" (dim {}): {} cells", g.name, g.dim, g.cells.len());
    }
    Ok(())
}

/// Most modes `modes --count` computes: 1000 (the dam's studies use 6–20; each mode is a
/// vector of the model's size and an eigen iteration).
const MAX_MODES: f64 = 1000.0;

/// `jointquake modes`: the lowest `count` modes of the scene's model.
fn cmd_modes(scene: &Path, count: usize, out: Option<PathBuf>, cache: &Path, json: bool) -> Result<()> {
    check_option("count", count as f64, (1.0, MAX_MODES), false, "modes")?;
    let mut s = jointquake::scene::Scene::load(scene).with_context(|| format!("loading scene {}", scene.display()))?;
    let mesh = jointquake::pipeline::load_scene_mesh(&mut s, scene, Some(cache)).with_context(|| format!("meshing scene {}", scene.display()))?;
    let out_dir = out.unwrap_or_else(|| s.output_dir());
    let problem = jointquake::problem::Problem::build(s, mesh).with_context(|| format!("building scene {}", scene.display()))?;
    let r = jointquake::statics::modes::modes(&problem, count, &out_dir).with_context(|| format!("modes of scene {}", scene.display()))?;
    if json {
        say!("{}", serde_json::to_string_pretty(&r).context("serialising the modes")?);
    } else {
        say_raw!("{}", r.to_text());
    }
    Ok(())
}

/// `jointquake dam-static`: the scene's static state as a zero-length run, and the dam's static
/// table written next to it (`studies::dam::static_table::write_static_table`).
fn cmd_dam_static(scene: &Path, out: Option<PathBuf>, cache: PathBuf) -> Result<()> {
    let opts = RunOptions { out_dir: out, mesh_cache: Some(cache), progress: false, duration: Some(0.0), threads: None };
    let mut table_md = None;
    let mut inspect = |sim: &jointquake::simulation::Simulation<'_>, dir: &Path| -> Result<(), jointquake::Error> {
        let (t, md) = jointquake::studies::dam::static_table::write_static_table(&sim.problem.model, &sim.state.u, dir)?;
        table_md = Some((t.to_markdown(), md));
        Ok(())
    };
    let summary = jointquake::pipeline::run_inspect(scene, &opts, &mut inspect).with_context(|| format!("static state of scene {}", scene.display()))?;
    say_raw!("{}", summary.to_text());
    if let Some((md, path)) = table_md {
        say!("{md}");
        say!("static table: {}", path.display());
    }
    if summary.interrupted.is_some() {
        std::process::exit(jointquake::interrupt::EXIT_STATUS);
    }
    Ok(())
}

/// `jointquake wedge-fs`: Hoek & Bray limit equilibrium of the seed wedge or the input's.
fn cmd_wedge_fs(input: Option<PathBuf>, height_def: Option<HeightDefArg>, h: Option<f64>, crack: Option<PlaneOrientation>, crack_distance: Option<f64>, json: bool) -> Result<()> {
    let mut w = match &input {
        Some(p) => {
            let text = std::fs::read_to_string(p).with_context(|| format!("reading wedge input {}", p.display()))?;
            serde_json::from_str::<WedgeInput>(&text).with_context(|| format!("wedge input {}: expected the fields of WedgeInput (see docs/cli.md)", p.display()))?
        }
        None => WedgeInput::default(),
    };
    if let Some(d) = height_def {
        w.height_def = match d {
            HeightDefArg::Intersection => HeightDef::Intersection,
            HeightDefArg::CrestOnA => HeightDef::CrestOnA,
        };
    }
    if let Some(h) = h {
        w.height = h;
    }
    match (crack, crack_distance, w.tension_crack.as_mut()) {
        (Some(orientation), Some(distance), _) => w.tension_crack = Some(TensionCrack { orientation, distance }),
        (Some(orientation), None, Some(tc)) => tc.orientation = orientation,
        (None, Some(distance), Some(tc)) => tc.distance = distance,
        (Some(_), None, None) => anyhow::bail!("--crack needs --crack-distance L [m] (distance behind the crest along the trace of plane A), or a tension_crack in the --input file"),
        (None, Some(_), None) => anyhow::bail!("--crack-distance needs --crack DIP/DIPDIR (the crack orientation), or a tension_crack in the --input file"),
        (None, None, _) => {}
    }
    let what = || match &input {
        Some(p) => format!("wedge of {}", p.display()),
        None => "seed wedge".to_string(),
    };
    if json {
        let result = analyse_wedge(&w).with_context(|| format!("limit equilibrium of the {}", what()))?;
        let srf = strength_reduction_factor(&w).with_context(|| format!("strength reduction of the {}", what()))?;
        let kc = critical_horizontal_acceleration(&w, 0.0).with_context(|| format!("critical acceleration of the {}", what()))?;
        let out = WedgeFsJson { result, strength_reduction_factor: srf, critical_kh_azimuth_0: kc };
        say!("{}", serde_json::to_string_pretty(&out).context("serialising the wedge result")?);
    } else {
        say_raw!("{}", wedge_fs_report(&w).with_context(|| format!("limit equilibrium of the {}", what()))?);
    }
    Ok(())
}

/// `jointquake testcase`: write the case (and with `--run` solve it and print its error).
fn cmd_testcase(args: TestcaseArgs) -> Result<()> {
    jointquake::testcase::check_finite_options(&[("penalty", args.penalty), ("mu", args.mu), ("pressure", args.pressure), ("shear", args.shear), ("inclination", args.inclination), ("duration", args.duration), ("residual", args.residual), ("pga", args.pga), ("edge_tolerance", args.edge_tolerance), ("offset", args.offset), ("rotate", args.rotate), ("curvature", args.curvature)])?;
    // the options as the study file writes a case (one parser and one set of checks)
    let value = serde_json::to_value(&args).context("testcase options (docs/cli.md, `testcase`)")?;
    let spec: jointquake::testcase::CaseSpec = serde_json::from_value(value).context("testcase options (docs/cli.md, `testcase`)")?;
    let case = jointquake::testcase::build(&spec)?;
    let out = &args.out;
    let files = jointquake::testcase::write_case(&case, out)?;
    say!("case      {}", case.spec.label());
    say!("mesh      {} ({} nodes, {} cells)", files.msh.display(), case.mesh.nodes.len(), case.mesh.cells.len());
    say!("scene     {}", files.scene.display());
    say!("reference {}", files.reference.display());
    if args.run {
        let r = jointquake::testcase::run::run_case(&case).with_context(|| format!("running {}", case.spec.label()))?;
        let p = out.join("result.json");
        std::fs::write(&p, serde_json::to_string_pretty(&r)?).with_context(|| format!("writing {}", p.display()))?;
        if args.json {
            say!("{}", serde_json::to_string_pretty(&r)?);
        } else {
            say!("result    {}", p.display());
            say!("error     {:.4e} ({}), {} steps, {:.2} s", r.error, r.error_of, r.steps, r.wall_time);
            say!("details   {}", serde_json::to_string(&r.errors)?);
        }
    }
    Ok(())
}

impl BaselineArgs {
    /// The baseline correction these options name.
    fn baseline(&self) -> Result<jointquake::motion::Baseline> {
        use jointquake::motion::Baseline;
        Ok(match self.method.as_str() {
            "mean" => Baseline::Mean,
            "polynomial" => Baseline::Polynomial { degree: self.degree },
            "highpass" => Baseline::HighPass { corner: self.corner.context("--method highpass needs --corner F [Hz] (e.g. 0.05)")?, order: self.order },
            other => anyhow::bail!("baseline method \"{other}\": use mean, polynomial or highpass"),
        })
    }
}

fn target_of(a: &TargetArgs) -> Result<jointquake::motion::TargetSpec> {
    use jointquake::motion::TargetSpec;
    match (&a.table, &a.uhs, &a.structure) {
        (Some(f), None, None) => Ok(TargetSpec::Table { points: None, file: Some(f.clone()) }),
        (None, Some(f), None) => Ok(TargetSpec::Uhs { points: None, file: Some(f.clone()) }),
        (None, None, Some(st)) => Ok(TargetSpec::Code {
            code: a.code.clone().unwrap_or_else(|| "DL 5073-2000".into()),
            structure: st.clone(),
            site_class: a.site.clone().context("the code spectrum needs --site CLASS (DL 5073-2000: I, II, III, IV)")?,
            basic_tg: a.basic_tg,
            tg: a.tg,
            beta_max: a.beta_max,
        }),
        (None, None, None) => anyhow::bail!("give a target spectrum: --structure arch --site I [--code \"DL 5073-2000\"], or --table FILE, or --uhs FILE"),
        _ => anyhow::bail!("give one target spectrum: the code form (--structure, --site), --table or --uhs"),
    }
}

fn band_of(s: &str) -> Result<[f64; 2]> {
    let (a, b) = s.split_once(',').with_context(|| format!("--band {s:?}: expected LO,HI in seconds, e.g. 0.1,3.0"))?;
    let band: [f64; 2] = [a.trim().parse().with_context(|| format!("--band {s:?}: {a:?} is not a number"))?, b.trim().parse().with_context(|| format!("--band {s:?}: {b:?} is not a number"))?];
    for v in band {
        check_option("band", v, (0.0, 100.0), true, "s (each end)")?;
    }
    Ok(band)
}

/// A numeric command-line option checked before anything is read or written: finite and in
/// `[lo, hi]` (the bounds docs/cli.md states next to the option; `lo_open`: `lo` itself
/// excluded). The error names the option, its value, the range and the unit (issue 34:
/// `record info --g -9.81` was accepted; NaN or inf options became the defaults).
fn check_option(option: &str, v: f64, (lo, hi): (f64, f64), lo_open: bool, unit: &str) -> Result<()> {
    let above_lo = if lo_open { v > lo } else { v >= lo };
    if !(v.is_finite() && above_lo && v <= hi) {
        // 1e308 as "1e308", not 309 digits
        let shown = if v.is_finite() && v != 0.0 && !(1e-4..1e6).contains(&v.abs()) { format!("{v:e}") } else { format!("{v}") };
        anyhow::bail!("option --{option} = {shown}: must be a finite number in {}{lo}, {hi}] {unit}", if lo_open { "(" } else { "[" });
    }
    Ok(())
}

/// [`check_option`] for an option that may be absent.
fn check_some(option: &str, v: Option<f64>, range: (f64, f64), lo_open: bool, unit: &str) -> Result<()> {
    v.map_or(Ok(()), |v| check_option(option, v, range, lo_open, unit))
}

/// Standard gravity accepted by `--g` [m/s²]: (0, 100] (Earth 9.81; a typo such as 981 or a
/// sign is refused).
const G_RANGE: (f64, f64) = (0.0, 100.0);
/// Largest PGA an option accepts [g]: 10 (the largest recorded are about 4 g).
const MAX_PGA_G: f64 = 10.0;
/// Largest `--max-iterations` of spectral matching: 10 000 (the defaults converge in under 100;
/// each iteration is a full response spectrum).
const MAX_FIT_ITERATIONS: f64 = 10_000.0;

impl TargetArgs {
    /// The code-spectrum numbers: `--basic-tg`, `--tg` (0, 10] s and `--beta-max` (0, 10].
    fn check(&self) -> Result<()> {
        check_some("basic-tg", self.basic_tg, (0.0, 10.0), true, "s")?;
        check_some("tg", self.tg, (0.0, 10.0), true, "s")?;
        check_some("beta-max", self.beta_max, (0.0, 10.0), true, "(amplification)")
    }
}

impl FitArgs {
    /// `--max-iterations` in [0, 10 000] and a finite `--tolerance` (its range is the
    /// synthesis's own check) and `--corner` (checked against the Nyquist frequency there).
    fn check(&self) -> Result<()> {
        check_option("max-iterations", self.max_iterations as f64, (0.0, MAX_FIT_ITERATIONS), false, "")?;
        check_option("tolerance", self.tolerance, (0.0, 1.0), true, "(fraction)")?;
        if let Some(b) = &self.band {
            band_of(b)?;
        }
        check_some("corner", self.baseline.corner, (0.0, 1e3), true, "Hz")
    }
}

fn record_cmd(action: RecordCmd) -> Result<()> {
    use jointquake::dynamics::record::Record;
    use jointquake::motion::{commands, synth};
    let stem = |p: &PathBuf| p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "record".into());
    match &action {
        RecordCmd::Info { g, .. } | RecordCmd::Correct { g, .. } => check_option("g", *g, G_RANGE, true, "m/s²")?,
        RecordCmd::Synth { target, pga, fit, .. } => {
            check_option("pga", *pga, (0.0, MAX_PGA_G), true, "g")?;
            target.check()?;
            fit.check()?;
        }
        RecordCmd::Match { target, pga, fit, g, .. } => {
            check_option("g", *g, G_RANGE, true, "m/s²")?;
            check_option("pga", *pga, (0.0, MAX_PGA_G), true, "g")?;
            target.check()?;
            fit.check()?;
        }
    }
    match action {
        RecordCmd::Info { files, out, g } => {
            for f in &files {
                let r = Record::read(f, g).with_context(|| format!("reading record {}", f.display()))?;
                let text = commands::info(&stem(f), r.t0, r.dt, &r.accel, g, &out).with_context(|| format!("record info of {}", f.display()))?;
                say_raw!("{text}");
            }
        }
        RecordCmd::Correct { file, baseline, out, g } => {
            let r = Record::read(&file, g).with_context(|| format!("reading record {}", file.display()))?;
            let m = baseline.baseline()?;
            let text = commands::correct_file(&file, r.t0, r.dt, &r.accel, g, &m, &out).with_context(|| format!("correcting {}", file.display()))?;
            say_raw!("{text}");
        }
        RecordCmd::Synth { target, pga, duration, dt, seed, components, vertical_ratio, rise, strong, decay, end_level, fit, out, name } => {
            let mut req = synth::SynthRequest::new(target_of(&target)?, pga, seed);
            req.duration = duration;
            req.dt = dt;
            req.components = components;
            if let Some(v) = vertical_ratio {
                req.vertical_ratio = v;
            }
            let e = &mut req.envelope;
            e.rise = rise.unwrap_or(e.rise);
            e.strong = strong.unwrap_or(e.strong);
            e.decay = decay.unwrap_or(e.decay);
            e.end_level = end_level.unwrap_or(e.end_level);
            req.tolerance = fit.tolerance;
            if let Some(b) = &fit.band {
                req.band = band_of(b)?;
            }
            req.max_iterations = fit.max_iterations;
            req.baseline = fit.baseline.baseline()?;
            let (text, _) = commands::synth_files(&req, &out, &name).context("synthesising the set")?;
            say_raw!("{text}");
        }
        RecordCmd::Match { file, target, pga, fit, out, g } => {
            let r = Record::read(&file, g).with_context(|| format!("reading record {}", file.display()))?;
            let t = target_of(&target)?.resolve(pga, "spectrum").context("the target spectrum")?;
            let band = match &fit.band {
                Some(b) => band_of(b)?,
                None => [f64::max(0.04, 4.0 * r.dt), 3.0],
            };
            let opts = synth::MatchOptions { tolerance: fit.tolerance, band, max_iterations: fit.max_iterations, baseline: fit.baseline.baseline()? };
            let ag: Vec<f64> = r.accel.iter().map(|a| a / g).collect();
            let text = commands::match_file(&file, r.dt, &ag, &t, pga, &opts, &out).with_context(|| format!("matching {}", file.display()))?;
            say_raw!("{text}");
        }
    }
    Ok(())
}

fn study_cmd(action: StudyCmd) -> Result<()> {
    use jointquake::study;
    let load = |p: &PathBuf| jointquake::studies::load(p).with_context(|| format!("loading study {}", p.display()));
    match action {
        StudyCmd::Plan { study: path, cache, bin } => {
            honour_interrupts()?;
            let (s, kind) = load(&path)?;
            let files = study::write_plan(&s, &kind.steps(), &cache.cache, &bin).with_context(|| format!("planning study {}", path.display()))?;
            say!(
                "study {} ({}): {} runs planned ({} scenes new or changed), {} steps, {} meshes ready",
                s.name,
                s.kind,
                files.scenes.len(),
                files.changed,
                kind.steps().len(),
                files.meshes.len()
            );
            say!("  plan      {}", files.plan.display());
            say!("  makefile  {}", files.makefile.display());
        }
        StudyCmd::Submit { study: path, slurm: _, partition, time, cpus_per_run, max_parallel, dry_run, cache, bin } => {
            use jointquake::study::slurm;
            let bin = match bin {
                Some(b) => b,
                None => std::env::current_exe().context("finding this jointquake binary (give --bin)")?,
            };
            let opts = slurm::SlurmOptions { partition, time, cpus_per_run, max_parallel, bin, cache: cache.cache };
            opts.check()?;
            honour_interrupts()?;
            let (s, kind) = load(&path)?;
            study::write_plan(&s, &kind.steps(), &opts.cache, &opts.bin.display().to_string()).with_context(|| format!("planning study {}", path.display()))?;
            let plan = study::Plan::read(&s.out)?;
            let sub = slurm::write_scripts(&plan, &opts).with_context(|| format!("writing the Slurm scripts of study {}", path.display()))?;
            say!("study {} ({}): {} of {} runs to do{}", s.name, s.kind, sub.todo.len(), sub.total, sub.array.as_ref().map(|a| format!(" (array {a})")).unwrap_or_default());
            for (k, id, why) in &sub.todo {
                say!("  task {k:>4}  {id} ({why})");
            }
            say!("  array job   {}", sub.runs_script.display());
            say!("  report job  {}", sub.collect_script.display());
            if dry_run {
                say!("dry run: submit with");
                for c in slurm::commands(&sub) {
                    say!("  {c}");
                }
            } else {
                let j = slurm::submit(&plan, &sub).with_context(|| format!("submitting study {}", path.display()))?;
                match &j.array_job {
                    Some(a) => say!("submitted: array job {a} ({} tasks), report job {} after it", sub.todo.len(), j.report_job),
                    None => say!("submitted: report job {} (every run is done)", j.report_job),
                }
                say!("  follow with `squeue --me`; report: {}", plan.out.join("report.md").display());
            }
        }
        StudyCmd::Step { study: path, name, cache, threads } => {
            threads.install()?;
            let (s, kind) = load(&path)?;
            let opts = study::StepOptions { mesh_cache: cache.cache };
            let (p, out) = study::run_step(&s, kind.as_ref(), &name, &opts).with_context(|| format!("step {name} of study {}", path.display()))?;
            for l in &out.lines {
                say!("{l}");
            }
            say!("  written {}", p.display());
        }
        StudyCmd::Report { study: path } => {
            let (s, kind) = load(&path)?;
            let r = study::write_report(&s, kind.as_ref()).with_context(|| format!("report of study {}", path.display()))?;
            say!("study {} report: {}", s.name, r.report.display());
            for c in &r.charts {
                say!("  chart {} (and .svg)", c.display());
            }
            for t in &r.lines {
                say!("  {t}");
            }
            if !r.problems.is_empty() {
                let list = r.problems.iter().map(|(id, why)| format!("  {id}: {why}")).collect::<Vec<_>>().join("\n");
                anyhow::bail!("the report is written, but {} run(s) or step(s) have no results (listed in it); `make -f {} all` runs them:\n{list}", r.problems.len(), s.out.join("runs.mk").display());
            }
        }
        StudyCmd::Extrapolate { study: path, out } => {
            let s = jointquake::study::Study::load(&path).with_context(|| format!("loading study {}", path.display()))?;
            let kind = jointquake::studies::dam::DamKind::new(&s).with_context(|| format!("study {} (must be of kind \"dam\")", path.display()))?;
            let r = jointquake::studies::dam::reference::extrapolate(&s, &kind, &out).with_context(|| format!("extrapolating study {}", path.display()))?;
            say!("study {} reference: {} ({} values; meshes {}; {})", s.name, out.display(), r.values.len(), r.meshes.iter().map(|m| m.label.as_str()).collect::<Vec<_>>().join(", "), r.note);
        }
        StudyCmd::Chart { study: path, scene, run } => {
            let (s, kind) = load(&path)?;
            let r = kind.run_charts(&s, &scene, &run).with_context(|| format!("charts of run {}", run.display()))?;
            for l in &r.lines {
                say!("{l}");
            }
            for c in &r.charts {
                say!("  chart {} (and .svg)", c.display());
            }
        }
    }
    Ok(())
}

/// `--threads N` within what the machine has: 0 is refused, more than its cores is cut to its
/// cores with a message (threads beyond them only compete, and an absurd count would try to
/// spawn them all).
fn capped_threads(n: usize) -> anyhow::Result<usize> {
    anyhow::ensure!(n >= 1, "--threads 0: give at least 1 thread (or leave --threads out for the default)");
    let cores = std::thread::available_parallelism().map(|c| c.get()).unwrap_or(1);
    if n > cores {
        eprintln!("note: --threads {n}: this machine has {cores} cores; using {cores}");
        return Ok(cores);
    }
    Ok(n)
}

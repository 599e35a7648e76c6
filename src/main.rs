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
use std::path::PathBuf;

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
        /// Scene file (JSON, see docs/scenes.md).
        scene: PathBuf,
        /// Mesh cache directory (meshes are keyed by the .geo text and the `set` numbers).
        #[arg(long, default_value = "build/mesh")]
        cache: PathBuf,
    },
    /// Run a scene: gravity equilibrium, dynamic stage, ParaView series, histories, summary.json.
    ///
    /// Scenes with `joints` run with the dynamic contact force (docs/contact.md); `jointquake tag`
    /// checks their joints without running.
    Run {
        /// Scene file (JSON, see docs/scenes.md).
        scene: PathBuf,
        /// Output directory (default: the scene's output.dir, else out/<name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Mesh cache directory.
        #[arg(long, default_value = "build/mesh")]
        cache: PathBuf,
        /// Threads (default: one below 30 000 elements, else all cores). Results are bit-identical whatever the count.
        #[arg(long)]
        threads: Option<usize>,
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
        /// Scene file (JSON, see docs/scenes.md).
        scene: PathBuf,
        /// Number of modes (lowest first).
        #[arg(short = 'n', long = "count", default_value_t = 6)]
        count: usize,
        /// Output directory (default: the scene's output.dir, else out/<name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Mesh cache directory.
        #[arg(long, default_value = "build/mesh")]
        cache: PathBuf,
        /// Print the report as JSON instead of the table.
        #[arg(long)]
        json: bool,
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
        /// Mesh cache directory.
        #[arg(long, default_value = "build/mesh")]
        cache: PathBuf,
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
    /// The wedge study of the seed paper: `plan`, `ssr`, `report`, `chart` (docs/wedge.md).
    Study {
        #[command(subcommand)]
        action: StudyCmd,
    },
}

/// Stages of the wedge study (`pipelines/wedge_study.json`; docs/wedge.md).
#[derive(Subcommand)]
enum StudyCmd {
    /// Write the variant scenes, `plan.json` and the Makefile `runs.mk` of the study under its
    /// output directory, and mesh every distinct geometry once.
    Plan {
        study: PathBuf,
        #[arg(long, default_value = "build/mesh")]
        cache: PathBuf,
        /// The jointquake binary the generated Makefile calls.
        #[arg(long, default_value = "target/release/jointquake")]
        bin: String,
    },
    /// FEM strength reduction of the study's wedge (gravity only) → `<out>/ssr.json`.
    Ssr {
        study: PathBuf,
        #[arg(long, default_value = "build/mesh")]
        cache: PathBuf,
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Read every run, add limit equilibrium and the rigid block, write `<out>/report.md`,
    /// `report.json` and `charts/`.
    Report { study: PathBuf },
    /// Charts of one run of the study's wedge (slip at P2, P1 displacement, rigid block) in
    /// `<run>/charts/`.
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
        eprintln!("error: {}", error_text(&e));
        std::process::exit(1);
    }
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
            let s = jointquake::scene::Scene::load(&scene).with_context(|| format!("loading scene {}", scene.display()))?;
            let opts = RunOptions { mesh_cache: Some(cache), ..Default::default() };
            let mesh = jointquake::pipeline::load_mesh(&s, &opts).with_context(|| format!("meshing scene {}", scene.display()))?;
            say!("{}", mesh.source.display());
            say!("  {} nodes, {} cells", mesh.nodes.len(), mesh.cells.len());
            for g in &mesh.groups {
                say!("  group \"{}\" (dim {}): {} cells", g.name, g.dim, g.cells.len());
            }
        }
        Cmd::Run { scene, out, cache, threads, quiet, duration } => {
            if let Some(n) = threads {
                rayon::ThreadPoolBuilder::new().num_threads(n).build_global().context("setting the thread count")?;
            }
            let opts = RunOptions { out_dir: out, mesh_cache: Some(cache), progress: !quiet, duration, threads };
            let summary = jointquake::pipeline::run(&scene, &opts).with_context(|| format!("running scene {}", scene.display()))?;
            say_raw!("{}", summary.to_text());
        }
        Cmd::Modes { scene, count, out, cache, json } => {
            let s = jointquake::scene::Scene::load(&scene).with_context(|| format!("loading scene {}", scene.display()))?;
            let opts = RunOptions { mesh_cache: Some(cache), ..Default::default() };
            let mesh = jointquake::pipeline::load_mesh(&s, &opts).with_context(|| format!("meshing scene {}", scene.display()))?;
            let out_dir = out.unwrap_or_else(|| s.output_dir());
            let problem = jointquake::problem::Problem::build(s, mesh).with_context(|| format!("building scene {}", scene.display()))?;
            let r = jointquake::modes::modes(&problem, count, &out_dir).with_context(|| format!("modes of scene {}", scene.display()))?;
            if json {
                say!("{}", serde_json::to_string_pretty(&r).context("serialising the modes")?);
            } else {
                say_raw!("{}", r.to_text());
            }
        }
        Cmd::Tag { scene, out, cache, json } => {
            let opts = RunOptions { out_dir: out, mesh_cache: Some(cache), progress: false, duration: None, threads: None };
            let summary = jointquake::pipeline::tag(&scene, &opts).with_context(|| format!("tagging the joints of scene {}", scene.display()))?;
            if json {
                say!("{}", serde_json::to_string_pretty(&summary).context("serialising the tag summary")?);
            } else {
                say_raw!("{}", summary.to_text());
            }
        }
        Cmd::WedgeFs { input, height_def, h, crack, crack_distance, json } => {
            let mut w = match &input {
                Some(p) => {
                    let text = std::fs::read_to_string(p).with_context(|| format!("reading wedge input {}", p.display()))?;
                    serde_json::from_str::<WedgeInput>(&text)
                        .with_context(|| format!("wedge input {}: expected the fields of WedgeInput (see docs/cli.md)", p.display()))?
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
        }
        Cmd::Study { action } => study_cmd(action)?,
    }
    Ok(())
}

fn study_cmd(action: StudyCmd) -> Result<()> {
    use jointquake::study::{wedge, wedge_report};
    let load = |p: &PathBuf| wedge::WedgeStudy::load(p).with_context(|| format!("loading study {}", p.display()));
    match action {
        StudyCmd::Plan { study, cache, bin } => {
            let s = load(&study)?;
            let files = wedge::write_plan(&study, &s, &cache, &bin).with_context(|| format!("planning study {}", study.display()))?;
            say!("study {}: {} runs planned, {} meshes ready", s.name(), files.scenes.len(), files.meshes.len());
            say!("  plan      {}", files.plan.display());
            say!("  makefile  {}", files.makefile.display());
        }
        StudyCmd::Ssr { study, cache, threads } => {
            if let Some(n) = threads {
                rayon::ThreadPoolBuilder::new().num_threads(n).build_global().context("setting the thread count")?;
            }
            let s = load(&study)?;
            let r = wedge::run_ssr(&s, &cache).with_context(|| format!("strength reduction of study {}", study.display()))?;
            let out = s.out_dir();
            std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
            let p = out.join("ssr.json");
            std::fs::write(&p, serde_json::to_string_pretty(&r).context("serialising the strength reduction")?).with_context(|| format!("writing {}", p.display()))?;
            say!(
                "strength reduction ({} mesh, {} elements): F = {:.4} (bracket {:.4}–{:.4}); limit equilibrium {:.4} → {:+.1} %",
                r.mesh, r.elements, r.result.factor, r.result.bracket[0], r.result.bracket[1], r.le_fs, 100.0 * (r.result.factor / r.le_fs - 1.0)
            );
            for t in &r.result.trials {
                say!(
                    "  F = {:.4}: {} (steps {}, residual {:.1e}, max slip {:.3e} m, |u| P1 {:.3e} m)",
                    t.factor, if t.failed { "fails" } else { "stable" }, t.steps, t.residual, t.max_slip, t.monitor_displacement
                );
            }
            say!("  written {} in {:.1} s", p.display(), r.wall_time);
        }
        StudyCmd::Report { study } => {
            let s = load(&study)?;
            let r = wedge_report::write_report(&s).with_context(|| format!("report of study {}", study.display()))?;
            say!("wedge study report: {}", r.report.display());
            for c in &r.charts {
                say!("  chart {} (and .svg)", c.display());
            }
            for t in &r.trend {
                say!("  {t}");
            }
        }
        StudyCmd::Chart { study, scene, run } => {
            let s = load(&study)?;
            let (charts, slip) = wedge_report::write_run_charts(&s, &scene, &run).with_context(|| format!("charts of run {}", run.display()))?;
            say!("residual slip at P2: {slip:.4} m");
            for c in &charts {
                say!("  chart {} (and .svg)", c.display());
            }
        }
    }
    Ok(())
}

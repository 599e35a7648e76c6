//! jointquake command line: parses arguments, calls the library, adds `anyhow` context.
//!
//! Every subcommand is documented with examples in `docs/cli.md`. Errors are printed as
//! `error: <context>: <cause>` on stderr with exit status 1; the library's typed errors name
//! the file, group, element or line to fix.
use anyhow::{Context, Result};
use clap::{Parser, Subcommand, ValueEnum};
use jointquake::pipeline::RunOptions;
use jointquake::rigid::wedge::{analyse_wedge, critical_horizontal_acceleration, strength_reduction_factor, wedge_fs_report, HeightDef, WedgeInput, WedgeResult};
use std::path::PathBuf;

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
    /// Scenes that declare `joints` are refused until contact is integrated in `run`; use
    /// `jointquake tag` to check their joints.
    Run {
        /// Scene file (JSON, see docs/scenes.md).
        scene: PathBuf,
        /// Output directory (default: the scene's output.dir, else out/<name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Mesh cache directory.
        #[arg(long, default_value = "build/mesh")]
        cache: PathBuf,
        /// Threads (default: all cores). Results are bit-identical whatever the count.
        #[arg(long)]
        threads: Option<usize>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
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
        /// Print the full result (input, geometry, forces, FS) as JSON.
        #[arg(long)]
        json: bool,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum HeightDefArg {
    Intersection,
    CrestOnA,
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
            println!("{}", mesh.source.display());
            println!("  {} nodes, {} cells", mesh.nodes.len(), mesh.cells.len());
            for g in &mesh.groups {
                println!("  group \"{}\" (dim {}): {} cells", g.name, g.dim, g.cells.len());
            }
        }
        Cmd::Run { scene, out, cache, threads, quiet } => {
            if let Some(n) = threads {
                rayon::ThreadPoolBuilder::new().num_threads(n).build_global().context("setting the thread count")?;
            }
            let opts = RunOptions { out_dir: out, mesh_cache: Some(cache), progress: !quiet };
            let summary = jointquake::pipeline::run(&scene, &opts).with_context(|| format!("running scene {}", scene.display()))?;
            print!("{}", summary.to_text());
        }
        Cmd::Tag { scene, out, cache, json } => {
            let opts = RunOptions { out_dir: out, mesh_cache: Some(cache), progress: false };
            let summary = jointquake::pipeline::tag(&scene, &opts).with_context(|| format!("tagging the joints of scene {}", scene.display()))?;
            if json {
                println!("{}", serde_json::to_string_pretty(&summary).context("serialising the tag summary")?);
            } else {
                print!("{}", summary.to_text());
            }
        }
        Cmd::WedgeFs { input, height_def, h, json } => {
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
            let what = || match &input {
                Some(p) => format!("wedge of {}", p.display()),
                None => "seed wedge".to_string(),
            };
            if json {
                let result = analyse_wedge(&w).with_context(|| format!("limit equilibrium of the {}", what()))?;
                let srf = strength_reduction_factor(&w).with_context(|| format!("strength reduction of the {}", what()))?;
                let kc = critical_horizontal_acceleration(&w, 0.0).with_context(|| format!("critical acceleration of the {}", what()))?;
                let out = WedgeFsJson { result, strength_reduction_factor: srf, critical_kh_azimuth_0: kc };
                println!("{}", serde_json::to_string_pretty(&out).context("serialising the wedge result")?);
            } else {
                print!("{}", wedge_fs_report(&w).with_context(|| format!("limit equilibrium of the {}", what()))?);
            }
        }
    }
    Ok(())
}

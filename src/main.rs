//! jointquake command line: parses arguments, calls the library, adds `anyhow` context.
use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use std::path::PathBuf;

#[derive(Parser)]
#[command(name = "jointquake", version, about = "Gmsh geometry to seismic simulation of jointed structures")]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Mesh a scene's .geo with gmsh (cached) and print the .msh path and its groups.
    Mesh {
        scene: PathBuf,
        /// Mesh cache directory.
        #[arg(long, default_value = "build/mesh")]
        cache: PathBuf,
    },
    /// Run a scene: equilibrium, dynamic stage, ParaView series, histories, summary.
    Run {
        scene: PathBuf,
        /// Output directory (default: the scene's output.dir or out/<name>).
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
}

fn main() {
    if let Err(e) = real_main() {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn real_main() -> Result<()> {
    let cli = Cli::parse();
    match cli.cmd {
        Cmd::Mesh { scene, cache } => {
            let s = jointquake::scene::Scene::load(&scene).with_context(|| format!("loading scene {}", scene.display()))?;
            let opts = jointquake::pipeline::RunOptions { mesh_cache: Some(cache), ..Default::default() };
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
            let opts = jointquake::pipeline::RunOptions { out_dir: out, mesh_cache: Some(cache), progress: !quiet };
            let summary = jointquake::pipeline::run(&scene, &opts).with_context(|| format!("running scene {}", scene.display()))?;
            print!("{}", summary.to_text());
        }
    }
    Ok(())
}

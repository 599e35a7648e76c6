//! Natural frequencies and mode shapes of a scene's model (`jointquake modes`).
//!
//! K of every element (the massless blocks included, so their unknowns are condensed by the
//! eigen-solver itself: M is singular there, see `linalg::eigen`), M the inertial mass with the
//! reservoir's added-mass blocks, on the free dofs; with `reservoir.model: "fe_incompressible"`
//! the full condensed added-mass operator (the model's blocks hold only its lumping; module
//! problem::reservoir::incompressible). The layer of a massless block along a joint
//! (mass without weight, kept only for the explicit contact force) is massless here too. Outputs: a table (frequency [Hz], period
//! [s], ω² [1/s²], participation factor Γ_d = φᵀ M ι_d and effective modal mass Γ_d² [kg] along
//! x, y, z with φ M-normalised, and that mass as a fraction of the total mass the ground moves
//! along d) and `modes/modes.pvd`: one VTU per mode (ParaView "time" = mode number) with the
//! point field `mode_shape` scaled to a largest nodal displacement of 1 (Warp By Vector).
//!
//! Joints are **bonded** (`bonded`): every slave node moves with its master point on the
//! initial configuration, an exact linear constraint eliminated by u = T û, so K̂ = Tᵀ K T and
//! M̂ = Tᵀ M T (the slave's mass and added mass go to its masters). Contact laws (friction,
//! opening) play no part: the modes are those of the grouted, bonded structure, the usual
//! linear reference of dam practice. The shapes are written on every node (u = T φ̂).

use crate::error::{Error, ModelError};
use crate::statics::bonding::{Bonding, TieInfo};
use crate::linalg::{dof_map, lowest_modes, mass_matrix, stiffness, ModesOptions};
use crate::problem::Problem;
use crate::vtk::pvd::PvdSeries;
use crate::vtk::vtu::{write_vtu, Field, Grid};
use std::path::{Path, PathBuf};

/// One mode of the table.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ModeRow {
    /// 1-based.
    pub mode: usize,
    pub frequency_hz: f64,
    pub period_s: f64,
    pub omega2: f64,
    /// Γ_d along x, y, z [√kg].
    pub participation: [f64; 3],
    /// Γ_d² [kg].
    pub effective_mass: [f64; 3],
    /// Γ_d² / total mass along d [-].
    pub effective_fraction: [f64; 3],
    /// ‖K φ − ω² M φ‖ / ‖K φ‖.
    pub residual: f64,
}

/// The result of `jointquake modes`.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ModesReport {
    pub scene: String,
    pub dofs: usize,
    /// Free dofs that carry mass (the rest are condensed).
    pub dofs_with_mass: usize,
    /// How the joints' slave nodes were bonded (all zero without joints).
    pub ties: TieInfo,
    pub lanczos_steps: usize,
    /// ι_dᵀ M ι_d along x, y, z [kg].
    pub total_mass: [f64; 3],
    pub modes: Vec<ModeRow>,
    pub pvd: PathBuf,
    pub wall_time: f64,
}

/// The `count` lowest modes of `problem`, with the shapes written under `out_dir/modes/`.
pub fn modes(problem: &Problem, count: usize, out_dir: &Path) -> Result<ModesReport, Error> {
    modes_with(problem, count, out_dir, true)
}

/// [`modes`], with the `"fe_incompressible"` reservoir's full added mass (`full_fluid_mass`,
/// what `jointquake modes` uses) or only its lumping (the model's nodal blocks: the mass the
/// explicit run integrates; to measure what the lumping loses).
pub fn modes_with(problem: &Problem, count: usize, out_dir: &Path, full_fluid_mass: bool) -> Result<ModesReport, Error> {
    let t0 = std::time::Instant::now();
    if count == 0 {
        return Err(ModelError::Invalid("modes: -n must be at least 1".into()).into());
    }
    if problem.scene.reservoir.as_ref().is_some_and(|r| r.added_mass && r.model == crate::scene::reservoir::ReservoirModel::Acoustic) {
        return Err(ModelError::Invalid("modes: reservoir.model \"acoustic\" (compressible water) has no frequency-independent added mass, so the dam's modes with it are not an eigenproblem of K and M: run `modes` with \"fe_incompressible\" (its limit c → ∞) on the same water mesh, or \"westergaard\"".into()).into());
    }
    let model = &problem.model;
    let n = 3 * model.n_nodes();
    let k = stiffness(model, &vec![true; model.materials.len()]);
    let bonded: Vec<&crate::contact::joint::ContactJoint> = problem.joints.iter().collect();
    let t = Bonding::build(model, &bonded, |d| model.is_free(d / 3, d % 3) && k.col_ptr[d + 1] > k.col_ptr[d])?;
    let nf = t.n;
    let kff = t.reduce(&k);
    let blocks: Vec<(usize, [[f64; 3]; 3])> =
        model.mass.blocks.iter().map(|b| (b.node as usize, std::array::from_fn(|i| std::array::from_fn(|j| b.added[(i, j)])))).collect();
    let (all, na) = dof_map(n, |_| true);
    // the massless foundation is massless here: the layer a massless block keeps along a joint
    // (mass without weight, for the explicit contact force) has no part in the modes
    let inertia: Vec<f64> = model.mass.inertial.iter().zip(&model.weightless).map(|(&m, &w)| if w { 0.0 } else { m }).collect();
    // the incompressible FE reservoir: its full added mass (the model holds its lumping)
    let mut m_all = mass_matrix(&inertia, &blocks, &all, na);
    if full_fluid_mass {
        if let Some(extra) = crate::problem::reservoir::coupled_added_mass_of_scene(&model.mesh, &problem.scene)? {
            m_all = crate::linalg::add_entries(&m_all, &extra);
        }
    }
    let mff = t.reduce(&m_all);
    let with_mass = (0..nf).filter(|&j| mff.get(j, j) > 0.0).count();
    let m = lowest_modes(&kff, &mff, &ModesOptions { count, ..Default::default() }).map_err(|e| ModelError::Invalid(e.to_string()))?;
    // influence vectors (a unit translation of the reduced unknowns is one of the whole model:
    // the weights of a master point sum to 1) and total masses
    let iota: Vec<Vec<f64>> = (0..3).map(|c| { let mut v = vec![0.0; nf]; for d in (c..n).step_by(3) { if t.map[d] != crate::linalg::NONE { v[t.map[d]] = 1.0; } } v }).collect();
    let mut mi = vec![vec![0.0; nf]; 3];
    for c in 0..3 {
        mff.mul_into(&iota[c], &mut mi[c]);
    }
    let total_mass: [f64; 3] = std::array::from_fn(|c| iota[c].iter().zip(&mi[c]).map(|(a, b)| a * b).sum());
    let dir = out_dir.join("modes");
    std::fs::create_dir_all(&dir).map_err(|e| crate::error::OutputError::write(&dir, e))?;
    let mut pvd = PvdSeries::new(dir.join("modes.pvd"));
    let grid = Grid { points: &model.mesh.nodes, cells: model.element_cells() };
    let mut rows = Vec::new();
    let mut full = vec![0.0; n];
    for (i, phi) in m.shapes.iter().enumerate() {
        let gamma: [f64; 3] = std::array::from_fn(|c| phi.iter().zip(&mi[c]).map(|(a, b)| a * b).sum());
        let w2 = m.omega2[i];
        rows.push(ModeRow {
            mode: i + 1,
            frequency_hz: m.frequency(i),
            period_s: 1.0 / m.frequency(i),
            omega2: w2,
            participation: gamma,
            effective_mass: gamma.map(|g| g * g),
            effective_fraction: std::array::from_fn(|c| if total_mass[c] > 0.0 { gamma[c] * gamma[c] / total_mass[c] } else { 0.0 }),
            residual: m.residual[i],
        });
        t.expand_into(phi, &mut full);
        let umax = full.chunks(3).map(|u| (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt()).fold(0.0, f64::max);
        if umax > 0.0 {
            full.iter_mut().for_each(|v| *v /= umax);
        }
        let path = dir.join(format!("mode_{:03}.vtu", i + 1));
        write_vtu(&path, &grid, &[Field::f64("mode_shape", 3, &full)], &[])?;
        pvd.push((i + 1) as f64, &path)?;
    }
    let report = ModesReport {
        scene: problem.scene.name().to_string(),
        dofs: nf,
        dofs_with_mass: with_mass,
        ties: t.info.clone(),
        lanczos_steps: m.lanczos_steps,
        total_mass,
        modes: rows,
        pvd: pvd.path().to_path_buf(),
        wall_time: t0.elapsed().as_secs_f64(),
    };
    let js = dir.join("modes.json");
    std::fs::write(&js, serde_json::to_string_pretty(&report).expect("serialises")).map_err(|e| crate::error::OutputError::write(&js, e))?;
    Ok(report)
}

impl ModesReport {
    /// The table as text.
    pub fn to_text(&self) -> String {
        use std::fmt::Write as _;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "scene {}: {} free dofs ({} with mass; the others condensed), {} Lanczos vectors, {:.2} s",
            self.scene, self.dofs, self.dofs_with_mass, self.lanczos_steps, self.wall_time
        );
        if self.ties.joints > 0 {
            let t = &self.ties;
            let _ = writeln!(
                s,
                "{} joint(s) bonded: {} slave nodes tied to their master points ({} projected, {} within half a face, {} to the nearest master node; {} already tied by an earlier joint)",
                t.joints, t.tied, t.projected, t.widened, t.nearest_node, t.already_tied
            );
        }
        let _ = writeln!(s, "total mass moved by the ground: x {:.4e} kg, y {:.4e} kg, z {:.4e} kg", self.total_mass[0], self.total_mass[1], self.total_mass[2]);
        let _ = writeln!(s, "{:>4} {:>11} {:>10} {:>11} {:>11} {:>11} {:>7} {:>7} {:>7}", "mode", "f [Hz]", "T [s]", "Meff_x [kg]", "Meff_y [kg]", "Meff_z [kg]", "x [%]", "y [%]", "z [%]");
        let mut cum = [0.0; 3];
        for r in &self.modes {
            for c in 0..3 {
                cum[c] += r.effective_fraction[c];
            }
            let _ = writeln!(
                s,
                "{:>4} {:>11.5} {:>10.5} {:>11.4e} {:>11.4e} {:>11.4e} {:>7.2} {:>7.2} {:>7.2}",
                r.mode, r.frequency_hz, r.period_s, r.effective_mass[0], r.effective_mass[1], r.effective_mass[2],
                100.0 * r.effective_fraction[0], 100.0 * r.effective_fraction[1], 100.0 * r.effective_fraction[2]
            );
        }
        let _ = writeln!(s, "cumulative effective mass: x {:.1} %, y {:.1} %, z {:.1} %", 100.0 * cum[0], 100.0 * cum[1], 100.0 * cum[2]);
        let _ = writeln!(s, "mode shapes (ParaView, time = mode number): {}", self.pvd.display());
        s
    }
}

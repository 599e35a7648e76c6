//! The reservoir as a fluid (issue 28): the incompressible FE added mass on a meshed water
//! volume against Westergaard's exact series, the non-conforming wet-face transfer, the
//! model's use in `modes`, and the compressible acoustic water against the closed forms of a
//! rigid dam on a compressible reservoir. Structured box meshes (no gmsh).

use crate::common::{problem, scene, stiff_block_base_shear};
use jointquake::mesh::structured::{add_box, box_mesh, BoxSpec};
use jointquake::mesh::Mesh;
use jointquake::problem::reservoir::incompressible::IncompressibleReservoir;
use jointquake::problem::reservoir::{wet_faces, ReservoirSpec};
use jointquake::scene::reservoir::FluidScene;
use std::f64::consts::PI;

/// Westergaard's exact pressure on a rigid vertical wall accelerating at a = 1 m/s² into a
/// semi-infinite incompressible reservoir of depth h, at height y above the bottom:
/// p(y) = (8 ρw h / π²) Σ_{m odd} (−1)^((m−1)/2) / m² cos(m π y / 2h) (derived in
/// docs/dam_physics.md "Reservoir models"; 4000 terms: the tail is below 1e-7 of p(0)).
fn westergaard_series_pressure(rho_w: f64, h: f64, y: f64) -> f64 {
    (0..4000)
        .map(|k| {
            let m = (2 * k + 1) as f64;
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            sign / (m * m) * (m * PI * y / (2.0 * h)).cos()
        })
        .sum::<f64>()
        * 8.0
        * rho_w
        * h
        / (PI * PI)
}

/// The resultant of that pressure per unit width and unit acceleration: (16/π³) ρw h² Σ_{m odd}
/// 1/m³ = (16/π³)(7/8) ζ(3) ρw h² = 0.542754 ρw h² (Westergaard's parabola: 7/12 = 0.5833).
fn westergaard_series_resultant(rho_w: f64, h: f64) -> f64 {
    let s: f64 = (0..100_000).map(|k| 1.0 / ((2 * k + 1) as f64).powi(3)).sum();
    16.0 / PI.powi(3) * s * rho_w * h * h
}

/// A dam block [−2, 0] × [0, b] × [0, 1.2 h] (wet face `dam:x1`) and a water box [0, lw] × [0,
/// b] × [0, h] (`block:water`, wet face `water:x0`, free surface `water:z1`, far end `water:x1`)
/// meshed apart: the divisions differ along y and z, so the wet face does not conform. The pool
/// level h is a node row of the dam (6 rows up its 1.2 h).
fn wall_and_water(h: f64, b: f64, lw: f64, water_div: [usize; 3], tets: bool) -> Mesh {
    let mut mesh = box_mesh(&BoxSpec::new("dam", [2.0, b, 1.2 * h], [2, 3, 6]).at([-2.0, 0.0, 0.0]));
    add_box(&mut mesh, &BoxSpec::new("water", [lw, b, h], water_div).tets(tets));
    mesh
}

fn water_groups() -> FluidScene {
    FluidScene {
        volume: "block:water".into(),
        wet: vec!["water:x0".into()],
        free_surface: vec!["water:z1".into()],
        far_end: vec!["water:x1".into()],
        bottom: vec![],
        reflection: None,
        sound_speed: None,
        vapour_pressure: None,
    }
}

fn rigid_wall_reservoir(h: f64, b: f64, water_div: [usize; 3], tets: bool) -> (Mesh, IncompressibleReservoir) {
    let mesh = wall_and_water(h, b, 3.0 * h, water_div, tets);
    let dam_cells = mesh.group("block:dam").unwrap().cells.clone();
    let faces = wet_faces(&mesh, "dam:x1", &dam_cells).unwrap();
    let spec = ReservoirSpec { rho_w: 1000.0, level: h, bottom: 0.0, g: 9.81, local_depth: false };
    let res = IncompressibleReservoir::build(&mesh, &faces, &spec, &water_groups()).unwrap();
    (mesh, res)
}

#[test]
fn fe_added_mass_of_a_rigid_wall_matches_westergaards_exact_series() {
    // Reference: Westergaard's exact solution (1933) for a rigid vertical wall on a semi-infinite
    // incompressible reservoir: resultant 0.542754 ρw a h² per unit width (16/π³ Σ_{m odd} 1/m³),
    // pressure p(y) as in `westergaard_series_pressure`. The FE reservoir is Lw = 3h long with
    // p = 0 at the far end: that shortens the series' first term by tanh(3π/2) (−0.016 %), far
    // below the tolerances. Tolerances (issue 28): resultant within 1 %, profile within 2 % of
    // the largest pressure (the bottom's, 0.742 ρw a h). h = 10 m, b = 3 m, water 36 × 2 × 18
    // hex8 cells, then 36 × 4 × 18 Kuhn-split tet4 cells, against a dam face of 3 × 6 quads:
    // non-conforming. The FE resultant is a lower bound (a Galerkin compliance) converging as h²:
    // −0.45 % (hex8) and −1.0 % (tet4) at 30 × 2 × 12 cells, −0.26 % and −0.61 % at 36 × 2 × 18;
    // the tet4 profile was 2.04 % off at 36 × 2 × 18 (hence the finer y division). Measured:
    // hex8 −0.26 %, profile 0.23 %; tet4 −0.62 %, profile 1.86 % (both worst at the node below
    // the free surface, where the wall meets p = 0: a log singularity of ∂p/∂y).
    let (h, b, rho_w) = (10.0, 3.0, 1000.0);
    for tets in [false, true] {
        // the Kuhn tets need the y division too (their diagonals make the error anisotropic)
        let (mesh, mut res) = rigid_wall_reservoir(h, b, [36, if tets { 4 } else { 2 }, 18], tets);
        let op = res.added_mass().unwrap();
        // rigid translation along +x (the dam face's outward normal, into the water)
        let nd = op.nodes.len();
        let iota: Vec<f64> = (0..3 * nd).map(|d| if d % 3 == 0 { 1.0 } else { 0.0 }).collect();
        let resultant: f64 = (0..3 * nd).map(|i| (0..3 * nd).map(|j| iota[i] * op.matrix[(i, j)] * iota[j]).sum::<f64>()).sum();
        let exact = westergaard_series_resultant(rho_w, h) * b;
        let p = res.pressure_of_acceleration(&vec![[1.0, 0.0, 0.0]; nd]);
        let p0 = westergaard_series_pressure(rho_w, h, 0.0);
        let (mut worst, mut worst_z) = (0.0f64, 0.0);
        for (k, &v) in res.fluid.nodes.iter().enumerate() {
            if mesh.nodes[v][0].abs() < 1e-9 {
                let exact_p = westergaard_series_pressure(rho_w, h, mesh.nodes[v][2]);
                if (p[k] - exact_p).abs() / p0 > worst {
                    worst = (p[k] - exact_p).abs() / p0;
                    worst_z = mesh.nodes[v][2];
                }
            }
        }
        println!("rigid wall, tets {tets}: resultant {resultant:.1} kg vs series {exact:.1} ({:+.3} %), profile worst {:.3} % of p(0) at z = {worst_z:.3} m; lumped total {:.1}", 100.0 * (resultant / exact - 1.0), 100.0 * worst, op.lumped().0.iter().map(|a| a.mass).sum::<f64>());
        assert!((resultant / exact - 1.0).abs() < 0.01, "tets {tets}: resultant {resultant} vs {exact}");
        assert!(worst < 0.02, "tets {tets}: pressure profile off by {worst} of p(0)");
        // the row-sum lumping keeps the rigid-translation mass: Σ m_b n_x² = ιᵀ M_a ι
        let (lumped, negative) = op.lumped();
        assert_eq!(negative, 0);
        let lumped_total: f64 = lumped.iter().map(|a| a.mass * a.normal[0] * a.normal[0]).sum();
        assert!((lumped_total / resultant - 1.0).abs() < 1e-9, "lumped {lumped_total} vs {resultant}");
    }
}

#[test]
fn uniform_pressure_on_a_non_conforming_wet_face_gives_the_exact_resultant() {
    // Reference: a uniform pressure p0 on the water's wet face must load the dam with exactly
    // −p0 ∫ n dA = −p0 b h along x over the wet part (the dam face continues 0.2 h above the
    // pool, dry); tolerance 1e-12 relative (the transfer's shape functions sum to 1 at every
    // point, so it holds whatever the two meshes). Water divisions unrelated to the dam's.
    let (h, b) = (10.0, 3.0);
    for (div, tets) in [([7, 5, 9], false), ([4, 2, 7], true)] {
        let (_, res) = rigid_wall_reservoir(h, b, div, tets);
        let c = &res.coupling;
        let f = c.forces_of_pressure(&vec![2.5e5; c.water_nodes.len()]);
        let total: [f64; 3] = std::array::from_fn(|k| f.iter().map(|v| v[k]).sum());
        let exact = -2.5e5 * b * h;
        assert!((total[0] / exact - 1.0).abs() < 1e-12, "div {div:?}: Fx {} vs {exact}", total[0]);
        assert!(total[1].abs() < 1e-12 * exact.abs() && total[2].abs() < 1e-12 * exact.abs(), "{total:?}");
        assert!((c.area / (b * h) - 1.0).abs() < 1e-12, "wet area {}", c.area);
        assert!(c.max_gap < 1e-9, "flat faces coincide: gap {}", c.max_gap);
    }
}

/// Dry Euler–Bernoulli cantilever mode n: φ(ζ) and φ''(ζ) (ζ = z / H, clamped at ζ = 0).
fn cantilever_mode(n: usize, zeta: f64) -> (f64, f64) {
    const BL: [f64; 6] = [1.875104068711961, 4.694091132974175, 7.854757438237613, 10.995540734875467, 14.137168391046471, 17.278759532088237];
    let b = BL[n];
    let s = (b.sinh() - b.sin()) / (b.cosh() + b.cos());
    let x = b * zeta;
    (x.cosh() - x.cos() - s * (x.sinh() - x.sin()), b * b * (x.cosh() + x.cos() - s * (x.sinh() + x.sin())))
}

/// ∫₀¹ f by composite 4-point Gauss–Legendre on 800 intervals.
fn integrate(f: impl Fn(f64) -> f64) -> f64 {
    const X: [f64; 4] = [-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526];
    const W: [f64; 4] = [0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538];
    let n = 800;
    let h = 1.0 / n as f64;
    (0..n).map(|i| (0..4).map(|q| 0.5 * h * W[q] * f((i as f64 + 0.5 + 0.5 * X[q]) * h)).sum::<f64>()).sum()
}

#[test]
fn wall_monolith_frequency_drop_with_fe_water_matches_the_exact_potential_flow() {
    // Reference (closed form): a rigid-base wall monolith H = 20 m, t = 1 m (x), b = 2 m (y),
    // E = 25 GPa, ν = 0, ρ = 2400, wet to the crest on x = 0, on a semi-infinite incompressible
    // reservoir (ρw = 1000). Rayleigh–Ritz on the first six dry Euler–Bernoulli cantilever modes
    // φ_i with the exact hydrodynamic mass of potential flow on a flexible wall (Westergaard's
    // series per mode, as in Chopra's rigid-base analysis, Fenves & Chopra UCB/EERC-85/10):
    // M^a_ij = b Σ_n 2ρw / (H λ_n) c_in c_jn, c_in = ∫₀^H φ_i(z) cos(λ_n z) dz, λ_n = (2n−1)π/2H
    // (400 terms). Checked: the ratio f_full / f_empty of `jointquake modes` with
    // "fe_incompressible" (monolith hex8 2 × 2 × 40; water 3H long, p = 0 at its far end, hex8
    // 36 × 2 × 24: non-conforming with the monolith's 40 rows) within 1 % of the reference
    // (mesh effects of the monolith cancel in the ratio). Also measured (printed, docs): the
    // lumped operator the explicit run uses, and Westergaard's parabola.
    let (h, t, b, e, rho, rho_w) = (20.0, 1.0, 2.0, 25e9, 2400.0, 1000.0);
    let dir = crate::common::scratch("reservoir_fe_monolith");
    let f1 = |model: Option<&str>| -> (f64, f64) {
        let mut mesh = box_mesh(&BoxSpec::new("b", [t, b, h], [2, 2, 40]));
        add_box(&mut mesh, &BoxSpec::new("water", [3.0 * h, b, h], [36, 2, 24]).at([-3.0 * h, 0.0, 0.0]));
        let mut v = serde_json::json!({
            "geometry": {"msh": "none.msh"},
            "materials": [{"group": "block:b", "E": e, "nu": 0.0, "rho": rho}],
            "boundary": [{"group": "b:z0"}],
            "time": {"duration": 0.0}
        });
        if let Some(m) = model {
            v["reservoir"] = serde_json::json!({"faces": ["b:x0"], "level": h, "rho_w": rho_w, "hydrostatic": false, "model": m});
            if m == "fe_incompressible" {
                v["reservoir"]["fluid"] = serde_json::json!({"volume": "block:water", "wet": ["water:x1"], "free_surface": ["water:z1"], "far_end": ["water:x0"]});
            }
        }
        let pb = problem(mesh, &scene(v), 0.9);
        let r = jointquake::statics::modes::modes(&pb, 2, &dir).unwrap();
        // the lumped operator alone (the explicit run's): the model's nodal blocks
        let model = &pb.model;
        let k = jointquake::linalg::stiffness(model, &vec![true; model.materials.len()]);
        let (map, nf) = jointquake::linalg::dof_map(3 * model.n_nodes(), |d| model.is_free(d / 3, d % 3) && k.col_ptr[d + 1] > k.col_ptr[d]);
        let blocks: Vec<(usize, [[f64; 3]; 3])> = model.mass.blocks.iter().map(|bl| (bl.node as usize, bl.added.into())).collect();
        let kff = jointquake::linalg::restrict(&k, &map, nf, &map, nf);
        let lumped = jointquake::linalg::lowest_modes(&kff, &jointquake::linalg::mass_matrix(&model.mass.inertial, &blocks, &map, nf), &Default::default()).unwrap();
        (r.modes[0].frequency_hz, lumped.frequency(0))
    };
    let (dry, _) = f1(None);
    let (fe, fe_lumped) = f1(Some("fe_incompressible"));
    let (wg, _) = f1(Some("westergaard"));
    // Ritz with the exact potential-flow added mass
    let nm = 6;
    let ei = e * b * t.powi(3) / 12.0;
    let lambdas: Vec<f64> = (1..=400).map(|n| (2 * n - 1) as f64 * PI / (2.0 * h)).collect();
    let c: Vec<Vec<f64>> = (0..nm).map(|i| lambdas.iter().map(|l| h * integrate(|z| cantilever_mode(i, z).0 * (l * h * z).cos())).collect()).collect();
    let ms = nalgebra::DMatrix::from_fn(nm, nm, |i, j| integrate(|z| rho * b * t * cantilever_mode(i, z).0 * cantilever_mode(j, z).0 * h));
    let ma = nalgebra::DMatrix::from_fn(nm, nm, |i, j| b * lambdas.iter().enumerate().map(|(n, l)| 2.0 * rho_w / (h * l) * c[i][n] * c[j][n]).sum::<f64>());
    let kr = nalgebra::DMatrix::from_fn(nm, nm, |i, j| integrate(|z| ei * cantilever_mode(i, z).1 * cantilever_mode(j, z).1 / h.powi(3)));
    let lowest = |m: nalgebra::DMatrix<f64>| {
        let li = m.cholesky().unwrap().l().try_inverse().unwrap();
        let a = &li * &kr * li.transpose();
        nalgebra::SymmetricEigen::new((&a + a.transpose()) * 0.5).eigenvalues.iter().copied().fold(f64::INFINITY, f64::min)
    };
    let ratio_ref = (lowest(&ms + &ma) / lowest(ms.clone())).sqrt();
    let ratio = fe / dry;
    println!(
        "wall monolith H = 20 m: f_empty {dry:.4} Hz; full: fe_incompressible {fe:.4} Hz (ratio {ratio:.5}, exact potential flow {ratio_ref:.5}, {:+.3} %), its lumping {fe_lumped:.4} Hz (ratio {:.5}), westergaard {wg:.4} Hz (ratio {:.5})",
        100.0 * (ratio / ratio_ref - 1.0),
        fe_lumped / dry,
        wg / dry
    );
    assert!((ratio / ratio_ref - 1.0).abs() < 0.01, "ratio {ratio} vs {ratio_ref}");
}

#[test]
fn base_shear_of_a_stiff_block_with_fe_water_includes_the_exact_added_mass() {
    // Reference: quasi-static rigid response to a uniform base acceleration a along x (the wet
    // face's normal): base shear V = (M + 0.542754 ρw H² b) a (Westergaard's exact series for a
    // rigid wall on a semi-infinite reservoir; the explicit run's row-sum lumping of the FE
    // operator is exact for a uniform normal acceleration), H = 10 m, b = 3 m. The setup of
    // dam_physics::base_shear_of_a_stiff_block_with_a_wet_face_includes_the_westergaard_mass
    // (block 2 × 3 × 10 m, E = 10⁵ GPa, ramp to 0.2 g over 0.2 s, V at 0.3 s) with the water
    // meshed (3H long, hex8 36 × 2 × 18, non-conforming with the block's 3 × 20 face).
    // Tolerance 1 % (the FE resultant is −0.2 % at this water mesh, the rigid-wall test).
    let (v, expect, notes) = water_block_base_shear("reservoir_fe_base_shear", "fe_incompressible", false);
    println!("fe water base shear {v:.5e} N, expected {expect:.5e} N ({:+.3} %), notes {notes:?}", 100.0 * (v / expect - 1.0));
    assert!((v / expect - 1.0).abs() < 0.01, "base shear {v} vs {expect}");
}

/// The base shear V [N] at 0.3 s of the stiff block of `common::stiff_block_base_shear` wet on
/// x = 0 to its crest, with the water meshed 3H upstream (hex8 36 × 2 × 18, non-conforming with
/// the block's 3 × 20 face) under `model`, its base ramped to 0.2 g (linearly, or by a half
/// cosine when `smooth`); the quasi-static expectation (M + 0.542754 ρw H² b) a; the notes.
fn water_block_base_shear(scratch: &str, model: &str, smooth: bool) -> (f64, f64, Vec<String>) {
    let mut mesh = box_mesh(&BoxSpec::new("b", [2.0, 3.0, 10.0], [2, 3, 20]));
    add_box(&mut mesh, &BoxSpec::new("water", [30.0, 3.0, 10.0], [36, 2, 18]).at([-30.0, 0.0, 0.0]));
    let reservoir = serde_json::json!({"faces": ["b:x0"], "level": 10.0, "hydrostatic": false, "model": model,
        "fluid": {"volume": "block:water", "wet": ["water:x1"], "free_surface": ["water:z1"], "far_end": ["water:x0"]}});
    let (v, m_total, a, pb) = stiff_block_base_shear(scratch, mesh, reservoir, smooth);
    let expect = (m_total + westergaard_series_resultant(1000.0, 10.0) * 3.0) * a;
    (v, expect, pb.notes.clone())
}

#[test]
fn coarse_dam_first_frequencies_with_each_reservoir_model() {
    // The committed coarse dam with its meshed water (tests/fixtures/arch_dam_coarse_water.msh,
    // geo/arch_dam.geo -setnumber water 1; pool 205 m on H = 210 m, water 3 × 205 m long):
    // `modes` empty, Westergaard (the seed's), Westergaard with local depth, FE incompressible
    // (full operator) and its lumping (what the explicit run integrates). Reference (ordering,
    // not a number): the lumping adds Σ_bc M_bc (φ_b − φ_c)² / 2 ≥ 0 of generalised mass to
    // every mode when M_a's entries are ≥ 0 (the Laplace Green's function), so f1(lumped) ≤
    // f1(full) < f1(empty); all three wet models lower f1. The numbers are in
    // docs/dam_physics.md "Reservoir models".
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("pipelines/dam_coarse_fe.json");
    let mut sc = jointquake::scene::Scene::load(&path).unwrap();
    let mesh = Mesh::from_msh(crate::common::fixture("arch_dam_coarse_water.msh")).unwrap();
    jointquake::pipeline::expand_patterns(&mut sc, &mesh, &path).unwrap();
    let dir = crate::common::scratch("reservoir_coarse_dam_modes");
    let f1 = |sc: &jointquake::scene::Scene, full: bool| -> f64 {
        let pb = problem(mesh.clone(), sc, 0.9);
        jointquake::statics::modes::modes_with(&pb, 1, &dir, full).unwrap().modes[0].frequency_hz
    };
    let (fe, fe_lumped) = (f1(&sc, true), f1(&sc, false));
    let mut wg = sc.clone();
    let r = wg.reservoir.as_mut().unwrap();
    r.model = jointquake::scene::reservoir::ReservoirModel::Westergaard;
    r.fluid = None;
    let f_wg = f1(&wg, true);
    let mut empty = sc.clone();
    empty.reservoir = None;
    let f_empty = f1(&empty, true);
    let drop = |f: f64| 100.0 * (1.0 - f / f_empty);
    println!(
        "coarse dam f1: empty {f_empty:.4} Hz; westergaard {f_wg:.4} ({:.1} % drop); fe_incompressible {fe:.4} ({:.1} %), its lumping {fe_lumped:.4} ({:.1} %)",
        drop(f_wg),
        drop(fe),
        drop(fe_lumped)
    );
    assert!(fe_lumped <= fe * (1.0 + 1e-9) && fe < f_empty && f_wg < f_empty, "{fe_lumped} {fe} {f_wg} {f_empty}");
}

// ---------------------------------------------------------------- acoustic water (compressible)

use jointquake::problem::reservoir::acoustic::{AcousticRun, AcousticWater};
use rustfft::num_complex::Complex;

/// A rigid dam face at x = 0 (block [−2, 0] × [0, b] × [0, 1.2 h], wet face `dam:x1`) and the
/// acoustic water [0, lw] × [0, b] × [0, h] (hex8 `div`) with `fluid`'s groups, pool at h.
fn acoustic_channel(h: f64, b: f64, lw: f64, div: [usize; 3], fluid: &FluidScene) -> (Mesh, AcousticWater) {
    let mesh = wall_and_water(h, b, lw, div, false);
    let dam_cells = mesh.group("block:dam").unwrap().cells.clone();
    let faces = wet_faces(&mesh, "dam:x1", &dam_cells).unwrap();
    let spec = ReservoirSpec { rho_w: 1000.0, level: h, bottom: 0.0, g: 9.81, local_depth: false };
    let water = AcousticWater::build(&mesh, &faces, &spec, fluid).unwrap();
    (mesh, water)
}

/// The water's unknown at the wall's foot (x = 0, z = 0, the y = 0 corner).
fn wall_foot_unknown(mesh: &Mesh, water: &AcousticWater) -> usize {
    water.fluid.nodes.iter().position(|&v| mesh.nodes[v][0].abs() < 1e-9 && mesh.nodes[v][2].abs() < 1e-9 && mesh.nodes[v][1].abs() < 1e-9).unwrap()
}

/// Chopra (1967) and Fenves & Chopra (1984): the harmonic pressure at the foot (x = 0, y = 0)
/// of a rigid vertical dam accelerating at a e^{iωt} (a = 1 m/s²) into a compressible reservoir of
/// depth h, infinite upstream, bottom reflection coefficient α (y up from the bottom):
/// p = Σ_n A_n Y_n(y) e^{−κ_n x}, Y_n = sin(λ_n (h − y)) (p = 0 at the surface), the bottom
/// condition ∂p/∂y = iωq p with q = (1 − α)/((1 + α) c) gives λ cos λh + iωq sin λh = 0 (λ_n real,
/// (2n−1)π/2h, when α = 1; complex otherwise, found by Newton from those), κ_n = √(λ_n² − ω²/c²)
/// (Re ≥ 0: decaying or outgoing), and ∂p/∂x = −ρ a at the wall A_n = ρ a ∫Y_n / (κ_n ∫Y_n²)
/// (the Y_n are orthogonal without conjugation). |p(0, 0)| [Pa], 2000 terms.
fn chopra_foot_pressure(rho: f64, c: f64, h: f64, omega: f64, alpha: f64) -> f64 {
    let q = (1.0 - alpha) / ((1.0 + alpha) * c);
    let iwq = Complex::new(0.0, omega * q);
    let mut p = Complex::new(0.0, 0.0);
    for n in 1..=2000 {
        let mut l = Complex::new((2 * n - 1) as f64 * PI / (2.0 * h), 0.0);
        for _ in 0..50 {
            let (s, co) = ((l * h).sin(), (l * h).cos());
            let f = l * co + iwq * s;
            let df = co - l * h * s + iwq * h * co;
            let step = f / df;
            l -= step;
            if step.norm() < 1e-14 * l.norm() {
                break;
            }
        }
        let kappa = (l * l - Complex::new(omega * omega / (c * c), 0.0)).sqrt();
        let int_y = (Complex::new(1.0, 0.0) - (l * h).cos()) / l;
        let int_y2 = Complex::new(h / 2.0, 0.0) - (l * 2.0 * h).sin() / (l * 4.0);
        p += rho * int_y / (kappa * int_y2) * (l * h).sin();
    }
    p.norm()
}

/// The steady harmonic amplitude of the pressure at the wall's foot: the rigid wall accelerates
/// at sin(ωt) along +x (into the water), ramped in by a half cosine over `ramp` periods, for
/// `periods` periods; the amplitude is fitted (sin and cos) over the last 4 periods.
fn harmonic_foot_amplitude(mesh: &Mesh, water: &AcousticWater, f: f64, ramp: f64, periods: usize) -> f64 {
    let loads = jointquake::dynamics::loads::Loads::default();
    let per = 1.0 / f;
    // a whole number of steps per period, within the water's stable step
    let steps_per = (per / (0.9 * water.stable_step())).ceil() as usize;
    let dt = per / steps_per as f64;
    let mut run = AcousticRun::new(water, &loads, false, dt);
    assert_eq!(run.substeps, 1);
    let foot = wall_foot_unknown(mesh, water);
    let nd = water.coupling.dam_nodes.len();
    let w = 2.0 * PI * f;
    let (mut s, mut c, mut n) = (0.0, 0.0, 0usize);
    for k in 0..periods * steps_per {
        let t = k as f64 * dt;
        let env = if t < ramp * per { 0.5 * (1.0 - (PI * t / (ramp * per)).cos()) } else { 1.0 };
        run.advance_with_acceleration(&vec![[env * (w * t).sin(), 0.0, 0.0]; nd], dt);
        // p now at t + dt
        if k >= (periods - 4) * steps_per {
            let tp = t + dt;
            s += run.p[foot] * (w * tp).sin();
            c += run.p[foot] * (w * tp).cos();
            n += 1;
        }
    }
    let (s, c) = (2.0 * s / n as f64, 2.0 * c / n as f64);
    (s * s + c * c).sqrt()
}

#[test]
fn acoustic_water_resonances_of_a_rigid_wall_are_the_quarter_wave_frequencies() {
    // Reference: a rigid dam on a compressible reservoir of depth h resonates at the cut-off
    // frequencies of the channel's modes, f_n = (2n − 1) c / 4h (Chopra 1967): there the mode's
    // pressure is uniform upstream and the wall's response unbounded. Those are the frequencies
    // of the x-uniform fields of the FE water; measured here by an impulse of the wall on a short
    // closed basin (lw = h/4, rigid far end: its other modes, √((2n−1)² + (8m)²) c/4h, lie far
    // from f1..f3), the pressure at the wall's foot over 10 s (Hann window, zero-padded ×16
    // FFT, parabolic peak), n = 1, 2, 3. Tolerance 1 % (issue 28). h = 36 m, c = 1440 m/s:
    // f1 = 10 Hz; hex8 of 1.5 m (24 over h).
    let (h, c) = (36.0, 1440.0);
    let mut fluid = water_groups();
    fluid.far_end = vec![];
    let (mesh, water) = acoustic_channel(h, 1.5, h / 4.0, [6, 1, 24], &fluid);
    let loads = jointquake::dynamics::loads::Loads::default();
    let dt = 0.5 * water.stable_step();
    let mut run = AcousticRun::new(&water, &loads, false, dt);
    let foot = wall_foot_unknown(&mesh, &water);
    let nd = water.coupling.dam_nodes.len();
    let n = (10.0 / dt) as usize;
    let (t0, sigma) = (0.005, 0.001);
    let mut rec = Vec::with_capacity(n);
    for k in 0..n {
        let t = k as f64 * dt;
        let a = (-((t - t0) / sigma).powi(2)).exp();
        run.advance_with_acceleration(&vec![[a, 0.0, 0.0]; nd], dt);
        rec.push(run.p[foot]);
    }
    let m = 16 * n.next_power_of_two();
    let mut buf: Vec<Complex<f64>> = (0..m).map(|k| if k < n { Complex::new(rec[k] * (0.5 - 0.5 * (2.0 * PI * k as f64 / n as f64).cos()), 0.0) } else { Complex::new(0.0, 0.0) }).collect();
    rustfft::FftPlanner::new().plan_fft_forward(m).process(&mut buf);
    let df = 1.0 / (m as f64 * dt);
    for k in 1..=3 {
        let exact = (2 * k - 1) as f64 * c / (4.0 * h);
        let (lo, hi) = ((0.8 * exact / df) as usize, (1.2 * exact / df) as usize);
        let i = (lo..hi).max_by(|&a, &b| buf[a].norm().total_cmp(&buf[b].norm())).unwrap();
        let (ym, y0, yp) = (buf[i - 1].norm(), buf[i].norm(), buf[i + 1].norm());
        let peak = (i as f64 + 0.5 * (ym - yp) / (ym - 2.0 * y0 + yp)) * df;
        println!("acoustic resonance n = {k}: FE {peak:.4} Hz, exact {exact:.4} Hz ({:+.3} %)", 100.0 * (peak / exact - 1.0));
        assert!((peak / exact - 1.0).abs() < 0.01, "n {k}: {peak} vs {exact}");
    }
}

#[test]
fn acoustic_harmonic_wall_pressure_matches_chopras_rigid_dam_solution() {
    // Reference: `chopra_foot_pressure` (Chopra 1967 for α = 1; Fenves & Chopra 1984 with the
    // bottom's reflection coefficient α < 1), the pressure amplitude at the foot of a rigid
    // dam on a reservoir infinite upstream. FE: h = 36 m (f1 = c/4h = 10 Hz), water 3h long
    // with the Sommerfeld far end, hex8 1.5 m, the wall driven harmonically to a steady state.
    // Tolerances: 3 % away from resonance (issue 28) at 0.5 f1 and 0.8 f1 with a rigid bottom;
    // at resonance (f1) with α = 0.5 the peak is bounded and within 5 % of the theory's (the
    // far end's plane-wave condition is not exact for the channel's modes, module doc of
    // problem::reservoir::acoustic). Measured in the output below and in docs/dam_physics.md.
    let (h, c, rho) = (36.0, 1440.0, 1000.0);
    let f1 = c / (4.0 * h);
    let (mesh, water) = acoustic_channel(h, 1.5, 3.0 * h, [72, 1, 24], &water_groups());
    for (ratio, tol) in [(0.5, 0.03), (0.8, 0.03)] {
        let fe = harmonic_foot_amplitude(&mesh, &water, ratio * f1, 4.0, 30);
        let exact = chopra_foot_pressure(rho, c, h, 2.0 * PI * ratio * f1, 1.0);
        println!("acoustic harmonic, rigid bottom, f = {ratio} f1: FE {fe:.1} Pa, Chopra {exact:.1} Pa ({:+.3} %), incompressible {:.1} Pa", 100.0 * (fe / exact - 1.0), 0.7425 * rho * h);
        assert!((fe / exact - 1.0).abs() < tol, "f/f1 {ratio}: {fe} vs {exact}");
    }
    let mut fluid = water_groups();
    fluid.bottom = vec!["water:z0".into()];
    fluid.reflection = Some(0.5);
    let (mesh, water) = acoustic_channel(h, 1.5, 3.0 * h, [72, 1, 24], &fluid);
    let fe = harmonic_foot_amplitude(&mesh, &water, f1, 4.0, 30);
    let exact = chopra_foot_pressure(rho, c, h, 2.0 * PI * f1, 0.5);
    println!("acoustic harmonic at resonance, α = 0.5: FE {fe:.1} Pa, Fenves-Chopra {exact:.1} Pa ({:+.3} %)", 100.0 * (fe / exact - 1.0));
    assert!((fe / exact - 1.0).abs() < 0.05, "resonance α 0.5: {fe} vs {exact}");
}

/// The run's water summary (`summary.json` → `water`) counts what it says: driven hard enough
/// (the wall at 30 m/s², 0.5 f1, into h = 36 m of water: a suction of the order ρ a h ≈ 1 MPa,
/// above the hydrostatic 353 kPa at the foot plus |p_v|), the cavitation floor holds unknowns;
/// the reference is an independent count of the unknowns sitting exactly at their floor after
/// each water step (one substep per step here), and the largest |p| seen. Exact (integers;
/// the peak to 1e-12). Without `vapour_pressure` nothing is counted and the field goes below
/// the floor.
#[test]
fn acoustic_water_summary_counts_cavitation_and_the_peak_pressure() {
    let (h, c) = (36.0, 1440.0);
    let f = 0.5 * c / (4.0 * h);
    let loads = jointquake::dynamics::loads::Loads::default();
    let mut below_floor = 0usize;
    for pv in [None, Some(-99000.0)] {
        let mut fluid = water_groups();
        fluid.vapour_pressure = pv;
        let (mesh, water) = acoustic_channel(h, 1.5, 3.0 * h, [36, 1, 12], &fluid);
        // the floor of the dynamic pressure, p_v − ρ g (h − z), per unknown (the water's own
        // with cavitation, after checking it against the formula)
        let formula: Vec<f64> = water.fluid.nodes.iter().map(|&v| -99000.0 - 1000.0 * 9.81 * (h - mesh.nodes[v][2])).collect();
        if let Some(fl) = &water.floor {
            assert!(fl.iter().zip(&formula).all(|(a, b)| (a - b).abs() < 1e-9 * b.abs()));
        }
        let floor = water.floor.clone().unwrap_or(formula);
        let dt = 0.9 * water.stable_step();
        let mut run = AcousticRun::new(&water, &loads, false, dt);
        assert_eq!(run.substeps, 1);
        let nd = water.coupling.dam_nodes.len();
        let (mut held, mut steps_with, mut most, mut peak, mut first) = (0u64, 0u64, 0usize, 0.0f64, None);
        for k in 0..(2.0 / f / dt) as usize {
            let t = k as f64 * dt;
            run.advance_with_acceleration(&vec![[30.0 * (2.0 * PI * f * t).sin(), 0.0, 0.0]; nd], dt);
            let at = run.p.iter().zip(&floor).filter(|(p, fl)| **p == **fl).count();
            below_floor += run.p.iter().zip(&floor).filter(|(p, fl)| **p < **fl).count();
            held += at as u64;
            steps_with += (at > 0) as u64;
            most = most.max(at);
            if at > 0 && first.is_none() {
                first = Some(t + dt);
            }
            peak = run.p.iter().fold(peak, |m, p| m.max(p.abs()));
        }
        let st = &run.stats;
        println!("vapour pressure {pv:?}: {} unknown-steps held in {} steps (most {}), first {:?} s; peak {:.4e} Pa; {}", st.cavitated_node_steps, st.cavitated_steps, st.max_cavitated_nodes, st.first_cavitation_t, st.peak_pressure, st.line());
        assert_eq!(st.cavitation, pv.is_some());
        assert!((st.peak_pressure - peak).abs() <= 1e-12 * peak, "peak {} vs {peak}", st.peak_pressure);
        assert!((st.dt_stable - water.stable_step()).abs() == 0.0 && st.substeps == 1 && st.dt == dt);
        if pv.is_some() {
            assert!(held > 0, "the wall's suction must reach the vapour pressure");
            assert_eq!((st.cavitated_node_steps, st.cavitated_steps, st.max_cavitated_nodes), (held, steps_with, most));
            let ft = st.first_cavitation_t.expect("cavitated");
            assert!((ft - first.unwrap()).abs() < 1e-9 * ft, "first {ft} vs {first:?}");
        } else {
            assert_eq!((st.cavitated_node_steps, st.cavitated_steps, st.first_cavitation_t), (0, 0, None));
            assert!(below_floor > 0, "without cavitation the same drive takes the water below the floor");
            below_floor = 0;
        }
    }
    assert_eq!(below_floor, 0, "with cavitation no unknown goes below its floor");
}

#[test]
fn acoustic_far_end_absorbs_a_plane_pulse() {
    // Reference: Sommerfeld's condition ∂p/∂t = −c ∂p/∂n is exact for a plane wave at normal
    // incidence; a pulse leaving the mesh must leave less than 5 % of its energy behind (issue
    // 28). A rigid duct 2 × 2 m, 240 m long (no free surface, every side rigid), hex8 of 2 m;
    // the wall at x = 0 pushes a sin² acceleration pulse of 0.05 s (72 m long: 36 elements),
    // the far end at x = 240 m radiates. The field energy of the water (½ v·Q v + ½ p·H p) once
    // the pulse is wholly inside, against what is left after its front has had time to leave
    // and come half-way back.
    let (len, b, c) = (240.0, 2.0, 1440.0);
    let mut fluid = water_groups();
    fluid.free_surface = vec![];
    let (_, water) = acoustic_channel(b, b, len, [120, 1, 1], &fluid);
    let loads = jointquake::dynamics::loads::Loads::default();
    let dt = 0.9 * water.stable_step();
    let mut run = AcousticRun::new(&water, &loads, false, dt);
    let nd = water.coupling.dam_nodes.len();
    let pulse = 0.05;
    let inside = pulse + 0.25 * len / c;
    let after = pulse + 1.5 * len / c;
    let (mut e_in, mut e_after) = (0.0, 0.0);
    let mut t = 0.0;
    while t < after {
        let a = if t < pulse { (PI * t / pulse).sin().powi(2) } else { 0.0 };
        run.advance_with_acceleration(&vec![[a, 0.0, 0.0]; nd], dt);
        t += dt;
        if e_in == 0.0 && t >= inside {
            e_in = run.field_energy(dt);
        }
        e_after = run.field_energy(dt);
    }
    println!("acoustic plane pulse: energy inside {e_in:.4e}, left after it reached the far end {e_after:.4e} ({:.3} %)", 100.0 * e_after / e_in);
    assert!(e_in > 0.0 && e_after / e_in < 0.05, "{e_after} / {e_in}");
}

#[test]
fn acoustic_water_at_rest_under_gravity_holds_the_hydrostatic_state_for_10_s() {
    // Reference: a dam block with its hydrostatic load in static equilibrium (construction
    // sequence, a direct solve) and the acoustic water at rest: nothing moves; the dynamic
    // pressure stays 0 and the block at its static displacement over 10 s of explicit steps
    // (issue 28). Tolerances: |p| below 1e-6 of ρw g H, the block's displacement within 1e-6 of
    // its static value (relative to that value).
    let mut mesh = box_mesh(&BoxSpec::new("b", [2.0, 3.0, 10.0], [2, 3, 10]));
    add_box(&mut mesh, &BoxSpec::new("water", [30.0, 3.0, 10.0], [30, 2, 10]).at([-30.0, 0.0, 0.0]));
    let sc = scene(serde_json::json!({
        "geometry": {"msh": "none.msh"},
        "materials": [{"group": "block:b", "E": 25e9, "nu": 0.2, "rho": 2400.0}],
        "boundary": [{"group": "b:z0"}],
        "loads": {"gravity": {"g": 9.81}},
        "equilibrium": {"sequence": "construction"},
        "reservoir": {"faces": ["b:x0"], "level": 10.0, "model": "acoustic",
            "fluid": {"volume": "block:water", "wet": ["water:x1"], "free_surface": ["water:z1"], "far_end": ["water:x0"], "bottom": ["water:z0"], "reflection": 0.8}},
        "time": {"duration": 10.0}
    }));
    let pb = problem(mesh, &sc, 0.9);
    let mut sim = jointquake::simulation::Simulation::new(&pb).unwrap();
    sim.equilibrate().unwrap();
    let u0 = sim.state.u.clone();
    let umax = u0.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(umax > 0.0);
    let steps = sim.n_steps();
    for _ in 0..steps {
        sim.step().unwrap();
    }
    let drift = sim.state.u.iter().zip(&u0).fold(0.0f64, |a, (u, v)| a.max((u - v).abs()));
    let pmax = sim.water.as_ref().unwrap().p.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    println!("acoustic water at rest, {steps} steps of {:.3e} s: drift {:.3e} of the static {umax:.3e} m, largest |p| {pmax:.3e} Pa; notes {:?}", sim.dt(), drift / umax, sim.notes);
    assert!(drift <= 1e-6 * umax, "drift {drift} of {umax}");
    assert!(pmax <= 1e-6 * 1000.0 * 9.81 * 10.0, "p {pmax}");
}

#[test]
fn base_shear_of_a_stiff_block_with_acoustic_water_tends_to_the_incompressible_added_mass() {
    // Reference: under a base acceleration that rises slowly against the water's first
    // resonance (c/4H = 36 Hz for H = 10 m) and then holds, compressible water carries the
    // incompressible pressure (p̈ → 0: H p = ρw G a), so the base shear of a stiff block tends to
    // (M + 0.542754 ρw H² b) a (Westergaard's exact series, rigid wall, semi-infinite
    // reservoir). The setup of base_shear_of_a_stiff_block_with_fe_water_includes_the_exact_added_mass
    // with "acoustic" (the water driven through the step's hook, both ways) and a half-cosine
    // ramp to 0.2 g over 0.2 s (7 periods of the resonance: little ringing), V at 0.3 s.
    // Tolerance 2 % (FE resultant −0.26 % at this water mesh; what rings on after the ramp).
    // Measured −1.94 % (fe_incompressible on the same block: −0.11 %).
    let (v, expect, notes) = water_block_base_shear("reservoir_acoustic_base_shear", "acoustic", true);
    println!("acoustic water base shear {v:.5e} N, expected {expect:.5e} N ({:+.3} %), notes {notes:?}", 100.0 * (v / expect - 1.0));
    assert!((v / expect - 1.0).abs() < 0.02, "base shear {v} vs {expect}");
}

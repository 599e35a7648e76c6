//! Foundation models (issue 29): the 1-D column deconvolution, the radiating far boundary on a
//! rock box (structured hex, no gmsh), the reflecting massed_fixed column, and scene checks.
//! References and tolerances are stated per test.

use super::common::{scene, scratch};
use jointquake::dynamics::record::Record;
use jointquake::mesh::structured::{box_mesh, BoxSpec};
use jointquake::motion::column::{free_field, incident_at_base, integrate_from_rest, low_pass, ColumnSpec};
use jointquake::motion::spectrum::{default_periods, response_spectrum};
use jointquake::problem::Problem;
use jointquake::simulation::Simulation;
use std::path::PathBuf;

/// The dam's rock (pipelines/dam.json): E 24.5 GPa, ν 0.25, ρ 2000 kg/m³.
const E_ROCK: f64 = 24.5e9;
const NU_ROCK: f64 = 0.25;
const RHO_ROCK: f64 = 2000.0;

fn shear_modulus() -> f64 {
    E_ROCK / (2.0 * (1.0 + NU_ROCK))
}

fn record_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("pipelines/records").join(name)
}

/// The first `n` samples of a committed record [m/s²] and its interval.
fn record(name: &str, n: usize) -> (Vec<f64>, f64) {
    let r = Record::read(&record_path(name), 9.81).unwrap();
    (r.accel[..n.min(r.accel.len())].to_vec(), r.dt)
}

fn peak(a: &[f64]) -> f64 {
    a.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// A lumped-mass shear column of `n` elements over the spec's height, its base loaded by the
/// Lysmer input 2ρc v_in with a dashpot ρc (central velocity), Rayleigh damping α M + β K with
/// the backward velocity as the explicit step uses; returns the surface acceleration at the
/// record's samples t = i dt_rec (i < samples). Independent of the code under test.
fn propagate_up(spec: &ColumnSpec, incident: &[f64], dt_rec: f64, samples: usize, n: usize, sub: usize) -> Vec<f64> {
    let dz = spec.height / n as f64;
    let dt = dt_rec / sub as f64;
    let c = spec.speed();
    assert!(c * dt / dz < 0.9, "Courant");
    let m: Vec<f64> = (0..=n).map(|j| if j == 0 || j == n { 0.5 } else { 1.0 } * spec.rho * dz).collect();
    let k = spec.modulus / dz;
    let cb = spec.rho * c;
    // v_in exact for the piecewise linear incident acceleration
    let v_nodes = integrate_from_rest(incident, dt_rec);
    let v_in = |t: f64| -> f64 {
        let s = t / dt_rec;
        if s < 0.0 || s >= (incident.len() - 1) as f64 {
            return 0.0;
        }
        let i = s.floor() as usize;
        let tau = t - i as f64 * dt_rec;
        v_nodes[i] + incident[i] * tau + (incident[i + 1] - incident[i]) * tau * tau / (2.0 * dt_rec)
    };
    let ku = |u: &[f64], j: usize| -> f64 {
        let mut f = 0.0;
        if j > 0 {
            f += k * (u[j] - u[j - 1]);
        }
        if j < n {
            f += k * (u[j] - u[j + 1]);
        }
        f
    };
    let (mut um, mut u, mut up) = (vec![0.0; n + 1], vec![0.0; n + 1], vec![0.0; n + 1]);
    let mut out = Vec::with_capacity(samples);
    let steps = samples * sub + 1;
    for s in 0..steps {
        let t = s as f64 * dt;
        for j in 0..=n {
            let vb = (u[j] - um[j]) / dt;
            let mut f = -ku(&u, j) - spec.beta * (ku(&u, j) - ku(&um, j)) / dt - spec.alpha * m[j] * vb;
            if j == 0 {
                f += 2.0 * cb * v_in(t);
            }
            let a = m[j] / (dt * dt);
            up[j] = if j == 0 {
                // (m/dt² + c/2dt) u+ = m (2u − u−)/dt² + f + c u−/2dt
                (a * (2.0 * u[j] - um[j]) + f + cb * um[j] / (2.0 * dt)) / (a + cb / (2.0 * dt))
            } else {
                2.0 * u[j] - um[j] + f / a
            };
        }
        if s % sub == 0 && out.len() < samples {
            out.push((up[n] - 2.0 * u[n] + um[n]) / (dt * dt));
        }
        std::mem::swap(&mut um, &mut u);
        std::mem::swap(&mut u, &mut up);
    }
    out
}

/// Largest |a − b| over the common samples, as a fraction of peak |b|.
fn misfit(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    (0..n).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max) / peak(&b[..n])
}

/// Largest relative difference of the 5 % response spectra over the default periods.
fn spectrum_misfit(a: &[f64], b: &[f64], dt: f64) -> f64 {
    let p = default_periods();
    let sa = response_spectrum(a, dt, &p, 0.05);
    let sb = response_spectrum(b, dt, &p, 0.05);
    sa.iter().zip(&sb).map(|(x, y)| (x - y).abs() / y).fold(0.0, f64::max)
}

/// `a` sampled `k` times per interval, linear between samples (the records' convention,
/// as the free field samples them: `problem::foundation::free_field::SUBSAMPLES`).
fn upsample(a: &[f64], k: usize) -> Vec<f64> {
    let mut out = Vec::with_capacity(a.len() * k);
    for i in 0..a.len() - 1 {
        for j in 0..k {
            let f = j as f64 / k as f64;
            out.push(a[i] * (1.0 - f) + a[i + 1] * f);
        }
    }
    out.push(a[a.len() - 1]);
    out
}

fn column_check(spec: ColumnSpec, elements: usize, sub: usize) -> (f64, f64) {
    let (surface, dt) = record("dam_dl5073_arch_I_s1_h1.txt", 2001);
    let fine = upsample(&surface, 4);
    let dtf = dt / 4.0;
    let (incident, delay) = incident_at_base(&spec, &fine, dtf);
    let lag = (delay / dtf).round() as usize;
    let out = propagate_up(&spec, &incident, dtf, lag + fine.len(), elements, sub);
    let got: Vec<f64> = out[lag..].iter().step_by(4).copied().collect();
    let want: Vec<f64> = low_pass(&spec, &fine, dtf).into_iter().step_by(4).collect();
    (misfit(&got, &want), spectrum_misfit(&got, &want, dt))
}

/// Reference: the surface record (DL 5073 arch, site I, 20 s at 100 Hz, low-passed at 25 Hz as
/// the free field is) deconvolved to
/// the base of a 400 m column of the dam's rock (c_s 2214 m/s), then propagated up by an
/// independent lumped-mass shear column (800 elements of 0.5 m, Courant 0.85: 88 per
/// wavelength at 50 Hz, the record's Nyquist frequency, which carries 5 % of its energy) with
/// the Lysmer input 2ρc v_in at its base, must give the record back: within 2 % of its peak at
/// every sample and its 5 % spectrum within 3 % at every period (issue 29's tolerances). The
/// misfit is the column's dispersion (measured 6.9 / 4.4 / 1.9 % with 200 / 400 / 800
/// elements), not the deconvolution's.
#[test]
fn column_deconvolution_then_propagation_gives_the_surface_record_back() {
    let spec = ColumnSpec { height: 400.0, rho: RHO_ROCK, modulus: shear_modulus(), alpha: 0.0, beta: 0.0, f_max: 25.0 };
    let (peak_err, spec_err) = column_check(spec, 800, 13);
    eprintln!("undamped column: peak misfit {:.3} %, spectrum misfit {:.3} %", 100.0 * peak_err, 100.0 * spec_err);
    assert!(peak_err < 0.02, "time misfit {peak_err}");
    assert!(spec_err < 0.03, "spectrum misfit {spec_err}");
}

/// The same with Rayleigh damping in the column, 2 % at 1.5 and 10 Hz (a rock's: α 0.33 1/s,
/// β 5.5e-4 s; 800 elements, the step 1.7e-5 s that the explicit β term needs): the
/// deconvolution undoes the damping the propagation applies. Same tolerances (2 % of peak, 3 %
/// of the spectrum). The misfit grows with the damping because the Lysmer dashpot ρc and the
/// input 2ρc v_in are the impedance of the undamped rock: measured 3.1 % of peak (spectrum
/// 6.8 %) with the dam scene's 5 % Rayleigh damping.
#[test]
fn damped_column_deconvolution_is_undone_by_damped_propagation() {
    let (w1, w2) = (2.0 * std::f64::consts::PI * 1.5, 2.0 * std::f64::consts::PI * 10.0);
    let (alpha, beta) = (2.0 * 0.02 * w1 * w2 / (w1 + w2), 2.0 * 0.02 / (w1 + w2));
    let spec = ColumnSpec { height: 400.0, rho: RHO_ROCK, modulus: shear_modulus(), alpha, beta, f_max: 25.0 };
    let (peak_err, spec_err) = column_check(spec, 800, 150);
    eprintln!("damped column: peak misfit {:.3} %, spectrum misfit {:.3} %", 100.0 * peak_err, 100.0 * spec_err);
    assert!(peak_err < 0.02, "time misfit {peak_err}");
    assert!(spec_err < 0.03, "spectrum misfit {spec_err}");
}

/// The free field at depth 0 is the surface record, delayed (the transform's padding does not
/// wrap): exact to round-off (1e-9 of the peak). At the base of an undamped column the
/// incident half of the field is half the surface motion shifted by the travel time H/c
/// (|U_in| = |U_s|/2): with a travel time of whole samples its peak is half the record's
/// within 1 %.
#[test]
fn free_field_at_the_surface_is_the_record_and_the_incident_wave_is_half() {
    let (surface, dt) = record("dam_dl5073_arch_I_s1_h1.txt", 800);
    // a travel time of 14 whole samples: the incident wave is the record itself, halved
    let spec = ColumnSpec { height: 14.0 * dt * (shear_modulus() / RHO_ROCK).sqrt(), rho: RHO_ROCK, modulus: shear_modulus(), alpha: 0.0, beta: 0.0, f_max: 1e6 };
    let f = free_field(&spec, &surface, dt, 10);
    let lag = (f.delay / dt).round() as usize;
    let top = &f.surface_accel()[lag..lag + surface.len()];
    assert!(misfit(top, &surface) < 1e-9, "surface misfit {}", misfit(top, &surface));
    let (inc, _) = incident_at_base(&spec, &surface, dt);
    let ratio = peak(&inc) / peak(&surface);
    eprintln!("incident peak / surface peak {ratio}");
    assert!((ratio - 0.5).abs() < 0.01, "incident peak / surface peak = {ratio}");
}

/// A rock box of the dam's rock with structured hexes (groups `block:rock`, `rock:x0` …).
fn rock_box(size: [f64; 3], div: [usize; 3]) -> jointquake::mesh::Mesh {
    box_mesh(&BoxSpec::new("rock", size, div).at([-0.5 * size[0], -0.5 * size[1], 0.0]))
}

fn rock_material() -> serde_json::Value {
    serde_json::json!({"group": "block:rock", "E": E_ROCK, "nu": NU_ROCK, "rho": RHO_ROCK})
}

const SIDES_AND_BOTTOM: [&str; 5] = ["rock:x0", "rock:x1", "rock:y0", "rock:y1", "rock:z0"];

/// The radiating rock box's scene over `duration` [s]: the rock alone, the three components of
/// the DL 5073 arch record (site I) as the surface free field, dashpots and free-field forces
/// on the bottom and four sides, no frames written.
fn radiating_box_scene(duration: f64) -> jointquake::scene::Scene {
    let rec = |f: &str| record_path(f).to_string_lossy().to_string();
    scene(serde_json::json!({
        "geometry": {"msh": "box.msh"},
        "materials": [rock_material()],
        "loads": {"base": [
            {"record": rec("dam_dl5073_arch_I_s1_h1.txt"), "direction": [1, 0, 0]},
            {"record": rec("dam_dl5073_arch_I_s1_h2.txt"), "direction": [0, 1, 0]},
            {"record": rec("dam_dl5073_arch_I_s1_v.txt"), "direction": [0, 0, 1]}
        ]},
        "time": {"duration": duration},
        "output": {"frames": false},
        "foundation": {"model": "radiating", "rock": ["block:rock"], "far": SIDES_AND_BOTTOM}
    }))
}

/// Reference: a box 10 × 10 × 200 m (2.5 m hexes, 35 per S wavelength at 25 Hz) of the dam's rock
/// on the radiating boundary (dashpots and free-field forces on the bottom and four sides),
/// under the three components of the DL 5073 arch record taken as the surface free field, is
/// the 1-D column itself: every top-surface node's acceleration equals the free field's surface
/// motion (the record low-passed at 25 Hz, delayed by the travel time) within 5 % of its peak,
/// per component, over 6 s: issue 29's tolerance. Its velocity within 1 % of the free field's
/// surface velocity peak.
///
/// The bug this guards (issue 29, "What is left"): with the free field sampled 4 times per
/// record interval the acceleration misfit was 7.7 / 7.6 / 7.5 % (velocity 0.04 / 0.06 / 0.6 %):
/// the boundary forces, linear in time between samples, kink at every sample and ring the box's
/// highest modes. Measured 3.1 / 3.0 / 2.8 % at 8 samples (the default now,
/// `free_field::SUBSAMPLES`) and 0.56 / 0.55 / 0.92 % at 16; 10 × finer depth levels left the
/// 7.7 % unchanged. So the test also checks the cause: sampled twice finer again, the misfit
/// falls by more than half.
#[test]
fn radiating_box_top_moves_with_the_free_field_record_within_5_percent() {
    let m = radiating_box_top_misfits(2.5);
    for c in 0..3 {
        assert!(m.accel[c] < 0.05, "component {c}: acceleration misfit {:.4} of peak", m.accel[c]);
        assert!(m.vel[c] < 0.01, "component {c}: velocity misfit {:.4} of peak", m.vel[c]);
    }
    let fine = radiating_box_top_misfits_with(2.5, 2);
    for c in 0..3 {
        assert!(fine.accel[c] < 0.5 * m.accel[c], "component {c}: the free field's time sampling should set the misfit: {:.4} at twice the samples against {:.4}", fine.accel[c], m.accel[c]);
    }
}

/// The top-surface misfits of the radiating box with hexes of `h` [m] (the largest over the top
/// nodes and the run), as fractions of the free field's surface peak, per component:
/// acceleration (`accel`) and velocity (`vel`).
struct TopMisfits {
    accel: [f64; 3],
    vel: [f64; 3],
}

fn radiating_box_top_misfits(h: f64) -> TopMisfits {
    radiating_box_top_misfits_with(h, 1)
}

/// [`radiating_box_top_misfits`] with the free field sampled `time_factor` times finer in time
/// (`FreeField::refined`, the same depth levels).
fn radiating_box_top_misfits_with(h: f64, time_factor: usize) -> TopMisfits {
    let sc = radiating_box_scene(6.0);
    let n = (10.0 / h).round() as usize;
    let mut p = Problem::build(sc, rock_box([10.0, 10.0, 200.0], [n, n, 20 * n])).unwrap();
    if time_factor > 1 {
        let nodes = p.model.mesh.nodes.clone();
        let far = p.far_boundary.as_mut().expect("radiating");
        far.free_field = far.free_field.refined(time_factor, far.free_field.levels());
        far.depth = far.nodes.iter().map(|&k| far.free_field.depth_weight(nodes[k][2])).collect();
    }
    let far = p.far_boundary.as_ref().expect("radiating");
    let ff = &far.free_field;
    let top: Vec<usize> = (0..p.model.n_nodes()).filter(|&n| p.model.mesh.nodes[n][2] > 199.9).collect();
    let surface = ff.depth_weight(200.0);
    let mut sim = Simulation::new(&p).unwrap();
    let steps = ((6.0 + ff.delay) / sim.dt()) as usize;
    let (mut ea, mut ev, mut pa, mut pv) = ([0.0f64; 3], [0.0f64; 3], [0.0f64; 3], [0.0f64; 3]);
    let mut at = [(0.0, 0.0, 0.0); 3];
    for _ in 0..steps {
        sim.step().unwrap();
        let k = sim.kinematics();
        let v_ff = ff.at(surface, k.t).vel;
        for c in 0..3 {
            let a_ff = ff.surface_accel_at(c, k.t);
            pa[c] = pa[c].max(a_ff.abs());
            pv[c] = pv[c].max(v_ff[c].abs());
            for &n in &top {
                let e = (k.acceleration(3 * n + c) - a_ff).abs();
                if e > ea[c] {
                    ea[c] = e;
                    at[c] = (k.t, a_ff, k.acceleration(3 * n + c));
                }
                ev[c] = ev[c].max((k.velocity(3 * n + c) - v_ff[c]).abs());
            }
        }
    }
    for c in 0..3 {
        eprintln!(
            "h {h} m, time x{time_factor}, {} levels, component {c}: top misfit {:.2} % of peak accel {:.3} m/s² (at {:?}, delay {}); velocity {:.2} % of peak {:.4} m/s",
            ff.levels(), 100.0 * ea[c] / pa[c], pa[c], at[c], ff.delay, 100.0 * ev[c] / pv[c], pv[c]
        );
    }
    TopMisfits { accel: std::array::from_fn(|c| ea[c] / pa[c]), vel: std::array::from_fn(|c| ev[c] / pv[c]) }
}

/// Regression (issue 29, the last `make dam`): the radiating runs reported total
/// displacements, so their peak |u| held the record's own ground displacement (the DL 5073 set
/// at 3× drifts by up to 2.1 m by 6 s) while the massless runs reported motion relative to the
/// base: 3.33 m radiating against 1.58 m massless at the crest. Every reported displacement is
/// now relative to the free field (`problem::foundation::free_field::Frame`). Reference: the
/// radiating box moves with the free field (its top within 1 % of the free field's velocity
/// peak, the test above), so the recorder's peak |u| relative to it is a small fraction of the
/// free field's own peak displacement: below 5 % of it (it was 100 %: the free field itself).
#[test]
fn radiating_peak_displacement_is_relative_to_the_free_field_not_the_record_drift() {
    let sc = radiating_box_scene(3.0);
    let p = Problem::build(sc, rock_box([10.0, 10.0, 200.0], [2, 2, 40])).unwrap();
    let far = p.far_boundary.as_ref().expect("radiating");
    let mut sim = Simulation::new(&p).unwrap();
    let out = scratch("foundation/radiating_peak_reference");
    let mut rec = jointquake::output::recorder::Recorder::create(&sim, &out, false).unwrap();
    sim.run(&mut rec).unwrap();
    // the free field's largest |u| over the nodes' depths and the run
    let ff = &far.free_field;
    let mut ff_peak = 0.0f64;
    for z in [0.0, 100.0, 200.0] {
        let dw = ff.depth_weight(z);
        for k in 0..=3000 {
            let d = ff.at(dw, k as f64 * 1e-3).disp;
            ff_peak = ff_peak.max((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt());
        }
    }
    let peak = rec.peaks.displacement.value;
    eprintln!("radiating box: peak |u| relative to the free field {peak:.4e} m, the free field's peak {ff_peak:.4e} m");
    assert!(ff_peak > 0.05, "the record should move the ground by centimetres: {ff_peak}");
    assert!(peak < 0.05 * ff_peak, "peak |u| {peak} m should be relative to the free field (its peak {ff_peak} m)");
}

/// ½ vᵀ M v + ½ uᵀ K u of the run's state at t[n] [J].
fn energy(sim: &Simulation<'_>, ku: &mut Vec<f64>) -> f64 {
    let m = &sim.problem.model;
    let k = sim.kinematics();
    ku.resize(k.u.len(), 0.0);
    m.internal_forces_into(k.u, ku);
    (0..k.u.len()).map(|i| 0.5 * m.mass.inertial[i / 3] * k.velocity(i).powi(2) + 0.5 * k.u[i] * ku[i]).sum()
}

/// Reference: a Gaussian displacement bump (σ 12 m, x direction) released at rest at the
/// centre of a 200 m cube of rock with dashpots on all six faces sends P and S waves out; the
/// slowest (S, 2214 m/s) has passed the farthest corner (173 m) after 0.08 s. What is left in
/// the box at 0.25 s (three corner travel times) is what the boundary reflected: less than 5 %
/// of the bump's energy (issue 29). Lysmer dashpots are exact at normal incidence and reflect
/// a few per cent at oblique incidence (Lysmer & Kuhlemeyer 1969, figure 3).
#[test]
fn radiating_box_lets_a_pulse_from_inside_leave() {
    let faces = ["rock:x0", "rock:x1", "rock:y0", "rock:y1", "rock:z0", "rock:z1"];
    let sc = scene(serde_json::json!({
        "geometry": {"msh": "box.msh"},
        "materials": [rock_material()],
        "time": {"duration": 0.3},
        "foundation": {"model": "radiating", "rock": ["block:rock"], "far": faces}
    }));
    let p = Problem::build(sc, rock_box([200.0, 200.0, 200.0], [20, 20, 20])).unwrap();
    let mut sim = Simulation::new(&p).unwrap();
    let s2 = 2.0 * 12.0f64.powi(2);
    for (n, x) in p.model.mesh.nodes.iter().enumerate() {
        let r2 = x[0] * x[0] + x[1] * x[1] + (x[2] - 100.0).powi(2);
        sim.state.u[3 * n] = 1e-3 * (-r2 / s2).exp();
    }
    sim.state.u_prev.copy_from_slice(&sim.state.u);
    sim.solver.start_energy(&p.model, &mut sim.state);
    let e0 = sim.state.energy.strain;
    let mut ku = Vec::new();
    let mut left = 0.0;
    while sim.state.t < 0.25 {
        sim.step().unwrap();
        left = energy(&sim, &mut ku);
    }
    eprintln!("pulse: energy left at 0.25 s {:.3} % of {e0:.4e} J", 100.0 * left / e0);
    assert!(left < 0.05 * e0, "energy left {left} of {e0}");
}

/// Reference: statics. The box under its own weight, its far faces held through gravity
/// relaxation (their `boundary` entries) and then released onto dashpots carrying their static
/// reactions, stays in its static state: after 1 s with no record no node has moved by more
/// than 1e-6 of the largest static displacement (the relaxation's residual is 1e-9).
#[test]
fn radiating_box_at_rest_under_gravity_holds_its_static_state() {
    let bc: Vec<serde_json::Value> = SIDES_AND_BOTTOM.iter().map(|g| serde_json::json!({"group": g})).collect();
    let sc = scene(serde_json::json!({
        "geometry": {"msh": "box.msh"},
        "materials": [rock_material()],
        "boundary": bc,
        "loads": {"gravity": {"g": 9.81}},
        "equilibrium": {"tolerance": 1e-9, "max_steps": 400000},
        "time": {"duration": 1.0},
        "foundation": {"model": "radiating", "rock": ["block:rock"], "far": SIDES_AND_BOTTOM, "rock_weight": true}
    }));
    let p = Problem::build(sc, rock_box([60.0, 60.0, 200.0], [6, 6, 20])).unwrap();
    let mut sim = Simulation::new(&p).unwrap();
    sim.equilibrate().unwrap();
    let u0 = sim.state.u.clone();
    let scale = peak(&u0);
    assert!(scale > 1e-4, "the box settles under its weight: {scale}");
    let steps = (1.0 / sim.dt()) as usize;
    let mut moved = 0.0f64;
    for _ in 0..steps {
        sim.step().unwrap();
        moved = moved.max(sim.state.u.iter().zip(&u0).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max));
    }
    eprintln!("at rest: largest motion {:.3e} of static {scale:.3e}", moved / scale);
    assert!(moved < 1e-6 * scale, "moved {moved} of {scale}");
}

/// Reference: 1-D wave theory. A shear column 200 m high (2 m hexes, uy, uz held) of the dam's
/// rock, massed and fixed at its base (massed_fixed), driven by a base velocity pulse
/// V sin²(πt/T) (V 0.1 m/s, T 0.05 s): the pulse rises, reflects at the free top and comes
/// back down, and the rigid base reflects it again, doubling the stress there: the base
/// shear stress peaks at 2 ρ c_s V (886 kPa) when it returns (t ≈ 2H/c_s), within 2 %.
#[test]
fn massed_fixed_column_doubles_the_returning_wave_at_its_fixed_base() {
    let dir = scratch("foundation_massed_fixed_pulse");
    let (v, t_p, dt_rec) = (0.1, 0.05, 0.0005);
    let mut text = String::new();
    for i in 0..=400 {
        let t = i as f64 * dt_rec;
        let a = if t <= t_p { v * std::f64::consts::PI / t_p * (2.0 * std::f64::consts::PI * t / t_p).sin() } else { 0.0 };
        text.push_str(&format!("{t} {}\n", a / 9.81));
    }
    let path = dir.join("pulse.txt");
    std::fs::write(&path, text).unwrap();
    let sides: Vec<serde_json::Value> = ["rock:x0", "rock:x1", "rock:y0", "rock:y1"].iter().map(|g| serde_json::json!({"group": g, "fix": ["y", "z"]})).collect();
    let mut bc = vec![serde_json::json!({"group": "rock:z0"})];
    bc.extend(sides);
    let mut mat = rock_material();
    mat["massless"] = serde_json::json!(true);
    let sc = scene(serde_json::json!({
        "geometry": {"msh": "col.msh"},
        "materials": [mat],
        "boundary": bc,
        "loads": {"base": [{"record": path.to_string_lossy(), "direction": [1, 0, 0]}]},
        "time": {"duration": 0.3},
        "foundation": {"model": "massed_fixed"}
    }));
    let p = Problem::build(sc, rock_box([2.0, 2.0, 200.0], [1, 1, 100])).unwrap_or_else(|e| panic!("{e}"));
    assert!(p.model.mass.inertial.iter().all(|&m| m > 0.0), "the rock is massed");
    let base: Vec<usize> = (0..p.model.n_nodes()).filter(|&n| p.model.mesh.nodes[n][2] < 1e-9).collect();
    let mut sim = Simulation::new(&p).unwrap();
    let cs = (shear_modulus() / RHO_ROCK).sqrt();
    let (mut first, mut second) = (0.0f64, 0.0f64);
    while sim.state.t < 0.3 {
        sim.step().unwrap();
        let t = sim.kinematics().t;
        let f = sim.solver.internal_force();
        let shear = base.iter().map(|&n| f[3 * n]).sum::<f64>().abs() / 4.0;
        if t < t_p {
            first = first.max(shear);
        } else if t > 2.0 * 200.0 / cs - t_p {
            second = second.max(shear);
        }
    }
    let incident = RHO_ROCK * cs * v;
    eprintln!("massed_fixed: first base stress {:.1} kPa, returning {:.1} kPa, 2ρcV {:.1} kPa", first / 1e3, second / 1e3, 2.0 * incident / 1e3);
    assert!((second / (2.0 * incident) - 1.0).abs() < 0.02, "returning {second}, expected {}", 2.0 * incident);
}

/// The top's x amplitude of a shear column 200 m high (2 × 2 m section, 4 m hexes, uy, uz
/// held, base fixed) of the dam's rock, massed_fixed with rock damping `rock_damping`, beside a
/// free "dam" block (the scene's `damping.mass_groups`: α = 2 1/s, β = 0), released from the
/// static shape of a uniform x load: (first period's peak, peak of the period from 1 s on and
/// its time [s]).
fn damped_column_amplitudes(rock_damping: &str) -> (f64, f64, f64) {
    let sides: Vec<serde_json::Value> = ["rock:x0", "rock:x1", "rock:y0", "rock:y1"].iter().map(|g| serde_json::json!({"group": g, "fix": ["y", "z"]})).collect();
    let mut bc = vec![serde_json::json!({"group": "rock:z0"})];
    bc.extend(sides);
    let mut rock = rock_material();
    rock["massless"] = serde_json::json!(true);
    let dam = serde_json::json!({"group": "block:dam", "E": 24e9, "nu": 0.17, "rho": 2400.0});
    let sc = scene(serde_json::json!({
        "geometry": {"msh": "col.msh"},
        "materials": [rock, dam],
        "boundary": bc,
        "damping": {"alpha": 2.0, "beta": 0.0, "mass_groups": ["block:dam"]},
        "time": {"duration": 1.5},
        "foundation": {"model": "massed_fixed", "damping": rock_damping}
    }));
    let mut mesh = rock_box([2.0, 2.0, 200.0], [1, 1, 50]);
    jointquake::mesh::structured::add_box(&mut mesh, &BoxSpec::new("dam", [2.0, 2.0, 2.0], [1, 1, 1]).at([100.0, 0.0, 0.0]));
    let p = Problem::build(sc, mesh).unwrap_or_else(|e| panic!("{e}"));
    let mut sim = Simulation::new(&p).unwrap();
    let top: Vec<usize> = (0..p.model.n_nodes()).filter(|&n| p.model.mesh.nodes[n][2] > 199.9 && p.model.mesh.nodes[n][0] < 50.0).collect();
    for (n, x) in p.model.mesh.nodes.iter().enumerate() {
        if x[0] < 50.0 {
            let z = x[2] / 200.0;
            sim.state.u[3 * n] = 1e-3 * z * (2.0 - z);
        }
    }
    sim.state.u_prev.copy_from_slice(&sim.state.u);
    sim.solver.start_energy(&p.model, &mut sim.state);
    let period = 4.0 * 200.0 / (shear_modulus() / RHO_ROCK).sqrt();
    let (mut first, mut later, mut t_later) = (0.0f64, 0.0f64, 0.0);
    while sim.state.t < 1.0 + period {
        sim.step().unwrap();
        let k = sim.kinematics();
        let u = top.iter().map(|&n| k.u[3 * n]).sum::<f64>() / top.len() as f64;
        if k.t < period {
            first = first.max(u.abs());
        } else if k.t >= 1.0 && u.abs() > later {
            (later, t_later) = (u.abs(), k.t);
        }
    }
    (first, later, t_later)
}

/// Reference: Rayleigh's mass term damps every mode's amplitude as e^{−αt/2} (ξω = α/2 in
/// each mode), so with the rock damped as the dam (`foundation.damping` "as_dam", the default:
/// the rock's groups join `damping.mass_groups`, α = 2 1/s) the column's top peaks in the
/// period after 1 s (at t) with e^{−t} of its first amplitude (e^{−1} = 0.37 to e^{−1.36}),
/// within 5 %; with "stiffness_only" (β = 0 here:
/// no rock damping, the state before this option) within 2 % of its first amplitude. The bug
/// this guards: the massed rock was left out of αM (the dam scenes name only the monoliths), so
/// the dam study's closed rock box (massed_fixed) rang undamped at 3× and its crest reached
/// 8.2 m (docs/dam_physics.md §4).
#[test]
fn massed_rock_is_damped_as_the_dam_by_default_not_left_out_of_alpha_m() {
    let (a0, a1, t) = damped_column_amplitudes("as_dam");
    let expected = (-t).exp();
    eprintln!("as_dam: top amplitude {a0:.4e} then {a1:.4e} m at {t:.4} s, ratio {:.4} (e^-t = {expected:.4})", a1 / a0);
    assert!((a1 / a0 / expected - 1.0).abs() < 0.05, "ratio {} against {expected}", a1 / a0);
    let (b0, b1, _) = damped_column_amplitudes("stiffness_only");
    eprintln!("stiffness_only: top amplitude {b0:.4e} then {b1:.4e} m");
    assert!((b1 / b0 - 1.0).abs() < 0.02, "undamped rock: ratio {}", b1 / b0);
}

/// The free decay of one column's top (x displacement averaged over its top nodes): its
/// positive peaks (time, amplitude).
#[derive(Default)]
struct Decay {
    peaks: Vec<(f64, f64)>,
    last: [f64; 2],
}

impl Decay {
    /// Add the sample `u` at `t` (a peak is a sample above both neighbours, recorded one
    /// sample late).
    fn add(&mut self, t: f64, dt: f64, u: f64) {
        let [a, b] = self.last;
        if b > 0.0 && b > a && b >= u {
            self.peaks.push((t - dt, b));
        }
        self.last = [b, u];
    }

    /// (damping ratio ξ from the mean logarithmic decrement δ over the peaks, ξ = δ / √(4π² +
    /// δ²); frequency [Hz] from their spacing).
    fn ratio_and_frequency(&self) -> (f64, f64) {
        let (first, last) = (self.peaks[0], self.peaks[self.peaks.len() - 1]);
        let n = (self.peaks.len() - 1) as f64;
        let delta = (first.1 / last.1).ln() / n;
        (delta / (4.0 * std::f64::consts::PI.powi(2) + delta * delta).sqrt(), n / (last.0 - first.0))
    }
}

/// Rayleigh's ratio ξ(f) = α/(2ω) + βω/2 of the pair given by `ratio` at `f1`, `f2` [Hz]
/// (α = 2ξ ω1ω2/(ω1+ω2), β = 2ξ/(ω1+ω2), written here apart from the code's).
fn rayleigh_ratio(ratio: f64, f1: f64, f2: f64, f: f64) -> f64 {
    let w = |f: f64| 2.0 * std::f64::consts::PI * f;
    let (alpha, beta) = (2.0 * ratio * w(f1) * w(f2) / (w(f1) + w(f2)), 2.0 * ratio / (w(f1) + w(f2)));
    alpha / (2.0 * w(f)) + beta * w(f) / 2.0
}

/// Two shear columns apart, each 2 × 2 m in section (4 m hexes, uy, uz held, base fixed): the
/// rock (block:rock, the dam's rock, 200 m, massed_fixed with `foundation.damping` =
/// `rock_damping`) and a "dam" column (block:dam, E 24 GPa, ν 0.17, ρ 2400 kg/m³, 100 m, the
/// scene's `damping` = `scene_damping`), both released at rest from their first mode's shape
/// sin(πz/2H) (1 mm at the top), run for `duration` [s]. Returns the problem's stable step, the
/// decays (rock, dam), the run's largest relative energy-balance error and the final u.
fn two_column_decay(scene_damping: serde_json::Value, rock_damping: serde_json::Value, duration: f64) -> (f64, [Decay; 2], f64, Vec<f64>) {
    let held = |p: &str| -> Vec<serde_json::Value> { ["x0", "x1", "y0", "y1"].iter().map(|s| serde_json::json!({"group": format!("{p}:{s}"), "fix": ["y", "z"]})).collect() };
    let mut bc = vec![serde_json::json!({"group": "rock:z0"}), serde_json::json!({"group": "dam:z0"})];
    bc.extend(held("rock"));
    bc.extend(held("dam"));
    let mut rock = rock_material();
    rock["massless"] = serde_json::json!(true);
    let dam = serde_json::json!({"group": "block:dam", "E": 24e9, "nu": 0.17, "rho": 2400.0});
    let sc = scene(serde_json::json!({
        "geometry": {"msh": "cols.msh"},
        "materials": [rock, dam],
        "boundary": bc,
        "damping": scene_damping,
        "time": {"duration": duration},
        "foundation": {"model": "massed_fixed", "damping": rock_damping}
    }));
    sc.validate().unwrap_or_else(|e| panic!("{e}"));
    let mut mesh = rock_box([2.0, 2.0, 200.0], [1, 1, 50]);
    jointquake::mesh::structured::add_box(&mut mesh, &BoxSpec::new("dam", [2.0, 2.0, 100.0], [1, 1, 25]).at([100.0, 0.0, 0.0]));
    let p = Problem::build(sc, mesh).unwrap_or_else(|e| panic!("{e}"));
    let mut sim = Simulation::new(&p).unwrap();
    let x = &p.model.mesh.nodes;
    let rock_col = |n: usize| x[n][0] < 50.0;
    let height = |n: usize| if rock_col(n) { 200.0 } else { 100.0 };
    let top: [Vec<usize>; 2] = [true, false].map(|r| (0..x.len()).filter(|&n| rock_col(n) == r && x[n][2] > height(n) - 0.1).collect());
    for n in 0..x.len() {
        sim.state.u[3 * n] = 1e-3 * (std::f64::consts::FRAC_PI_2 * x[n][2] / height(n)).sin();
    }
    sim.state.u_prev.copy_from_slice(&sim.state.u);
    sim.solver.start_energy(&p.model, &mut sim.state);
    let mut decay = [Decay::default(), Decay::default()];
    while sim.state.t < duration {
        sim.step().unwrap();
        let k = sim.kinematics();
        for c in 0..2 {
            decay[c].add(k.t, k.dt, top[c].iter().map(|&n| k.u[3 * n]).sum::<f64>() / top[c].len() as f64);
        }
    }
    (p.model.stable_dt(), decay, sim.state.energy.max_error, sim.state.u.clone())
}

/// Reference: the free decay of a mode of a Rayleigh-damped structure has the ratio ξ(f) =
/// α/(2ω) + βω/2 at its frequency (Chopra, Dynamics of Structures, §11.4). The rock column with
/// its own pair, 2 % at 2.77 and 13.8 Hz (its first mode c_s/4H and its third), decays at
/// ξ(f_rock) within 5 % of it, while the dam column beside it keeps the scene's pair (5 % at 2
/// and 20 Hz, β 7.2e-4 s against the rock's 3.8e-4 s: the step forms βK per pair) and decays at
/// that pair's ξ(f_dam) within 5 %. Each is measured from the logarithmic decrement of its
/// top's peaks over 2 s (5 rock periods, 10 dam ones), the frequency from their spacing. The
/// energy balance of the run holds within 1e-3 of its scale (the βK work of both pairs
/// accounted), and the stable step is the one of the pair whose stiffest element has the
/// smaller damped step (`model::damped_step`, hex ω² from `hex8::max_eigenvalue`).
#[test]
fn rock_with_its_own_rayleigh_pair_decays_at_its_ratio_and_the_dam_at_its_own() {
    let (fr, fd) = (2214.0 / 800.0, 2067.0 / 400.0);
    let (dt, decay, energy_error, _) = two_column_decay(
        serde_json::json!({"ratio": 0.05, "f1": 2.0, "f2": 20.0, "mass_groups": ["block:dam"]}),
        serde_json::json!({"ratio": 0.02, "f1": fr, "f2": 5.0 * fr}),
        2.0,
    );
    let (xi_r, f_r) = decay[0].ratio_and_frequency();
    let (xi_d, f_d) = decay[1].ratio_and_frequency();
    let (want_r, want_d) = (rayleigh_ratio(0.02, fr, 5.0 * fr, f_r), rayleigh_ratio(0.05, 2.0, 20.0, f_d));
    eprintln!("rock: f {f_r:.4} Hz ({fr:.4} analytic), ξ {:.4} % (Rayleigh {:.4} %); dam: f {f_d:.4} Hz ({fd:.4}), ξ {:.4} % (Rayleigh {:.4} %); energy error {energy_error:.2e}; dt_stable {dt:.4e} s", 100.0 * xi_r, 100.0 * want_r, 100.0 * xi_d, 100.0 * want_d);
    assert!((f_r / fr - 1.0).abs() < 0.01 && (f_d / fd - 1.0).abs() < 0.01, "first modes {f_r}, {f_d} Hz");
    assert!((xi_r / want_r - 1.0).abs() < 0.05, "rock ξ {xi_r} against its pair's {want_r}");
    assert!((xi_d / want_d - 1.0).abs() < 0.05, "dam ξ {xi_d} against the scene's {want_d}");
    assert!(energy_error.abs() < 1e-3, "energy balance {energy_error}");
    // the stable step: each column's stiffest element with its own pair
    let lame = |e: f64, nu: f64| jointquake::model::material::Material::new("m", e, nu, 1.0).lame;
    let step = |size: [f64; 3], rho: f64, e: f64, nu: f64, alpha: f64, beta: f64| {
        let h = [[0.0, 0.0, 0.0], [size[0], 0.0, 0.0], [size[0], size[1], 0.0], [0.0, size[1], 0.0], [0.0, 0.0, size[2]], [size[0], 0.0, size[2]], [size[0], size[1], size[2]], [0.0, size[1], size[2]]].map(nalgebra::Vector3::from);
        let shape = jointquake::model::hex8::hex_shape(&h, &lame(e, nu)).unwrap();
        jointquake::model::damped_step(jointquake::model::hex8::max_eigenvalue(&shape, rho, &lame(e, nu)), alpha, beta)
    };
    let w = |f: f64| 2.0 * std::f64::consts::PI * f;
    let pair = |xi: f64, f1: f64, f2: f64| (2.0 * xi * w(f1) * w(f2) / (w(f1) + w(f2)), 2.0 * xi / (w(f1) + w(f2)));
    let (ar, br) = pair(0.02, fr, 5.0 * fr);
    let (ad, bd) = pair(0.05, 2.0, 20.0);
    let want = step([2.0, 2.0, 4.0], RHO_ROCK, E_ROCK, NU_ROCK, ar, br).min(step([2.0, 2.0, 4.0], 2400.0, 24e9, 0.17, ad, bd));
    assert!((dt / want - 1.0).abs() < 1e-9, "stable step {dt} against {want}");
}

/// The rock's own pair equal to the scene's (α 1.2 1/s, β 2e-4 s given as `{"alpha", "beta"}`)
/// is "as_dam" exactly: the same αM on every node and one β, so the two runs' states agree bit
/// for bit (the "as_dam" path, the default, is the one every run took before the option).
#[test]
fn rock_pair_equal_to_the_scenes_is_as_dam_bit_for_bit() {
    let scene_pair = serde_json::json!({"alpha": 1.2, "beta": 2e-4, "mass_groups": ["block:dam"]});
    let (dt_a, _, _, as_dam) = two_column_decay(scene_pair.clone(), serde_json::json!("as_dam"), 0.3);
    let (dt_b, _, _, own) = two_column_decay(scene_pair, serde_json::json!({"alpha": 1.2, "beta": 2e-4}), 0.3);
    assert_eq!(dt_a.to_bits(), dt_b.to_bits());
    assert!(as_dam.iter().zip(&own).all(|(a, b)| a.to_bits() == b.to_bits()), "the states differ");
    assert!(as_dam.iter().any(|&u| u != 0.0));
}

/// Bad input of the rock's own pair: each error names the field and the fix.
#[test]
fn rock_pair_errors_name_the_field() {
    let with = |model: &str, damping: serde_json::Value| -> Result<jointquake::scene::Scene, String> {
        let v = serde_json::json!({
            "geometry": {"msh": "box.msh"},
            "materials": [rock_material()],
            "time": {"duration": 0.1},
            "foundation": {"model": model, "rock": ["block:rock"], "damping": damping}
        });
        let sc: jointquake::scene::Scene = serde_json::from_value(v).map_err(|e| e.to_string())?;
        sc.validate().map(|_| sc)
    };
    let cases = [
        ("massed_fixed", serde_json::json!({"ratio": -0.02, "f1": 1.0, "f2": 10.0}), vec!["foundation.damping", "ratio -0.02"]),
        ("massed_fixed", serde_json::json!({"ratio": 0.02, "f1": 10.0, "f2": 1.0}), vec!["foundation.damping", "f2 = 1 Hz must be above f1 = 10 Hz"]),
        ("massed_fixed", serde_json::json!({"ratio": 0.02, "f1": 2.0, "f2": 2.0}), vec!["foundation.damping", "f1", "f2"]),
        ("massed_fixed", serde_json::json!({"alpha": -1.0}), vec!["foundation.damping", "alpha = -1"]),
        ("massed_fixed", serde_json::json!({"ratio": 0.02, "f1": 1.0, "f2": 10.0, "mass_groups": ["block:rock"]}), vec!["foundation.damping.mass_groups", "leave mass_groups out"]),
        ("massless", serde_json::json!({"ratio": 0.02, "f1": 1.0, "f2": 10.0}), vec!["foundation.damping", "only with a massed rock", "massed_fixed"]),
        ("massed_fixed", serde_json::json!("rock_only"), vec!["as_dam", "stiffness_only", "ratio"]),
    ];
    for (model, damping, want) in cases {
        let e = with(model, damping.clone()).err().unwrap_or_else(|| panic!("{damping} accepted"));
        assert!(want.iter().all(|w| e.contains(w)), "{damping}: {e}");
    }
    assert!(with("massed_fixed", serde_json::json!({"ratio": 0.02, "f1": 1.0, "f2": 10.0})).is_ok());
    // the model refuses the pair on a rock still massless (a model built without Problem::build)
    let mut mat = rock_material();
    mat["massless"] = serde_json::json!(true);
    let dam = serde_json::json!({"group": "block:dam", "E": 24e9, "nu": 0.17, "rho": 2400.0});
    let sc = scene(serde_json::json!({
        "geometry": {"msh": "box.msh"},
        "materials": [mat, dam],
        "time": {"duration": 0.1},
        "foundation": {"model": "massed_fixed", "damping": {"alpha": 1.0}}
    }));
    let mut mesh = rock_box([20.0, 20.0, 20.0], [2, 2, 2]);
    jointquake::mesh::structured::add_box(&mut mesh, &BoxSpec::new("dam", [2.0, 2.0, 2.0], [1, 1, 1]).at([100.0, 0.0, 0.0]));
    let e = jointquake::model::Model::build(mesh, &sc).unwrap_err().to_string();
    assert!(e.contains("foundation.damping") && e.contains("massless") && e.contains("Problem::build"), "{e}");
}

/// Bad input: springs on a massless foundation, and a far pattern that matches no face group,
/// are errors naming the field.
#[test]
fn foundation_scene_errors_name_the_field() {
    let mut sc = scene(serde_json::json!({
        "geometry": {"msh": "box.msh"},
        "materials": [rock_material()],
        "time": {"duration": 0.1},
        "foundation": {"model": "massless", "springs": true}
    }));
    let e = sc.validate().unwrap_err();
    assert!(e.contains("foundation.springs"), "{e}");
    sc.foundation = Some(serde_json::from_value(serde_json::json!({"model": "radiating", "rock": ["block:rock"], "far": ["bc:far*"]})).unwrap());
    let e = Problem::build(sc, rock_box([20.0, 20.0, 20.0], [2, 2, 2])).unwrap_err().to_string();
    assert!(e.contains("foundation.far") && e.contains("bc:far*"), "{e}");
}

/// pipelines/dam_coarse_radiating.json on the committed coarse fixture: the radiating rock
/// builds (the far faces of `bc:far` found, their outward normals, the free field of the three
/// records), its stable step is the massed rock's or the dam's, and the far boundary covers
/// the rock's five far faces: total area within 1 % of the box's bottom plus four sides
/// (geometry; the box's extents from the rock's nodes).
#[test]
fn dam_coarse_radiating_builds_with_its_far_boundary() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("pipelines/dam_coarse_radiating.json");
    let mut s = jointquake::scene::Scene::load(&path).unwrap();
    let mesh = jointquake::mesh::Mesh::from_msh(super::common::fixture("arch_dam_coarse.msh")).unwrap();
    jointquake::pipeline::expand_patterns(&mut s, &mesh, &path).unwrap();
    let p = Problem::build(s, mesh).unwrap_or_else(|e| panic!("{e}"));
    let far = p.far_boundary.as_ref().expect("radiating");
    let rock = p.model.mesh.group_nodes("block:rock").unwrap();
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for &n in &rock {
        for c in 0..3 {
            lo[c] = lo[c].min(p.model.mesh.nodes[n][c]);
            hi[c] = hi[c].max(p.model.mesh.nodes[n][c]);
        }
    }
    let (lx, ly) = (hi[0] - lo[0], hi[1] - lo[1]);
    let bottom = lx * ly;
    for n in &p.notes {
        eprintln!("{n}");
    }
    eprintln!("far area {:.4e} m², bottom {:.4e} m², box {:?} … {:?}", far.area, bottom, lo, hi);
    assert!(far.area > bottom, "the far faces include the bottom");
    assert!(p.loads.base.is_empty(), "the records are the free field, not a base force");
    let sim = Simulation::new(&p).unwrap();
    eprintln!("dt {:.4e} s (stable {:.4e} s, element {} in {})", sim.dt(), sim.time.dt_stable, p.model.critical.tag, p.model.critical.group);
    assert!(sim.radiating.is_some());
}

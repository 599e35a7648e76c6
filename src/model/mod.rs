//! The model: built once from the mesh and the scene, never mutated during a run.
//!
//! Owns: materials per volume group, element data (tet4 geometry, shared hex8 shapes),
//! lumped nodal masses, fixed components, and the element colouring used for deterministic
//! parallel assembly. Inputs: [`Mesh`], scene materials and boundary conditions.
//! Outputs: `K u` ([`Model::internal_forces_into`]), element stresses, the stable step.
//!
//! Invariants:
//! - Degrees of freedom are `3 * node + component` (x, y, z), for every mesh node; nodes with
//!   no mass (not in any material volume) are inactive and treated as fixed.
//! - Elements are stored grouped by colour: no two elements of one colour share a node, so a
//!   colour is assembled in parallel without races, and the sum order at every node is the
//!   colour order whatever the number of threads (bit-identical results).
//! - Sign: `internal_forces_into` gives f_int = K u; the equation of motion is
//!   M ü + C u̇ + f_int = F_ext + R.

pub mod hex8;
pub mod material;
pub mod tet4;

use crate::error::{MeshError, ModelError};
use crate::mesh::{CellKind, Mesh};
use crate::scene::Scene;
use hex8::HexShape;
use material::{Lame, Material};
use nalgebra::Vector3;
use rayon::prelude::*;
use std::collections::HashMap;
use std::ops::Range;

/// Tetrahedra, stored by colour.
#[derive(Clone, Debug, Default)]
pub struct Tet4Set {
    pub nodes: Vec<[u32; 4]>,
    pub geom: Vec<tet4::TetGeom>,
    pub mat: Vec<u16>,
    /// Mesh cell index of each element.
    pub cell: Vec<u32>,
    pub colors: Vec<Range<usize>>,
}

/// Hexahedra, stored by colour; congruent elements share a [`HexShape`].
#[derive(Clone, Debug, Default)]
pub struct Hex8Set {
    pub nodes: Vec<[u32; 8]>,
    pub shape: Vec<u32>,
    pub mat: Vec<u16>,
    pub cell: Vec<u32>,
    pub colors: Vec<Range<usize>>,
    pub shapes: Vec<HexShape>,
}

/// The critical element of the stable-step estimate.
#[derive(Clone, Debug)]
pub struct CriticalElement {
    /// Gmsh element tag.
    pub tag: u64,
    pub group: String,
    /// Largest element eigenvalue ω² [1/s²].
    pub omega2: f64,
}

/// Everything that does not change during a run.
#[derive(Debug)]
pub struct Model {
    pub mesh: Mesh,
    pub materials: Vec<Material>,
    pub tets: Tet4Set,
    pub hexes: Hex8Set,
    /// Lumped mass per node [kg] (0 = inactive node).
    pub mass: Vec<f64>,
    /// Fixed components per node: bit 0 = x, 1 = y, 2 = z. Inactive nodes are fully fixed.
    pub fixed: Vec<u8>,
    /// Rayleigh damping C = αM + βK: α [1/s], β [s].
    pub alpha: f64,
    /// Per node: whether αM applies in the dynamic stage (scene `damping.mass_groups`; all
    /// nodes by default). Relaxation damping applies to every node regardless.
    pub mass_damped: Vec<bool>,
    pub beta: f64,
    pub critical: CriticalElement,
    /// Joints (tagged interfaces with their laws), in scene order.
    pub joints: Vec<crate::contact::joint::ContactJoint>,
}

/// Scatter target shared across threads. Safe use requires that no two concurrent writers touch
/// the same index: guaranteed by the colouring (see the module invariants).
#[derive(Clone, Copy)]
struct SharedMut(*mut f64);
unsafe impl Send for SharedMut {}
unsafe impl Sync for SharedMut {}

/// Elements per parallel task; below this many elements in a colour, run it on one thread.
const PAR_MIN: usize = 512;

fn color_order<const N: usize>(conn: &[[u32; N]], n_nodes: usize) -> Result<(Vec<usize>, Vec<Range<usize>>), ModelError> {
    let mut used = vec![0u128; n_nodes];
    let mut color = vec![0u8; conn.len()];
    let mut ncolors = 0;
    for (e, c) in conn.iter().enumerate() {
        let mask = c.iter().fold(0u128, |m, &n| m | used[n as usize]);
        let k = mask.trailing_ones();
        if k >= 128 {
            return Err(ModelError::Invalid(format!("element colouring needs more than 128 colours (element {e}): a node has too many elements")));
        }
        color[e] = k as u8;
        ncolors = ncolors.max(k as usize + 1);
        for &n in c {
            used[n as usize] |= 1u128 << k;
        }
    }
    let mut order: Vec<usize> = (0..conn.len()).collect();
    order.sort_by_key(|&e| (color[e], e));
    let mut ranges = Vec::with_capacity(ncolors);
    let mut start = 0;
    for k in 0..ncolors {
        let end = start + order[start..].iter().take_while(|&&e| color[e] as usize == k).count();
        ranges.push(start..end);
        start = end;
    }
    Ok((order, ranges))
}

fn permute<T: Clone>(v: &[T], order: &[usize]) -> Vec<T> {
    order.iter().map(|&i| v[i].clone()).collect()
}

impl Model {
    /// Build the model: materials, elements, masses, fixed components, stable-step data.
    pub fn build(mesh: Mesh, scene: &Scene) -> Result<Model, crate::Error> {
        let n = mesh.nodes.len();
        let mut materials = Vec::new();
        let mut owner: HashMap<usize, usize> = HashMap::new();
        for (mi, ms) in scene.materials.iter().enumerate() {
            if ms.rho == 0.0 {
                return Err(ModelError::Invalid(format!(
                    "material \"{}\": rho = 0 (massless foundation) needs static condensation, which this version does not provide; give the foundation a density",
                    ms.group
                ))
                .into());
            }
            let g = mesh.group_of_dim(&ms.group, 3)?;
            mesh.check_orientation(g)?;
            for &c in &g.cells {
                if let Some(&other) = owner.get(&c) {
                    return Err(ModelError::Invalid(format!(
                        "element {} is in two material groups, \"{}\" and \"{}\"",
                        mesh.cells[c].tag, scene.materials[other].group, ms.group
                    ))
                    .into());
                }
                owner.insert(c, mi);
            }
            materials.push(Material::new(&ms.group, ms.e, ms.nu, ms.rho));
        }
        let mut cells: Vec<(usize, usize)> = owner.into_iter().collect();
        cells.sort_unstable();

        // ---- elements
        let mut tn = Vec::new();
        let mut tg = Vec::new();
        let mut tm = Vec::new();
        let mut tc = Vec::new();
        let mut hn = Vec::new();
        let mut hs = Vec::new();
        let mut hm = Vec::new();
        let mut hc = Vec::new();
        let mut shapes: Vec<HexShape> = Vec::new();
        let mut shape_key: HashMap<(usize, [i64; 21]), u32> = HashMap::new();
        let mut mass = vec![0.0; n];
        let inverted = |c: usize, mi: usize| -> crate::Error {
            MeshError::InvertedElement {
                path: mesh.source.clone(),
                group: materials[mi].group.clone(),
                element: mesh.cells[c].tag,
                jacobian: mesh.min_corner_jacobian(c),
            }
            .into()
        };
        for &(c, mi) in &cells {
            let cell = &mesh.cells[c];
            let rho = materials[mi].rho;
            match cell.kind {
                CellKind::Tet4 => {
                    let x: [Vector3<f64>; 4] = std::array::from_fn(|a| mesh.x(cell.node(a)));
                    let g = tet4::tet_geometry(&x).ok_or_else(|| inverted(c, mi))?;
                    for a in 0..4 {
                        mass[cell.node(a)] += rho * g.vol / 4.0;
                    }
                    tn.push(std::array::from_fn(|a| cell.nodes()[a]));
                    tg.push(g);
                    tm.push(mi as u16);
                    tc.push(c as u32);
                }
                CellKind::Hex8 => {
                    let x: [Vector3<f64>; 8] = std::array::from_fn(|a| mesh.x(cell.node(a)));
                    // congruence key: edge vectors from node 0, rounded to 1e-9 of the element size
                    let size = (x[6] - x[0]).norm();
                    let q = 1e-9 * size;
                    let mut key = [0i64; 21];
                    for a in 1..8 {
                        for i in 0..3 {
                            key[3 * (a - 1) + i] = ((x[a][i] - x[0][i]) / q).round() as i64;
                        }
                    }
                    let id = match shape_key.get(&(mi, key)) {
                        Some(&id) => id,
                        None => {
                            let s = hex8::hex_shape(&x, &materials[mi].lame).ok_or_else(|| inverted(c, mi))?;
                            shapes.push(s);
                            let id = (shapes.len() - 1) as u32;
                            shape_key.insert((mi, key), id);
                            id
                        }
                    };
                    let s = &shapes[id as usize];
                    for a in 0..8 {
                        mass[cell.node(a)] += rho * s.vol * s.mass_frac[a];
                    }
                    hn.push(std::array::from_fn(|a| cell.nodes()[a]));
                    hs.push(id);
                    hm.push(mi as u16);
                    hc.push(c as u32);
                }
                _ => unreachable!("material groups hold volume cells only"),
            }
        }
        if tn.is_empty() && hn.is_empty() {
            return Err(ModelError::Invalid("the material groups hold no tet4 or hex8 elements".into()).into());
        }
        let (to, tcol) = color_order(&tn, n)?;
        let (ho, hcol) = color_order(&hn, n)?;
        let tets = Tet4Set { nodes: permute(&tn, &to), geom: permute(&tg, &to), mat: permute(&tm, &to), cell: permute(&tc, &to), colors: tcol };
        let hexes = Hex8Set {
            nodes: permute(&hn, &ho),
            shape: permute(&hs, &ho),
            mat: permute(&hm, &ho),
            cell: permute(&hc, &ho),
            colors: hcol,
            shapes,
        };

        // ---- boundary conditions
        let mut fixed: Vec<u8> = mass.iter().map(|&m| if m > 0.0 { 0 } else { 7 }).collect();
        for b in &scene.boundary {
            let bits = b.fix.iter().fold(0u8, |acc, c| acc | match c.as_str() { "x" => 1, "y" => 2, _ => 4 });
            for node in mesh.group_nodes(&b.group)? {
                fixed[node] |= bits;
            }
        }
        let (alpha, beta) = scene.damping.coefficients().map_err(ModelError::Invalid)?;
        let mass_damped = match &scene.damping.mass_groups {
            None => vec![true; n],
            Some(groups) => {
                let mut d = vec![false; n];
                for g in groups {
                    mesh.group_of_dim(g, 3)?;
                    for node in mesh.group_nodes(g)? {
                        d[node] = true;
                    }
                }
                d
            }
        };
        // ---- joints (tagged once on the initial configuration)
        let size = {
            let (lo, hi) = mesh.nodes.iter().fold(([f64::MAX; 3], [f64::MIN; 3]), |(mut lo, mut hi), x| {
                for i in 0..3 {
                    lo[i] = lo[i].min(x[i]);
                    hi[i] = hi[i].max(x[i]);
                }
                (lo, hi)
            });
            ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt()
        };
        let mut joints = Vec::new();
        for js in &scene.joints {
            joints.push(crate::contact::joint::ContactJoint::build(&mesh, js, size)?);
        }

        let mut model = Model {
            mesh,
            materials,
            tets,
            hexes,
            mass,
            fixed,
            alpha,
            mass_damped,
            beta,
            critical: CriticalElement { tag: 0, group: String::new(), omega2: 0.0 },
            joints,
        };
        model.critical = model.max_element_eigenvalue();
        Ok(model)
    }

    pub fn n_nodes(&self) -> usize {
        self.mesh.nodes.len()
    }

    pub fn n_elements(&self) -> usize {
        self.tets.nodes.len() + self.hexes.nodes.len()
    }

    /// Whether dof (node, component) is free.
    #[inline]
    pub fn is_free(&self, node: usize, comp: usize) -> bool {
        self.fixed[node] & (1 << comp) == 0
    }

    /// The element with the largest ω²_max (element eigenvalue theorem: the global ω_max is bounded
    /// by the largest element ω_max with lumped mass).
    fn max_element_eigenvalue(&self) -> CriticalElement {
        let t = (0..self.tets.nodes.len())
            .into_par_iter()
            .map(|e| {
                let m = &self.materials[self.tets.mat[e] as usize];
                let g = &self.tets.geom[e];
                (tet4::max_eigenvalue(&g.grad, g.vol, m.rho, &m.lame), self.tets.cell[e] as usize, self.tets.mat[e] as usize)
            })
            .reduce(|| (0.0, 0, 0), |a, b| if b.0 > a.0 || (b.0 == a.0 && b.1 < a.1) { b } else { a });
        // shapes are shared: one eigenvalue per (shape), then the element using it
        let shape_omega: Vec<f64> = self
            .hexes
            .shapes
            .par_iter()
            .enumerate()
            .map(|(si, s)| {
                let e = self.hexes.shape.iter().position(|&x| x as usize == si).unwrap();
                let m = &self.materials[self.hexes.mat[e] as usize];
                hex8::max_eigenvalue(s, m.rho, &m.lame)
            })
            .collect();
        let mut best = t;
        for e in 0..self.hexes.nodes.len() {
            let w = shape_omega[self.hexes.shape[e] as usize];
            let c = self.hexes.cell[e] as usize;
            if w > best.0 || (w == best.0 && c < best.1) {
                best = (w, c, self.hexes.mat[e] as usize);
            }
        }
        CriticalElement { tag: self.mesh.cells[best.1].tag, group: self.materials[best.2].group.clone(), omega2: best.0 }
    }

    /// Stable time step [s] of the central-difference scheme with Rayleigh damping:
    /// the largest dt with ω²dt² + 2(α + βω²) dt − 4 ≤ 0 at ω = ω_max (undamped: 2/ω_max).
    pub fn stable_dt(&self) -> f64 {
        let w2 = self.critical.omega2;
        let c = self.alpha + self.beta * w2;
        (-c + (c * c + 4.0 * w2).sqrt()) / w2
    }

    /// Stable step with an extra ω² bound `extra_omega2` [1/s²] added to the element bound
    /// (λ_max(A + B) ≤ λ_max(A) + λ_max(B)), e.g. for penalty springs.
    pub fn stable_dt_with(&self, extra_omega2: f64) -> f64 {
        let w2 = self.critical.omega2 + extra_omega2;
        let c = self.alpha + self.beta * w2;
        (-c + (c * c + 4.0 * w2).sqrt()) / w2
    }

    /// f = K u (f is overwritten). Deterministic whatever the thread count.
    pub fn internal_forces_into(&self, u: &[f64], f: &mut [f64]) {
        f.fill(0.0);
        let fp = SharedMut(f.as_mut_ptr());
        // one thread: no pool hand-off per colour (it costs a context switch each time, which
        // on a 10⁴-element model took about as long as the elements themselves)
        let serial = rayon::current_num_threads() == 1;
        for r in &self.tets.colors {
            let body = |e: usize| {
                let nd = &self.tets.nodes[e];
                let ue: [[f64; 3]; 4] = std::array::from_fn(|a| {
                    let i = 3 * nd[a] as usize;
                    [u[i], u[i + 1], u[i + 2]]
                });
                let g = &self.tets.geom[e];
                let fe = tet4::internal_forces(&g.grad, g.vol, &ue, &self.materials[self.tets.mat[e] as usize].lame);
                let p = fp;
                for a in 0..4 {
                    let i = 3 * nd[a] as usize;
                    // SAFETY: within one colour no two elements share a node (module invariant).
                    unsafe {
                        *p.0.add(i) += fe[a][0];
                        *p.0.add(i + 1) += fe[a][1];
                        *p.0.add(i + 2) += fe[a][2];
                    }
                }
            };
            if serial || r.len() < PAR_MIN {
                r.clone().for_each(body);
            } else {
                r.clone().into_par_iter().with_min_len(PAR_MIN / 2).for_each(body);
            }
        }
        for r in &self.hexes.colors {
            let body = |e: usize| {
                let nd = &self.hexes.nodes[e];
                let ue: [[f64; 3]; 8] = std::array::from_fn(|a| {
                    let i = 3 * nd[a] as usize;
                    [u[i], u[i + 1], u[i + 2]]
                });
                let s = &self.hexes.shapes[self.hexes.shape[e] as usize];
                let fe = hex8::internal_forces(s, &ue, &self.materials[self.hexes.mat[e] as usize].lame);
                let p = fp;
                for a in 0..8 {
                    let i = 3 * nd[a] as usize;
                    // SAFETY: as above.
                    unsafe {
                        *p.0.add(i) += fe[a][0];
                        *p.0.add(i + 1) += fe[a][1];
                        *p.0.add(i + 2) += fe[a][2];
                    }
                }
            };
            if serial || r.len() < PAR_MIN {
                r.clone().for_each(body);
            } else {
                r.clone().into_par_iter().with_min_len(PAR_MIN / 2).for_each(body);
            }
        }
    }

    /// Element stresses (xx, yy, zz, xy, yz, zx) [Pa] in model element order (tets, then hexes).
    pub fn element_stress_into(&self, u: &[f64], out: &mut Vec<[f64; 6]>) {
        out.clear();
        let gather = |i: u32| {
            let i = 3 * i as usize;
            [u[i], u[i + 1], u[i + 2]]
        };
        for e in 0..self.tets.nodes.len() {
            let ue = self.tets.nodes[e].map(gather);
            out.push(tet4::stress(&self.tets.geom[e].grad, &ue, &self.materials[self.tets.mat[e] as usize].lame));
        }
        for e in 0..self.hexes.nodes.len() {
            let ue = self.hexes.nodes[e].map(gather);
            let s = &self.hexes.shapes[self.hexes.shape[e] as usize];
            out.push(hex8::stress(s, &ue, &self.materials[self.hexes.mat[e] as usize].lame));
        }
    }

    /// (kind, nodes) of every element in model order, for output grids.
    pub fn element_cells(&self) -> Vec<(CellKind, &[u32])> {
        let mut v: Vec<(CellKind, &[u32])> = Vec::with_capacity(self.n_elements());
        v.extend(self.tets.nodes.iter().map(|n| (CellKind::Tet4, &n[..])));
        v.extend(self.hexes.nodes.iter().map(|n| (CellKind::Hex8, &n[..])));
        v
    }

    /// Material (block) index of every element in model order.
    pub fn element_blocks(&self) -> Vec<i32> {
        self.tets.mat.iter().chain(self.hexes.mat.iter()).map(|&m| m as i32).collect()
    }

    /// Lamé constants of element `e` in model order.
    pub fn element_lame(&self, e: usize) -> &Lame {
        let nt = self.tets.nodes.len();
        let m = if e < nt { self.tets.mat[e] } else { self.hexes.mat[e - nt] };
        &self.materials[m as usize].lame
    }
}

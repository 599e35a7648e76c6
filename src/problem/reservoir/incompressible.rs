//! Incompressible FE added mass (`reservoir.model: "fe_incompressible"`): the water's exact
//! potential-flow added-mass operator on the dam's wet face, condensed once.
//!
//! With H the water's Laplacian (module `fluid_mesh`) and G the wet-face coupling (module
//! `transfer`), a dam acceleration a gives the pressure H p = ρw G a and the forces
//! f = −Gᵀ p = −M_a a with
//!
//! ```text
//! M_a = ρw Gᵀ H⁻¹ G   [kg], symmetric positive semi-definite, 3 n_wet × 3 n_wet, dense.
//! ```
//!
//! H is factorised once (faer sparse Cholesky); only the water's wet unknowns W enter G, so
//! M_a = ρw G_Wᵀ S G_W with S = (H⁻¹)_WW from n_W solves (blocks of 64 right-hand sides).
//!
//! How the two consumers use it:
//! - `jointquake modes` (module statics::modes): the **full** operator added to the mass matrix.
//! - The explicit run: its **row-sum lumping along the nodal normals**, m_b n_b n_bᵀ with
//!   m_b = n_b·Σ_c M_a[b,c] n_c (n_b the normalised ∫ N_b n dA), the same 3×3 nodal blocks as
//!   Westergaard's, so the diagonal-mass explicit step and the per-pair contact weights are
//!   unchanged and the step costs what the Westergaard step costs. It is exact for a uniform
//!   normal acceleration of the face (the force of each node is M_a's), and loses the coupling
//!   between nodes: for a flexible mode whose normal acceleration changes sign along the face
//!   the lumped mass is too large (what it loses is measured by `modes` on the dam,
//!   docs/dam_physics.md "Reservoir models").

use super::fluid_mesh::{fluid_mesh, FluidMesh};
use super::transfer::{wet_coupling, WetCoupling};
use super::{AddedMass, ReservoirSpec, WetFace};
use crate::error::{Error, ModelError};
use crate::linalg::{SparseCholesky, NONE};
use crate::mesh::Mesh;
use crate::scene::reservoir::FluidScene;
use nalgebra::{DMatrix, Vector3};

/// The largest dense matrix (entries) the condensation may allocate: 1.5e8 (1.2 GB).
const MAX_DENSE: usize = 150_000_000;

/// The water, its coupling with the dam and the factorised Laplacian.
pub struct IncompressibleReservoir {
    pub fluid: FluidMesh,
    pub coupling: WetCoupling,
    pub rho_w: f64,
    factor: SparseCholesky,
}

impl std::fmt::Debug for IncompressibleReservoir {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "IncompressibleReservoir {{ unknowns: {}, dam wet nodes: {} }}", self.fluid.nodes.len(), self.coupling.dam_nodes.len())
    }
}

/// The condensed operator M_a on the dam's wet nodes.
#[derive(Clone, Debug)]
pub struct AddedMassOperator {
    /// The dam's wet nodes (mesh indices): M_a's node b is `nodes[b]`, dofs 3b + component.
    pub nodes: Vec<usize>,
    /// M_a [kg], 3 n × 3 n.
    pub matrix: DMatrix<f64>,
    /// ∫ N_b n dA [m²] of each node (the area-weighted normal: a nodal normal and area).
    pub area_normals: Vec<Vector3<f64>>,
}

impl IncompressibleReservoir {
    /// Build the water of `fluid` on `mesh`, couple it to the dam's wet faces `dam` below the
    /// pool level and factorise its Laplacian.
    pub fn build(mesh: &Mesh, dam: &[WetFace], spec: &ReservoirSpec, fluid: &FluidScene) -> Result<IncompressibleReservoir, Error> {
        let water = fluid_mesh(mesh, fluid)?;
        let coupling = wet_coupling(mesh, dam, &water.wet, spec.level)?;
        if coupling.dam_nodes.is_empty() {
            return Err(ModelError::Invalid(format!("reservoir.fluid: no wet face of the dam lies below the pool level {} m", spec.level)).into());
        }
        let factor = SparseCholesky::factor(&water.laplacian, "reservoir water Laplacian", faer::Par::Seq).map_err(|e| {
            ModelError::Invalid(format!(
                "reservoir.fluid.volume \"{}\": the water's Laplacian cannot be factorised ({e}); a part of the water touches no p = 0 face (free_surface, far_end): connect it or name its free surface",
                fluid.volume
            ))
        })?;
        Ok(IncompressibleReservoir { fluid: water, coupling, rho_w: spec.rho_w, factor })
    }

    /// The water's pressure [Pa] at its unknowns (`fluid.nodes`) for the dam accelerations `a`
    /// [m/s²] of the coupling's dam nodes: H p = ρw G a.
    pub fn pressure_of_acceleration(&mut self, a: &[[f64; 3]]) -> Vec<f64> {
        let mut p = vec![0.0; self.fluid.nodes.len()];
        for &(i, b, g) in &self.coupling.entries {
            let k = self.fluid.unknown[self.coupling.water_nodes[i]];
            if k != NONE {
                p[k] += self.rho_w * (g[0] * a[b][0] + g[1] * a[b][1] + g[2] * a[b][2]);
            }
        }
        self.factor.solve_in_place(&mut p);
        p
    }

    /// The condensed added mass M_a = ρw G_Wᵀ (H⁻¹)_WW G_W. Errors (before allocating) when the
    /// dense matrices would exceed 1.5e8 entries.
    pub fn added_mass(&mut self) -> Result<AddedMassOperator, Error> {
        let c = &self.coupling;
        // the water's wet unknowns W (rows of G that are not held at p = 0)
        let mut w_of = vec![NONE; c.water_nodes.len()];
        let mut w_unknown = Vec::new();
        for (i, &v) in c.water_nodes.iter().enumerate() {
            let k = self.fluid.unknown[v];
            if k != NONE {
                w_of[i] = w_unknown.len();
                w_unknown.push(k);
            }
        }
        let (nw, nd) = (w_unknown.len(), 3 * c.dam_nodes.len());
        let nf = self.fluid.nodes.len();
        let block = 64.min(nw.max(1));
        let sizes = [nw.saturating_mul(nw), nw.saturating_mul(nd), nd.saturating_mul(nd), nf.saturating_mul(block)];
        if sizes.iter().any(|&s| s > MAX_DENSE) {
            return Err(ModelError::Invalid(format!(
                "reservoir \"fe_incompressible\": the condensed added mass needs dense matrices of {nw} × {nw}, {nw} × {nd} and {nd} × {nd} entries (limit {MAX_DENSE}): mesh the dam's wet face and the water's coarser"
            ))
            .into());
        }
        // S = (H⁻¹)_WW, column blocks
        let mut s = DMatrix::<f64>::zeros(nw, nw);
        let mut rhs = vec![0.0; nf * block];
        for start in (0..nw).step_by(block) {
            let cols = block.min(nw - start);
            rhs[..nf * cols].iter_mut().for_each(|v| *v = 0.0);
            for j in 0..cols {
                rhs[j * nf + w_unknown[start + j]] = 1.0;
            }
            self.factor.solve_mat_in_place(faer::MatMut::from_column_major_slice_mut(&mut rhs[..nf * cols], nf, cols));
            for j in 0..cols {
                for (r, &k) in w_unknown.iter().enumerate() {
                    s[(r, start + j)] = rhs[j * nf + k];
                }
            }
        }
        let mut g = DMatrix::<f64>::zeros(nw, nd);
        let mut area_normals = vec![Vector3::zeros(); c.dam_nodes.len()];
        for &(i, b, gv) in &c.entries {
            area_normals[b] += Vector3::from(gv);
            if w_of[i] != NONE {
                for k in 0..3 {
                    g[(w_of[i], 3 * b + k)] += gv[k];
                }
            }
        }
        let sg = &s * &g;
        let mut m = g.transpose() * sg;
        m *= self.rho_w;
        // symmetric to round-off: make it exactly so
        let mt = m.transpose();
        m = (m + mt) * 0.5;
        Ok(AddedMassOperator { nodes: c.dam_nodes.clone(), matrix: m, area_normals })
    }
}

impl AddedMassOperator {
    /// The unit nodal normal of node b (out of the dam).
    fn normal(&self, b: usize) -> Vector3<f64> {
        let n = self.area_normals[b];
        if n.norm() > 0.0 {
            n.normalize()
        } else {
            n
        }
    }

    /// The 3×3 block M_a[b, c] [kg].
    pub fn block(&self, b: usize, c: usize) -> nalgebra::Matrix3<f64> {
        self.matrix.fixed_view::<3, 3>(3 * b, 3 * c).into_owned()
    }

    /// The row-sum lumping along the nodal normals (module doc): m_b n_b n_bᵀ per wet node, and
    /// how many nodes had m_b < 0 (set to 0; none on the meshes tested).
    pub fn lumped(&self) -> (Vec<AddedMass>, usize) {
        let n: Vec<Vector3<f64>> = (0..self.nodes.len()).map(|b| self.normal(b)).collect();
        let mut negative = 0;
        let out = (0..self.nodes.len())
            .map(|b| {
                let mut f = Vector3::zeros();
                for (c, nc) in n.iter().enumerate() {
                    f += self.block(b, c) * nc;
                }
                let mut mass = n[b].dot(&f);
                if mass < 0.0 {
                    negative += 1;
                    mass = 0.0;
                }
                AddedMass { node: self.nodes[b], mass, normal: [n[b][0], n[b][1], n[b][2]], area: self.area_normals[b].norm() }
            })
            .collect();
        (out, negative)
    }

    /// M_a minus its lumping, as (model dof, model dof, value) entries [kg] (dof = 3 node +
    /// component): added to a mass matrix that already holds the lumped blocks, it gives the
    /// full operator.
    pub fn coupling_beyond_lumped(&self) -> Vec<(usize, usize, f64)> {
        let (lumped, _) = self.lumped();
        let nd = 3 * self.nodes.len();
        let mut out = Vec::with_capacity(nd * nd);
        for j in 0..nd {
            for i in 0..nd {
                let (b, c) = (i / 3, j / 3);
                let mut v = self.matrix[(i, j)];
                if b == c {
                    let a = &lumped[b];
                    v -= a.mass * a.normal[i % 3] * a.normal[j % 3];
                }
                if v != 0.0 {
                    out.push((3 * self.nodes[b] + i % 3, 3 * self.nodes[c] + j % 3, v));
                }
            }
        }
        out
    }
}

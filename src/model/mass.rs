//! Nodal masses (design §4 "Mass"): inertia and weight apart.
//!
//! - **Inertial mass** M: what resists acceleration and what the base motion acts on in the
//!   relative form (F = −M ι a_g). Per node either isotropic, `m I` (every node by default: the
//!   lumped mass of its elements), or a symmetric 3×3 block `m I + A` where an added inertia `A`
//!   is declared ([`NodalMass::add_inertia`]; e.g. a reservoir's added mass m_a n nᵀ along a wet
//!   face's normal). A node with `m = 0` and no block has no inertia (a massless foundation
//!   node): the explicit step does not integrate it, a constraint (static condensation) must.
//! - **Gravitational mass**: what gravity acts on (the weight is m_g g). The lumped mass by
//!   default (`gravitational: None`, so that the load loop reads one vector, as before); added
//!   inertia adds none (water's added mass has no weight on the dam). A model whose weight is
//!   not its lumped inertia sets its own vector ([`NodalMass::set_gravitational`]).
//!
//! Hot path: the step divides by `inertial[node]` for every node, as it did with one mass per
//! node, and then redoes the few block nodes with their inverse ([`InertiaBlock::inverse`]);
//! without blocks the second pass is empty. Units: kg.

use nalgebra::{Matrix3, Vector3};

/// A node whose inertia is the symmetric block `m I + added`.
#[derive(Clone, Debug)]
pub struct InertiaBlock {
    pub node: u32,
    /// The added inertia A (symmetric) [kg].
    pub added: Matrix3<f64>,
    /// The full inertia m I + A [kg].
    pub full: Matrix3<f64>,
    /// Inverse of the full inertia restricted to the node's free components (rows and columns of
    /// fixed components are 0) [1/kg]: a = inverse (f_free).
    pub inverse: Matrix3<f64>,
}

/// The masses of every node.
#[derive(Clone, Debug, Default)]
pub struct NodalMass {
    /// Lumped (isotropic) inertial mass per node [kg]: m in m I (+ A for block nodes).
    pub inertial: Vec<f64>,
    /// Gravitational mass per node [kg]; `None`: equal to `inertial` (the default).
    pub gravitational: Option<Vec<f64>>,
    /// The nodes with an added inertia, ascending by node (empty for most models).
    pub blocks: Vec<InertiaBlock>,
}

impl NodalMass {
    /// Isotropic masses, weight equal to inertia (the lumped mass of the elements).
    pub fn lumped(m: Vec<f64>) -> NodalMass {
        NodalMass { gravitational: None, inertial: m, blocks: Vec::new() }
    }

    /// Gravitational mass of `node` [kg].
    #[inline]
    pub fn weight_mass(&self, node: usize) -> f64 {
        match &self.gravitational {
            Some(g) => g[node],
            None => self.inertial[node],
        }
    }

    /// Set the gravitational mass of every node [kg] (one per node).
    pub fn set_gravitational(&mut self, g: Vec<f64>) {
        assert_eq!(g.len(), self.inertial.len(), "one gravitational mass per node");
        self.gravitational = Some(g);
    }

    /// Total gravitational mass [kg].
    pub fn total_weight_mass(&self) -> f64 {
        match &self.gravitational {
            Some(g) => g.iter().sum(),
            None => self.inertial.iter().sum(),
        }
    }

    pub fn len(&self) -> usize {
        self.inertial.len()
    }

    pub fn is_empty(&self) -> bool {
        self.inertial.is_empty()
    }

    /// Whether the node's inertia is a block (a binary search in the few block nodes).
    pub fn block_of(&self, node: usize) -> Option<&InertiaBlock> {
        if self.blocks.is_empty() {
            return None;
        }
        self.blocks.binary_search_by_key(&(node as u32), |b| b.node).ok().map(|k| &self.blocks[k])
    }

    /// Add the symmetric inertia `a` [kg] to `node` (summed with any earlier addition), with the
    /// node's fixed components `fixed` (bit 0 = x, 1 = y, 2 = z) for the restricted inverse.
    /// Panics if `a` is not symmetric to round-off (a programming error, not input).
    pub fn add_inertia(&mut self, node: usize, a: Matrix3<f64>, fixed: u8) {
        assert!((a - a.transpose()).norm() <= 1e-12 * a.norm().max(1e-300), "added inertia of node {node} is not symmetric");
        let m = self.inertial[node];
        let k = match self.blocks.binary_search_by_key(&(node as u32), |b| b.node) {
            Ok(k) => k,
            Err(k) => {
                self.blocks.insert(k, InertiaBlock { node: node as u32, added: Matrix3::zeros(), full: Matrix3::zeros(), inverse: Matrix3::zeros() });
                k
            }
        };
        let b = &mut self.blocks[k];
        b.added += a;
        b.full = Matrix3::identity() * m + b.added;
        b.inverse = restricted_inverse(&b.full, fixed);
    }

    /// M v at a node [kg · unit of v].
    #[inline]
    pub fn apply(&self, node: usize, v: &Vector3<f64>) -> Vector3<f64> {
        match self.block_of(node) {
            Some(b) => b.full * v,
            None => v * self.inertial[node],
        }
    }

    /// n · M⁻¹ n for a unit vector n at a free node [1/kg]: the inverse mass along n (1/m for an
    /// isotropic node, 0 for a node without inertia). How a contact pair reads a block node's
    /// inertia: see docs/contact.md "Mobility".
    #[inline]
    pub fn inverse_along(&self, node: usize, n: &Vector3<f64>) -> f64 {
        match self.block_of(node) {
            Some(b) => n.dot(&(b.inverse * n)),
            None => {
                let m = self.inertial[node];
                if m > 0.0 { 1.0 / m } else { 0.0 }
            }
        }
    }

    /// Total inertial mass along a unit direction d, Σ dᵀ M d [kg].
    pub fn total_along(&self, d: &Vector3<f64>) -> f64 {
        let iso: f64 = self.inertial.iter().sum::<f64>() * d.norm_squared();
        iso + self.blocks.iter().map(|b| d.dot(&(b.added * d))).sum::<f64>()
    }
}

/// Inverse of `m` on the free components (bits of `fixed` clear), zero rows and columns on the
/// fixed ones. A singular free block (no inertia on a free direction) gives zeros there.
fn restricted_inverse(m: &Matrix3<f64>, fixed: u8) -> Matrix3<f64> {
    let free: Vec<usize> = (0..3).filter(|c| fixed & (1 << c) == 0).collect();
    let mut out = Matrix3::zeros();
    let k = free.len();
    if k == 0 {
        return out;
    }
    let sub = nalgebra::DMatrix::from_fn(k, k, |i, j| m[(free[i], free[j])]);
    if let Some(inv) = sub.try_inverse() {
        for i in 0..k {
            for j in 0..k {
                out[(free[i], free[j])] = inv[(i, j)];
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// m I + m_a n nᵀ has the inverse (1/m)(I − m_a/(m + m_a) n nᵀ) (Sherman–Morrison): along n
    /// the inverse mass is 1/(m + m_a), across it 1/m.
    #[test]
    fn added_mass_along_a_normal_inverts_by_sherman_morrison() {
        let mut mass = NodalMass::lumped(vec![2.0, 3.0]);
        let n = Vector3::new(1.0, 2.0, 2.0) / 3.0;
        mass.add_inertia(1, n * n.transpose() * 5.0, 0);
        assert!((mass.inverse_along(1, &n) - 1.0 / 8.0).abs() < 1e-15);
        let t = Vector3::new(2.0, -1.0, 0.0) / 5f64.sqrt();
        assert!((mass.inverse_along(1, &t) - 1.0 / 3.0).abs() < 1e-15);
        assert_eq!(mass.inverse_along(0, &n), 0.5);
        assert!((mass.apply(1, &n) - n * 8.0).norm() < 1e-14);
        assert!((mass.total_along(&n) - 10.0).abs() < 1e-14);
        assert_eq!((mass.weight_mass(0), mass.weight_mass(1)), (2.0, 3.0));
    }

    /// A fixed component takes no part in the inverse: with z fixed, the x–y block alone.
    #[test]
    fn fixed_component_is_left_out_of_the_block_inverse() {
        let mut mass = NodalMass::lumped(vec![1.0]);
        let a = Matrix3::new(1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0);
        mass.add_inertia(0, a, 4);
        let inv = mass.blocks[0].inverse;
        assert!((inv[(0, 0)] - 0.5).abs() < 1e-15 && inv[(2, 2)] == 0.0 && inv[(0, 2)] == 0.0 && (inv[(1, 1)] - 1.0).abs() < 1e-15);
    }
}

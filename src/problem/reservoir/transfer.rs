//! The wet-face transfer between the water's mesh and the dam's (non-conforming, like every
//! joint): the coupling G_ib = ∫_Γ N^w_i N^d_b n dA [m²] (a 3-vector per pair), N^w the water's
//! shape functions on its wet face, N^d the dam's on its wet face, n the dam's outward unit
//! normal (towards the water).
//!
//! - Water flux from the dam: q_i = ρw Σ_b G_ib·a_b (∂p/∂n_water = ρw a·n on Γ).
//! - Dam forces from the water: f_b = −Σ_i G_ib p_i (the water pushes along −n).
//!
//! G is integrated on the **dam's** faces (a composite rule: 4 × 4 cells of 2×2 Gauss points
//! per quad4, 16 sub-triangles of 3 points per tri3), each point projected on the nearest water
//! face (closest point, clamped to the face) where N^w is evaluated. Because Σ_i N^w_i = 1 at
//! every projected point, a uniform pressure p0 gives f_b = −p0 ∫ N^d_b n dA: the exact
//! resultant −p0 ∫_Γ n dA of the dam's wet face, whatever the two meshes (test). Points above
//! the pool level are dry (the dam face continues above the water; p = 0 there).

use super::{face_points_refined, WetFace};
use crate::error::{Error, ModelError};
use crate::mesh::geometry::closest_on_triangle;
use crate::mesh::{CellKind, Mesh};
use nalgebra::{Matrix2, Vector2, Vector3};

/// The coupling G of one dam face group and one water face group.
#[derive(Clone, Debug)]
pub struct WetCoupling {
    /// The dam's wet nodes (mesh indices, increasing): the columns b.
    pub dam_nodes: Vec<usize>,
    /// The water's wet nodes (mesh indices, increasing): the rows i.
    pub water_nodes: Vec<usize>,
    /// (i, b, G_ib [m²]) with i, b indices into `water_nodes`, `dam_nodes`; one entry per pair.
    pub entries: Vec<(usize, usize, [f64; 3])>,
    /// The largest distance between a wet point of the dam and its water face [m] (0 where the
    /// two faceted surfaces coincide).
    pub max_gap: f64,
    /// The dam's wet area below the pool [m²].
    pub area: f64,
}

impl WetCoupling {
    /// Dam nodal forces [N] (by index of `dam_nodes`) of a water pressure given at the water's
    /// wet nodes (by index of `water_nodes`) [Pa]: f_b = −Σ_i G_ib p_i.
    pub fn forces_of_pressure(&self, p: &[f64]) -> Vec<[f64; 3]> {
        let mut f = vec![[0.0; 3]; self.dam_nodes.len()];
        for &(i, b, g) in &self.entries {
            for c in 0..3 {
                f[b][c] -= g[c] * p[i];
            }
        }
        f
    }
}

/// Points per face of the integration (module doc).
const QUAD_CELLS: usize = 4;
const TRI_LEVELS: usize = 2;

/// G between the dam's wet faces `dam` (outward from the dam) and the water's `water` (either
/// orientation), below `level`. Errors when a wet point of the dam is farther from every water
/// face than half its own face's diameter (the water mesh does not cover the dam's wet face).
pub fn wet_coupling(mesh: &Mesh, dam: &[WetFace], water: &[WetFace], level: f64) -> Result<WetCoupling, Error> {
    let index = |faces: &[WetFace]| -> (Vec<usize>, std::collections::HashMap<usize, usize>) {
        let mut v: Vec<usize> = faces.iter().flat_map(|f| f.nodes.iter().copied()).collect();
        v.sort_unstable();
        v.dedup();
        let m = v.iter().enumerate().map(|(i, &n)| (n, i)).collect();
        (v, m)
    };
    let (dam_all, dam_of) = index(dam);
    let (water_nodes, water_of) = index(water);
    let water_x: Vec<Vec<Vector3<f64>>> = water.iter().map(|f| f.nodes.iter().map(|&v| mesh.x(v)).collect()).collect();
    let water_box: Vec<(Vector3<f64>, Vector3<f64>)> = water_x.iter().map(|x| bounds(x)).collect();
    let mut acc: std::collections::BTreeMap<(usize, usize), Vector3<f64>> = Default::default();
    let (mut max_gap, mut area) = (0.0f64, 0.0);
    for f in dam {
        let x: Vec<Vector3<f64>> = f.nodes.iter().map(|&v| mesh.x(v)).collect();
        let (lo, hi) = bounds(&x);
        if lo[2] >= level {
            continue;
        }
        let tol = 0.5 * (hi - lo).norm();
        let near: Vec<usize> = (0..water.len())
            .filter(|&k| (0..3).all(|c| water_box[k].0[c] <= hi[c] + tol && water_box[k].1[c] >= lo[c] - tol))
            .collect();
        for (nsh, da) in face_points_refined(f.kind, &x, QUAD_CELLS, TRI_LEVELS) {
            let p: Vector3<f64> = (0..x.len()).map(|a| x[a] * nsh[a]).sum();
            if p[2] >= level {
                continue;
            }
            let best = near.iter().map(|&k| (k, closest_on_face(water[k].kind, &water_x[k], &p))).min_by(|a, b| a.1 .1.total_cmp(&b.1 .1));
            let Some((k, (nw, d))) = best.filter(|b| b.1 .1 <= tol) else {
                return Err(ModelError::Invalid(format!(
                    "reservoir.fluid.wet: the water's wet face does not cover the dam's at ({:.3}, {:.3}, {:.3}) m, below the pool level {level} m (no water face within {tol:.3} m): mesh the water against the whole wet face of the dam",
                    p[0], p[1], p[2]
                ))
                .into());
            };
            max_gap = max_gap.max(d);
            area += da.norm();
            for (a, &vd) in f.nodes.iter().enumerate() {
                for (i, &vw) in water[k].nodes.iter().enumerate() {
                    let w = nsh[a] * nw[i];
                    if w != 0.0 {
                        *acc.entry((water_of[&vw], dam_of[&vd])).or_insert_with(Vector3::zeros) += da * w;
                    }
                }
            }
        }
    }
    // keep the dam nodes that touch the water, renumbered
    let mut used = vec![false; dam_all.len()];
    acc.keys().for_each(|&(_, b)| used[b] = true);
    let mut renum = vec![usize::MAX; dam_all.len()];
    let mut dam_nodes = Vec::new();
    for (b, &v) in dam_all.iter().enumerate() {
        if used[b] {
            renum[b] = dam_nodes.len();
            dam_nodes.push(v);
        }
    }
    let entries = acc.into_iter().map(|((i, b), g)| (i, renum[b], [g[0], g[1], g[2]])).collect();
    Ok(WetCoupling { dam_nodes, water_nodes, entries, max_gap, area })
}

fn bounds(x: &[Vector3<f64>]) -> (Vector3<f64>, Vector3<f64>) {
    x.iter().fold((Vector3::repeat(f64::INFINITY), Vector3::repeat(f64::NEG_INFINITY)), |(lo, hi), p| (lo.inf(p), hi.sup(p)))
}

/// The closest point of a face to `p`: its shape-function values there and the distance [m].
pub fn closest_on_face(kind: CellKind, x: &[Vector3<f64>], p: &Vector3<f64>) -> ([f64; 4], f64) {
    match kind {
        CellKind::Tri3 => {
            let l = closest_on_triangle(x[0], x[1], x[2], p);
            let q = x[0] * l[0] + x[1] * l[1] + x[2] * l[2];
            ([l[0], l[1], l[2], 0.0], (q - p).norm())
        }
        _ => {
            // Gauss-Newton on |x(s, t) − p|² from the centre, clamped to [−1, 1]² (a bilinear face)
            let r = crate::mesh::cell::QUAD4_REF;
            let shape = |s: f64, t: f64| -> [f64; 4] { std::array::from_fn(|k| 0.25 * (1.0 + s * r[k][0]) * (1.0 + t * r[k][1])) };
            let mut st = Vector2::zeros();
            for _ in 0..20 {
                let n = shape(st[0], st[1]);
                let q: Vector3<f64> = (0..4).map(|k| x[k] * n[k]).sum();
                let xs: Vector3<f64> = (0..4).map(|k| x[k] * (0.25 * r[k][0] * (1.0 + st[1] * r[k][1]))).sum();
                let xt: Vector3<f64> = (0..4).map(|k| x[k] * (0.25 * r[k][1] * (1.0 + st[0] * r[k][0]))).sum();
                let j = Matrix2::new(xs.dot(&xs), xs.dot(&xt), xs.dot(&xt), xt.dot(&xt));
                let g = Vector2::new(xs.dot(&(q - p)), xt.dot(&(q - p)));
                let Some(step) = j.try_inverse().map(|ji| -(ji * g)) else { break };
                let next = (st + step).map(|v| v.clamp(-1.0, 1.0));
                let moved = (next - st).norm();
                st = next;
                if moved < 1e-12 {
                    break;
                }
            }
            let n = shape(st[0], st[1]);
            let q: Vector3<f64> = (0..4).map(|k| x[k] * n[k]).sum();
            (n, (q - p).norm())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_points_on_a_triangle_and_a_quad() {
        // Reference: the point above the inside of a face projects along the normal (distance =
        // height, shape values = its barycentric / bilinear coordinates); a point beyond an edge
        // goes to the edge. Tolerance 1e-12.
        let t = [Vector3::new(0.0, 0.0, 0.0), Vector3::new(2.0, 0.0, 0.0), Vector3::new(0.0, 2.0, 0.0)];
        let (n, d) = closest_on_face(CellKind::Tri3, &t, &Vector3::new(0.5, 0.5, 3.0));
        assert!((d - 3.0).abs() < 1e-12 && (n[1] - 0.25).abs() < 1e-12 && (n[2] - 0.25).abs() < 1e-12);
        let (n, d) = closest_on_face(CellKind::Tri3, &t, &Vector3::new(1.0, -1.0, 0.0));
        assert!((d - 1.0).abs() < 1e-12 && (n[0] - 0.5).abs() < 1e-12 && (n[1] - 0.5).abs() < 1e-12);
        let q = [Vector3::new(0.0, 0.0, 0.0), Vector3::new(2.0, 0.0, 0.0), Vector3::new(2.0, 4.0, 0.0), Vector3::new(0.0, 4.0, 0.0)];
        let (n, d) = closest_on_face(CellKind::Quad4, &q, &Vector3::new(1.5, 1.0, -2.0));
        // s = 0.5, t = -0.5
        let exact = [0.25 * 0.5 * 1.5, 0.25 * 1.5 * 1.5, 0.25 * 1.5 * 0.5, 0.25 * 0.5 * 0.5];
        assert!((d - 2.0).abs() < 1e-12);
        for k in 0..4 {
            assert!((n[k] - exact[k]).abs() < 1e-12, "{n:?} vs {exact:?}");
        }
        let (_, d) = closest_on_face(CellKind::Quad4, &q, &Vector3::new(3.0, 2.0, 0.0));
        assert!((d - 1.0).abs() < 1e-12);
    }
}

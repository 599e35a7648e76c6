//! Nearest master node O (k-d tree), the candidate sets Layer1/Layer2, and slave-to-master distances
//! (design.md §3 items 2–5).
//!
//! - O: nearest master node by Euclidean distance (`kiddo` immutable k-d tree over the master
//!   nodes). Ties within `tie` [m] go to the lowest master-local index, so results do not depend
//!   on the tree's internal order.
//! - Layer1 of a slave node: the master faces containing O (ascending face index).
//! - Layer2: Layer1 plus every master face sharing a node with a Layer1 face (ascending, unique).
//! - Surface distance: closest-point distance from the slave node to the Layer2 faces (quads split
//!   along the diagonal 0–2 into two triangles, exact for planar quads).
//!
//! Everything is one pass over the slave nodes with reused buffers (no per-node allocation).

use super::normals::vec3;
use nalgebra::Vector3;
use super::{Csr, Surface};
use kiddo::{ImmutableKdTree, SquaredEuclidean};

/// Nearest master node (master-local index) and its distance [m] for each point, into the buffers.
///
/// `tie` [m]: a master node sharing a face with the tree's answer whose distance exceeds the
/// smallest by less than `tie` counts as equally near, and the lowest index wins (`0.0` keeps the
/// tree's answer). This settles the ties of structured meshes (a slave node at the centre of a
/// master face, or midway along an edge) independently of the tree's internal order, without a
/// second tree query. Results are deterministic in any case: each point is answered on its own.
pub fn nearest_master_nodes_into(master: &Surface, points: &[[f64; 3]], tie: f64, nearest: &mut [u32], distance: &mut [f64]) {
    assert_eq!(points.len(), nearest.len());
    assert_eq!(points.len(), distance.len());
    // A Surface always has at least one face, hence nodes; u32 items hold up to 4·10⁹ nodes.
    let tree: ImmutableKdTree<f64, 3> =
        ImmutableKdTree::new_from_slice(&master.points).expect("k-d tree over a non-empty master surface");
    for ((p, o), d) in points.iter().zip(nearest.iter_mut()).zip(distance.iter_mut()) {
        let nn = tree.query(p).nearest_one::<SquaredEuclidean<f64>>().execute();
        let mut best = nn.item;
        let dist = |l: u32| {
            (vec3(*p) - vec3(master.points[l as usize])).norm()
        };
        let mut dbest = dist(best);
        if tie > 0.0 {
            let limit = dbest + tie;
            for &f in master.faces_of_node(nn.item as usize) {
                for &l in master.faces[f as usize].local_nodes() {
                    if l < best {
                        let dl = dist(l);
                        if dl <= limit {
                            best = l;
                            dbest = dl;
                        }
                    }
                }
            }
        }
        *o = best;
        *d = dbest;
    }
}

/// Layer1 of each slave node: the master faces containing its O (`nearest`, master-local nodes).
pub fn layer1_candidates(master: &Surface, nearest: &[u32]) -> Csr {
    let mut csr = Csr::with_capacity(nearest.len(), 4 * nearest.len());
    for &o in nearest {
        csr.push_row(master.faces_of_node(o as usize));
    }
    csr
}

/// Layer2 of each slave node: its Layer1 plus every master face sharing a node with a Layer1 face.
pub fn layer2_candidates(master: &Surface, layer1: &Csr) -> Csr {
    let rows = layer1.rows();
    let mut csr = Csr::with_capacity(rows, 16 * rows);
    let mut buf: Vec<u32> = Vec::with_capacity(64);
    // stamp[f] == i + 1 once face f is in row i: dedup without sorting duplicates
    let mut stamp = vec![0u32; master.faces.len()];
    for i in 0..rows {
        buf.clear();
        let mark = i as u32 + 1;
        for &f in layer1.row(i) {
            for &l in master.faces[f as usize].local_nodes() {
                for &g in master.faces_of_node(l as usize) {
                    if stamp[g as usize] != mark {
                        stamp[g as usize] = mark;
                        buf.push(g);
                    }
                }
            }
        }
        buf.sort_unstable();
        csr.push_row(&buf);
    }
    csr
}

/// Distance [m] from each point to the union of its Layer2 master faces, into `out`.
///
/// A face is skipped when the distance to its
/// bounding sphere (centre = node average, radius = farthest node) is already ≥ the best distance.
pub fn master_surface_distances_into(master: &Surface, points: &[[f64; 3]], layer2: &Csr, out: &mut [f64]) {
    assert_eq!(points.len(), out.len());
    let spheres: Vec<(Vector3<f64>, f64)> = (0..master.faces.len())
        .map(|f| {
            let (x, n) = master.face_points(f);
            let c = x[..n].iter().fold(Vector3::zeros(), |s: Vector3<f64>, &q| s + vec3(q)) * (1.0 / n as f64);
            let r = x[..n].iter().map(|&q| (vec3(q) - c).norm()).fold(0.0, f64::max);
            (c, r * (1.0 + 1e-12))
        })
        .collect();
    for (i, (p, o)) in points.iter().zip(out.iter_mut()).enumerate() {
        let mut best = f64::INFINITY;
        for &f in layer2.row(i) {
            let (c, r) = spheres[f as usize];
            if (vec3(*p) - c).norm() - r >= best {
                continue;
            }
            let (x, n) = master.face_points(f as usize);
            best = best.min(point_triangle_distance(*p, x[0], x[1], x[2]));
            if n == 4 {
                best = best.min(point_triangle_distance(*p, x[0], x[2], x[3]));
            }
        }
        *o = best;
    }
}

/// Distance [m] from point `p` to the triangle (a, b, c) (closest point by Voronoi regions,
/// Ericson, Real-Time Collision Detection §5.1.5).
pub fn point_triangle_distance(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let (p, a, b, c) = (vec3(p), vec3(a), vec3(b), vec3(c));
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    let dist = |q: Vector3<f64>| (p - q).norm();
    if d1 <= 0.0 && d2 <= 0.0 {
        return dist(a);
    }
    let bp = p - b;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    if d3 >= 0.0 && d4 <= d3 {
        return dist(b);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return dist(a + ab * v);
    }
    let cp = p - c;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    if d6 >= 0.0 && d5 <= d6 {
        return dist(c);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return dist(a + ac * w);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return dist(b + (c - b) * w);
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    dist(a + (ab * v + ac * w))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reference: hand-computed distances to the unit right triangle in z = 0 (interior: height;
    /// edge and vertex regions: Pythagoras). Tolerance 1e-15.
    #[test]
    fn point_triangle_distance_regions() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let cases = [
            ([0.2, 0.2, 0.5], 0.5),                         // above the interior
            ([-1.0, -1.0, 0.0], 2f64.sqrt()),               // vertex a
            ([2.0, 0.0, 1.0], 2f64.sqrt()),                 // vertex b
            ([0.5, -2.0, 0.0], 2.0),                        // edge ab
            ([1.0, 1.0, 0.0], 0.5f64.sqrt()),               // edge bc
            ([-3.0, 0.5, 4.0], 5.0),                        // edge ca
        ];
        for (p, d) in cases {
            let got = point_triangle_distance(p, a, b, c);
            assert!((got - d).abs() < 1e-15, "{p:?}: {got} vs {d}");
        }
    }
}

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

/// Distance [m] from point `p` to the triangle (a, b, c): the closest point by Voronoi regions
/// of [`crate::mesh::geometry::closest_on_triangle`] (Ericson, Real-Time Collision Detection
/// §5.1.5), the one routine of the crate.
///
/// The point is rebuilt from the barycentric weights in the form of its region, as the tagger
/// computed it when it had its own copy of the routine: a vertex itself, a point of edge ab or
/// ac as a + (b − a) v or a + (c − a) w, of edge bc as b + (c − b) w, of the face as a + ((b −
/// a) v + (c − a) w), v and w being the very weights the routine returns. The rebuilt point
/// l₀ a + l₁ b + l₂ c would differ from those by round-off (of order 1e-16 of the face size),
/// and the distances are the tagger's output (the tolerance check, `interface::write`'s joint files):
/// this keeps them bit for bit (checked on the tagger's fixtures, the wedge and the contact
/// bench's state hash). Only a face point whose weight lands on exactly 0 or 1 by round-off
/// could take another form; both forms then are the same point to round-off.
pub fn point_triangle_distance(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let (p, a, b, c) = (vec3(p), vec3(a), vec3(b), vec3(c));
    let l = crate::mesh::geometry::closest_on_triangle(a, b, c, &p);
    let q = match l {
        [1.0, 0.0, 0.0] => a,
        [0.0, 1.0, 0.0] => b,
        [0.0, 0.0, 1.0] => c,
        [_, v, 0.0] => a + (b - a) * v,
        [_, 0.0, w] => a + (c - a) * w,
        [0.0, _, w] => b + (c - b) * w,
        [_, v, w] => a + ((b - a) * v + (c - a) * w),
    };
    (p - q).norm()
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

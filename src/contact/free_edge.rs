//! Where a lost slave node is: beyond the master surface's free edge, or lost inside its
//! outline (issue 32). A slave node is *lost* in a step when its projection along its normal
//! lands on no master face (`force`'s search). Two cases differ in meaning:
//!
//! - **beyond the free edge**: the projection lies outside the master surface's outer boundary
//!   (its free edges: edges on one face only), as when a block slides out past the end of the
//!   surface it rests on (the wedge daylighting on the slope, a dam joint's edge node sliding
//!   past the curved face). Nothing is there to touch: expected, reported as a note;
//! - **inside**: the projection lies within the master's outline but no face was found (a gap
//!   in the candidate set, a failed projection): the node carries no force where it should,
//!   the dangerous case, reported as a warning.
//!
//! The test ([`lost_where`]) is pure geometry on the faces near the node: the free edge nearest
//! the slave node, and on which side of it (in the plane of its face) the node's projection
//! along its normal lies. Conventions as in `contact` (module doc): `n` is the slave node's
//! outward unit normal; positions in m. A face's corners are in its outward node order.

use crate::interface::Surface;
use nalgebra::Vector3;

/// Where a lost slave node is (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LostWhere {
    BeyondFreeEdge,
    Inside,
}

/// A master face near a lost node: its corners (3 or 4, outward order; `corners[3]` unused for a
/// triangle) and which of its edges are free. Edge `k` runs from corner `k` to corner `k + 1`
/// (cyclically); free = on no other face of the master surface.
#[derive(Clone, Copy, Debug)]
pub struct OutlineFace {
    pub corners: [Vector3<f64>; 4],
    pub n: usize,
    pub free: [bool; 4],
}

/// Whether the slave node at `xs` with unit normal `normal` lies beyond the free edge nearest
/// to it among `faces`, or inside the outline (also when no face has a free edge).
///
/// Beyond: its projection along `normal` onto the plane of that edge's face (the orthogonal
/// projection when `normal` is nearly parallel to the plane, |n · n_f| < 0.1) lies on the outer
/// side of the edge, the side away from the face's centroid.
pub fn lost_where(faces: &[OutlineFace], xs: &Vector3<f64>, normal: &Vector3<f64>) -> LostWhere {
    // (distance², face, edge) of the nearest free edge
    let mut best: Option<(f64, usize, usize)> = None;
    for (fi, f) in faces.iter().enumerate() {
        for k in (0..f.n).filter(|&k| f.free[k]) {
            let (a, b) = (f.corners[k], f.corners[(k + 1) % f.n]);
            let d2 = segment_distance2(xs, &a, &b);
            if best.is_none_or(|(d, _, _)| d2 < d) {
                best = Some((d2, fi, k));
            }
        }
    }
    let Some((_, fi, k)) = best else { return LostWhere::Inside };
    let f = &faces[fi];
    let (a, b) = (f.corners[k], f.corners[(k + 1) % f.n]);
    let centroid = f.corners[..f.n].iter().sum::<Vector3<f64>>() / f.n as f64;
    // the face normal from two diagonals (a triangle: two edges)
    let nf = match f.n {
        4 => (f.corners[2] - f.corners[0]).cross(&(f.corners[3] - f.corners[1])),
        _ => (f.corners[1] - f.corners[0]).cross(&(f.corners[2] - f.corners[0])),
    };
    let Some(nf) = nf.try_normalize(1e-300) else { return LostWhere::Inside };
    let c = nf.dot(normal);
    let xp = if c.abs() >= 0.1 { xs + normal * (nf.dot(&(a - xs)) / c) } else { xs - nf * nf.dot(&(xs - a)) };
    let mut out = (b - a).cross(&nf);
    if out.dot(&(centroid - a)) > 0.0 {
        out = -out;
    }
    if out.dot(&(xp - a)) > 0.0 { LostWhere::BeyondFreeEdge } else { LostWhere::Inside }
}

/// Squared distance from `p` to the segment `a`–`b`.
fn segment_distance2(p: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let ab = b - a;
    let l2 = ab.norm_squared();
    let t = if l2 > 0.0 { ((p - a).dot(&ab) / l2).clamp(0.0, 1.0) } else { 0.0 };
    (p - (a + ab * t)).norm_squared()
}

/// The faces `faces` of `master` as [`OutlineFace`]s at the positions `position(mesh node)`:
/// an edge is free when no other face of the surface holds both its nodes.
pub fn outline_faces(master: &Surface, faces: &[u32], position: impl Fn(usize) -> Vector3<f64>) -> Vec<OutlineFace> {
    faces
        .iter()
        .map(|&fi| {
            let f = &master.faces[fi as usize];
            let (local, nodes) = (f.local_nodes(), f.nodes());
            let n = local.len();
            let mut o = OutlineFace { corners: [Vector3::zeros(); 4], n, free: [false; 4] };
            for k in 0..n {
                o.corners[k] = position(nodes[k] as usize);
                let (a, b) = (local[k], local[(k + 1) % n]);
                o.free[k] = !master.faces_of_node(a as usize).iter().any(|&g| g != fi && master.faces[g as usize].local_nodes().contains(&b));
            }
            o
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2 × 1 strip of unit squares in the plane z = 0 (x in 0..2, y in 0..1), normal +z: its
    /// outline is the rectangle's boundary; the middle edge x = 1 is shared.
    fn strip() -> Vec<OutlineFace> {
        let v = |x: f64, y: f64| Vector3::new(x, y, 0.0);
        vec![
            OutlineFace { corners: [v(0.0, 0.0), v(1.0, 0.0), v(1.0, 1.0), v(0.0, 1.0)], n: 4, free: [true, false, true, true] },
            OutlineFace { corners: [v(1.0, 0.0), v(2.0, 0.0), v(2.0, 1.0), v(1.0, 1.0)], n: 4, free: [true, true, true, false] },
        ]
    }

    #[test]
    fn a_node_past_the_outline_is_beyond_the_free_edge_and_one_over_the_middle_is_inside() {
        // slave normal pointing down onto the master (−z), node 1 cm above it
        let n = Vector3::new(0.0, 0.0, -1.0);
        // slid 0.3 m past the right end (x = 2)
        assert_eq!(lost_where(&strip(), &Vector3::new(2.3, 0.5, 0.01), &n), LostWhere::BeyondFreeEdge);
        // past the long side y = 0, near the shared edge
        assert_eq!(lost_where(&strip(), &Vector3::new(1.0, -0.2, 0.01), &n), LostWhere::BeyondFreeEdge);
        // over the middle of the strip (a node the search failed to place): inside
        assert_eq!(lost_where(&strip(), &Vector3::new(1.05, 0.5, 0.01), &n), LostWhere::Inside);
        // just inside the right end
        assert_eq!(lost_where(&strip(), &Vector3::new(1.95, 0.5, 0.01), &n), LostWhere::Inside);
        // a tilted normal carries the projection: the node is above x = 1.9 but its line along
        // n = (1, 0, −1)/√2 from 0.2 m up meets the plane at x = 2.1, past the end
        let tilted = Vector3::new(1.0, 0.0, -1.0).normalize();
        assert_eq!(lost_where(&strip(), &Vector3::new(1.9, 0.5, 0.2), &tilted), LostWhere::BeyondFreeEdge);
        // no free edge among the faces given: inside
        let mut closed = strip();
        for f in &mut closed {
            f.free = [false; 4];
        }
        assert_eq!(lost_where(&closed, &Vector3::new(2.3, 0.5, 0.01), &n), LostWhere::Inside);
    }
}

//! Polygon clipping in the auxiliary plane (Sutherland–Hodgman): the overlap of a slave face
//! and a master face, both projected and convex, as a convex polygon (2-D coordinates, m).

/// At most this many vertices in a clipped polygon: a convex quad clipped by a convex quad has
/// at most 8; the buffers keep room for 16.
pub const MAX_VERTICES: usize = 16;

/// A polygon of at most [`MAX_VERTICES`] vertices (2-D), on the stack.
#[derive(Clone, Copy, Debug)]
pub struct Polygon {
    pub v: [[f64; 2]; MAX_VERTICES],
    pub len: usize,
}

impl Polygon {
    pub fn from_points(p: &[[f64; 2]]) -> Polygon {
        let mut v = [[0.0; 2]; MAX_VERTICES];
        v[..p.len()].copy_from_slice(p);
        Polygon { v, len: p.len() }
    }

    pub fn points(&self) -> &[[f64; 2]] {
        &self.v[..self.len]
    }

    /// Signed area (positive counter-clockwise) [m²].
    pub fn signed_area(&self) -> f64 {
        signed_area(self.points())
    }

    fn push(&mut self, p: [f64; 2]) {
        if self.len < MAX_VERTICES {
            self.v[self.len] = p;
            self.len += 1;
        }
    }
}

/// Signed area of a polygon (shoelace; positive counter-clockwise) [m²].
pub fn signed_area(p: &[[f64; 2]]) -> f64 {
    let n = p.len();
    let mut a = 0.0;
    for k in 0..n {
        let (x, y) = (p[k], p[(k + 1) % n]);
        a += x[0] * y[1] - x[1] * y[0];
    }
    0.5 * a
}

#[inline]
fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// The part of `subject` inside the convex, counter-clockwise polygon `clip`
/// (Sutherland–Hodgman: `subject` cut by the half-plane left of each edge of `clip` in turn).
/// Empty (`len` 0) when they do not overlap; may have fewer than 3 vertices or zero area when
/// they only touch (the caller drops those).
pub fn clip_convex(subject: &Polygon, clip: &[[f64; 2]]) -> Polygon {
    let mut out = *subject;
    let m = clip.len();
    for e in 0..m {
        if out.len == 0 {
            break;
        }
        let (a, b) = (clip[e], clip[(e + 1) % m]);
        let input = out;
        out.len = 0;
        let pts = input.points();
        for k in 0..pts.len() {
            let (p, q) = (pts[k], pts[(k + 1) % pts.len()]);
            let (dp, dq) = (cross(a, b, p), cross(a, b, q));
            if dp >= 0.0 {
                out.push(p);
            }
            if (dp >= 0.0) != (dq >= 0.0) {
                // the edge p → q crosses the line a → b
                let t = dp / (dp - dq);
                out.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two unit squares shifted by (0.5, 0.25) overlap in a 0.5 × 0.75 rectangle (area 0.375);
    /// a triangle inside a square is returned whole; disjoint squares give nothing.
    /// Reference: elementary geometry; tolerance 1e-15 (round-off).
    #[test]
    fn clipping_gives_the_overlap_of_convex_polygons() {
        let sq = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let shifted: Vec<[f64; 2]> = sq.iter().map(|p| [p[0] + 0.5, p[1] + 0.25]).collect();
        let c = clip_convex(&Polygon::from_points(&shifted), &sq);
        assert!((c.signed_area() - 0.375).abs() < 1e-15, "{:?}", c.points());
        let tri = [[0.2, 0.2], [0.8, 0.2], [0.2, 0.8]];
        let c = clip_convex(&Polygon::from_points(&tri), &sq);
        assert!((c.signed_area() - 0.18).abs() < 1e-15);
        let far: Vec<[f64; 2]> = sq.iter().map(|p| [p[0] + 2.0, p[1]]).collect();
        let c = clip_convex(&Polygon::from_points(&far), &sq);
        assert!(c.len < 3 || c.signed_area().abs() < 1e-15);
    }
}

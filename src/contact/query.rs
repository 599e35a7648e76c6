//! Local search geometry (node-to-segment, inside-outside; design.md §5).
//!
//! A slave node `x_s` is projected **along its normal** `n` (not by closest point) onto a
//! master face: the master point is `x̄ = x_s + t n` on the face. Sign conventions are those
//! of [`crate::contact`]; `n` is normalised here, so `t` and the gap are distances (m).
//!
//! **Inside-outside test.** For each edge `a → b` of the face (edge `e` runs from local node
//! `e` to node `e + 1 mod n_nodes`),
//!
//! ```text
//! Δ_e = n · ((x_b − x_a) × (x_p − x_a))
//! ```
//!
//! The point is inside when every `Δ_e` has the same sign; that sign is the sign `s` of
//! `n · m`, where `m` is the face's right-hand normal (for a quad, the cross product of its
//! diagonals). `Δ_e / |n × (x_b − x_a)|` is the signed distance of `x_p` from the edge *as
//! seen along `n`*, so the tolerance is a distance: the point is accepted when
//! `s Δ_e / |n × (x_b − x_a)| ≥ −tol h` for every edge, with `h` the longest edge of the face.
//! Edges with `|s Δ_e| / |n × (x_b − x_a)| ≤ tol h` are the edges the point lies on, which gives
//! [`Location`].
//!
//! Because the test looks along the slave normal, a slave node near a convex corner of a
//! folded master surface always lands on one of the faces; the closest-point projection has
//! a dead zone there (it lands outside both faces).
//!
//! Non-finite inputs give `None` (the explicit solver reports non-finite positions itself).

use nalgebra::{Vector2, Vector3};
use thiserror::Error;

/// Inside tolerance (dimensionless, fraction of the face's longest edge): 1e-8.
///
/// Why: a point on an edge shared by two faces must pass the test of both faces, or it could
/// be lost between them by round-off (Δ is computed from different nodes for each face, with
/// errors of order 1e-16 h). 1e-8 h is far above round-off and far below any physical
/// displacement of a step. Must be > 0.
pub const INSIDE_TOL_DEFAULT: f64 = 1e-8;

/// Below this `|n̂ · m̂|` (cosine between the slave normal and the face normal) the line is taken
/// as parallel to the face and the face is not hit. 1e-12: only exactly edge-on faces.
const PARALLEL_COS: f64 = 1e-12;

/// Newton iterations before the analytic fallback for quads (design: ~20). Newton from the
/// centre converges quadratically in 3–6 iterations on any reasonable quad.
const QUAD_NEWTON_MAX_ITER: usize = 20;

/// Newton step below which the quad local solve has converged (dimensionless in ξ; `t` scaled by `h`).
const QUAD_NEWTON_STEP_TOL: f64 = 1e-13;

/// Where on the face the projected point landed (local numbering of the face, Gmsh order).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Location {
    /// Strictly inside (farther than `tol h` from every edge).
    Inside,
    /// On edge `e` (from local node `e` to node `e + 1 mod n_nodes`), within `tol h`.
    Edge(u8),
    /// On local node `v` (on both edges meeting there), within `tol h`.
    Vertex(u8),
}

impl Location {
    /// Preference when several faces are hit at the same distance: inside first.
    fn rank(self) -> u8 {
        match self {
            Location::Inside => 0,
            Location::Edge(_) => 1,
            Location::Vertex(_) => 2,
        }
    }
}

/// Where the line from a slave node along its normal meets a master face (and is inside it).
#[derive(Clone, Debug, PartialEq)]
pub struct Projection {
    /// The master point `x̄ = x_s + t n` on the face (m).
    pub point: Vector3<f64>,
    /// Signed distance along the unit normal from `x_s` to `x̄` (m).
    pub t: f64,
    /// Gap `g = n · (x̄ − x_s)` (m): positive open, negative penetration. Equal to `t` (unit `n`);
    /// kept as its own field so callers read the intent.
    pub gap: f64,
    /// Local coordinates on the face: tri3 `(ξ1, ξ2) = (N_1, N_2)` on the reference triangle
    /// (0,0),(1,0),(0,1); quad4 `(ξ1, ξ2)` in `[-1, 1]²`.
    pub xi: [f64; 2],
    /// Shape-function values `N_I` at `xi` for the face's nodes in order; unused entries are 0.
    /// They sum to 1 and reproduce `point`.
    pub weights: [f64; 4],
    /// Number of face nodes (3 or 4).
    pub n_nodes: u8,
    /// Inside, on an edge, or on a vertex.
    pub location: Location,
}

/// The nodes of one master face: 3 (tri3) or 4 (quad4) points, Gmsh order.
pub type FaceNodes<'a> = &'a [Vector3<f64>];

/// The local solve on a bilinear quad failed: Newton did not converge and the analytic solve
/// could not give an answer either.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum QuadProjectionError {
    #[error(
        "local search on a quad4 master face failed: Newton did not converge in {iterations} iterations \
         (last residual {residual:.3e} m) and the analytic solve failed ({reason}). The face is degenerate \
         or strongly warped as seen along the slave normal: remesh the master surface with better-shaped \
         quads, or mesh it with triangles"
    )]
    NoSolution { iterations: usize, residual: f64, reason: &'static str },
}

/// Failure of [`select_projection`] on one candidate face.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum SearchError {
    #[error("master face {face}: {source}")]
    Quad {
        face: usize,
        #[source]
        source: QuadProjectionError,
    },
    #[error("master face {face} has {n_nodes} nodes; contact faces must be tri3 (3 nodes) or quad4 (4 nodes)")]
    FaceNodes { face: usize, n_nodes: usize },
}

/// Longest edge of a closed polygon (m).
fn face_size(x: &[Vector3<f64>]) -> f64 {
    let n = x.len();
    // one square root: the root of the largest square is the largest root, exactly; the max by
    // comparison (`f64::max`'s NaN handling was a twelfth of a quad projection's time; a NaN edge
    // cannot reach here, the callers test the nodes for finiteness first)
    let mut m2 = 0.0;
    for e in 0..n {
        let l2 = (x[(e + 1) % n] - x[e]).norm_squared();
        if l2 > m2 {
            m2 = l2;
        }
    }
    m2.sqrt()
}

/// `n` normalised; `n` itself when it is already unit to round-off (a slave normal always is),
/// which saves a root and a division per projection. `None` for a zero vector.
fn unit(n: &Vector3<f64>) -> Option<Vector3<f64>> {
    if (n.norm_squared() - 1.0).abs() <= 8.0 * f64::EPSILON { Some(*n) } else { n.try_normalize(0.0) }
}

/// The sign of `n · m` (which side of the face `n` sees, for the inside test), or `None` when the
/// face is degenerate (`|m| ≤ 1e-14 h²`, `m` the face normal of length twice the area for a
/// triangle, the diagonals' cross product for a quad) or seen edge-on (`|n · m̂| <`
/// [`PARALLEL_COS`]). Compared through squares: no root or division.
fn facing_sign(n: &Vector3<f64>, m: &Vector3<f64>, h: f64) -> Option<f64> {
    let m2 = m.norm_squared();
    let h2 = h * h;
    if m2.is_nan() || m2 <= 1e-28 * h2 * h2 {
        return None;
    }
    let nm = n.dot(m);
    if nm * nm < PARALLEL_COS * PARALLEL_COS * m2 {
        return None;
    }
    Some(nm.signum())
}

fn all_finite(v: &[Vector3<f64>]) -> bool {
    v.iter().all(|p| p.iter().all(|c| c.is_finite()))
}

/// Inside-outside test of `p` against the polygon `x` seen along the unit normal `n`.
/// `s` is the orientation sign (sign of `n · m`), `h` the face size. Returns the location, or
/// `None` when the point is outside by more than `tol h` across some edge.
fn inside_outside(
    x: &[Vector3<f64>],
    n: &Vector3<f64>,
    p: &Vector3<f64>,
    s: f64,
    h: f64,
    tol: f64,
) -> Option<Location> {
    let k = x.len();
    let band = tol * h;
    let mut on = [false; 4];
    for e in 0..k {
        let (a, b) = (x[e], x[(e + 1) % k]);
        let edge = b - a;
        // Δ = n · (edge × (p − a)) = (n × edge) · (p − a): one cross product for Δ and the length
        let c = n.cross(&edge);
        let delta = c.dot(&(p - a));
        let len2 = c.norm_squared();
        // Signed distance from the edge seen along n (positive inside): d = s Δ / |n × edge|,
        // compared with the band through its square (no root or division per edge). An edge
        // parallel to n has no extent in the view: the point is on it (d = 0).
        let sd = s * delta;
        if sd.is_nan() || len2.is_nan() {
            return None;
        }
        if len2 == 0.0 {
            on[e] = true;
            continue;
        }
        let band2 = band * band * len2;
        if sd < 0.0 && sd * sd > band2 {
            return None;
        }
        on[e] = sd <= 0.0 || sd * sd <= band2;
    }
    for v in 0..k {
        if on[(v + k - 1) % k] && on[v] {
            return Some(Location::Vertex(v as u8));
        }
    }
    Some(match (0..k).find(|&e| on[e]) {
        Some(e) => Location::Edge(e as u8),
        None => Location::Inside,
    })
}

/// Project `xs` along `n` onto the triangle `[a, b, c]` (Gmsh tri3 order).
///
/// `n`: the slave normal (normalised here). `tol`: inside tolerance as a fraction of the
/// longest edge ([`INSIDE_TOL_DEFAULT`]). Returns `None` when the line is parallel to the
/// triangle's plane, the triangle is degenerate, or the intersection is outside the triangle.
pub fn project_along_on_tri(
    xs: &Vector3<f64>,
    n: &Vector3<f64>,
    x: [&Vector3<f64>; 3],
    tol: f64,
) -> Option<Projection> {
    let [a, b, c] = x;
    let nodes = [*a, *b, *c];
    if !all_finite(&nodes) || !all_finite(&[*xs, *n]) {
        return None;
    }
    let n = unit(n)?;
    let m = (b - a).cross(&(c - a)); // right-hand normal, |m| = 2 area
    let h = face_size(&nodes);
    let s = facing_sign(&n, &m, h)?;
    // Plane m · (x − a) = 0 with x = xs + t n.
    let t = m.dot(&(a - xs)) / n.dot(&m);
    let p = xs + n * t;
    let location = inside_outside(&nodes, &n, &p, s, h, tol)?;
    // Barycentric weights: sub-triangle areas over the total area (signed, exact on the plane).
    let inv_m2 = 1.0 / m.norm_squared();
    let w0 = m.dot(&(b - p).cross(&(c - p))) * inv_m2;
    let w1 = m.dot(&(c - p).cross(&(a - p))) * inv_m2;
    let w2 = 1.0 - w0 - w1;
    Some(Projection { point: p, t, gap: t, xi: [w1, w2], weights: [w0, w1, w2, 0.0], n_nodes: 3, location })
}

/// The bilinear quad written as `x(ξ) = c0 + ξ1 c1 + ξ2 c2 + ξ1 ξ2 c12`.
struct Bilinear {
    c0: Vector3<f64>,
    c1: Vector3<f64>,
    c2: Vector3<f64>,
    c12: Vector3<f64>,
}

impl Bilinear {
    fn new(x: &[Vector3<f64>; 4]) -> Self {
        Bilinear {
            c0: (x[0] + x[1] + x[2] + x[3]) * 0.25,
            c1: (-x[0] + x[1] + x[2] - x[3]) * 0.25,
            c2: (-x[0] - x[1] + x[2] + x[3]) * 0.25,
            c12: (x[0] - x[1] + x[2] - x[3]) * 0.25,
        }
    }
    fn at(&self, xi: [f64; 2]) -> Vector3<f64> {
        self.c0 + self.c1 * xi[0] + self.c2 * xi[1] + self.c12 * (xi[0] * xi[1])
    }
}

/// Quad4 shape functions `N_I = ¼ (1 + ξ1 ξ1I)(1 + ξ2 ξ2I)`, Gmsh order.
fn quad_weights(xi: [f64; 2]) -> [f64; 4] {
    let [a, b] = xi;
    [
        0.25 * (1.0 - a) * (1.0 - b),
        0.25 * (1.0 + a) * (1.0 - b),
        0.25 * (1.0 + a) * (1.0 + b),
        0.25 * (1.0 - a) * (1.0 + b),
    ]
}

/// Outcome of the Newton local solve on a quad.
enum Newton {
    Converged {
        xi: [f64; 2],
        /// Distance along n; the caller recomputes it from the final point, the tests read it.
        #[cfg_attr(not(test), allow(dead_code))]
        t: f64,
    },
    Failed {
        iterations: usize,
        residual: f64,
    },
}

/// Solve `[a b c] x = r` by Cramer's rule (the 3 × 3 Jacobian of the quad projection; cheaper
/// than an LU factorisation with pivoting, which was a sixth of the contact search's time), with
/// one division. Returns the solution, `1 / det` and `b × c` (the chord steps of
/// [`quad_local_newton`] reuse them). `None` when the determinant is zero or the solution is not
/// finite (a singular Jacobian: the normal lies in the quad's tangent plane).
fn solve_3x3_by_columns(a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>, r: &Vector3<f64>) -> Option<(Vector3<f64>, f64, Vector3<f64>)> {
    let bc = b.cross(c);
    let det = a.dot(&bc);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let x = Vector3::new(r.dot(&bc) * inv, a.dot(&r.cross(c)) * inv, a.dot(&b.cross(r)) * inv);
    x.iter().all(|v| v.is_finite()).then_some((x, inv, bc))
}

/// Chord steps after a Newton step, before a full Newton step is taken again.
const QUAD_CHORD_MAX_STEPS: usize = 6;

/// Newton on `x(ξ) − xs − t n = 0` for `(ξ1, ξ2, t)`, from `xi0` (the centre, or the node's
/// local coordinates of the last step). `n` unit, `h` face size. Converged when a step is below
/// [`QUAD_NEWTON_STEP_TOL`].
///
/// Near the root (a step below 1e-3) it goes on with chord steps, which need no new residual or
/// Jacobian: the map is bilinear, so after a step `s` from the point `ξ_J` where the Jacobian J
/// was taken the residual is exactly `ρ c12` with `ρ = s1 s2`, and after a chord step `s` from
/// `ξ_J + δ` it is `ρ c12` with `ρ = δ2 s1 + δ1 s2 + s1 s2`. So every chord step is
/// `−ρ J⁻¹ c12`, with `J⁻¹ c12` solved once. They contract by about `|c12| |δ| |J⁻¹|` (1e-8 on
/// a node that stays on its face); if they do not reach the tolerance, full Newton steps resume.
fn quad_local_newton(q: &Bilinear, xs: &Vector3<f64>, n: &Vector3<f64>, h: f64, max_iter: usize, xi0: [f64; 2]) -> Newton {
    let inv_h = 1.0 / h;
    let mut xi = xi0;
    let p0 = q.at(xi) - xs;
    let mut t = n.dot(&p0);
    let mut f = p0 - n * t;
    let residual = |xi: [f64; 2], t: f64| q.at(xi) - xs - n * t;
    // the step measure, max by comparison (`f64::max`'s NaN handling was a tenth of a projection;
    // a non-finite step is caught by `ok` before its size is taken)
    let max = |a: f64, b: f64| if a > b { a } else { b };
    let size_of = |s: &Vector3<f64>| max(max(s[0].abs(), s[1].abs()), s[2].abs() * inv_h);
    let ok = |xi: [f64; 2], t: f64| xi[0].abs() < 1e6 && xi[1].abs() < 1e6 && t.is_finite();
    let c = -n;
    for it in 0..max_iter {
        if it > 0 {
            f = residual(xi, t);
        }
        let (ja, jb) = (q.c1 + q.c12 * xi[1], q.c2 + q.c12 * xi[0]);
        let Some((step, inv, bc)) = solve_3x3_by_columns(&ja, &jb, &c, &(-f)) else {
            return Newton::Failed { iterations: it, residual: f.norm() };
        };
        xi[0] += step[0];
        xi[1] += step[1];
        t += step[2];
        if !ok(xi, t) {
            return Newton::Failed { iterations: it + 1, residual: f64::INFINITY };
        }
        let size = size_of(&step);
        if size <= QUAD_NEWTON_STEP_TOL {
            return Newton::Converged { xi, t };
        }
        if size < 1e-3 {
            let v = Vector3::new(q.c12.dot(&bc) * inv, ja.dot(&q.c12.cross(&c)) * inv, ja.dot(&jb.cross(&q.c12)) * inv);
            let (mut d1, mut d2) = (step[0], step[1]);
            let mut rho = step[0] * step[1];
            for _ in 0..QUAD_CHORD_MAX_STEPS {
                let s = v * -rho;
                xi[0] += s[0];
                xi[1] += s[1];
                t += s[2];
                if !ok(xi, t) {
                    return Newton::Failed { iterations: it + 1, residual: f64::INFINITY };
                }
                if size_of(&s) <= QUAD_NEWTON_STEP_TOL {
                    return Newton::Converged { xi, t };
                }
                rho = d2 * s[0] + d1 * s[1] + s[0] * s[1];
                d1 += s[0];
                d2 += s[1];
            }
        }
    }
    Newton::Failed { iterations: max_iter, residual: residual(xi, t).norm() }
}

/// Analytic solve of the two bilinear equations `A ξ1ξ2 + B ξ1 + C ξ2 + D = 0` (the components of
/// `x(ξ) − xs` along two tangents orthogonal to `n`, which eliminates `t`). Eliminating `ξ1`
/// leaves a quadratic in `ξ2`. Of its real roots, the one inside `[-1, 1]²` (nearest along `n`
/// if two are) is returned, else the one closest to the square. `Ok(None)`: the line does not
/// meet the bilinear surface (no real root).
fn quad_local_analytic(
    q: &Bilinear,
    xs: &Vector3<f64>,
    n: &Vector3<f64>,
    h: f64,
) -> Result<Option<[f64; 2]>, &'static str> {
    let (t1, t2) = tangent_frame(n);
    let proj = |v: &Vector3<f64>| Vector2::new(t1.dot(v), t2.dot(v));
    let (a, b, c, d) = (proj(&q.c12), proj(&q.c1), proj(&q.c2), proj(&(q.c0 - xs)));
    // (A1 ξ2 + B1)(C2 ξ2 + D2) − (A2 ξ2 + B2)(C1 ξ2 + D1) = 0
    let qa = a.x * c.y - a.y * c.x;
    let qb = a.x * d.y + b.x * c.y - a.y * d.x - b.y * c.x;
    let qc = b.x * d.y - b.y * d.x;
    let scale = h * h; // the coefficients are areas
    let tiny = 1e-14 * scale;
    let mut roots = [f64::NAN; 2];
    if qa.abs() <= tiny && qb.abs() <= tiny {
        return Err("the quad is degenerate as seen along the normal (zero projected area)");
    }
    if qa == 0.0 {
        roots[0] = -qc / qb;
    } else {
        let mut disc = qb * qb - 4.0 * qa * qc;
        if disc < 0.0 {
            if disc >= -1e-12 * qb * qb {
                disc = 0.0; // a double root perturbed by round-off
            } else {
                return Ok(None);
            }
        }
        // Stable roots: q/qa and qc/q with q = −(qb + sign(qb) √disc) / 2.
        let qq = -0.5 * (qb + qb.signum() * disc.sqrt());
        roots[0] = qq / qa;
        if qq != 0.0 {
            roots[1] = qc / qq;
        }
    }
    let mut best: Option<([f64; 2], bool, f64, f64)> = None; // (xi, inside square, |t|, max|xi|)
    for &x2 in roots.iter().filter(|r| r.is_finite()) {
        let (den1, den2) = (a.x * x2 + b.x, a.y * x2 + b.y);
        let x1 = if den1.abs() >= den2.abs() { -(c.x * x2 + d.x) / den1 } else { -(c.y * x2 + d.y) / den2 };
        if !x1.is_finite() {
            continue;
        }
        let xi = [x1, x2];
        let size = x1.abs().max(x2.abs());
        let inside = size <= 1.0 + 1e-9;
        let dist = n.dot(&(q.at(xi) - xs)).abs();
        let better = match best {
            None => true,
            Some((_, b_in, b_t, b_size)) => match (inside, b_in) {
                (true, false) => true,
                (false, true) => false,
                (true, true) => dist < b_t,
                (false, false) => size < b_size,
            },
        };
        if better {
            best = Some((xi, inside, dist, size));
        }
    }
    match best {
        Some((xi, ..)) => Ok(Some(xi)),
        None => Err("the quad is degenerate as seen along the normal (no finite local coordinates)"),
    }
}

/// The tangent frame of a unit normal `n`: a deterministic orthonormal pair `(t1, t2)` with
/// `(n, t1, t2)` right-handed. `t1` is the axis least aligned with `n` (x before y before z on a
/// tie) with its component along `n` removed, normalised; `t2 = n × t1`. The one frame rule of
/// the crate: the pairs' local frames and the quad projection's analytic solve use it.
pub fn tangent_frame(n: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let a = if n.x.abs() <= n.y.abs() && n.x.abs() <= n.z.abs() {
        Vector3::x()
    } else if n.y.abs() <= n.z.abs() {
        Vector3::y()
    } else {
        Vector3::z()
    };
    let t1 = (a - n * n.dot(&a)).normalize();
    let t2 = n.cross(&t1);
    (t1, t2)
}

/// Project `xs` along `n` onto the bilinear quad `[x0, x1, x2, x3]` (Gmsh quad4 order:
/// (-1,-1), (1,-1), (1,1), (-1,1)).
///
/// Solves `Σ N_I(ξ) x_I = xs + t n` for `(ξ1, ξ2, t)` by Newton from the centre; if Newton does
/// not converge within 20 iterations, by the analytic solution of the bilinear system (a
/// quadratic). The inside test is the edge test of the module doc on the projected point.
/// `Ok(None)`: no contact (parallel, no intersection, or outside). `Err`: neither solve worked.
pub fn project_along_on_quad(
    xs: &Vector3<f64>,
    n: &Vector3<f64>,
    x: [&Vector3<f64>; 4],
    tol: f64,
) -> Result<Option<Projection>, QuadProjectionError> {
    project_quad_with(xs, n, x, tol, QUAD_NEWTON_MAX_ITER, [0.0, 0.0])
}

/// [`project_along_on_quad`] with Newton started from `xi0` instead of the centre: a node that
/// stays on its face starts from its local coordinates of the last step and converges in one
/// Newton solve and one or two chord steps instead of four solves. The same equations and the same root (to the Newton
/// tolerance); a start that is not finite or far outside the face (|ξ| > 2) falls back to the
/// centre.
pub fn project_along_on_quad_from(
    xs: &Vector3<f64>,
    n: &Vector3<f64>,
    x: [&Vector3<f64>; 4],
    tol: f64,
    xi0: [f64; 2],
) -> Result<Option<Projection>, QuadProjectionError> {
    let xi0 = if xi0.iter().all(|v| v.is_finite() && v.abs() <= 2.0) { xi0 } else { [0.0, 0.0] };
    project_quad_with(xs, n, x, tol, QUAD_NEWTON_MAX_ITER, xi0)
}

/// [`project_along_on_quad`] with the Newton iteration budget as a parameter (0 forces the
/// analytic solve; used by the tests to exercise the fallback).
fn project_quad_with(
    xs: &Vector3<f64>,
    n: &Vector3<f64>,
    x: [&Vector3<f64>; 4],
    tol: f64,
    max_newton: usize,
    xi0: [f64; 2],
) -> Result<Option<Projection>, QuadProjectionError> {
    let nodes = [*x[0], *x[1], *x[2], *x[3]];
    if !all_finite(&nodes) || !all_finite(&[*xs, *n]) {
        return Ok(None);
    }
    let Some(n) = unit(n) else { return Ok(None) };
    let h = face_size(&nodes);
    let m = (nodes[2] - nodes[0]).cross(&(nodes[3] - nodes[1])); // centre normal (diagonals)
    let Some(cos_sign) = facing_sign(&n, &m, h) else { return Ok(None) };
    let q = Bilinear::new(&nodes);
    let xi = match quad_local_newton(&q, xs, &n, h, max_newton, xi0) {
        Newton::Converged { xi, .. } => xi,
        Newton::Failed { iterations, residual } => match quad_local_analytic(&q, xs, &n, h) {
            Ok(Some(xi)) => {
                // Guard the analytic root: it must satisfy the 3D equations.
                let p = q.at(xi);
                let off = (p - xs) - n * n.dot(&(p - xs));
                let size = xi[0].abs().max(xi[1].abs()).max(1.0);
                if off.norm() > 1e-8 * h * size * size {
                    return Err(QuadProjectionError::NoSolution {
                        iterations,
                        residual,
                        reason: "the analytic root does not satisfy the projection equations",
                    });
                }
                xi
            }
            Ok(None) => return Ok(None),
            Err(reason) => return Err(QuadProjectionError::NoSolution { iterations, residual, reason }),
        },
    };
    let point = q.at(xi);
    let t = n.dot(&(point - xs));
    let location = match inside_outside(&nodes, &n, &point, cos_sign, h, tol) {
        Some(l) => l,
        None => return Ok(None),
    };
    Ok(Some(Projection { point, t, gap: t, xi, weights: quad_weights(xi), n_nodes: 4, location }))
}

/// Project `xs` along `n` onto every candidate face and choose exactly one.
///
/// Candidates are `(face id, nodes)` with 3 or 4 nodes. The rule, independent of the order of
/// the candidates:
/// 1. keep the faces whose inside test passes (with tolerance `tol`, so a point on a shared
///    edge or vertex passes on every face around it);
/// 2. nearest along `n`: keep those with `|t|` within `tol h_max` of the smallest `|t|`
///    (`h_max` = largest face size among them). On a folded master surface that the line
///    crosses several times, the contact is with the nearest sheet;
/// 3. strictly inside before on an edge before on a vertex;
/// 4. the smallest face id.
///
/// `Ok(None)`: no face is hit (the caller widens the candidate set or reports the node).
pub fn select_projection<'a>(
    xs: &Vector3<f64>,
    n: &Vector3<f64>,
    candidates: impl IntoIterator<Item = (usize, FaceNodes<'a>)>,
    tol: f64,
) -> Result<Option<(usize, Projection)>, SearchError> {
    let mut hits: Vec<(usize, Projection, f64)> = Vec::new();
    for (face, x) in candidates {
        let p = match x.len() {
            3 => project_along_on_tri(xs, n, [&x[0], &x[1], &x[2]], tol),
            4 => project_along_on_quad(xs, n, [&x[0], &x[1], &x[2], &x[3]], tol)
                .map_err(|source| SearchError::Quad { face, source })?,
            n_nodes => return Err(SearchError::FaceNodes { face, n_nodes }),
        };
        if let Some(p) = p {
            hits.push((face, p, face_size(x)));
        }
    }
    let t_min = hits.iter().map(|(_, p, _)| p.t.abs()).fold(f64::INFINITY, f64::min);
    let h_max = hits.iter().map(|(_, _, h)| *h).fold(0.0, f64::max);
    let best = hits
        .into_iter()
        .filter(|(_, p, _)| p.t.abs() <= t_min + tol * h_max)
        .min_by_key(|(face, p, _)| (p.location.rank(), *face));
    Ok(best.map(|(face, p, _)| (face, p)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> Vector3<f64> {
        Vector3::new(x, y, z)
    }

    /// Σ N_I x_I of a projection's face.
    fn interpolate(p: &Projection, x: &[Vector3<f64>]) -> Vector3<f64> {
        x.iter().zip(p.weights.iter()).map(|(x, w)| x * *w).sum()
    }

    const TOL: f64 = INSIDE_TOL_DEFAULT;

    #[test]
    fn point_inside_tri_weights_reproduce_point() {
        // Reference: barycentric interpolation is exact; tolerance 1e-12 (round-off).
        let x = [v(0.1, 0.2, 0.3), v(2.0, 0.5, 0.1), v(0.4, 1.7, 0.6)];
        let target = x[0] * 0.2 + x[1] * 0.5 + x[2] * 0.3;
        let n = v(0.1, -0.2, -1.0).normalize();
        let xs = target - n * 0.25; // 0.25 m before the face along n: open gap
        let p = project_along_on_tri(&xs, &n, [&x[0], &x[1], &x[2]], TOL).expect("inside");
        assert_eq!(p.location, Location::Inside);
        assert_eq!(p.n_nodes, 3);
        assert!((p.weights.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert!((interpolate(&p, &x) - p.point).norm() < 1e-12);
        assert!((p.point - target).norm() < 1e-12);
        assert!((p.weights[0] - 0.2).abs() < 1e-12 && (p.weights[1] - 0.5).abs() < 1e-12);
        assert_eq!(p.xi, [p.weights[1], p.weights[2]]);
        assert!((p.t - 0.25).abs() < 1e-12 && (p.gap - 0.25).abs() < 1e-12);
    }

    #[test]
    fn point_inside_quad_weights_reproduce_point() {
        // Planar trapezoid (not a parallelogram). Reference: Σ N_I x_I = x̄, tolerance 1e-12.
        let x = [v(0.0, 0.0, 0.0), v(2.0, 0.0, 0.0), v(1.6, 1.0, 0.0), v(0.3, 1.2, 0.0)];
        let xs = v(0.9, 0.4, 0.3);
        let n = v(0.05, 0.1, -1.0).normalize();
        let p = project_along_on_quad(&xs, &n, [&x[0], &x[1], &x[2], &x[3]], TOL).unwrap().expect("inside");
        assert_eq!(p.location, Location::Inside);
        assert!((p.weights.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert!((interpolate(&p, &x) - p.point).norm() < 1e-12);
        assert!((xs + n * p.t - p.point).norm() < 1e-12);
        assert!(p.point.z.abs() < 1e-12);
        assert!(p.xi[0].abs() < 1.0 && p.xi[1].abs() < 1.0);
    }

    #[test]
    fn quad_projection_from_a_start_matches_the_one_from_the_centre() {
        // The search starts a node's Newton from its local coordinates of the last step. Reference:
        // the projection from the centre on the same distorted quad; from any start in [-2, 2]²
        // the same root to 1e-12 in ξ and m, same location; a start that is not finite or
        // outside [-2, 2]² falls back to the centre and gives the centre's result bit for bit.
        let x = [v(0.0, 0.0, 0.0), v(2.1, -0.2, 0.3), v(1.8, 1.9, -0.25), v(-0.3, 1.4, 0.2)];
        let n = v(0.15, -0.1, -1.0).normalize();
        let xq = [&x[0], &x[1], &x[2], &x[3]];
        for &xs in &[v(0.7, 0.6, 0.8), v(1.5, 1.2, -0.3), v(0.1, 1.1, 0.05)] {
            let centre = project_along_on_quad(&xs, &n, xq, TOL).unwrap().expect("inside");
            for start in [centre.xi, [centre.xi[0] + 1e-4, centre.xi[1] - 1e-4], [-0.9, 0.9], [1.9, -1.9]] {
                let p = project_along_on_quad_from(&xs, &n, xq, TOL, start).unwrap().expect("inside");
                assert!((p.xi[0] - centre.xi[0]).abs() < 1e-12 && (p.xi[1] - centre.xi[1]).abs() < 1e-12, "{start:?}: {:?} vs {:?}", p.xi, centre.xi);
                assert!((p.point - centre.point).norm() < 1e-12 && (p.t - centre.t).abs() < 1e-12);
                assert_eq!(p.location, centre.location);
            }
            for bad in [[f64::NAN, 0.0], [3.0, 0.0], [0.0, f64::INFINITY]] {
                assert_eq!(project_along_on_quad_from(&xs, &n, xq, TOL, bad).unwrap(), Some(centre.clone()));
            }
        }
    }

    #[test]
    fn distorted_quad_newton_matches_analytic() {
        // Non-planar, non-parallelogram quad; tilted normal. Reference: the two solves of the same
        // equations agree to 1e-10 in ξ and t, and Newton's 3D residual is below 1e-12 m.
        let x = [v(0.0, 0.0, 0.0), v(2.1, -0.2, 0.3), v(1.8, 1.9, -0.25), v(-0.3, 1.4, 0.2)];
        let n = v(0.15, -0.1, -1.0).normalize();
        let q = Bilinear::new(&x);
        let h = face_size(&x);
        let mut worst: f64 = 0.0;
        for &xs in &[v(0.7, 0.6, 0.8), v(1.5, 1.2, -0.3), v(0.1, 1.1, 0.05), v(1.9, 0.0, 0.5), v(2.5, 2.5, 0.0)] {
            let Newton::Converged { xi, t } = quad_local_newton(&q, &xs, &n, h, QUAD_NEWTON_MAX_ITER, [0.0, 0.0]) else {
                panic!("Newton did not converge at {xs:?}");
            };
            let xi_a = quad_local_analytic(&q, &xs, &n, h).unwrap().expect("a root");
            let t_a = n.dot(&(q.at(xi_a) - xs));
            let diff = (xi[0] - xi_a[0]).abs().max((xi[1] - xi_a[1]).abs()).max((t - t_a).abs());
            worst = worst.max(diff);
            assert!(diff < 1e-10, "{xi:?} {t} vs {xi_a:?} {t_a}");
            assert!((q.at(xi) - xs - n * t).norm() < 1e-12);
            // The public path (Newton) and the forced fallback give the same projection.
            let public = project_along_on_quad(&xs, &n, [&x[0], &x[1], &x[2], &x[3]], TOL).unwrap();
            let fallback = project_quad_with(&xs, &n, [&x[0], &x[1], &x[2], &x[3]], TOL, 0, [0.0, 0.0]).unwrap();
            assert_eq!(public.is_some(), fallback.is_some());
            if let (Some(p), Some(f)) = (public, fallback) {
                assert!((p.point - f.point).norm() < 1e-10);
                assert!((interpolate(&p, &x) - p.point).norm() < 1e-12);
            }
        }
        eprintln!("distorted quad: largest Newton/analytic difference {worst:.1e}");
        assert!(q.c12.norm() > 0.1, "non-parallelogram");
        let m = (x[2] - x[0]).cross(&(x[3] - x[1])).normalize();
        assert!(m.dot(&(x[1] - x[0])).abs() > 0.01, "non-planar: node 1 is off the centre plane");
    }

    #[test]
    fn analytic_fallback_on_saddle_quad() {
        // A strongly warped quad: the saddle z = x y over [-1, 1]² (c12 = (0, 0, 1)). Newton is
        // disabled (budget 0) so the analytic solve alone answers.
        let x = [v(-1.0, -1.0, 1.0), v(1.0, -1.0, -1.0), v(1.0, 1.0, 1.0), v(-1.0, 1.0, -1.0)];
        let n = v(0.0, 0.0, -1.0);
        for budget in [0, QUAD_NEWTON_MAX_ITER] {
            let p = project_quad_with(&v(0.5, -0.5, 2.0), &n, [&x[0], &x[1], &x[2], &x[3]], TOL, budget, [0.0, 0.0])
                .unwrap()
                .expect("inside");
            // Reference: on the saddle z = x y, so at (0.5, -0.5) z = -0.25 and t = 2.25 (exact
            // up to round-off, tolerance 1e-12); ξ = (x, y) there.
            assert!((p.t - 2.25).abs() < 1e-12, "budget {budget}: {p:?}");
            assert!((p.xi[0] - 0.5).abs() < 1e-12 && (p.xi[1] + 0.5).abs() < 1e-12);
            // Outside the square: no contact, not an error.
            let out = project_quad_with(&v(3.0, 0.0, 2.0), &n, [&x[0], &x[1], &x[2], &x[3]], TOL, budget, [0.0, 0.0]).unwrap();
            assert!(out.is_none());
        }
    }

    #[test]
    fn degenerate_quads() {
        let n = v(0.0, 0.0, -1.0);
        // A bow-tie (nodes 2 and 3 swapped): the diagonals are parallel, no centre normal → None.
        let x = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0), v(1.0, 1.0, 0.0)];
        let r = project_along_on_quad(&v(0.5, 0.5, 1.0), &n, [&x[0], &x[1], &x[2], &x[3]], TOL).unwrap();
        assert!(r.is_none());
        // A face collapsed onto a segment: the analytic solve names the failure.
        let x = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 0.0, 0.0)];
        let q = Bilinear::new(&x);
        assert!(quad_local_analytic(&q, &v(0.5, 0.0, 1.0), &n, 1.0).is_err());
    }

    #[test]
    fn gap_sign_open_positive_penetration_negative() {
        // Master face z = 0, slave above it with n = −z (out of the slave, towards the master).
        let x = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(1.0, 1.0, 0.0), v(0.0, 1.0, 0.0)];
        let n = v(0.0, 0.0, -1.0);
        let open = project_along_on_quad(&v(0.3, 0.3, 0.1), &n, [&x[0], &x[1], &x[2], &x[3]], TOL).unwrap().unwrap();
        assert!((open.gap - 0.1).abs() < 1e-15);
        let pen = project_along_on_quad(&v(0.3, 0.3, -0.05), &n, [&x[0], &x[1], &x[2], &x[3]], TOL).unwrap().unwrap();
        assert!((pen.gap + 0.05).abs() < 1e-15);
        let tri = project_along_on_tri(&v(0.3, 0.2, -0.05), &n, [&x[0], &x[1], &x[2]], TOL).unwrap();
        assert!((tri.gap + 0.05).abs() < 1e-15);
        // Same for a master face given in the opposite orientation (inside test uses n · m).
        let tri_rev = project_along_on_tri(&v(0.3, 0.2, 0.07), &n, [&x[0], &x[2], &x[1]], TOL).unwrap();
        assert!((tri_rev.gap - 0.07).abs() < 1e-15);
    }

    #[test]
    fn outside_all_faces_is_none() {
        let quads = grid_quads(2, 2, 1.0);
        let n = v(0.0, 0.0, -1.0);
        for xs in [v(2.5, 0.5, 0.1), v(-0.01, 1.0, 0.0), v(1.0, 2.2, -0.1)] {
            let cands = quads.iter().enumerate().map(|(i, q)| (i, q.as_slice()));
            assert_eq!(select_projection(&xs, &n, cands, TOL).unwrap(), None, "{xs:?}");
        }
        // Parallel to the face.
        let q = &quads[0];
        assert!(
            project_along_on_quad(&v(0.5, 0.5, 0.0), &v(1.0, 0.0, 0.0), [&q[0], &q[1], &q[2], &q[3]], TOL)
                .unwrap()
                .is_none()
        );
        assert!(project_along_on_tri(&v(0.5, 0.5, 0.0), &v(1.0, 0.0, 0.0), [&q[0], &q[1], &q[2]], TOL).is_none());
    }

    /// nx × ny square quads of side `a` in the plane z = 0, Gmsh order (right-hand normal +z).
    fn grid_quads(nx: usize, ny: usize, a: f64) -> Vec<Vec<Vector3<f64>>> {
        let mut out = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                let (x0, y0) = (i as f64 * a, j as f64 * a);
                out.push(vec![v(x0, y0, 0.0), v(x0 + a, y0, 0.0), v(x0 + a, y0 + a, 0.0), v(x0, y0 + a, 0.0)]);
            }
        }
        out
    }

    /// All permutations of 0..k (Heap's algorithm).
    fn permutations(k: usize) -> Vec<Vec<usize>> {
        fn heap(k: usize, a: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
            if k == 1 {
                out.push(a.clone());
                return;
            }
            for i in 0..k {
                heap(k - 1, a, out);
                let j = if k.is_multiple_of(2) { i } else { 0 };
                a.swap(j, k - 1);
            }
        }
        let mut out = Vec::new();
        heap(k, &mut (0..k).collect(), &mut out);
        out
    }

    /// Select among `faces` (with ids) in every order; assert the same single face each time.
    fn select_all_orders(
        xs: &Vector3<f64>,
        n: &Vector3<f64>,
        faces: &[(usize, Vec<Vector3<f64>>)],
    ) -> (usize, Projection) {
        let mut first: Option<(usize, Projection)> = None;
        for perm in permutations(faces.len()) {
            let cands = perm.iter().map(|&k| (faces[k].0, faces[k].1.as_slice()));
            let got = select_projection(xs, n, cands, TOL).unwrap().expect("a face");
            match &first {
                None => first = Some(got),
                Some(f) => assert_eq!(f, &got, "order {perm:?}"),
            }
        }
        first.unwrap()
    }

    fn passing(xs: &Vector3<f64>, n: &Vector3<f64>, faces: &[(usize, Vec<Vector3<f64>>)]) -> usize {
        faces.iter().filter(|(_, x)| select_projection(xs, n, [(0, x.as_slice())], TOL).unwrap().is_some()).count()
    }

    #[test]
    fn shared_edge_of_two_quads_selects_one() {
        let q = grid_quads(2, 1, 1.0);
        let faces = vec![(9, q[0].clone()), (4, q[1].clone())];
        let n = v(0.0, 0.0, -1.0);
        // On the shared edge x = 1, and within round-off of it on either side.
        for dx in [0.0, 1e-14, -1e-14] {
            let xs = v(1.0 + dx, 0.37, 0.2);
            assert_eq!(passing(&xs, &n, &faces), 2, "both faces pass with tolerance");
            let (id, p) = select_all_orders(&xs, &n, &faces);
            assert_eq!(id, 4, "smallest id among the tied faces");
            assert!(matches!(p.location, Location::Edge(3)), "{:?}", p.location); // edge 3→0 of face 4
            assert!((interpolate(&p, &faces[1].1) - p.point).norm() < 1e-12);
        }
        // Clearly inside face 9: face 9, inside.
        let (id, p) = select_all_orders(&v(0.6, 0.37, 0.2), &n, &faces);
        assert_eq!((id, p.location), (9, Location::Inside));
    }

    #[test]
    fn shared_edge_of_two_tris_selects_one() {
        // Square split along the diagonal 0–2; the slave point is on the diagonal.
        let (a, b, c, d) = (v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(1.0, 1.0, 0.0), v(0.0, 1.0, 0.0));
        let faces = vec![(1, vec![a, b, c]), (0, vec![a, c, d])];
        let n = v(0.0, 0.0, -1.0);
        for s in [0.3, 0.5, 0.81] {
            let xs = v(s, s, 0.1);
            assert_eq!(passing(&xs, &n, &faces), 2);
            let (id, p) = select_all_orders(&xs, &n, &faces);
            assert_eq!(id, 0);
            assert_eq!(p.location, Location::Edge(0)); // face 0 = [a, c, d]: edge 0 is a→c
        }
    }

    #[test]
    fn shared_vertex_of_four_quads_selects_one() {
        let q = grid_quads(2, 2, 0.5);
        // Ids deliberately not in geometric order.
        let faces = vec![(7, q[0].clone()), (3, q[1].clone()), (12, q[2].clone()), (5, q[3].clone())];
        let n = v(0.0, 0.0, -1.0);
        let xs = v(0.5, 0.5, -0.01);
        assert_eq!(passing(&xs, &n, &faces), 4);
        let (id, p) = select_all_orders(&xs, &n, &faces);
        assert_eq!(id, 3);
        // Face 3 is q[1] = [(0.5,0),(1,0),(1,0.5),(0.5,0.5)]: the shared vertex is its node 3.
        assert_eq!(p.location, Location::Vertex(3));
        assert!((p.weights[3] - 1.0).abs() < 1e-12);
        assert!((p.gap + 0.01).abs() < 1e-15);
    }

    #[test]
    fn convex_corner_dead_zone_found_along_normal() {
        // Master block below a ridge along y: face L rises from x = -1 to the ridge at x = 0,
        // face R falls to x = 1 (slope 0.5, i.e. 26.6°). A slave point just above the ridge.
        let s = 0.5;
        let l = vec![v(-1.0, 0.0, -s), v(0.0, 0.0, 0.0), v(0.0, 1.0, 0.0), v(-1.0, 1.0, -s)];
        let r = vec![v(0.0, 0.0, 0.0), v(1.0, 0.0, -s), v(1.0, 1.0, -s), v(0.0, 1.0, 0.0)];
        let faces = vec![(0, l.clone()), (1, r.clone())];
        let xs = v(0.02, 0.5, 0.1);
        // The classic dead zone: the closest-point foot on each face's plane lies outside that face.
        let foot = |face: &[Vector3<f64>]| {
            let m = (face[2] - face[0]).cross(&(face[3] - face[1])).normalize();
            xs - m * m.dot(&(xs - face[0]))
        };
        assert!(foot(&l).x > 0.0, "closest-point foot on L's plane is beyond the ridge");
        assert!(foot(&r).x < 0.0, "closest-point foot on R's plane is beyond the ridge");
        // Along the slave normal (vertical, or tilted a little), exactly one face is hit.
        for n in [v(0.0, 0.0, -1.0), v(-0.1, 0.05, -1.0).normalize(), v(0.1, 0.0, -1.0).normalize()] {
            assert_eq!(passing(&xs, &n, &faces), 1, "n = {n:?}");
            let (id, p) = select_all_orders(&xs, &n, &faces);
            let expected = if (xs + n * p.t).x > 0.0 { 1 } else { 0 };
            assert_eq!(id, expected);
            assert!(p.gap > 0.0);
        }
    }

    #[test]
    fn folded_surface_prefers_nearest_along_normal() {
        // Two sheets of the master surface crossed by the same vertical line: z = 0 (face 5)
        // and z = -1 (face 2, smaller id). The nearest along n wins, whichever id it has.
        let top: Vec<_> = grid_quads(1, 1, 1.0).remove(0);
        let bottom: Vec<_> = top.iter().map(|p| p - v(0.0, 0.0, 1.0)).collect();
        let faces = vec![(5, top), (2, bottom)];
        let n = v(0.0, 0.0, -1.0);
        let (id, p) = select_all_orders(&v(0.4, 0.4, 0.05), &n, &faces);
        assert_eq!(id, 5);
        assert!((p.t - 0.05).abs() < 1e-15);
        // Penetrated past the top sheet but nearer to it than to the bottom one.
        let (id, p) = select_all_orders(&v(0.4, 0.4, -0.3), &n, &faces);
        assert_eq!(id, 5);
        assert!((p.gap + 0.3).abs() < 1e-15);
        let (id, _) = select_all_orders(&v(0.4, 0.4, -0.7), &n, &faces);
        assert_eq!(id, 2);
    }

    #[test]
    fn bad_face_is_an_error() {
        let pts = vec![v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0)];
        let e = select_projection(&v(0.0, 0.0, 1.0), &v(0.0, 0.0, -1.0), [(11, pts.as_slice())], TOL).unwrap_err();
        assert_eq!(e, SearchError::FaceNodes { face: 11, n_nodes: 2 });
    }
}

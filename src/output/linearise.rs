//! Stresses linearised through the thickness, as dam engineers report them (USACE EM
//! 1110-2-6053, "Earthquake Design and Evaluation of Concrete Hydraulic Structures", §4-5: the
//! arch and cantilever stresses of a 3-D solid model integrated through the thickness; the same
//! "stress linearisation" as ASME BPVC VIII-2 Annex 5-A on a stress classification line).
//!
//! A cut is a straight line from the centre of a face of one face group (`from`, e.g. the dam's
//! upstream face; x = 0) to the nearest point of another (`to`, the downstream face; x = t).
//! Along it, for a normal stress σ(x) in a direction normal to the cut:
//!   membrane σ_m = (1/t) ∫₀ᵗ σ dx,   bending σ_b = (6/t²) ∫₀ᵗ σ (x − t/2) dx,
//! and the linearised surface values σ_m − σ_b at `from` (x = 0) and σ_m + σ_b at `to` (x = t):
//! the straight line with the same resultant force and moment per unit length as σ(x).
//! Two normal stresses per cut: **arch** along a = e_z × n / |e_z × n| (horizontal, tangential to
//! the faces; n the cut's unit direction, z up) and **cantilever** along c = n × a (in the faces'
//! plane, the direction nearest to vertical).
//!
//! Computed during the run, not from frames afterwards: the frames hold the stress of one run at
//! 0.05 s intervals only when asked (121 frames of the whole mesh for one run of `make dam`),
//! while the cut needs every element it crosses at every envelope sample of every run. The cuts
//! are located once at set-up (each element's interval along the line, exact for tet4; for
//! hex8 the union of its 6-tet split's intervals, exact for hexes with plane faces); a sample
//! is then two dot products per crossed element, after the envelope's own element stresses.
//!
//! What the element stress is: the element's value at its centre (`Model::element_stress_into`),
//! constant over the element's interval. The linearisation of that piecewise-constant field is
//! exact (intervals integrated exactly); against the continuum it errs like the elements do: for
//! a stress linear through the thickness over n equal elements the membrane is exact and the
//! bending is (1 − 1/n²) of the true one (the midpoint value misses the linear part's moment
//! within each element: tested below), 0.75 with 2 elements, 0.94 with 4, 0.99 with 10.

use crate::error::ModelError;
use crate::mesh::geometry::closest_on_triangle;
use crate::model::Model;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

type P3 = [f64; 3];

/// Membrane and bending parts of a through-thickness distribution [Pa].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Linearised {
    pub membrane: f64,
    pub bending: f64,
}

impl Linearised {
    /// The linearised value at the cut's start (x = 0, the `from` face).
    pub fn start(&self) -> f64 {
        self.membrane - self.bending
    }
    /// The linearised value at the cut's end (x = t, the `to` face).
    pub fn end(&self) -> f64 {
        self.membrane + self.bending
    }
}

/// Linearise σ over [0, t] from segments (x0, x1, σ(x0), σ(x1)), σ linear on each segment
/// (constant when σ(x0) = σ(x1)): σ_m = (1/t) ∫σ, σ_b = (6/t²) ∫σ (x − t/2), each segment
/// integrated by Simpson's rule, exact for the quadratic integrand. Parts of [0, t] without a
/// segment count as σ = 0.
pub fn linearise(segments: &[(f64, f64, f64, f64)], t: f64) -> Linearised {
    let c = 0.5 * t;
    let (mut i0, mut i1) = (0.0, 0.0);
    for &(a, b, sa, sb) in segments {
        let (m, sm, w) = (0.5 * (a + b), 0.5 * (sa + sb), (b - a) / 6.0);
        i0 += w * (sa + 4.0 * sm + sb);
        i1 += w * (sa * (a - c) + 4.0 * sm * (m - c) + sb * (b - c));
    }
    Linearised { membrane: i0 / t, bending: 6.0 * i1 / (t * t) }
}

/// Least share of a cut's length that must lie in the faces' volume elements [1]: 0.99. Why: a
/// cut that leaves the dam (near the foundation, where the nearest downstream point lies across
/// the rock) would integrate zero stress over the gap; across a joint of mismatched meshes the
/// two sides' elements leave at most round-off gaps. A cut below it is dropped and counted.
pub const MIN_COVERAGE: f64 = 0.99;

/// Max and min over the run of one normal stress's membrane and surface values [Pa].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ComponentEnvelope {
    /// [max, min] of σ_m.
    pub membrane: [f64; 2],
    /// [max, min] of σ_m − σ_b (the `from` face).
    pub start: [f64; 2],
    /// [max, min] of σ_m + σ_b (the `to` face).
    pub end: [f64; 2],
}

impl ComponentEnvelope {
    fn new() -> Self {
        let e = [f64::NEG_INFINITY, f64::INFINITY];
        ComponentEnvelope { membrane: e, start: e, end: e }
    }
    fn add(&mut self, l: Linearised) {
        for (e, v) in [(&mut self.membrane, l.membrane), (&mut self.start, l.start()), (&mut self.end, l.end())] {
            e[0] = e[0].max(v);
            e[1] = e[1].min(v);
        }
    }
}

/// One cut's geometry and its envelopes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CutEnvelope {
    /// Index of the cut's face in the `from` group's [`super::envelope::FaceEnvelope`].
    pub face: usize,
    /// Start (the `from` face's centre) and end (nearest point of `to`) [m].
    pub start: P3,
    pub end: P3,
    /// Thickness t = |end − start| [m].
    pub thickness: f64,
    /// Elements crossed.
    pub elements: usize,
    pub arch: ComponentEnvelope,
    pub cantilever: ComponentEnvelope,
}

/// The linearised envelopes of one pair of face groups (in `envelope.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LinearisedEnvelope {
    pub from: String,
    pub to: String,
    pub cuts: Vec<CutEnvelope>,
    /// Faces of `from` whose cut had less than [`MIN_COVERAGE`] of its length in the elements.
    pub dropped: usize,
}

/// The extremes over the cuts of one normal stress (see [`LinearisedEnvelope::extremes`]) [Pa].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LinearisedExtremes {
    /// Largest surface tension at `from` / `to`, most compressive surface value at `from` / `to`.
    pub tension_start: f64,
    pub tension_end: f64,
    pub compression_start: f64,
    pub compression_end: f64,
    /// Largest and most compressive membrane stress.
    pub membrane_tension: f64,
    pub membrane_compression: f64,
    /// Start of the cut with the largest surface tension [m].
    pub tension_at: P3,
}

impl LinearisedExtremes {
    /// Largest surface tension over both faces.
    pub fn tension(&self) -> f64 {
        self.tension_start.max(self.tension_end)
    }
    /// Most compressive surface value over both faces.
    pub fn compression(&self) -> f64 {
        self.compression_start.min(self.compression_end)
    }
}

impl LinearisedEnvelope {
    /// The extremes over the cuts kept by `keep` (index of the cut's face → kept) of the arch
    /// (`arch` true) or cantilever stress; `None` when no cut is kept.
    pub fn extremes(&self, arch: bool, keep: impl Fn(usize) -> bool) -> Option<LinearisedExtremes> {
        let kept: Vec<&CutEnvelope> = self.cuts.iter().filter(|c| keep(c.face)).collect();
        let comp = |c: &CutEnvelope| if arch { c.arch.clone() } else { c.cantilever.clone() };
        let max = |f: &dyn Fn(&ComponentEnvelope) -> f64| kept.iter().map(|c| f(&comp(c))).fold(f64::NEG_INFINITY, f64::max);
        let min = |f: &dyn Fn(&ComponentEnvelope) -> f64| kept.iter().map(|c| f(&comp(c))).fold(f64::INFINITY, f64::min);
        let top = kept.iter().max_by(|a, b| {
            let v = |c: &CutEnvelope| comp(c).start[0].max(comp(c).end[0]);
            v(a).total_cmp(&v(b))
        })?;
        Some(LinearisedExtremes {
            tension_start: max(&|e| e.start[0]),
            tension_end: max(&|e| e.end[0]),
            compression_start: min(&|e| e.start[1]),
            compression_end: min(&|e| e.end[1]),
            membrane_tension: max(&|e| e.membrane[0]),
            membrane_compression: min(&|e| e.membrane[1]),
            tension_at: top.start,
        })
    }
}

/// A located cut: its pieces (x0, x1, element, share of the element's stress) and directions.
struct Cut {
    face: usize,
    start: P3,
    end: P3,
    t: f64,
    pieces: Vec<(f64, f64, usize, f64)>,
    arch: Vector3<f64>,
    cantilever: Vector3<f64>,
    env: [ComponentEnvelope; 2],
}

/// Locates the cuts at set-up and envelopes their linearised stresses at every sample.
pub struct Lineariser {
    from: String,
    to: String,
    cuts: Vec<Cut>,
    dropped: usize,
    buf: Vec<(f64, f64, f64, f64)>,
}

/// The corner points of model element `e` (tets first, then hexes).
fn element_points(model: &Model, e: usize) -> Vec<P3> {
    let nt = model.tets.nodes.len();
    let nodes: &[u32] = if e < nt { &model.tets.nodes[e] } else { &model.hexes.nodes[e - nt] };
    nodes.iter().map(|&i| model.mesh.nodes[i as usize]).collect()
}

/// The interval [s0, s1] ⊂ [0, t] of the line p + s d inside the tetrahedron `x` (barycentric
/// coordinates linear in s), `None` if it misses it or the tet is degenerate.
fn tet_interval(x: [P3; 4], p: P3, d: P3, t: f64) -> Option<(f64, f64)> {
    let v = |q: P3| Vector3::from(q);
    let m = Matrix3::from_columns(&[v(x[1]) - v(x[0]), v(x[2]) - v(x[0]), v(x[3]) - v(x[0])]);
    let inv = m.try_inverse()?;
    let l = inv * (v(p) - v(x[0]));
    let g = inv * v(d);
    let lam = [1.0 - l.sum(), l[0], l[1], l[2]];
    let grad = [-g.sum(), g[0], g[1], g[2]];
    let (mut lo, mut hi) = (0.0f64, t);
    const EPS: f64 = 1e-12;
    for k in 0..4 {
        if grad[k].abs() < EPS {
            if lam[k] < -EPS {
                return None;
            }
        } else if grad[k] > 0.0 {
            lo = lo.max(-lam[k] / grad[k]);
        } else {
            hi = hi.min(-lam[k] / grad[k]);
        }
    }
    (hi > lo + EPS * t.max(1.0)).then_some((lo, hi))
}

/// The interval of the line in model element `e`: a tet's, or the union of a hex's 6-tet split
/// around its diagonal 0–6 (gmsh node order).
fn element_interval(model: &Model, e: usize, p: P3, d: P3, t: f64) -> Option<(f64, f64)> {
    let x = element_points(model, e);
    if x.len() == 4 {
        return tet_interval([x[0], x[1], x[2], x[3]], p, d, t);
    }
    const RING: [usize; 6] = [1, 2, 3, 7, 4, 5];
    (0..6)
        .filter_map(|k| tet_interval([x[0], x[6], x[RING[k]], x[RING[(k + 1) % 6]]], p, d, t))
        .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
}

/// Closest point of triangle `abc` to `p` ([`closest_on_triangle`]'s barycentric weights).
fn closest_point_on_triangle(p: P3, a: P3, b: P3, c: P3) -> Vector3<f64> {
    let (a, b, c) = (Vector3::from(a), Vector3::from(b), Vector3::from(c));
    let l = closest_on_triangle(a, b, c, &Vector3::from(p));
    a * l[0] + b * l[1] + c * l[2]
}

/// A uniform grid of the elements' bounding boxes, for the elements a segment may cross.
struct Grid {
    lo: Vector3<f64>,
    cell: f64,
    dims: [usize; 3],
    bins: Vec<Vec<u32>>,
}

impl Grid {
    fn new(model: &Model, elements: &[usize]) -> Grid {
        let boxes: Vec<(Vector3<f64>, Vector3<f64>)> = elements.iter().map(|&e| bbox(&element_points(model, e))).collect();
        let (mut lo, mut hi) = (Vector3::repeat(f64::INFINITY), Vector3::repeat(f64::NEG_INFINITY));
        let mut size = 0.0;
        for (a, b) in &boxes {
            lo = lo.inf(a);
            hi = hi.sup(b);
            size += (b - a).max();
        }
        // twice the mean element extent, but at most about MAX_BINS bins over the elements' box
        const MAX_BINS: f64 = 4e6;
        let ext = hi - lo;
        let cell = (2.0 * size / boxes.len().max(1) as f64).max(((ext.x + 1e-9) * (ext.y + 1e-9) * (ext.z + 1e-9) / MAX_BINS).cbrt()).max(1e-9);
        let dims = [0, 1, 2].map(|k| ((ext[k] / cell).floor() as usize + 1).min(1 << 10));
        let mut g = Grid { lo, cell, dims, bins: vec![Vec::new(); dims[0] * dims[1] * dims[2]] };
        for (i, (a, b)) in boxes.iter().enumerate() {
            for bin in g.bins_of(a, b) {
                g.bins[bin].push(elements[i] as u32);
            }
        }
        g
    }
    fn bins_of(&self, a: &Vector3<f64>, b: &Vector3<f64>) -> Vec<usize> {
        let idx = |x: f64, k: usize| (((x - self.lo[k]) / self.cell).floor().max(0.0) as usize).min(self.dims[k] - 1);
        let (i0, i1) = ([0, 1, 2].map(|k| idx(a[k], k)), [0, 1, 2].map(|k| idx(b[k], k)));
        let mut v = Vec::new();
        for i in i0[0]..=i1[0] {
            for j in i0[1]..=i1[1] {
                for k in i0[2]..=i1[2] {
                    v.push((i * self.dims[1] + j) * self.dims[2] + k);
                }
            }
        }
        v
    }
    /// Elements whose box may meet the segment p–q (sorted, distinct).
    fn candidates(&self, p: P3, q: P3) -> Vec<usize> {
        let (a, b) = bbox(&[p, q]);
        let mut v: Vec<usize> = self.bins_of(&a, &b).into_iter().flat_map(|i| self.bins[i].iter().map(|&e| e as usize)).collect();
        v.sort_unstable();
        v.dedup();
        v
    }
}

fn bbox(x: &[P3]) -> (Vector3<f64>, Vector3<f64>) {
    let (mut lo, mut hi) = (Vector3::repeat(f64::INFINITY), Vector3::repeat(f64::NEG_INFINITY));
    for p in x {
        lo = lo.inf(&Vector3::from(*p));
        hi = hi.sup(&Vector3::from(*p));
    }
    (lo, hi)
}

/// The pieces of [0, t] between the crossed elements' interval ends, each with the elements
/// over it sharing equally (a line along a face shared by two elements takes their mean), and
/// the covered length.
fn pieces(intervals: &[(usize, f64, f64)], t: f64) -> (Vec<(f64, f64, usize, f64)>, f64) {
    let mut cuts: Vec<f64> = intervals.iter().flat_map(|&(_, a, b)| [a, b]).chain([0.0, t]).collect();
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * t);
    let (mut out, mut covered) = (Vec::new(), 0.0);
    for w in cuts.windows(2) {
        let m = 0.5 * (w[0] + w[1]);
        let over: Vec<usize> = intervals.iter().filter(|&&(_, a, b)| a <= m && m <= b).map(|x| x.0).collect();
        if !over.is_empty() {
            covered += w[1] - w[0];
            out.extend(over.iter().map(|&e| (w[0], w[1], e, 1.0 / over.len() as f64)));
        }
    }
    (out, covered)
}

impl Lineariser {
    /// Locate a cut for every face of `from` (`(face cell, element)` pairs as the envelope holds
    /// them) to the nearest point of the faces of `to`, through the elements of the volumes
    /// under both groups.
    pub fn create(model: &Model, from: (&str, &[(usize, usize)]), to: (&str, &[(usize, usize)])) -> Result<Lineariser, ModelError> {
        let mesh = &model.mesh;
        let nt = model.tets.nodes.len();
        let mat = |e: usize| if e < nt { model.tets.mat[e] } else { model.hexes.mat[e - nt] };
        let mut mats: Vec<u16> = from.1.iter().chain(to.1).map(|&(_, e)| mat(e)).collect();
        mats.sort_unstable();
        mats.dedup();
        let elements: Vec<usize> = (0..model.n_elements()).filter(|&e| mats.binary_search(&mat(e)).is_ok()).collect();
        let grid = Grid::new(model, &elements);
        let tris: Vec<[P3; 3]> = to
            .1
            .iter()
            .flat_map(|&(c, _)| {
                let x: Vec<P3> = mesh.cells[c].nodes().iter().map(|&i| mesh.nodes[i as usize]).collect();
                let mut v = vec![[x[0], x[1], x[2]]];
                if x.len() == 4 {
                    v.push([x[0], x[2], x[3]]);
                }
                v
            })
            .collect();
        if tris.is_empty() {
            return Err(ModelError::Invalid(format!("output.envelope.linearise: face group \"{}\" has no faces", to.0)));
        }
        let (mut cuts, mut dropped) = (Vec::new(), 0);
        for (face, &(c, _)) in from.1.iter().enumerate() {
            let x: Vec<P3> = mesh.cells[c].nodes().iter().map(|&i| mesh.nodes[i as usize]).collect();
            let p: P3 = [0, 1, 2].map(|k| x.iter().map(|q| q[k]).sum::<f64>() / x.len() as f64);
            let q = tris.iter().map(|t| closest_point_on_triangle(p, t[0], t[1], t[2])).min_by(|a, b| (a - Vector3::from(p)).norm_squared().total_cmp(&(b - Vector3::from(p)).norm_squared())).expect("non-empty");
            match Self::cut(model, &grid, face, p, q.into()) {
                Some(cut) => cuts.push(cut),
                None => dropped += 1,
            }
        }
        Ok(Lineariser { from: from.0.into(), to: to.0.into(), cuts, dropped, buf: Vec::new() })
    }

    /// The cut from `p` to `q`, `None` when shorter than 1 mm or less than [`MIN_COVERAGE`] of it
    /// lies in the elements.
    fn cut(model: &Model, grid: &Grid, face: usize, p: P3, q: P3) -> Option<Cut> {
        let n = Vector3::from(q) - Vector3::from(p);
        let t = n.norm();
        if t < 1e-3 {
            return None;
        }
        let n = n / t;
        let intervals: Vec<(usize, f64, f64)> = grid.candidates(p, q).into_iter().filter_map(|e| element_interval(model, e, p, n.into(), t).map(|(a, b)| (e, a, b))).collect();
        let (pieces, covered) = pieces(&intervals, t);
        if covered < MIN_COVERAGE * t {
            return None;
        }
        let ez = Vector3::z();
        let arch = ez.cross(&n).try_normalize(1e-9).unwrap_or_else(Vector3::x);
        let cantilever = n.cross(&arch);
        Some(Cut { face, start: p, end: q, t, pieces, arch, cantilever, env: [ComponentEnvelope::new(), ComponentEnvelope::new()] })
    }

    /// Linearise the element stresses `stress` (Voigt xx, yy, zz, xy, yz, zx; model order) of
    /// one sample into the envelopes.
    pub fn sample(&mut self, stress: &[[f64; 6]]) {
        for cut in &mut self.cuts {
            for (k, dir) in [cut.arch, cut.cantilever].iter().enumerate() {
                let normal = |s: &[f64; 6]| {
                    let (a, b, c) = (dir[0], dir[1], dir[2]);
                    s[0] * a * a + s[1] * b * b + s[2] * c * c + 2.0 * (s[3] * a * b + s[4] * b * c + s[5] * c * a)
                };
                self.buf.clear();
                self.buf.extend(cut.pieces.iter().map(|&(x0, x1, e, share)| {
                    let s = share * normal(&stress[e]);
                    (x0, x1, s, s)
                }));
                cut.env[k].add(linearise(&self.buf, cut.t));
            }
        }
    }

    /// The envelopes so far.
    pub fn envelope(&self) -> LinearisedEnvelope {
        LinearisedEnvelope {
            from: self.from.clone(),
            to: self.to.clone(),
            cuts: self
                .cuts
                .iter()
                .map(|c| CutEnvelope {
                    face: c.face,
                    start: c.start,
                    end: c.end,
                    thickness: c.t,
                    elements: c.pieces.iter().map(|p| p.2).collect::<std::collections::BTreeSet<_>>().len(),
                    arch: c.env[0].clone(),
                    cantilever: c.env[1].clone(),
                })
                .collect(),
            dropped: self.dropped,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linearising_pure_membrane_and_pure_bending_is_exact() {
        // Reference: σ(x) = σ_m + σ_b (2x/t − 1) is its own linearisation (ASME VIII-2 5.A:
        // membrane = mean, bending = 6/t² ∫σ (x − t/2)): a uniform 4 MPa gives σ_m = 4, σ_b = 0;
        // a pure bending ±7 MPa gives σ_m = 0, σ_b = 7 (start −7, end +7); their sum both.
        // Cut into unequal segments, t = 3.7 m; tolerance 1e-12 relative (round-off).
        let t = 3.7;
        let xs = [0.0, 0.3, 1.1, 1.15, 2.9, 3.7];
        let seg = |f: &dyn Fn(f64) -> f64| xs.windows(2).map(|w| (w[0], w[1], f(w[0]), f(w[1]))).collect::<Vec<_>>();
        for (sm, sb) in [(4e6, 0.0), (0.0, 7e6), (4e6, 7e6), (-2e6, -3e6)] {
            let l = linearise(&seg(&|x| sm + sb * (2.0 * x / t - 1.0)), t);
            let tol = 1e-12 * (sm.abs() + sb.abs());
            assert!((l.membrane - sm).abs() < tol && (l.bending - sb).abs() < tol, "{sm} {sb}: {l:?}");
            assert!((l.start() - (sm - sb)).abs() < tol && (l.end() - (sm + sb)).abs() < tol);
        }
        // not linear: σ = x² on [0, 1] has σ_m = 1/3 and σ_b = 6 ∫x²(x − ½) dx = 1/2 (hand
        // integrals); its linear interpolation on 1000 equal pieces errs by h²/6 ≈ 2e-7 in σ_m
        let n = 1000;
        let segs: Vec<_> = (0..n).map(|i| { let (a, b) = (i as f64 / n as f64, (i + 1) as f64 / n as f64); (a, b, a * a, b * b) }).collect();
        let l = linearise(&segs, 1.0);
        assert!((l.membrane - 1.0 / 3.0).abs() < 1e-6 && (l.bending - 0.5).abs() < 1e-6, "{l:?}");
    }

    /// The linearised arch (σ_yy) envelope of the single cut of a box 2 × 1 × 1 m from its x0
    /// face to its x1 face, under a displacement field `u(x)`.
    fn box_cut(tets: bool, div: [usize; 3], u: impl Fn(P3) -> P3) -> (LinearisedEnvelope, f64) {
        let m = crate::linalg::assemble::tests::box_model(tets, div);
        let spec = crate::scene::EnvelopeSpec {
            faces: vec!["b:x0".into(), "b:x1".into()],
            stride: 1,
            linearise: Some(crate::scene::LineariseSpec { from: "b:x0".into(), to: "b:x1".into() }),
        };
        let mut w = super::super::envelope::EnvelopeWriter::create(&m, &spec).unwrap();
        let disp: Vec<f64> = m.mesh.nodes.iter().flat_map(|&x| u(x)).collect();
        w.sample(&m, &disp, 0.0);
        let l = w.envelope(&m).linearised.unwrap();
        let lame = &m.materials[0].lame;
        (l, lame.lambda + 2.0 * lame.mu)
    }

    #[test]
    fn a_box_cut_tiles_its_thickness_and_linearises_membrane_exactly_and_bending_to_one_minus_one_over_n_squared() {
        // Cuts along x from every face of x0 to x1 (t = 2 m): arch direction e_z × e_x = e_y.
        // Membrane: u_y = ε y gives σ_yy = (λ + 2μ) ε in every element (tet4 and hex8): σ_m
        // exact, σ_b = 0 (tolerance 1e-9 relative: round-off of the element stresses).
        // Bending: u_y = κ x y (bilinear, exact in hex8) gives ε_yy = κ x, so σ_yy is linear
        // through the thickness, σ_b = (λ + 2μ) κ t/2 about σ_m = (λ + 2μ) κ t/2; hex8 centre
        // values over n equal elements give σ_m exactly and σ_b × (1 − 1/n²) (midpoint rule:
        // each element misses κ(λ+2μ) h³/12 of the moment, n h = t): n = 4 → 0.9375.
        let eps = 1e-4;
        for tets in [false, true] {
            let (l, e) = box_cut(tets, [4, 2, 2], |x| [0.0, eps * x[1], 0.0]);
            assert_eq!((l.cuts.len(), l.dropped), (if tets { 8 } else { 4 }, 0), "tets {tets}");
            for c in &l.cuts {
                assert!((c.thickness - 2.0).abs() < 1e-12 && (c.end[0] - 2.0).abs() < 1e-12, "{c:?}");
                for v in [c.arch.membrane, c.arch.start, c.arch.end] {
                    assert!((v[0] - e * eps).abs() < 1e-9 * e * eps && v[0] == v[1], "tets {tets}: {v:?}");
                }
            }
        }
        let kappa = 1e-4;
        let (l, e) = box_cut(false, [4, 2, 2], |x| [0.0, kappa * x[0] * x[1], 0.0]);
        let (sm, sb) = (e * kappa * 1.0, e * kappa * 1.0 * (1.0 - 1.0 / 16.0));
        for c in &l.cuts {
            assert!((c.arch.membrane[0] - sm).abs() < 1e-9 * sm, "{c:?}");
            assert!((c.arch.end[0] - (sm + sb)).abs() < 1e-9 * sm && (c.arch.start[0] - (sm - sb)).abs() < 1e-9 * sm, "{c:?}");
        }
        let x = l.extremes(true, |_| true).unwrap();
        assert!((x.tension() - (sm + sb)).abs() < 1e-9 * sm && (x.tension_end - x.tension()).abs() == 0.0);
    }
}

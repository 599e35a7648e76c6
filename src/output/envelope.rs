//! Stress envelopes over time on face groups (scene `output.envelope`): for each face of the
//! groups, the largest principal stress σ1 (tension positive) and the smallest σ3 (the most
//! compressive) that the volume element under it reached during the run, with when.
//!
//! Sign convention: stresses in Pa, tension positive (as the frames' `principal_stress`).
//! A face's value is its element's stress at the element centre (constant in a tet4, the
//! centroid of a hex8: `Model::element_stress_into`), not extrapolated to the surface.
//! Sampling: every `stride` steps from the first step (the static state at t ≈ 0 is included)
//! and at the last step; a peak between two samples is missed by at most 1 − cos(π/n) for a
//! response with n samples per period (stride 10 at dt 5.4e-4 s: 1.5 % at 10 Hz).
//!
//! Written at the end of the run: `envelope.vtu` (the faces, cell fields `max_principal`,
//! `min_principal` [Pa], `max_principal_t`, `min_principal_t` [s], `group` = index in `faces`)
//! for ParaView, and `envelope.json` (also each face's corners, for maps), read back by
//! [`StressEnvelope::read`].

use crate::error::{ModelError, OutputError};
use crate::model::Model;
use super::linearise::{LinearisedEnvelope, Lineariser};
use crate::scene::EnvelopeSpec;
use crate::vtk::vtu::{Field, Grid, write_vtu};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// An extreme value and where and when it happened.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Extreme {
    /// Pa.
    pub value: f64,
    /// s.
    pub t: f64,
    /// Gmsh tag of the element.
    pub element_tag: u64,
    /// Centre of the face [m].
    pub position: [f64; 3],
}

/// The envelope of one face group.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FaceEnvelope {
    pub group: String,
    /// Per face of the group: the element under it, in model order (the frames' cell order).
    pub elements: Vec<usize>,
    /// Per face: the largest σ1 [Pa] over the run.
    pub max_principal: Vec<f64>,
    /// Per face: the smallest σ3 [Pa] over the run.
    pub min_principal: Vec<f64>,
    /// The largest σ1 over the group (the largest tension when > 0).
    pub max_tension: Extreme,
    /// The smallest σ3 over the group (the largest compression when < 0).
    pub max_compression: Extreme,
    /// Per face: its corners in the reference configuration [m] (3 or 4, the face's node
    /// order), for maps of the face (the dam report's face maps). Empty in files written before
    /// it was added.
    #[serde(default)]
    pub corners: Vec<Vec<[f64; 3]>>,
    /// Per face: its area [m²] (tri3: half the cross product of two edges; quad4: half the
    /// cross product of its diagonals, exact for a plane quad). Empty in files written before
    /// it was added.
    #[serde(default)]
    pub areas: Vec<f64>,
}

/// Tension thresholds of the demand–capacity area measure [Pa]: 3, 5 and 10 MPa. Why: the
/// face area above a tensile stress, as USACE EM 1110-2-6053 plots it against the concrete's
/// dynamic tensile strength (3–5 MPa for dam concrete; 10 MPa well above any strength, the
/// area where a linear model is far from a cracked dam).
pub const TENSION_THRESHOLDS: [f64; 3] = [3e6, 5e6, 10e6];

impl FaceEnvelope {
    /// The area [m²] of the faces whose largest σ1 over the run exceeded `threshold` [Pa]
    /// (0 when the file has no areas).
    pub fn area_above(&self, threshold: f64) -> f64 {
        self.areas.iter().zip(&self.max_principal).filter(|(_, s)| **s > threshold).map(|(a, _)| a).sum()
    }
}

/// Width of the band along a face's contact with the rock excluded from the mesh-objective
/// stress [m]: 20 m. Why: the raw element peak sits in the elements touching the dam–rock
/// contact and the abutments' re-entrant corners, where the elastic stress is singular and grows
/// under refinement (docs/dam.md, "Convergence"); 20 m is two crest thicknesses (Tc 10 m) and
/// one element of the coarsest study mesh (h 20 m), so on every mesh of the study the elements
/// along the contact line are out and the same physical region is kept.
pub const OBJECTIVE_BAND: f64 = 20.0;

/// A boundary edge whose midpoint is within this fraction of its length of another boundary
/// edge is along a joint, not on the rock (dimensionless): 0.1. Why: on the rock the next edge
/// of the contact line starts at the edge's end, (L/2)·sin θ ≥ 0.1 L away from its midpoint for
/// any turn of the line sharper than θ = 11.5° back on itself; across a joint of mismatched
/// meshes the other side's chord of the same trace is at most the difference of the two
/// sagittas away, L²/(8R) = 0.05 L for L = 20 m on the 50 m radius of the tightest curve of
/// the dam's faces.
pub const JOINT_EDGE_TOLERANCE: f64 = 0.1;

/// The face stress outside a band along the face's contact with the rock (the mesh-objective
/// measure of [`FaceEnvelope::objective`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ObjectiveStress {
    /// The excluded band's width [m] (distance of a face's centre to the contact line).
    pub band: f64,
    /// Largest σ1 [Pa] over the kept faces and the centre of its face [m].
    pub max_tension: f64,
    pub max_tension_at: [f64; 3],
    /// Smallest σ3 [Pa] over the kept faces and the centre of its face [m].
    pub max_compression: f64,
    pub max_compression_at: [f64; 3],
    /// Faces kept and excluded.
    pub kept: usize,
    pub excluded: usize,
}

impl FaceEnvelope {
    /// The centre of face `i` [m] (mean of its corners).
    pub fn centre(&self, i: usize) -> [f64; 3] {
        let c = &self.corners[i];
        let n = c.len().max(1) as f64;
        let mut x = [0.0; 3];
        for p in c {
            for k in 0..3 {
                x[k] += p[k] / n;
            }
        }
        x
    }

    /// The face group's contact line with the rock: its boundary edges (an edge of exactly one
    /// face, corners matched by position to 1 mm) except those along a joint and those on the
    /// crest (both ends within 1 mm of the highest z of the group). An edge is along a joint when
    /// another boundary edge passes within [`JOINT_EDGE_TOLERANCE`] × its length of its midpoint:
    /// the two sides of a joint of mismatched meshes (the dam's odd and even monoliths) have
    /// different edges along the same trace. For a dam face: the foundation line and the
    /// abutments.
    pub fn contact_edges(&self) -> Vec<[[f64; 3]; 2]> {
        use std::collections::HashMap;
        let key = |p: &[f64; 3]| p.map(|x| (x * 1e3).round() as i64);
        let mut count: HashMap<([i64; 3], [i64; 3]), ([f64; 3], [f64; 3], usize)> = HashMap::new();
        for c in &self.corners {
            for k in 0..c.len() {
                let (a, b) = (c[k], c[(k + 1) % c.len()]);
                let (ka, kb) = (key(&a), key(&b));
                let e = count.entry(if ka < kb { (ka, kb) } else { (kb, ka) }).or_insert((a, b, 0));
                e.2 += 1;
            }
        }
        let top = self.corners.iter().flatten().map(|p| p[2]).fold(f64::NEG_INFINITY, f64::max);
        let boundary: Vec<[[f64; 3]; 2]> = count
            .into_values()
            .filter(|(a, b, n)| *n == 1 && !(a[2] >= top - 1e-3 && b[2] >= top - 1e-3))
            .map(|(a, b, _)| [a, b])
            .collect();
        let along_joint = |i: usize| {
            let [a, b] = boundary[i];
            let m = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2])];
            let tol = JOINT_EDGE_TOLERANCE * segment_distance(a, b, b);
            boundary.iter().enumerate().any(|(k, f)| k != i && segment_distance(m, f[0], f[1]) < tol)
        };
        let mut edges: Vec<[[f64; 3]; 2]> = (0..boundary.len()).filter(|&i| !along_joint(i)).map(|i| boundary[i]).collect();
        edges.sort_by(|x, y| x[0].partial_cmp(&y[0]).unwrap_or(std::cmp::Ordering::Equal));
        edges
    }

    /// Which faces are within `band` [m] of the contact line ([`Self::contact_edges`]): the
    /// distance of the face's centre to the nearest edge segment.
    pub fn in_band(&self, band: f64) -> Vec<bool> {
        let edges = self.contact_edges();
        (0..self.corners.len())
            .map(|i| {
                let x = self.centre(i);
                edges.iter().any(|e| segment_distance(x, e[0], e[1]) <= band)
            })
            .collect()
    }

    /// The mesh-objective face stress: the envelope's σ1 and σ3 over the faces outside `band`
    /// [m] of the contact with the rock. `None` without corners (files written before them) or
    /// when every face is in the band.
    pub fn objective(&self, band: f64) -> Option<ObjectiveStress> {
        if self.corners.len() != self.elements.len() || self.corners.is_empty() {
            return None;
        }
        let out = self.in_band(band);
        let kept: Vec<usize> = (0..out.len()).filter(|&i| !out[i]).collect();
        let t = *kept.iter().max_by(|&&a, &&b| self.max_principal[a].total_cmp(&self.max_principal[b]))?;
        let c = *kept.iter().min_by(|&&a, &&b| self.min_principal[a].total_cmp(&self.min_principal[b]))?;
        Some(ObjectiveStress {
            band,
            max_tension: self.max_principal[t],
            max_tension_at: self.centre(t),
            max_compression: self.min_principal[c],
            max_compression_at: self.centre(c),
            kept: kept.len(),
            excluded: out.len() - kept.len(),
        })
    }
}

/// Distance from point `x` to segment `a`–`b` [m].
fn segment_distance(x: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let v = |p: [f64; 3]| nalgebra::Vector3::from(p);
    let (ab, ax) = (v(b) - v(a), v(x) - v(a));
    let s = if ab.norm_squared() > 0.0 { (ax.dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0) } else { 0.0 };
    (ax - s * ab).norm()
}

/// Area of a tri3 or quad4 face with corner points `x` (see [`FaceEnvelope::areas`]).
fn face_area(x: &[[f64; 3]]) -> f64 {
    let v = |p: [f64; 3]| nalgebra::Vector3::from(p);
    let cross = match x.len() {
        3 => (v(x[1]) - v(x[0])).cross(&(v(x[2]) - v(x[0]))),
        4 => (v(x[2]) - v(x[0])).cross(&(v(x[3]) - v(x[1]))),
        _ => return 0.0,
    };
    0.5 * cross.norm()
}

/// What `envelope.json` holds.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StressEnvelope {
    /// Steps between samples.
    pub stride: usize,
    /// Samples taken.
    pub samples: usize,
    /// Time of the last sample [s].
    pub t_last: f64,
    pub faces: Vec<FaceEnvelope>,
    /// The stresses linearised through the thickness (`output.envelope.linearise`;
    /// [`super::linearise`]). Absent in files written before it or without it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linearised: Option<LinearisedEnvelope>,
}

impl StressEnvelope {
    /// Read `envelope.json` (`path` is the file or the run directory).
    pub fn read(path: &Path) -> Result<StressEnvelope, OutputError> {
        let file = if path.is_dir() {
            path.join("envelope.json")
        } else {
            path.to_path_buf()
        };
        let text = std::fs::read_to_string(&file).map_err(|e| OutputError::read(&file, e))?;
        let env: StressEnvelope = serde_json::from_str(&text)
            .map_err(|e| OutputError::read(&file, format!("not a stress envelope: {e}")))?;
        for f in &env.faces {
            if f.max_principal.len() != f.elements.len()
                || f.min_principal.len() != f.elements.len()
                || (!f.corners.is_empty() && f.corners.len() != f.elements.len())
            {
                return Err(OutputError::read(
                    &file,
                    format!(
                        "face group \"{}\": {} elements but {} / {} values",
                        f.group,
                        f.elements.len(),
                        f.max_principal.len(),
                        f.min_principal.len()
                    ),
                ));
            }
        }
        Ok(env)
    }

    /// The envelope of face group `group`.
    pub fn face(&self, group: &str) -> Option<&FaceEnvelope> {
        self.faces.iter().find(|f| f.group == group)
    }
}

/// Tracks the envelopes while a run steps.
pub struct EnvelopeWriter {
    pub stride: usize,
    groups: Vec<String>,
    /// Per group: its face cells (mesh indices) and the model element under each.
    faces: Vec<Vec<(usize, usize)>>,
    /// Per model element: the running max σ1, min σ3 and their times (only those under a face).
    max_s1: Vec<(f64, f64)>,
    min_s3: Vec<(f64, f64)>,
    samples: usize,
    t_last: f64,
    stress: Vec<[f64; 6]>,
    lineariser: Option<Lineariser>,
}

impl EnvelopeWriter {
    /// Find the element under every face of `spec.faces`. An unknown group, a group that is not
    /// of faces, or a face that bounds no element is an error naming the group and the face.
    pub fn create(model: &Model, spec: &EnvelopeSpec) -> Result<EnvelopeWriter, crate::Error> {
        let mesh = &model.mesh;
        let ne = model.n_elements();
        // node → model elements
        let mut of_node: Vec<Vec<u32>> = vec![Vec::new(); model.n_nodes()];
        let nt = model.tets.nodes.len();
        for (e, n) in model.tets.nodes.iter().enumerate() {
            for &i in n {
                of_node[i as usize].push(e as u32);
            }
        }
        for (e, n) in model.hexes.nodes.iter().enumerate() {
            for &i in n {
                of_node[i as usize].push((nt + e) as u32);
            }
        }
        let elem_nodes = |e: usize| -> &[u32] {
            if e < nt {
                &model.tets.nodes[e]
            } else {
                &model.hexes.nodes[e - nt]
            }
        };
        let mut faces = Vec::new();
        for g in &spec.faces {
            let group = mesh.group_of_dim(g, 2)?;
            let mut v = Vec::with_capacity(group.cells.len());
            for &c in &group.cells {
                let fnodes = mesh.cells[c].nodes();
                let e = of_node[fnodes[0] as usize].iter().map(|&e| e as usize).find(|&e| fnodes.iter().all(|n| elem_nodes(e).contains(n))).ok_or_else(|| {
                    ModelError::Invalid(format!("output.envelope: face {} of group \"{g}\" bounds no volume element (give a face group on the surface of a material volume)", mesh.cells[c].tag))
                })?;
                v.push((c, e));
            }
            faces.push(v);
        }
        let lineariser = match &spec.linearise {
            Some(l) => {
                let of = |g: &str| {
                    spec.faces.iter().position(|f| f == g).ok_or_else(|| {
                        ModelError::Invalid(format!("output.envelope.linearise: \"{g}\" is not one of output.envelope.faces {:?}", spec.faces))
                    })
                };
                let (i, j) = (of(&l.from)?, of(&l.to)?);
                Some(Lineariser::create(model, (&l.from, &faces[i]), (&l.to, &faces[j]))?)
            }
            None => None,
        };
        Ok(EnvelopeWriter {
            lineariser,
            stride: spec.stride.max(1),
            groups: spec.faces.clone(),
            faces,
            max_s1: vec![(f64::NEG_INFINITY, 0.0); ne],
            min_s3: vec![(f64::INFINITY, 0.0); ne],
            samples: 0,
            t_last: 0.0,
            stress: Vec::new(),
        })
    }

    /// Sample the stresses of displacement `u` at time `t`.
    pub fn sample(&mut self, model: &Model, u: &[f64], t: f64) {
        model.element_stress_into(u, &mut self.stress);
        for g in &self.faces {
            for &(_, e) in g {
                let p = super::principal_stresses(&self.stress[e]);
                if p[0] > self.max_s1[e].0 {
                    self.max_s1[e] = (p[0], t);
                }
                if p[2] < self.min_s3[e].0 {
                    self.min_s3[e] = (p[2], t);
                }
            }
        }
        if let Some(l) = self.lineariser.as_mut() {
            l.sample(&self.stress);
        }
        self.samples += 1;
        self.t_last = t;
    }

    /// The envelope so far.
    pub fn envelope(&self, model: &Model) -> StressEnvelope {
        let mesh = &model.mesh;
        let centre = |c: usize| {
            let n = mesh.cells[c].nodes();
            let mut x = [0.0; 3];
            for &i in n {
                for (k, xk) in x.iter_mut().enumerate() {
                    *xk += mesh.nodes[i as usize][k] / n.len() as f64;
                }
            }
            x
        };
        let tag = |e: usize| {
            let nt = model.tets.nodes.len();
            let cell = if e < nt {
                model.tets.cell[e]
            } else {
                model.hexes.cell[e - nt]
            };
            mesh.cells[cell as usize].tag
        };
        let faces = self
            .groups
            .iter()
            .zip(&self.faces)
            .map(|(g, fs)| {
                let (mut ten, mut com) = (
                    Extreme {
                        value: f64::NEG_INFINITY,
                        ..Default::default()
                    },
                    Extreme {
                        value: f64::INFINITY,
                        ..Default::default()
                    },
                );
                for &(c, e) in fs {
                    if self.max_s1[e].0 > ten.value {
                        ten = Extreme {
                            value: self.max_s1[e].0,
                            t: self.max_s1[e].1,
                            element_tag: tag(e),
                            position: centre(c),
                        };
                    }
                    if self.min_s3[e].0 < com.value {
                        com = Extreme {
                            value: self.min_s3[e].0,
                            t: self.min_s3[e].1,
                            element_tag: tag(e),
                            position: centre(c),
                        };
                    }
                }
                FaceEnvelope {
                    group: g.clone(),
                    elements: fs.iter().map(|&(_, e)| e).collect(),
                    max_principal: fs.iter().map(|&(_, e)| self.max_s1[e].0).collect(),
                    min_principal: fs.iter().map(|&(_, e)| self.min_s3[e].0).collect(),
                    max_tension: ten,
                    max_compression: com,
                    corners: fs
                        .iter()
                        .map(|&(c, _)| {
                            mesh.cells[c]
                                .nodes()
                                .iter()
                                .map(|&i| mesh.nodes[i as usize])
                                .collect()
                        })
                        .collect(),
                    areas: fs.iter().map(|&(c, _)| face_area(&mesh.cells[c].nodes().iter().map(|&n| mesh.nodes[n as usize]).collect::<Vec<_>>())).collect(),
                }
            })
            .collect();
        StressEnvelope {
            stride: self.stride,
            samples: self.samples,
            t_last: self.t_last,
            faces,
            linearised: self.lineariser.as_ref().map(Lineariser::envelope),
        }
    }

    /// Write `envelope.vtu` and `envelope.json` into `out_dir` (nothing if no sample was taken).
    pub fn write(&self, model: &Model, out_dir: &Path) -> Result<Option<PathBuf>, OutputError> {
        if self.samples == 0 {
            return Ok(None);
        }
        let env = self.envelope(model);
        let mesh = &model.mesh;
        let (mut s1, mut s3, mut t1, mut t3, mut gid) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut cells = Vec::new();
        for (k, fs) in self.faces.iter().enumerate() {
            for &(c, e) in fs {
                cells.push((mesh.cells[c].kind, mesh.cells[c].nodes()));
                s1.push(self.max_s1[e].0);
                s3.push(self.min_s3[e].0);
                t1.push(self.max_s1[e].1);
                t3.push(self.min_s3[e].1);
                gid.push(k as i32);
            }
        }
        let grid = Grid {
            points: &mesh.nodes,
            cells,
        };
        write_vtu(
            &out_dir.join("envelope.vtu"),
            &grid,
            &[],
            &[
                Field::f64("max_principal", 1, &s1),
                Field::f64("min_principal", 1, &s3),
                Field::f64("max_principal_t", 1, &t1),
                Field::f64("min_principal_t", 1, &t3),
                Field::i32("group", 1, &gid),
            ],
        )?;
        let p = out_dir.join("envelope.json");
        std::fs::write(
            &p,
            serde_json::to_string(&env).expect("an envelope serialises"),
        )
        .map_err(|e| OutputError::write(&p, e))?;
        Ok(Some(p))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn face_areas_sum_to_the_face_and_the_area_above_a_threshold_counts_only_those_faces() {
        // Reference: the x0 face of a 2 × 1 × 1 m box is 1 m² whatever its cells (quad4 of a
        // hex mesh, tri3 of a tet mesh); to 1e-12. Then a hand-made envelope: faces of 1, 2
        // and 3 m² at 2, 4 and 11 MPa: above 3 MPa 5 m², above 5 MPa 3 m², above 10 MPa 3 m².
        for tets in [false, true] {
            let m = crate::linalg::assemble::tests::box_model(tets, [2, 3, 2]);
            let w = EnvelopeWriter::create(&m, &EnvelopeSpec { faces: vec!["b:x0".into()], stride: 1, linearise: None }).unwrap();
            let env = w.envelope(&m);
            let total: f64 = env.faces[0].areas.iter().sum();
            assert!((total - 1.0).abs() < 1e-12, "tets {tets}: {total}");
        }
        let f = FaceEnvelope {
            group: "g".into(),
            elements: vec![0, 1, 2],
            max_principal: vec![2e6, 4e6, 11e6],
            min_principal: vec![0.0; 3],
            max_tension: Extreme::default(),
            max_compression: Extreme::default(),
            corners: vec![],
            areas: vec![1.0, 2.0, 3.0],
        };
        let got: Vec<f64> = TENSION_THRESHOLDS.iter().map(|&t| f.area_above(t)).collect();
        assert_eq!(got, vec![5.0, 3.0, 3.0]);
    }

    #[test]
    fn the_objective_band_excludes_exactly_the_faces_near_the_rock_and_keeps_the_crest() {
        // A 50 × 30 m face in the xz-plane, crest at z = 30, rock along z = 0, x = 0 and x = 50
        // (each square has its own corners, as across a joint). Distance of a face centre to the
        // contact line: min(z, x, 50 − x) (the crest and the joints are not contact), so a 12 m
        // band keeps exactly the centres with 12 < x < 38 and z > 12: x 15, 35 at z 15, 25 and
        // x 25 at z 12.5 … 27.5; the 50 MPa in the corner face is out, the 7 MPa at (25, 22.5)
        // is the objective peak, the −9 MPa at (35, 15) its σ3.
        let mut f = FaceEnvelope { group: "g".into(), elements: vec![], max_principal: vec![], min_principal: vec![], max_tension: Extreme::default(), max_compression: Extreme::default(), corners: vec![], areas: vec![] };
        // the middle column (x 20–30) is a monolith meshed finer, squares of 5 m: its joints
        // with its neighbours are mismatched (edges of 5 m against 10 m), not contact
        for i in 0..5 {
            let (n, d) = if i == 2 { (6, 5.0) } else { (3, 10.0) };
            for k in 0..n {
                let (x, z) = (10.0 * i as f64, d * k as f64);
                f.corners.push(vec![[x, 0.0, z], [x + 10.0, 0.0, z], [x + 10.0, 0.0, z + d], [x, 0.0, z + d]]);
                f.elements.push(f.elements.len());
                f.areas.push(10.0 * d);
                let s1 = match (i, k) { (0, 0) => 50e6, (2, 4) => 7e6, _ => 1e6 };
                let s3 = match (i, k) { (4, 0) => -40e6, (3, 1) => -9e6, _ => -1e6 };
                f.max_principal.push(s1);
                f.min_principal.push(s3);
            }
        }
        // the base (5 edges), the two sides (3 + 3); not the joints, not the crest
        assert_eq!(f.contact_edges().len(), 5 + 3 + 3);
        let band = f.in_band(12.0);
        let kept: Vec<[f64; 3]> = (0..f.elements.len()).filter(|&i| !band[i]).map(|i| f.centre(i)).collect();
        let want: Vec<[f64; 3]> = vec![[15.0, 0.0, 15.0], [15.0, 0.0, 25.0], [25.0, 0.0, 12.5], [25.0, 0.0, 17.5], [25.0, 0.0, 22.5], [25.0, 0.0, 27.5], [35.0, 0.0, 15.0], [35.0, 0.0, 25.0]];
        assert_eq!(kept, want);
        let o = f.objective(12.0).unwrap();
        assert_eq!((o.max_tension, o.max_tension_at, o.max_compression, o.max_compression_at, o.kept, o.excluded), (7e6, [25.0, 0.0, 22.5], -9e6, [35.0, 0.0, 15.0], 8, 10));
        // area above 3 MPa: the 50 MPa (100 m²) and 7 MPa (50 m²) faces, 150 m² (hand sum);
        // above 10 MPa: the first only
        assert_eq!((f.area_above(3e6), f.area_above(10e6)), (150.0, 100.0));
        // a band wider than the face keeps nothing
        assert_eq!(f.objective(30.0), None);
    }
}

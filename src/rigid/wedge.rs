//! Hoek & Bray limit equilibrium of a tetrahedral rock wedge on two joint planes.
//!
//! Port of `refs/hoek_bray_wedge.py` (shared refs): the wedge is built as an explicit
//! tetrahedron — toe O (where the line of intersection of A and B daylights in the slope
//! face, at the origin), P (top of the line of intersection, on the upper slope), QA and
//! QB (crest points: plane A resp. B ∩ face ∩ upper slope). It slides along the line of
//! intersection; the normal reactions NA, NB balance the weight normal to that line (a
//! 2×2 solve); Mohr-Coulomb on both planes gives
//!
//! ```text
//! FS = (cA AA + cB AB + (NA − UA) tan φA + (NB − UB) tan φB) / (W sin ψi)
//! ```
//!
//! Conventions: see [`crate::rigid`] (axes, upward plane normals, ground-acceleration
//! signs). `e` is the unit vector of the line of intersection pointing *down* it; the
//! trend/plunge are those of `e`. Height H is either the vertical rise of the line of
//! intersection (O to P, [`HeightDef::Intersection`], default, the "total wedge height"
//! of the Hoek & Bray short solution) or the height of QA above the toe
//! ([`HeightDef::CrestOnA`], H1 of the comprehensive solution / SWedge). For the seed
//! geometry with H = 39.624 m the two readings give FS 1.848 and 1.677 (dry).
//!
//! Water ([`Water::HoekBrayShort`]): wedge saturated, pressure zero on the free faces and
//! γw H/2 on the line of intersection (H = rise of the line), so U = γw H A / 6 per joint.
//!
//! Tension crack ([`TensionCrack`], dry only): a plane of given dip / dip direction through
//! the point X0 at distance L from the crest point QA along the trace of plane A on the
//! upper slope, towards P (Hoek & Bray's appendix definition, 0 ≤ L < |QA P|). The wedge is
//! the tetrahedron clipped by that plane, keeping the side of the toe O and of the crest:
//! each face triangle is clipped by the half-space, the solid is closed by the cap polygon
//! on the crack, the volume is a sum of tetrahedra (an inner point to a fan of each face).
//! The same limit equilibrium then uses the truncated weight and the clipped areas on A and
//! B (the crack face carries no force), and so do [`strength_reduction_factor`] and
//! [`wedge_seismic_coeffs`] (both go through [`analyse_wedge`]). The crack always cuts off P;
//! it may also cut off QB (crossing the slope face near QB), which the clipping handles.
//! Errors: L ≥ |QA P| ([`RigidError::CrackMissesWedge`]), the toe O behind the crack
//! ([`RigidError::CrackCutsOffToe`]), no volume left ([`RigidError::CrackLeavesNothing`]),
//! a crack with water pressure ([`RigidError::CrackWithWater`]: the comprehensive water
//! case with a water-filled crack is not implemented). Reference: `clipped_wedge_fs` of the
//! same script (appendix wedge, crack 70/165, L = 12.192 m, H1 = 30.48 m: FS 1.7369).
//!
//! Not covered: water with a tension crack, a wedge in contact with one plane only
//! (reported as [`RigidError::LostContact`]), external loads other than the pseudo-static
//! ground acceleration.

use super::{RigidError, non_negative, positive};
use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
use serde::{Deserialize, Serialize};

type V3 = Vector3<f64>;

/// Orientation of a plane: dip [deg, 0..90] and dip direction [deg, clockwise from north].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneOrientation {
    pub dip: f64,
    pub dip_direction: f64,
}

impl PlaneOrientation {
    pub const fn new(dip: f64, dip_direction: f64) -> Self {
        PlaneOrientation { dip, dip_direction }
    }

    /// Upward unit normal (x east, y north, z up).
    pub fn normal(&self) -> V3 {
        let (d, a) = (self.dip.to_radians(), self.dip_direction.to_radians());
        V3::new(d.sin() * a.sin(), d.sin() * a.cos(), d.cos())
    }

    fn check(&self, what: &str) -> Result<(), RigidError> {
        if !(self.dip.is_finite() && (0.0..=90.0).contains(&self.dip)) {
            return Err(RigidError::invalid(&format!("{what} dip [deg]"), self.dip, "must be in 0..=90"));
        }
        if !self.dip_direction.is_finite() {
            return Err(RigidError::invalid(&format!("{what} dip direction [deg]"), self.dip_direction, "must be finite"));
        }
        Ok(())
    }
}

impl std::fmt::Display for PlaneOrientation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{:03}", self.dip, self.dip_direction)
    }
}

/// Mohr-Coulomb strength of one joint plane.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointStrength {
    /// Cohesion [Pa].
    pub cohesion: f64,
    /// Friction angle [deg].
    pub friction: f64,
}

/// What the wedge height H measures.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HeightDef {
    /// Vertical rise of the line of intersection from the toe O to its top P (default).
    #[default]
    Intersection,
    /// Height of the crest point QA on plane A above the toe (Hoek & Bray H1).
    CrestOnA,
}

/// Water pressure on the joints.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Water {
    /// No water pressure (default).
    #[default]
    Dry,
    /// Hoek & Bray short-solution assumption: U = γw H A / 6 on each joint.
    HoekBrayShort,
}

/// A tension crack behind the crest (Hoek & Bray's appendix definition): a plane of
/// orientation `orientation` through the point at distance `distance` from the crest point
/// QA along the trace of plane A on the upper slope (towards P). It truncates the wedge; the
/// part in front of it (the side of the toe O and the crest) is analysed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TensionCrack {
    /// Dip / dip direction of the crack plane [deg]; no default (both required).
    pub orientation: PlaneOrientation,
    /// L [m]: distance from the crest point QA along the trace of plane A on the upper slope
    /// towards P, 0 <= L < |QA P|; no default (required).
    pub distance: f64,
}

impl std::fmt::Display for TensionCrack {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} at L = {} m", self.orientation, self.distance)
    }
}

/// Everything the limit equilibrium needs. `Default` is the seed-paper wedge
/// (Hoek & Bray's example in SI: A 45/105, B 70/235, face 65/185, upper 12/195,
/// H = 39.624 m along the intersection, cA 24 kPa φA 20°, cB 48 kPa φB 30°,
/// ρ = 2563 kg/m³, g = 9.81 m/s², dry, no tension crack).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WedgeInput {
    pub plane_a: PlaneOrientation,
    pub plane_b: PlaneOrientation,
    pub face: PlaneOrientation,
    pub upper: PlaneOrientation,
    /// Wedge height H [m]; what it measures is `height_def`.
    pub height: f64,
    pub height_def: HeightDef,
    pub joint_a: JointStrength,
    pub joint_b: JointStrength,
    /// Rock density [kg/m³] (default 2563 = 160 pcf, the seed example).
    pub density: f64,
    /// Gravity [m/s²] (default 9.81, the project's value).
    pub g: f64,
    pub water: Water,
    /// Water density [kg/m³] (default 1000), used only with water pressure.
    pub water_density: f64,
    /// Tension crack truncating the wedge (default none: the full tetrahedron). Dry only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tension_crack: Option<TensionCrack>,
}

impl Default for WedgeInput {
    fn default() -> Self {
        WedgeInput {
            plane_a: PlaneOrientation::new(45.0, 105.0),
            plane_b: PlaneOrientation::new(70.0, 235.0),
            face: PlaneOrientation::new(65.0, 185.0),
            upper: PlaneOrientation::new(12.0, 195.0),
            height: 39.624,
            height_def: HeightDef::Intersection,
            joint_a: JointStrength { cohesion: 24e3, friction: 20.0 },
            joint_b: JointStrength { cohesion: 48e3, friction: 30.0 },
            density: 2563.0,
            g: 9.81,
            water: Water::Dry,
            water_density: 1000.0,
            tension_crack: None,
        }
    }
}

impl WedgeInput {
    fn check(&self) -> Result<(), RigidError> {
        self.plane_a.check("plane A")?;
        self.plane_b.check("plane B")?;
        self.face.check("slope face")?;
        self.upper.check("upper slope")?;
        positive("wedge height H [m]", self.height)?;
        positive("rock density [kg/m3]", self.density)?;
        positive("g [m/s2]", self.g)?;
        non_negative("water density [kg/m3]", self.water_density)?;
        for (name, j) in [("A", &self.joint_a), ("B", &self.joint_b)] {
            non_negative(&format!("cohesion of plane {name} [Pa]"), j.cohesion)?;
            if !(j.friction.is_finite() && (0.0..90.0).contains(&j.friction)) {
                return Err(RigidError::invalid(&format!("friction angle of plane {name} [deg]"), j.friction, "must be in 0..90"));
            }
        }
        if let Some(tc) = &self.tension_crack {
            tc.orientation.check("tension crack")?;
            non_negative("tension crack distance L behind the crest [m]", tc.distance)?;
            if self.water != Water::Dry {
                return Err(RigidError::CrackWithWater { crack: tc.to_string() });
            }
        }
        Ok(())
    }
}

/// The wedge tetrahedron and its measures. With a tension crack, the vertices O, P, QA, QB
/// are those of the untruncated tetrahedron and the volume and areas those of the truncated
/// wedge (details in `crack`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WedgeGeometry {
    /// Toe O: the line of intersection daylights in the slope face here (origin) [m].
    pub o: [f64; 3],
    /// Top P of the line of intersection, on the upper slope [m].
    pub p: [f64; 3],
    /// Crest point QA: plane A ∩ face ∩ upper slope [m].
    pub qa: [f64; 3],
    /// Crest point QB: plane B ∩ face ∩ upper slope [m].
    pub qb: [f64; 3],
    /// Upward unit normals of A, B, face, upper slope.
    pub normal_a: [f64; 3],
    pub normal_b: [f64; 3],
    pub normal_face: [f64; 3],
    pub normal_upper: [f64; 3],
    /// Unit normals of A and B pointing into the wedge (direction of NA, NB on the wedge).
    pub inward_a: [f64; 3],
    pub inward_b: [f64; 3],
    /// Unit vector down the line of intersection.
    pub e: [f64; 3],
    /// Trend [deg from north] and plunge [deg] of the line of intersection.
    pub trend: f64,
    pub plunge: f64,
    /// Heights above the toe [m]: P (rise of the line of intersection), QA, QB.
    pub height_intersection: f64,
    pub height_crest_a: f64,
    pub height_crest_b: f64,
    /// Volume [m³] and face areas [m²] of the wedge that is analysed: A (O P QA), B (O P QB),
    /// face (O QA QB), upper (P QA QB), each clipped by the tension crack if there is one.
    pub volume: f64,
    pub area_a: f64,
    pub area_b: f64,
    pub area_face: f64,
    pub area_upper: f64,
    /// The truncation by the tension crack (absent without one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub crack: Option<CrackGeometry>,
}

/// The wedge truncated by a tension crack: the tetrahedron O P QA QB clipped by the crack
/// plane, keeping the side of the toe O (and of the crest point QA).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CrackGeometry {
    /// The crack as given (orientation [deg], L [m]).
    pub crack: TensionCrack,
    /// Upward unit normal of the crack plane.
    pub normal: [f64; 3],
    /// X0: where the crack meets the trace of plane A on the upper slope, L from QA towards P [m].
    pub point: [f64; 3],
    /// |QA P|: length of the trace of plane A on the upper slope [m] (the largest L).
    pub trace_length_a: f64,
    /// Where the crack cuts the line of intersection O P [m] (null if it does not, i.e. if
    /// it passes through the toe).
    pub on_intersection: Option<[f64; 3]>,
    /// Vertices of the tetrahedron cut off by the crack (always "P"; "QB" too if the crack
    /// also crosses the slope face near QB).
    pub removed: Vec<String>,
    /// Vertices of the truncated wedge [m]: the kept tetrahedron vertices, then the points
    /// where the crack cuts the tetrahedron's edges.
    pub vertices: Vec<[f64; 3]>,
    /// Area of the crack face of the truncated wedge [m²].
    pub area_crack: f64,
    /// The untruncated tetrahedron: volume [m³], areas on A and B [m²].
    pub full_volume: f64,
    pub full_area_a: f64,
    pub full_area_b: f64,
}

/// Limit-equilibrium result. Forces in N, FS dimensionless.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WedgeResult {
    pub input: WedgeInput,
    pub geometry: WedgeGeometry,
    /// Mass [kg] and weight [N].
    pub mass: f64,
    pub weight: f64,
    /// Normal reactions of planes A and B on the wedge (total, before uplift) [N].
    pub normal_a: f64,
    pub normal_b: f64,
    /// Water forces on A and B [N] (0 when dry).
    pub uplift_a: f64,
    pub uplift_b: f64,
    /// W sin ψi, the weight component down the line of intersection [N].
    pub driving_force: f64,
    /// cA AA + cB AB + (NA − UA) tan φA + (NB − UB) tan φB [N].
    pub resisting_force: f64,
    pub fs: f64,
    /// FS with the cohesion left out.
    pub fs_friction_only: f64,
    /// Non-fatal remarks (e.g. negative effective normal force with water).
    pub warnings: Vec<String>,
}

/// Build the wedge tetrahedron (O, P, QA, QB) and its measures.
pub fn build_wedge(input: &WedgeInput) -> Result<WedgeGeometry, RigidError> {
    input.check()?;
    let (na, nb, nf, nu) = (input.plane_a.normal(), input.plane_b.normal(), input.face.normal(), input.upper.normal());
    let cross = na.cross(&nb);
    if cross.norm() < 1e-9 {
        return Err(RigidError::ParallelPlanes { a: input.plane_a.to_string(), b: input.plane_b.to_string() });
    }
    let mut e = cross.normalize();
    if e.z > 0.0 {
        e = -e;
    }
    if e.z > -1e-9 {
        return Err(RigidError::NotAWedge { reason: "the line of intersection of A and B is horizontal".into() });
    }
    let h = input.height;
    // Level du of the upper slope: nu · x = du.
    let du = match input.height_def {
        HeightDef::Intersection => nu.dot(&(-e * h / (-e.z))),
        HeightDef::CrestOnA => {
            let mut g = nf.cross(&na);
            if g.z < 0.0 {
                g = -g;
            }
            if g.z < 1e-9 {
                return Err(RigidError::NotAWedge { reason: "the trace of plane A on the slope face is horizontal, so H on plane A is undefined".into() });
            }
            nu.dot(&(g * h / g.z))
        }
    };
    let p = three_planes(na, nb, nu, du, "A, B and the upper slope")?;
    let qa = three_planes(na, nf, nu, du, "A, the face and the upper slope")?;
    let qb = three_planes(nb, nf, nu, du, "B, the face and the upper slope")?;
    let o = V3::zeros();
    if !(p.z > 0.0 && qa.z > 0.0 && qb.z > 0.0) || p.dot(&-e) <= 0.0 {
        return Err(RigidError::NotAWedge {
            reason: format!(
                "the line of intersection (trend/plunge {:.1}/{:.1}) does not rise from the toe to the upper slope with both crest points above the toe (P_z = {:.3}, QA_z = {:.3}, QB_z = {:.3} m); the upper slope must be flatter than the line of intersection",
                trend_plunge(e).0, trend_plunge(e).1, p.z, qa.z, qb.z
            ),
        });
    }
    if nf.dot(&p) >= 0.0 {
        return Err(RigidError::NotAWedge {
            reason: format!("the line of intersection (plunge {:.1}°) does not daylight in the slope face {}: it must plunge less steeply than the face in its direction", trend_plunge(e).1, input.face),
        });
    }
    let volume = (p - o).cross(&(qa - o)).dot(&(qb - o)).abs() / 6.0;
    if volume.is_nan() || volume <= 0.0 {
        return Err(RigidError::NotAWedge { reason: "the tetrahedron O P QA QB has no volume".into() });
    }
    let c = (o + p + qa + qb) / 4.0;
    let inward = |n: V3| if n.dot(&(c - o)) >= 0.0 { n } else { -n };
    let (trend, plunge) = trend_plunge(e);
    let full = [volume, tri_area(o, p, qa), tri_area(o, p, qb), tri_area(o, qa, qb), tri_area(p, qa, qb)];
    let (measures, crack) = match &input.tension_crack {
        None => (full, None),
        Some(tc) => {
            let (t, crack) = truncate(tc, [o, p, qa, qb], full)?;
            ([t.volume, t.area_a, t.area_b, t.area_face, t.area_upper], Some(crack))
        }
    };
    let [volume, area_a, area_b, area_face, area_upper] = measures;
    Ok(WedgeGeometry {
        o: o.into(),
        p: p.into(),
        qa: qa.into(),
        qb: qb.into(),
        normal_a: na.into(),
        normal_b: nb.into(),
        normal_face: nf.into(),
        normal_upper: nu.into(),
        inward_a: inward(na).into(),
        inward_b: inward(nb).into(),
        e: e.into(),
        trend,
        plunge,
        height_intersection: p.z - o.z,
        height_crest_a: qa.z - o.z,
        height_crest_b: qb.z - o.z,
        volume,
        area_a,
        area_b,
        area_face,
        area_upper,
        crack,
    })
}

/// Measures of the truncated wedge.
struct Truncated {
    volume: f64,
    area_a: f64,
    area_b: f64,
    area_face: f64,
    area_upper: f64,
}

/// Clip the tetrahedron `[O, P, QA, QB]` by the tension crack, keeping the side of the toe
/// and the crest (Hoek & Bray: the crack lies behind the crest). Each face triangle is
/// clipped by the half-space (Sutherland-Hodgman), the solid is closed by the cap polygon
/// on the crack plane, and the volume is the sum of the tetrahedra from an inner point to a
/// fan of each face. `full` = [volume, area A, B, face, upper] of the tetrahedron.
fn truncate(tc: &TensionCrack, tet: [V3; 4], full: [f64; 5]) -> Result<(Truncated, CrackGeometry), RigidError> {
    let [o, p, qa, qb] = tet;
    let name = tc.orientation.to_string();
    let nt = tc.orientation.normal();
    let trace = p - qa;
    let trace_length = trace.norm();
    let t3 = trace / trace_length;
    let x0 = qa + t3 * tc.distance;
    let misses = |reason: String| RigidError::CrackMissesWedge { crack: name.clone(), distance: tc.distance, trace_length, reason };
    if tc.distance >= trace_length {
        return Err(misses(format!(
            "it meets the trace of plane A on the upper slope {:.3} m beyond P, outside the wedge",
            tc.distance - trace_length
        )));
    }
    let along = nt.dot(&t3);
    if along.abs() < 1e-9 {
        return Err(RigidError::invalid(
            &format!("angle between the tension crack {name} and the trace of plane A on the upper slope [deg]"),
            along.asin().to_degrees(),
            "must not be 0: a crack containing that trace cannot be placed by its distance L along it; give another crack orientation",
        ));
    }
    // Signed distance to the crack plane, positive on the crest side (where QA lies for L > 0:
    // f(QA) = -L nt·t3 before the sign), snapped to 0 within the round-off of the wedge size.
    let scale = [p, qa, qb].iter().map(|v| v.norm()).fold(0.0, f64::max);
    let tol = 1e-9 * scale;
    let side = -along.signum();
    let f = |x: &V3| {
        let d = side * nt.dot(&(x - x0));
        if d.abs() <= tol { 0.0 } else { d }
    };
    let names = ["O", "P", "QA", "QB"];
    let fs: Vec<f64> = tet.iter().map(f).collect();
    if fs[0] < 0.0 {
        return Err(RigidError::CrackCutsOffToe {
            crack: name.clone(),
            distance: tc.distance,
            reason: format!(
                "the toe O lies {:.3} m behind the crack plane, on the far side from the crest point QA",
                -fs[0]
            ),
        });
    }
    if fs.iter().all(|&d| d >= 0.0) {
        // Not reached for 0 <= L < |QA P| (P is then strictly behind), kept for round-off.
        return Err(misses("it passes through P to within round-off and cuts nothing off".into()));
    }
    // Clip one convex polygon (vertices with their f) to f >= 0.
    let clip = |poly: &[(V3, f64)]| -> Vec<(V3, f64)> {
        let mut out = Vec::new();
        for i in 0..poly.len() {
            let (a, fa) = poly[i];
            let (b, fb) = poly[(i + 1) % poly.len()];
            if fa >= 0.0 {
                out.push((a, fa));
            }
            if (fa > 0.0 && fb < 0.0) || (fa < 0.0 && fb > 0.0) {
                out.push((a + (b - a) * (fa / (fa - fb)), 0.0));
            }
        }
        out
    };
    let vf = |i: usize| (tet[i], fs[i]);
    // Faces A (O P QA), B (O P QB), slope face (O QA QB), upper slope (P QA QB).
    let faces: Vec<Vec<V3>> = [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]
        .iter()
        .map(|ix| clip(&ix.map(vf)).into_iter().map(|(x, _)| x).collect())
        .collect();
    // Vertices of the truncated solid: kept tetrahedron vertices, then the cut points.
    let mut vertices: Vec<V3> = (0..4).filter(|&i| fs[i] >= 0.0).map(|i| tet[i]).collect();
    let mut cap: Vec<V3> = (0..4).filter(|&i| fs[i] == 0.0).map(|i| tet[i]).collect();
    for (i, j) in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)] {
        let (fa, fb) = (fs[i], fs[j]);
        if (fa > 0.0 && fb < 0.0) || (fa < 0.0 && fb > 0.0) {
            let x = tet[i] + (tet[j] - tet[i]) * (fa / (fa - fb));
            vertices.push(x);
            cap.push(x);
        }
    }
    // Order the cap polygon around its centroid in the crack plane.
    let cc = cap.iter().fold(V3::zeros(), |s, x| s + x) / cap.len().max(1) as f64;
    let u = if nt.cross(&V3::z()).norm() > 1e-6 { nt.cross(&V3::z()).normalize() } else { V3::x() };
    let w = nt.cross(&u);
    cap.sort_by(|a, b| {
        let ang = |x: &V3| (x - cc).dot(&w).atan2((x - cc).dot(&u));
        ang(a).total_cmp(&ang(b))
    });
    let inner = vertices.iter().fold(V3::zeros(), |s, x| s + x) / vertices.len() as f64;
    let mut volume = 0.0;
    for poly in faces.iter().chain(std::iter::once(&cap)) {
        for k in 1..poly.len().saturating_sub(1) {
            volume += (poly[0] - inner).dot(&(poly[k] - inner).cross(&(poly[k + 1] - inner))).abs() / 6.0;
        }
    }
    if !(volume > 1e-9 * full[0]) {
        return Err(RigidError::CrackLeavesNothing { crack: name, distance: tc.distance, volume, full_volume: full[0] });
    }
    let t = Truncated {
        volume,
        area_a: polygon_area(&faces[0]),
        area_b: polygon_area(&faces[1]),
        area_face: polygon_area(&faces[2]),
        area_upper: polygon_area(&faces[3]),
    };
    let on_intersection = (fs[0] > 0.0 && fs[1] < 0.0).then(|| (o + (p - o) * (fs[0] / (fs[0] - fs[1]))).into());
    let crack = CrackGeometry {
        crack: *tc,
        normal: nt.into(),
        point: x0.into(),
        trace_length_a: trace_length,
        on_intersection,
        removed: (0..4).filter(|&i| fs[i] < 0.0).map(|i| names[i].to_string()).collect(),
        vertices: vertices.iter().map(|&x| x.into()).collect(),
        area_crack: polygon_area(&cap),
        full_volume: full[0],
        full_area_a: full[1],
        full_area_b: full[2],
    };
    Ok((t, crack))
}

/// Area of a planar polygon (vertices in order) [m²].
fn polygon_area(poly: &[V3]) -> f64 {
    if poly.len() < 3 {
        return 0.0;
    }
    let mut s = V3::zeros();
    for k in 1..poly.len() - 1 {
        s += (poly[k] - poly[0]).cross(&(poly[k + 1] - poly[0]));
    }
    0.5 * s.norm()
}

/// Point on the planes a·x = 0, b·x = 0, c·x = d.
fn three_planes(a: V3, b: V3, c: V3, d: f64, what: &str) -> Result<V3, RigidError> {
    let m = Matrix3::from_rows(&[a.transpose(), b.transpose(), c.transpose()]);
    m.lu()
        .solve(&V3::new(0.0, 0.0, d))
        .filter(|x| x.iter().all(|v| v.is_finite()))
        .ok_or_else(|| RigidError::NotAWedge { reason: format!("the planes {what} do not meet in one point") })
}

fn tri_area(p: V3, q: V3, r: V3) -> f64 {
    0.5 * (q - p).cross(&(r - p)).norm()
}

/// Trend [deg from north, 0..360) and plunge [deg, ≥ 0] of a line.
pub fn trend_plunge(v: V3) -> (f64, f64) {
    let mut v = v.normalize();
    if v.z > 0.0 {
        v = -v;
    }
    let plunge = (-v.z).asin().to_degrees();
    let trend = v.x.atan2(v.y).to_degrees().rem_euclid(360.0);
    (trend, plunge)
}

/// Decomposition of a body force F on the wedge: (F · e, NA, NB) with
/// NA mA + NB mB + (F − (F·e) e) = 0 (normal equations of the consistent 3×2 system).
fn reactions(geom: &WedgeGeometry, force: V3) -> Result<(f64, f64, f64), RigidError> {
    let e = V3::from(geom.e);
    let (ma, mb) = (V3::from(geom.inward_a), V3::from(geom.inward_b));
    let drive = force.dot(&e);
    let rhs = -(force - e * drive);
    let mtm = Matrix2::new(ma.dot(&ma), ma.dot(&mb), mb.dot(&ma), mb.dot(&mb));
    let n = mtm
        .lu()
        .solve(&Vector2::new(ma.dot(&rhs), mb.dot(&rhs)))
        .ok_or_else(|| RigidError::NotAWedge { reason: "planes A and B are parallel".into() })?;
    Ok((drive, n.x, n.y))
}

fn uplifts(input: &WedgeInput, geom: &WedgeGeometry) -> (f64, f64) {
    match input.water {
        Water::Dry => (0.0, 0.0),
        Water::HoekBrayShort => {
            let gw = input.water_density * input.g;
            (gw * geom.height_intersection * geom.area_a / 6.0, gw * geom.height_intersection * geom.area_b / 6.0)
        }
    }
}

/// Hoek & Bray limit equilibrium: geometry, reactions, FS.
pub fn analyse_wedge(input: &WedgeInput) -> Result<WedgeResult, RigidError> {
    let geometry = build_wedge(input)?;
    let mass = input.density * geometry.volume;
    let weight = mass * input.g;
    let (drive, na, nb) = reactions(&geometry, V3::new(0.0, 0.0, -weight))?;
    for (plane, n) in [('A', na), ('B', nb)] {
        if n <= 0.0 {
            return Err(RigidError::LostContact { plane, load: "its own weight".into(), force: n });
        }
    }
    let (ua, ub) = uplifts(input, &geometry);
    let (ta, tb) = (input.joint_a.friction.to_radians().tan(), input.joint_b.friction.to_radians().tan());
    let cohesion = input.joint_a.cohesion * geometry.area_a + input.joint_b.cohesion * geometry.area_b;
    let friction = (na - ua) * ta + (nb - ub) * tb;
    let mut warnings = Vec::new();
    for (plane, n, u) in [('A', na, ua), ('B', nb, ub)] {
        if n - u < 0.0 {
            warnings.push(format!(
                "effective normal force on plane {plane} is negative ({:.4e} N): water pressure exceeds the contact force, the joint would open",
                n - u
            ));
        }
    }
    Ok(WedgeResult {
        input: input.clone(),
        mass,
        weight,
        normal_a: na,
        normal_b: nb,
        uplift_a: ua,
        uplift_b: ub,
        driving_force: drive,
        resisting_force: cohesion + friction,
        fs: (cohesion + friction) / drive,
        fs_friction_only: friction / drive,
        warnings,
        geometry,
    })
}

/// Strength-reduction factor: the F such that the wedge with c/F and tan φ/F on both
/// planes is at limit equilibrium (FS = 1), found by bisection to 1e-12 relative. For a
/// rigid wedge it equals the limit-equilibrium FS; FEM strength reduction is compared to it.
pub fn strength_reduction_factor(input: &WedgeInput) -> Result<f64, RigidError> {
    let fs_reduced = |f: f64| -> Result<f64, RigidError> {
        let mut r = input.clone();
        for j in [&mut r.joint_a, &mut r.joint_b] {
            j.cohesion /= f;
            j.friction = (j.friction.to_radians().tan() / f).atan().to_degrees();
        }
        Ok(analyse_wedge(&r)?.fs)
    };
    let (mut lo, mut hi) = (1.0, 1.0);
    while fs_reduced(hi)? > 1.0 {
        hi *= 2.0;
        if hi > 1e6 {
            return Err(RigidError::NoLimitState { lo, hi, reason: "the wedge stays stable under any reduction".into() });
        }
    }
    while fs_reduced(lo)? < 1.0 {
        lo *= 0.5;
        if lo < 1e-6 {
            return Err(RigidError::NoLimitState { lo, hi, reason: "the wedge is unstable even with strengths multiplied by 1e6".into() });
        }
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if fs_reduced(mid)? > 1.0 {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-12 * hi {
            break;
        }
    }
    Ok(0.5 * (lo + hi))
}

/// Linear pseudo-static coefficients of the wedge for ground acceleration
/// a_ground = g (kh ĥ + kv ẑ), ĥ the horizontal unit vector of azimuth `azimuth`
/// (port of `wedge_linear_coeffs`, refs/analytic.py section D). While both planes are in
/// contact, everything is linear in kh and kv:
///
/// - relative acceleration down the line of intersection while sliding down
///   r = r0 + rh kh + rv kv [m/s²] (friction and cohesion resisting);
/// - the same while sliding *up* the line (friction and cohesion reversed): `up`;
/// - normal reactions NA = n0 + nh kh + nv kv (same for NB) [N].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WedgeSeismicCoeffs {
    /// Azimuth of the positive horizontal ground acceleration [deg from north].
    pub azimuth: f64,
    /// Whether cohesion was kept (c = 0 on both planes otherwise).
    pub cohesion_kept: bool,
    pub mass: f64,
    pub g: f64,
    /// Down the line: [r0 (m/s²), rh (m/s² per g), rv (m/s² per g)].
    pub down: [f64; 3],
    /// Up the line: [r0, rh, rv], same units; sliding up starts when this is < 0.
    pub up: [f64; 3],
    /// NA and NB: [at rest (N), per g horizontal, per g vertical].
    pub normal_a: [f64; 3],
    pub normal_b: [f64; 3],
}

impl WedgeSeismicCoeffs {
    pub fn r0(&self) -> f64 {
        self.down[0]
    }
    pub fn rh(&self) -> f64 {
        self.down[1]
    }
    pub fn rv(&self) -> f64 {
        self.down[2]
    }

    /// Critical horizontal ground acceleration kc [g] along the azimuth (kv = 0): the
    /// wedge starts to slide down the line when kh > kc. `None` if a ground acceleration
    /// along this azimuth never destabilises the wedge (rh ≤ 0). A value ≤ 0 means the
    /// wedge slides without shaking.
    pub fn critical_horizontal_acceleration(&self) -> Option<f64> {
        (self.rh() > 0.0).then(|| -self.r0() / self.rh())
    }
}

/// The linear pseudo-static coefficients for ground acceleration along `azimuth` [deg].
/// `keep_cohesion = false` drops c on both planes (cohesion lost once sliding started).
/// Water uplift, if any, is constant and enters r0.
pub fn wedge_seismic_coeffs(input: &WedgeInput, azimuth: f64, keep_cohesion: bool) -> Result<WedgeSeismicCoeffs, RigidError> {
    if !azimuth.is_finite() {
        return Err(RigidError::invalid("ground-acceleration azimuth [deg]", azimuth, "must be finite"));
    }
    let le = analyse_wedge(input)?;
    let geom = &le.geometry;
    let (m, g) = (le.mass, input.g);
    let az = azimuth.to_radians();
    let h = V3::new(az.sin(), az.cos(), 0.0);
    let w = V3::new(0.0, 0.0, -m * g);
    let (ta, tb) = (input.joint_a.friction.to_radians().tan(), input.joint_b.friction.to_radians().tan());
    let coh = if keep_cohesion { input.joint_a.cohesion * geom.area_a + input.joint_b.cohesion * geom.area_b } else { 0.0 };
    let (ua, ub) = (le.uplift_a, le.uplift_b);
    // Body force = weight − m a_ground; kh = 1 or kv = 1 give the unit responses.
    let (d0, na0, nb0) = reactions(geom, w)?;
    let (dh, nah, nbh) = reactions(geom, w - h * (m * g))?;
    let (dv, nav, nbv) = reactions(geom, w - V3::z() * (m * g))?;
    let fric = |na: f64, nb: f64| na * ta + nb * tb;
    let f0 = fric(na0 - ua, nb0 - ub);
    let (fh, fv) = (fric(nah, nbh) - fric(na0, nb0), fric(nav, nbv) - fric(na0, nb0));
    let (ddh, ddv) = (dh - d0, dv - d0);
    Ok(WedgeSeismicCoeffs {
        azimuth,
        cohesion_kept: keep_cohesion,
        mass: m,
        g,
        down: [(d0 - f0 - coh) / m, (ddh - fh) / m, (ddv - fv) / m],
        up: [(d0 + f0 + coh) / m, (ddh + fh) / m, (ddv + fv) / m],
        normal_a: [na0, nah - na0, nav - na0],
        normal_b: [nb0, nbh - nb0, nbv - nb0],
    })
}

/// Pseudo-static critical horizontal acceleration [g] for ground acceleration along
/// `azimuth` [deg], cohesion kept; see [`WedgeSeismicCoeffs::critical_horizontal_acceleration`].
pub fn critical_horizontal_acceleration(input: &WedgeInput, azimuth: f64) -> Result<Option<f64>, RigidError> {
    Ok(wedge_seismic_coeffs(input, azimuth, true)?.critical_horizontal_acceleration())
}

/// A short plain-text table of the limit equilibrium (for `jointquake wedge-fs`).
pub fn wedge_fs_report(input: &WedgeInput) -> Result<String, RigidError> {
    use std::fmt::Write;
    let r = analyse_wedge(input)?;
    let srf = strength_reduction_factor(input)?;
    let g = &r.geometry;
    let hdef = match input.height_def {
        HeightDef::Intersection => "vertical rise of the line of intersection",
        HeightDef::CrestOnA => "crest point on plane A above the toe",
    };
    let water = match input.water {
        Water::Dry => "dry".to_string(),
        Water::HoekBrayShort => format!("Hoek & Bray short-solution water pressure (rho_w = {} kg/m3)", input.water_density),
    };
    let mut s = String::new();
    let v = |x: [f64; 3]| format!("({:9.3}, {:9.3}, {:9.3})", x[0], x[1], x[2]);
    let _ = writeln!(s, "Hoek & Bray wedge, limit equilibrium (x east, y north, z up; toe O at the origin)");
    let _ = writeln!(s, "  planes (dip/dip direction, deg): A {}  B {}  face {}  upper {}", input.plane_a, input.plane_b, input.face, input.upper);
    let _ = writeln!(s, "  H = {:.3} m ({hdef}); {water}", input.height);
    let _ = writeln!(
        s,
        "  strength: A c = {:.1} kPa, phi = {:.1} deg;  B c = {:.1} kPa, phi = {:.1} deg;  rho = {} kg/m3, g = {} m/s2",
        input.joint_a.cohesion / 1e3,
        input.joint_a.friction,
        input.joint_b.cohesion / 1e3,
        input.joint_b.friction,
        input.density,
        input.g
    );
    let _ = writeln!(s, "  {:<34} {}", "vertex P  (top of intersection) [m]", v(g.p));
    let _ = writeln!(s, "  {:<34} {}", "vertex QA (crest on A) [m]", v(g.qa));
    let _ = writeln!(s, "  {:<34} {}", "vertex QB (crest on B) [m]", v(g.qb));
    if let Some(c) = &g.crack {
        let _ = writeln!(
            s,
            "  tension crack {} at L = {:.3} m behind the crest along the trace of A (|QA P| = {:.3} m); truncated wedge (cut off: {})",
            c.crack.orientation,
            c.crack.distance,
            c.trace_length_a,
            c.removed.join(", ")
        );
        let _ = writeln!(s, "  {:<34} {}", "crack on the upper slope X0 [m]", v(c.point));
        if let Some(x) = c.on_intersection {
            let _ = writeln!(s, "  {:<34} {}", "crack on the intersection [m]", v(x));
        }
    }
    let mut rows: Vec<(&str, String)> = Vec::new();
    if let Some(c) = &g.crack {
        rows.push(("tetrahedron volume (no crack)", format!("{:.2} m3", c.full_volume)));
        rows.push(("tetrahedron area A, B (no crack)", format!("{:.2}, {:.2} m2", c.full_area_a, c.full_area_b)));
        rows.push(("area of the crack face", format!("{:.2} m2", c.area_crack)));
    }
    let volume_label = if g.crack.is_some() { "volume (truncated by the crack)" } else { "volume" };
    rows.extend([
        ("line of intersection trend/plunge", format!("{:.2} / {:.2} deg", g.trend, g.plunge)),
        ("heights P, QA, QB above toe", format!("{:.3}, {:.3}, {:.3} m", g.height_intersection, g.height_crest_a, g.height_crest_b)),
        (volume_label, format!("{:.2} m3", g.volume)),
        ("weight", format!("{:.4} MN", r.weight / 1e6)),
        ("area A, B", format!("{:.2}, {:.2} m2", g.area_a, g.area_b)),
        ("area face, upper slope", format!("{:.2}, {:.2} m2", g.area_face, g.area_upper)),
        ("normal reaction NA, NB", format!("{:.4}, {:.4} MN", r.normal_a / 1e6, r.normal_b / 1e6)),
        ("water force UA, UB", format!("{:.4}, {:.4} MN", r.uplift_a / 1e6, r.uplift_b / 1e6)),
        ("driving force W sin(psi_i)", format!("{:.4} MN", r.driving_force / 1e6)),
        ("resisting force", format!("{:.4} MN", r.resisting_force / 1e6)),
        ("FS", format!("{:.4}", r.fs)),
        ("FS friction only (c = 0)", format!("{:.4}", r.fs_friction_only)),
        ("strength-reduction factor", format!("{:.4}", srf)),
        (
            "critical kh, ground accel. az 0",
            match critical_horizontal_acceleration(input, 0.0)? {
                Some(k) => format!("{k:.4} g"),
                None => "none (this azimuth does not destabilise)".into(),
            },
        ),
    ]);
    for (k, val) in rows {
        let _ = writeln!(s, "  {k:<34} {val}");
    }
    for w in &r.warnings {
        let _ = writeln!(s, "  warning: {w}");
    }
    Ok(s)
}

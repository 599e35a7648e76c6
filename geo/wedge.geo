// Hoek & Bray rock wedge on a slope (seed-paper geometry), for jointquake.
//
// Axes: x east, y north, z up; lengths in m, angles in degrees. The toe O of the
// wedge (where the line of intersection of joints A and B daylights in the slope
// face) is at the origin. How it is built, the groups and the monitored points are
// described in geo/wedge.md. The vertex formulas are the same as in
// src/rigid/wedge.rs (`build_wedge`); tests/all/rigid.rs checks that they agree.
//
// Override any parameter on the command line, e.g.
//   gmsh wedge.geo -3 -setnumber H 30 -setnumber hw 4 -o wedge.msh

SetFactory("OpenCASCADE");

DefineConstant[
  dipA  = {45,  Name "Parameters/Joint A/dip [deg]"},
  ddA   = {105, Name "Parameters/Joint A/dip direction [deg]"},
  dipB  = {70,  Name "Parameters/Joint B/dip [deg]"},
  ddB   = {235, Name "Parameters/Joint B/dip direction [deg]"},
  dipF  = {65,  Name "Parameters/Slope face/dip [deg]"},
  ddF   = {185, Name "Parameters/Slope face/dip direction [deg]"},
  dipU  = {12,  Name "Parameters/Upper slope/dip [deg]"},
  ddU   = {195, Name "Parameters/Upper slope/dip direction [deg]"},
  H     = {39.624, Name "Parameters/Wedge/H [m]"},
  Hdef  = {0, Choices{0 = "vertical rise of the line of intersection", 1 = "crest point on plane A above the toe"},
           Name "Parameters/Wedge/H definition"},
  margin = {90, Name "Parameters/Rock/margin beyond the wedge [m] (80-100)"},
  toe   = {20, Name "Parameters/Rock/slope face below the toe O [m]"},
  hw    = {4,  Name "Parameters/Mesh/wedge element size hw [m]"},
  hr    = {15, Name "Parameters/Mesh/rock element size hr [m]"}
];

If (hw <= 0 || hr <= 0 || H <= 0 || margin <= 0 || toe < 0 || toe >= margin)
  Error("wedge.geo: hw, hr, H and margin must be positive and 0 <= toe < margin (hw = %g, hr = %g, H = %g, margin = %g, toe = %g)", hw, hr, H, margin, toe);
  Abort;
EndIf

d2r = Pi / 180;
// Upward unit normals n = (sin(dip) sin(dd), sin(dip) cos(dd), cos(dip)).
nAx = Sin(dipA*d2r)*Sin(ddA*d2r); nAy = Sin(dipA*d2r)*Cos(ddA*d2r); nAz = Cos(dipA*d2r);
nBx = Sin(dipB*d2r)*Sin(ddB*d2r); nBy = Sin(dipB*d2r)*Cos(ddB*d2r); nBz = Cos(dipB*d2r);
nFx = Sin(dipF*d2r)*Sin(ddF*d2r); nFy = Sin(dipF*d2r)*Cos(ddF*d2r); nFz = Cos(dipF*d2r);
nUx = Sin(dipU*d2r)*Sin(ddU*d2r); nUy = Sin(dipU*d2r)*Cos(ddU*d2r); nUz = Cos(dipU*d2r);

// Level of the upper slope, du = nU . x on that plane. The plane through a point X is
// nU . x = nU . X, with X = the top P of the line of intersection (Hdef = 0, P = H t / t_z
// with t = nA x nB pointing up) or the crest point QA on plane A (Hdef = 1, QA = H g / g_z
// with g = nF x nA pointing up).
If (Hdef == 0)
  tx = nAy*nBz - nAz*nBy; ty = nAz*nBx - nAx*nBz; tz = nAx*nBy - nAy*nBx;
Else
  tx = nFy*nAz - nFz*nAy; ty = nFz*nAx - nFx*nAz; tz = nFx*nAy - nFy*nAx;
EndIf
If (Fabs(tz) < 1e-9)
  Error("wedge.geo: the reference line for H is horizontal; check the plane orientations");
  Abort;
EndIf
du = H * (nUx*tx + nUy*ty + nUz*tz) / tz;

// A point on the planes a and b through O and on the upper slope nU . x = du:
// x = du (a x b) / (nU . (a x b)).
abx = nAy*nBz - nAz*nBy; aby = nAz*nBx - nAx*nBz; abz = nAx*nBy - nAy*nBx;
s = du / (nUx*abx + nUy*aby + nUz*abz);
Px = s*abx; Py = s*aby; Pz = s*abz;
afx = nAy*nFz - nAz*nFy; afy = nAz*nFx - nAx*nFz; afz = nAx*nFy - nAy*nFx;
s = du / (nUx*afx + nUy*afy + nUz*afz);
QAx = s*afx; QAy = s*afy; QAz = s*afz;
bfx = nBy*nFz - nBz*nFy; bfy = nBz*nFx - nBx*nFz; bfz = nBx*nFy - nBy*nFx;
s = du / (nUx*bfx + nUy*bfy + nUz*bfz);
QBx = s*bfx; QBy = s*bfy; QBz = s*bfz;
If (Pz <= 0 || QAz <= 0 || QBz <= 0)
  Error("wedge.geo: the planes do not form a wedge above the toe (P_z = %g, QA_z = %g, QB_z = %g)", Pz, QAz, QBz);
  Abort;
EndIf
Printf("wedge.geo: P  = (%.9f, %.9f, %.9f)", Px, Py, Pz);
Printf("wedge.geo: QA = (%.9f, %.9f, %.9f)", QAx, QAy, QAz);
Printf("wedge.geo: QB = (%.9f, %.9f, %.9f)", QBx, QBy, QBz);

// ---------------------------------------------------------------- rock mass
// Bounding box: the wedge's bounding box grown by `margin` sideways and below z = 0;
// the top is above the upper slope at every corner of the box.
xmin = Min(Min(0, Px), Min(QAx, QBx)) - margin; xmax = Max(Max(0, Px), Max(QAx, QBx)) + margin;
ymin = Min(Min(0, Py), Min(QAy, QBy)) - margin; ymax = Max(Max(0, Py), Max(QAy, QBy)) + margin;
zmin = -margin;
zmax = Max(Max((du - nUx*xmin - nUy*ymin)/nUz, (du - nUx*xmax - nUy*ymin)/nUz),
           Max((du - nUx*xmin - nUy*ymax)/nUz, (du - nUx*xmax - nUy*ymax)/nUz)) + 10;
L = 4 * (xmax - xmin + ymax - ymin + zmax - zmin);

box = newv; Box(box) = {xmin, ymin, zmin, xmax - xmin, ymax - ymin, zmax - zmin};

// Half-space "below the plane with upward normal n through O": a large box z <= 0
// rotated so that e_z turns into n (axis e_z x n, angle = dip).
hf = newv; Box(hf) = {-L/2, -L/2, -L, L, L, L};
Rotate {{-nFy, nFx, 0}, {0, 0, 0}, dipF*d2r} { Volume{hf}; }
hu = newv; Box(hu) = {-L/2, -L/2, -L, L, L, L};
Rotate {{-nUy, nUx, 0}, {0, 0, 0}, dipU*d2r} { Volume{hu}; }
Translate {0, 0, du/nUz} { Volume{hu}; }

// Slope body (below face and upper slope) united with the ground in front of the slope,
// a horizontal bench at z = -toe: the face continues `toe` metres below the wedge's toe O,
// so that a wedge sliding out along its line of intersection leaves the face into the air
// (it reaches the bench only after sliding about toe / sin(plunge) metres).
body() = BooleanIntersection{ Volume{box}; Delete; }{ Volume{hf}; Delete; };
body() = BooleanIntersection{ Volume{body()}; Delete; }{ Volume{hu}; Delete; };
bench = newv; Box(bench) = {xmin, ymin, zmin, xmax - xmin, ymax - ymin, -zmin - toe};
rock() = BooleanUnion{ Volume{body()}; Delete; }{ Volume{bench}; Delete; };

// Remove a throw-away copy of the wedge; the wedge itself is built afresh below from
// new points, so that wedge and rock share no point, curve or surface: the two blocks
// are meshed independently and the joints are non-conforming.
p1 = newp; Point(p1) = {0, 0, 0};
p2 = newp; Point(p2) = {Px, Py, Pz};
p3 = newp; Point(p3) = {QAx, QAy, QAz};
p4 = newp; Point(p4) = {QBx, QBy, QBz};
pm = newp; Point(pm) = {Px/2, Py/2, Pz/2};  // M, so that the rock has a node at P2 too
l0 = newl; Line(l0) = {p1, pm}; l1 = newl; Line(l1) = {pm, p2};
l2 = newl; Line(l2) = {p2, p3}; l3 = newl; Line(l3) = {p3, p1};
l4 = newl; Line(l4) = {p2, p4}; l5 = newl; Line(l5) = {p4, p1}; l6 = newl; Line(l6) = {p3, p4};
c1 = newcl; Curve Loop(c1) = {l0, l1, l2, l3}; t1 = news; Plane Surface(t1) = {c1};
c2 = newcl; Curve Loop(c2) = {l0, l1, l4, l5}; t2 = news; Plane Surface(t2) = {c2};
c3 = newcl; Curve Loop(c3) = {l3, l6, l5}; t3 = news; Plane Surface(t3) = {c3};
c4 = newcl; Curve Loop(c4) = {l2, l6, l4}; t4 = news; Plane Surface(t4) = {c4};
sl = newsl; Surface Loop(sl) = {t1, t2, t3, t4}; tool = newv; Volume(tool) = {sl};
rock() = BooleanDifference{ Volume{rock()}; Delete; }{ Volume{tool}; Delete; };
If (#rock() != 1)
  Error("wedge.geo: the rock mass came out as %g volumes instead of 1", #rock());
  Abort;
EndIf

// ---------------------------------------------------------------- wedge
// Tetrahedron O, P, QA, QB; the line of intersection O-P is split at its middle M
// (monitored point P2), the slope-face triangle carries its centroid F (P1).
q0 = newp; Point(q0) = {0, 0, 0};
q1 = newp; Point(q1) = {Px, Py, Pz};
q2 = newp; Point(q2) = {QAx, QAy, QAz};
q3 = newp; Point(q3) = {QBx, QBy, QBz};
qm = newp; Point(qm) = {Px/2, Py/2, Pz/2};
k0 = newl; Line(k0) = {q0, qm}; k1 = newl; Line(k1) = {qm, q1};
k2 = newl; Line(k2) = {q1, q2}; k3 = newl; Line(k3) = {q2, q0};
k4 = newl; Line(k4) = {q1, q3}; k5 = newl; Line(k5) = {q3, q0}; k6 = newl; Line(k6) = {q2, q3};
w1 = newcl; Curve Loop(w1) = {k0, k1, k2, k3}; wA = news; Plane Surface(wA) = {w1};
w2 = newcl; Curve Loop(w2) = {k0, k1, k4, k5}; wB = news; Plane Surface(wB) = {w2};
w3 = newcl; Curve Loop(w3) = {k3, k6, k5}; wF = news; Plane Surface(wF) = {w3};
w4 = newcl; Curve Loop(w4) = {k2, k6, k4}; wU = news; Plane Surface(wU) = {w4};
wl = newsl; Surface Loop(wl) = {wA, wB, wF, wU}; wedge = newv; Volume(wedge) = {wl};
qf = newp; Point(qf) = {(QAx + QBx)/3, (QAy + QBy)/3, (QAz + QBz)/3};
Point{qf} In Surface{wF};

// ---------------------------------------------------------------- groups
// Rock faces under the wedge: rock boundary surfaces inside the bounding box of the
// wedge's triangle on that plane (the wedge's own faces are not rock boundaries).
eps = 1e-3;
rb() = Abs(Boundary{ Volume{rock()}; });
inA() = Surface In BoundingBox{Min(0, Min(Px, QAx)) - eps, Min(0, Min(Py, QAy)) - eps, -eps,
                               Max(0, Max(Px, QAx)) + eps, Max(0, Max(Py, QAy)) + eps, Max(Pz, QAz) + eps};
inB() = Surface In BoundingBox{Min(0, Min(Px, QBx)) - eps, Min(0, Min(Py, QBy)) - eps, -eps,
                               Max(0, Max(Px, QBx)) + eps, Max(0, Max(Py, QBy)) + eps, Max(Pz, QBz) + eps};
rockA() = {}; rockB() = {};
For i In {0:#rb()-1}
  For j In {0:#inA()-1}
    If (rb(i) == inA(j))
      rockA() += rb(i);
    EndIf
  EndFor
  For j In {0:#inB()-1}
    If (rb(i) == inB(j))
      rockB() += rb(i);
    EndIf
  EndFor
EndFor
If (#rockA() != 1 || #rockB() != 1)
  Error("wedge.geo: found %g rock faces on joint A and %g on joint B (expected 1 and 1)", #rockA(), #rockB());
  Abort;
EndIf

// Fixed boundary: bottom and the four vertical sides of the box.
fixed() = Surface In BoundingBox{xmin - eps, ymin - eps, zmin - eps, xmax + eps, ymax + eps, zmin + eps};
fixed() += Surface In BoundingBox{xmin - eps, ymin - eps, zmin - eps, xmin + eps, ymax + eps, zmax + eps};
fixed() += Surface In BoundingBox{xmax - eps, ymin - eps, zmin - eps, xmax + eps, ymax + eps, zmax + eps};
fixed() += Surface In BoundingBox{xmin - eps, ymin - eps, zmin - eps, xmax + eps, ymin + eps, zmax + eps};
fixed() += Surface In BoundingBox{xmin - eps, ymax - eps, zmin - eps, xmax + eps, ymax + eps, zmax + eps};

Physical Volume("block:wedge") = {wedge};
Physical Volume("block:rock") = {rock()};
Physical Surface("joint:A:wedge") = {wA};
Physical Surface("joint:B:wedge") = {wB};
Physical Surface("joint:A:rock") = {rockA()};
Physical Surface("joint:B:rock") = {rockB()};
Physical Surface("bc:fixed") = {fixed()};

// ---------------------------------------------------------------- mesh
MeshSize{ PointsOf{ Volume{rock()}; } } = hr;
MeshSize{ PointsOf{ Volume{wedge}; } } = hw;
MeshSize{ qf } = hw;
Mesh.MeshSizeExtendFromBoundary = 1;
Mesh.MeshSizeFromCurvature = 0;
Mesh.ElementOrder = 1;
// HXT (algorithm 10): on this geometry it gives no slivers (smallest tet altitude 0.68 m at
// hw = 2.5 against 0.27 m with the default Delaunay), and the explicit time step is set by
// the smallest altitude.
Mesh.Algorithm3D = 10;
Mesh.MshFileVersion = 4.1;

// arch_dam.geo -- a parametric double-curvature arch dam cut by N radial contraction
// joints, on a foundation rock block, for jointquake (issue 15; design.md §7).
//
// The seed paper (Zhong 2022, section 5: a 210 m arch dam, 28 joints, foundation 2H) does not
// publish the dam's shape; this one is ours, laid out the way USBR's "Design of Arch Dams"
// (1977) and Engineering Monograph 36 ("Guide for preliminary design of arch dams", 1977)
// lay out a double-curvature dam: a crown cantilever (thickness and upstream overhang as
// functions of elevation) and horizontal arches whose crown radius and abutment thickening
// vary with elevation. Full description, parameters and defaults: geo/README.md, docs/dam.md.
//
// Axes (design.md §7): x across the valley from the left bank to the right bank looking
// downstream, y downstream, z up; SI units (m), angles in degrees. The upstream crest edge of
// the crown is at (0, 0, H); the crown's foundation (the valley floor) is z = 0.
//
// Arches (elevation z, zeta = z/H), parabolic in plan (USBR: parabolic arches):
//   upstream face    y = Yu(zeta) + x^2 / (2 Ru(zeta)),  Ru = Rc (rb + (1 - rb) zeta)
//   downstream face  y = Yu(zeta) + Tcr(zeta) + x^2 / (2 Rd(zeta)),
//                    1/Rd = 1/Ru + 2 (k(zeta) - 1) Tcr / Xa(zeta)^2,  k = 1 + (ka - 1) zeta
//   so the horizontal (y) thickness grows from Tcr at the crown to k Tcr at the abutments.
// Crown cantilever:
//   thickness        Tcr(zeta) = Tc + (Tb - Tc) (1 - zeta)^tpow
//   upstream face    Yu(zeta)  = -over (1 - ((zeta - zover) / (1 - zover))^2)  (0 at the crest,
//                    largest upstream overhang `over` at zeta = zover)
// Joints: vertical planes through the points of the axis (the upstream crest edge) at equal
// arc lengths w = Lc / (N + 1), radial to the crest arch (normal to the axis there), numbered
// 1..N from the left bank; monoliths 1..N+1. Monoliths jL+1..jR (nfloor of them, centred on
// the crown) stand on the valley floor z = 0; the banks are the planes through the floor's
// edges (the base traces of joints jL and jR) and the crest's ends, so every monolith has one
// planar foundation face. Upstream and downstream of the dam the valley is the dam's
// foundation outline extruded along y; above the banks the rock is a plateau at z = H.
//
// Meshing (each monolith and the rock on its own: no shared point, curve or surface, so no
// joint and no dam-rock interface conforms): monoliths 2..N are transfinite blocks (nw along
// the arch, nz up, nt through the thickness); the abutment wedges (1, N+1) are 3 transfinite
// blocks each (their triangular section split at the edge midpoints and the centroid). hex = 1:
// hex8 everywhere in the dam; hex = 0: the same structured face meshes with tet4 inside (HXT).
// Odd and even monoliths differ by one division through the thickness and up, so the two sides
// of every joint differ. The rock: unstructured tet4, hr at the dam, hrf far away.
//
// Physical groups: block:monolith:01..NN, block:rock; joint:KK:left (face of monolith KK, on
// the left of joint KK) and joint:KK:right (face of monolith KK+1); face:upstream,
// face:downstream, face:crest; interface:dam:base (the monoliths' foundation faces),
// interface:rock:base (the rock's faces under them); bc:far (the rock's bottom and 4 sides).

SetFactory("Built-in");
Geometry.AutoCoherence = 0; // never merge coincident entities: blocks must not share nodes
Mesh.MshFileVersion = 4.1;
Mesh.SaveAll = 0;
Mesh.ElementOrder = 1;

DefineConstant[
  H      = {210,  Min 1, Name "Parameters/Dam/H height [m]"},
  Lc     = {620,  Min 1, Name "Parameters/Dam/Lc crest length along the axis [m]"},
  Rc     = {270,  Min 1, Name "Parameters/Dam/Rc crest arch radius, upstream face [m]"},
  rb     = {0.35, Min 0.05, Name "Parameters/Dam/rb base-to-crest arch radius ratio [-]"},
  Tc     = {10,   Min 0.1, Name "Parameters/Dam/Tc crest thickness [m]"},
  Tb     = {50,   Min 0.1, Name "Parameters/Dam/Tb base thickness (crown) [m]"},
  tpow   = {1.5,  Min 0.5, Name "Parameters/Dam/tpow crown thickness exponent [-]"},
  over   = {16,   Min 0, Name "Parameters/Dam/over upstream overhang of the crown [m]"},
  zover  = {0.4,  Min 0, Max 0.95, Name "Parameters/Dam/zover relative elevation of the overhang [-]"},
  ka     = {1.8,  Min 1, Name "Parameters/Dam/ka abutment-to-crown thickness ratio at the crest [-]"},
  bank   = {0,    Min 0, Max 89, Name "Parameters/Valley/bank inclination [deg] (0: from Lc)"},
  nfloor = {3,    Min 1, Step 2, Name "Parameters/Valley/nfloor monoliths on the floor"},
  N      = {28,   Min 2, Step 1, Name "Parameters/Joints/N contraction joints"},
  h      = {10,   Min 0.1, Name "Parameters/Mesh/h dam size along arch and height [m]"},
  ht     = {2.5,  Min 0.01, Name "Parameters/Mesh/ht dam size through the crest thickness [m]"},
  hr     = {25,   Min 0.1, Name "Parameters/Mesh/hr rock size at the dam [m]"},
  hrf    = {120,  Min 0.1, Name "Parameters/Mesh/hrf rock size at the far faces [m]"},
  ext    = {2,    Min 0.1, Name "Parameters/Rock/ext extent beyond the dam in units of H [-]"},
  hex    = {1, Choices {0 = "tet4", 1 = "hex8 (monoliths 2..N)"}, Name "Parameters/Mesh/hex"},
  water  = {0, Choices {0 = "none", 1 = "meshed water volume"}, Name "Parameters/Water/water (issue 28)"},
  dw     = {5,    Min 0, Name "Parameters/Water/dw freeboard: pool level H - dw [m]"},
  Lw     = {3,    Min 0.1, Name "Parameters/Water/Lw water length upstream in units of the depth [-]"},
  hw     = {0,    Min 0, Name "Parameters/Water/hw water size at the dam [m] (0: h)"},
  hwf    = {0,    Min 0, Name "Parameters/Water/hwf water size at the far end [m] (0: 2 hw)"}
];

NM = N + 1;                  // monoliths
jL = (NM - nfloor) / 2;      // joint at the floor's left edge
jR = jL + nfloor;            // joint at the floor's right edge
If (Fmod(NM - nfloor, 2) != 0 || nfloor < 1 || nfloor > NM - 2 || Floor(N) != N)
  Error("arch_dam.geo: N + 1 - nfloor must be even and 1 <= nfloor <= N - 1 (N = %g, nfloor = %g)", N, nfloor);
  Abort;
EndIf
If (Tb < Tc || over < 0 || zover < 0 || zover >= 1 || rb <= 0 || ka < 1 || ext <= 0)
  Error("arch_dam.geo: need Tb >= Tc, over >= 0, 0 <= zover < 1, rb > 0, ka >= 1, ext > 0");
  Abort;
EndIf
nt0 = Ceil(Tc / ht);
If (nt0 < 3)
  nt0 = 3;   // at least 3 elements through the crest
EndIf

// ------------------------------------------------------------------ the axis
// Arc length along y = x^2/(2 Rc) from the crown: S(x) = (x sqrt(1+s^2) + Rc asinh(s)) / 2,
// s = x/Rc; its inverse by Newton (the macro reads ax_s, writes ax_x).
Macro AxisX
  ax_x = ax_s;
  For ax_i In {1:60}
    ax_u = ax_x / Rc;
    ax_S = 0.5 * (ax_x * Sqrt(1 + ax_u*ax_u) + Rc * Log(ax_u + Sqrt(1 + ax_u*ax_u)));
    ax_x = ax_x - (ax_S - ax_s) / Sqrt(1 + ax_u*ax_u);
  EndFor
Return

// The left bank plane through the base trace of joint jL and the left crest end, for the
// crest length bk_L: writes bk_n[] (unit normal, n_z > 0), bk_q[] (a point of it), bk_beta.
Macro LeftBank
  bk_w = bk_L / NM;
  ax_s = (jL - NM/2) * bk_w;
  Call AxisX;
  bk_x = ax_x; bk_y = bk_x*bk_x/(2*Rc); bk_m = Sqrt(1 + (bk_x/Rc)^2);
  bk_dx = -bk_x/Rc/bk_m; bk_dy = 1/bk_m;
  ax_s = -bk_L/2;
  Call AxisX;
  bk_vx = ax_x - bk_x; bk_vy = ax_x*ax_x/(2*Rc) - bk_y; bk_vz = H;
  bk_nx = bk_dy*bk_vz; bk_ny = -bk_dx*bk_vz; bk_nz = bk_dx*bk_vy - bk_dy*bk_vx;
  If (bk_nz < 0)
    bk_nx = -bk_nx; bk_ny = -bk_ny; bk_nz = -bk_nz;
  EndIf
  bk_nn = Sqrt(bk_nx^2 + bk_ny^2 + bk_nz^2);
  bk_n[] = {bk_nx/bk_nn, bk_ny/bk_nn, bk_nz/bk_nn};
  bk_q[] = {bk_x, bk_y, 0};
  bk_beta = Acos(bk_n[2]) * 180 / Pi;
Return

If (bank > 0)
  // solve the crest length for the given bank inclination (it grows as the banks flatten)
  lo = 1.05 * (2 * H / Tan(bank*Pi/180)); hi = 20 * H + 10 * lo;
  For it In {1:80}
    bk_L = 0.5 * (lo + hi);
    Call LeftBank;
    If (bk_beta > bank)
      lo = bk_L;
    Else
      hi = bk_L;
    EndIf
  EndFor
  Lcrest = 0.5 * (lo + hi);
Else
  Lcrest = Lc;
EndIf
bk_L = Lcrest;
Call LeftBank;
nL[] = bk_n[]; qL[] = bk_q[]; betaL = bk_beta;
// the right bank: the mirror image (x -> -x) of the left one
nR[] = {-nL[0], nL[1], nL[2]}; qR[] = {-qL[0], qL[1], 0};
w = Lcrest / NM;

// ------------------------------------------------------------------ arches
// At elevation z: Yu, Ru, Yd0 = Yu + Tcr, Rd (macro ArchAt reads az_z).
Macro ArchAt
  az_t = az_z / H;
  az_u = (az_t - zover) / (1 - zover);
  az_Yu = -over * (1 - az_u*az_u);
  az_T = Tc + (Tb - Tc) * (1 - az_t)^tpow;
  az_Ru = Rc * (rb + (1 - rb) * az_t);
  az_Xa = Xf + (Xe - Xf) * az_t;
  az_k = 1 + (ka - 1) * az_t;
  az_Rd = 1 / (1/az_Ru + 2 * (az_k - 1) * az_T / (az_Xa*az_Xa));
  az_Yd = az_Yu + az_T;
Return

// Joint planes k = 0..NM (0 and NM: the crest ends): axis point (jx, jy, H), radial
// direction (jdx, jdy) (horizontal, towards downstream).
For k In {0:NM}
  ax_s = (k - NM/2) * w;
  Call AxisX;
  jx[k] = ax_x; jy[k] = ax_x*ax_x/(2*Rc);
  jm = Sqrt(1 + (ax_x/Rc)^2);
  jdx[k] = -ax_x/Rc/jm; jdy[k] = 1/jm;
EndFor
Xe = -jx[0]; Xf = -jx[jL];

// Distance r along the radial direction of joint k from its axis point to the upstream
// (fc = 0) or downstream (fc = 1) face at elevation z (macro FaceR reads fr_k, fr_z, fr_f;
// writes fr_r): the small root of a r^2 + b r + c = 0.
Macro FaceR
  az_z = fr_z;
  Call ArchAt;
  If (fr_f == 0)
    fr_Y = az_Yu; fr_R = az_Ru;
  Else
    fr_Y = az_Yd; fr_R = az_Rd;
  EndIf
  fr_a = jdx[fr_k]^2 / (2*fr_R);
  fr_b = jx[fr_k]*jdx[fr_k]/fr_R - jdy[fr_k];
  fr_c = jx[fr_k]^2/(2*fr_R) + fr_Y - jy[fr_k];
  fr_disc = fr_b*fr_b - 4*fr_a*fr_c;
  If (fr_disc < 0)
    Error("arch_dam.geo: joint %g does not cut face %g at z = %g; check Rc, rb, ka", fr_k, fr_f, fr_z);
    Abort;
  EndIf
  fr_r = 2*fr_c / (-fr_b + Sqrt(fr_disc));
Return

// Foundation point of joint k on face fr_f: elevation of the intersection of the joint's
// face line with the valley (floor z = 0 for jL <= k <= jR, else its bank): fb_z, fb_r.
Macro FootOf
  If (fr_k >= jL && fr_k <= jR)
    fr_z = 0;
    Call FaceR;
    fb_z = 0; fb_r = fr_r;
  Else
    If (fr_k < jL)
      fb_n[] = nL[]; fb_q[] = qL[];
    Else
      fb_n[] = nR[]; fb_q[] = qR[];
    EndIf
    fb_lo = 0; fb_hi = H;
    For fb_i In {1:60}
      fr_z = 0.5 * (fb_lo + fb_hi);
      Call FaceR;
      fb_g = fb_n[0]*(jx[fr_k] + fr_r*jdx[fr_k] - fb_q[0]) + fb_n[1]*(jy[fr_k] + fr_r*jdy[fr_k] - fb_q[1]) + fb_n[2]*fr_z;
      If (fb_g > 0)
        fb_hi = fr_z;
      Else
        fb_lo = fr_z;
      EndIf
    EndFor
    fb_z = 0.5 * (fb_lo + fb_hi);
    fr_z = fb_z;
    Call FaceR;
    fb_r = fr_r;
  EndIf
Return

// Node coordinates of every joint k = 1..N: U (upstream foot), D (downstream foot),
// CU/CD (upstream/downstream crest), the profile samples PU/PD (np points, foot to crest).
np = 10;
For k In {1:N}
  fr_k = k;
  fr_f = 0; Call FootOf;
  Ux[k] = jx[k] + fb_r*jdx[k]; Uy[k] = jy[k] + fb_r*jdy[k]; Uz[k] = fb_z;
  fr_f = 1; Call FootOf;
  Dx[k] = jx[k] + fb_r*jdx[k]; Dy[k] = jy[k] + fb_r*jdy[k]; Dz[k] = fb_z;
  fr_z = H; fr_f = 1; Call FaceR;
  CDx[k] = jx[k] + fr_r*jdx[k]; CDy[k] = jy[k] + fr_r*jdy[k];
  CUx[k] = jx[k]; CUy[k] = jy[k];
EndFor
// the crest ends: upstream on the axis, downstream where the bank plane meets the downstream
// crest arch (Newton on the quadratic in x)
az_z = H; Call ArchAt; Rd1 = az_Rd; Yd1 = az_Yd;
For e In {0:1}
  If (e == 0)
    k = 0; en[] = nL[]; eq[] = qL[];
  Else
    k = NM; en[] = nR[]; eq[] = qR[];
  EndIf
  CUx[k] = jx[k]; CUy[k] = jy[k];
  xx = jx[k];
  For i In {1:60}
    ff = en[0]*(xx - eq[0]) + en[1]*(Yd1 + xx*xx/(2*Rd1) - eq[1]) + en[2]*H;
    df = en[0] + en[1]*xx/Rd1;
    xx = xx - ff/df;
  EndFor
  CDx[k] = xx; CDy[k] = Yd1 + xx*xx/(2*Rd1);
  Ux[k] = CUx[k]; Uy[k] = CUy[k]; Uz[k] = H;
  Dx[k] = CDx[k]; Dy[k] = CDy[k]; Dz[k] = H;
EndFor
ymin = -over; ymax = Dy[jL];
For k In {0:NM}
  ymax = Max(ymax, Max(Dy[k], CDy[k]));
EndFor
Printf("arch_dam.geo: crest length %.3f m, bank inclination %.3f deg, %g monoliths of %.3f m at the crest", Lcrest, betaL, NM, w);
Printf("arch_dam.geo: crest ends x = %.3f / %.3f m, floor joints %g and %g, dam y in [%.3f, %.3f] m", jx[0], jx[NM], jL, jR, ymin, ymax);

// ------------------------------------------------------------------ monoliths
// Curves of one monolith between joints kl and kr (own points and curves). Macros write
// the new curve into cv.
Macro ProfileCurve   // joint pk, face pf (0 up, 1 down): spline from the foot to the crest
  fr_k = pk; fr_f = pf; Call FootOf;
  pz0 = fb_z;
  pp[] = {};
  For pi In {0:np-1}
    fr_z = pz0 + (H - pz0) * pi / (np - 1);
    If (pi == 0)
      pr = fb_r;
    Else
      Call FaceR;
      pr = fr_r;
    EndIf
    pt = newp; Point(pt) = {jx[pk] + pr*jdx[pk], jy[pk] + pr*jdy[pk], fr_z};
    pp[] += pt;
  EndFor
  cv = newc; Spline(cv) = {pp[]};
  cvs = pp[0]; cve = pp[np-1];
Return
Macro CrestArc       // from joint ak to joint ak+1 on face af at z = H, points a0 -> a1
  aX0 = CUx[ak]; aX1 = CUx[ak+1];
  If (af == 1)
    aX0 = CDx[ak]; aX1 = CDx[ak+1];
  EndIf
  ap[] = {a0};
  For ai In {1:3}
    axx = aX0 + (aX1 - aX0) * ai / 4;
    If (af == 0)
      ayy = axx*axx/(2*Rc);
    Else
      ayy = Yd1 + axx*axx/(2*Rd1);
    EndIf
    pt = newp; Point(pt) = {axx, ayy, H}; ap[] += pt;
  EndFor
  ap[] += a1;
  cv = newc; Spline(cv) = {ap[]};
Return


// Abutment wedge (monolith 1 or N+1) between the crest end `we`, joint `wk` and the bank, as
// three transfinite blocks: its triangular section (crest end A, joint crest B, joint foot C)
// split into 3 quads by the edge midpoints and the centroid G, each swept from the upstream to
// the downstream face. wflip = 1 for the right wedge (mirror order, so the cells stay
// positively oriented). Out: wvol[] (3 volumes), wU[], wD[], wC[], wB[], wJ[] (its faces).
Macro ArcBetween     // spline on crest face af (0 up, 1 down) from point a0 at x aX0 to a1 at aX1
  ap[] = {a0};
  For ai In {1:3}
    axx = aX0 + (aX1 - aX0) * ai / 4;
    If (af == 0)
      ayy = axx*axx/(2*Rc);
    Else
      ayy = Yd1 + axx*axx/(2*Rd1);
    EndIf
    pt = newp; Point(pt) = {axx, ayy, H}; ap[] += pt;
  EndFor
  ap[] += a1;
  cv = newc; Spline(cv) = {ap[]};
Return
Macro ProfBetween    // spline on joint pk's face pf from point p0 (z pz0) to p1 (z pz1)
  pp[] = {p0};
  For pi In {1:4}
    fr_k = pk; fr_f = pf; fr_z = pz0 + (pz1 - pz0) * pi / 5;
    Call FaceR;
    pt = newp; Point(pt) = {jx[pk] + fr_r*jdx[pk], jy[pk] + fr_r*jdy[pk], fr_z}; pp[] += pt;
  EndFor
  pp[] += p1;
  cv = newc; Spline(cv) = {pp[]};
Return
Macro AbutmentWedge
  For wf In {0:1}      // 0 upstream, 1 downstream face
    If (wf == 0)
      wAx = CUx[we]; wAy = CUy[we]; wBx = CUx[wk]; wBy = CUy[wk]; wCx = Ux[wk]; wCy = Uy[wk]; wCz = Uz[wk];
    Else
      wAx = CDx[we]; wAy = CDy[we]; wBx = CDx[wk]; wBy = CDy[wk]; wCx = Dx[wk]; wCy = Dy[wk]; wCz = Dz[wk];
    EndIf
    pA[wf] = newp; Point(pA[wf]) = {wAx, wAy, H};
    pB[wf] = newp; Point(pB[wf]) = {wBx, wBy, H};
    pC[wf] = newp; Point(pC[wf]) = {wCx, wCy, wCz};
    // midpoint of AB on the crest arc, of BC on the joint's profile, of CA on the chord
    mx = 0.5 * (wAx + wBx);
    If (wf == 0)
      my = mx*mx/(2*Rc);
    Else
      my = Yd1 + mx*mx/(2*Rd1);
    EndIf
    pmAB[wf] = newp; Point(pmAB[wf]) = {mx, my, H};
    fr_k = wk; fr_f = wf; fr_z = 0.5 * (wCz + H); Call FaceR;
    pmBC[wf] = newp; Point(pmBC[wf]) = {jx[wk] + fr_r*jdx[wk], jy[wk] + fr_r*jdy[wk], fr_z};
    pmCA[wf] = newp; Point(pmCA[wf]) = {0.5*(wCx + wAx), 0.5*(wCy + wAy), 0.5*(wCz + H)};
    // centroid, moved along y onto the face
    gx = (wAx + wBx + wCx) / 3; gz = (2*H + wCz) / 3;
    az_z = gz; Call ArchAt;
    If (wf == 0)
      gy = az_Yu + gx*gx/(2*az_Ru);
    Else
      gy = az_Yd + gx*gx/(2*az_Rd);
    EndIf
    pG[wf] = newp; Point(pG[wf]) = {gx, gy, gz};
    af = wf; a0 = pA[wf]; aX0 = wAx; a1 = pmAB[wf]; aX1 = mx; Call ArcBetween;
    cAm[wf] = cv;
    af = wf; a0 = pmAB[wf]; aX0 = mx; a1 = pB[wf]; aX1 = wBx; Call ArcBetween;
    cmB[wf] = cv;
    pk = wk; pf = wf; p0 = pC[wf]; pz0 = wCz; p1 = pmBC[wf]; pz1 = 0.5*(wCz + H); Call ProfBetween;
    cCm[wf] = cv;
    pk = wk; pf = wf; p0 = pmBC[wf]; pz0 = 0.5*(wCz + H); p1 = pB[wf]; pz1 = H; Call ProfBetween;
    cmBp[wf] = cv;    // mBC -> B
    cCmA[wf] = newc; Line(cCmA[wf]) = {pC[wf], pmCA[wf]};
    cmAA[wf] = newc; Line(cmAA[wf]) = {pmCA[wf], pA[wf]};
    gAB[wf] = newc; Line(gAB[wf]) = {pmAB[wf], pG[wf]};
    gBC[wf] = newc; Line(gBC[wf]) = {pmBC[wf], pG[wf]};
    gCA[wf] = newc; Line(gCA[wf]) = {pmCA[wf], pG[wf]};
    l = newcl; Curve Loop(l) = {cAm[wf], gAB[wf], -gCA[wf], cmAA[wf]}; q1[wf] = news; Surface(q1[wf]) = {l};
    l = newcl; Curve Loop(l) = {cmB[wf], -cmBp[wf], gBC[wf], -gAB[wf]}; q2[wf] = news; Surface(q2[wf]) = {l};
    l = newcl; Curve Loop(l) = {-gBC[wf], -cCm[wf], cCmA[wf], gCA[wf]}; q3[wf] = news; Surface(q3[wf]) = {l};
  EndFor
  // through the thickness
  tA = newc; Line(tA) = {pA[0], pA[1]};   tB = newc; Line(tB) = {pB[0], pB[1]};
  tC = newc; Line(tC) = {pC[0], pC[1]};   tG = newc; Line(tG) = {pG[0], pG[1]};
  tmAB = newc; Line(tmAB) = {pmAB[0], pmAB[1]}; tmBC = newc; Line(tmBC) = {pmBC[0], pmBC[1]};
  tmCA = newc; Line(tmCA) = {pmCA[0], pmCA[1]};
  l = newcl; Curve Loop(l) = {cAm[0], tmAB, -cAm[1], -tA}; K1 = news; Surface(K1) = {l};
  l = newcl; Curve Loop(l) = {cmB[0], tB, -cmB[1], -tmAB}; K2 = news; Surface(K2) = {l};
  l = newcl; Curve Loop(l) = {-cmBp[0], tmBC, cmBp[1], -tB}; J1 = news; Surface(J1) = {l};
  l = newcl; Curve Loop(l) = {-cCm[0], tC, cCm[1], -tmBC}; J2 = news; Surface(J2) = {l};
  l = newcl; Curve Loop(l) = {cCmA[0], tmCA, -cCmA[1], -tC}; W1 = news; Plane Surface(W1) = {l};
  l = newcl; Curve Loop(l) = {cmAA[0], tA, -cmAA[1], -tmCA}; W2 = news; Plane Surface(W2) = {l};
  l = newcl; Curve Loop(l) = {gAB[0], tG, -gAB[1], -tmAB}; I1 = news; Surface(I1) = {l};
  l = newcl; Curve Loop(l) = {gBC[0], tG, -gBC[1], -tmBC}; I2 = news; Surface(I2) = {l};
  l = newcl; Curve Loop(l) = {gCA[0], tG, -gCA[1], -tmCA}; I3 = news; Surface(I3) = {l};
  sl = newsl; Surface Loop(sl) = {q1[0], q1[1], K1, I1, I3, W2}; V1 = newv; Volume(V1) = {sl};
  sl = newsl; Surface Loop(sl) = {q2[0], q2[1], K2, J1, I2, I1}; V2 = newv; Volume(V2) = {sl};
  sl = newsl; Surface Loop(sl) = {q3[0], q3[1], I2, J2, W1, I3}; V3 = newv; Volume(V3) = {sl};
  wvol[] = {V1, V2, V3}; wU[] = {q1[0], q2[0], q3[0]}; wD[] = {q1[1], q2[1], q3[1]};
  wC[] = {K1, K2}; wB[] = {W1, W2}; wJ[] = {J1, J2};
  // divisions: every half-edge and interior line nh, through the thickness nt
  nh = Ceil(0.5 * Max(w, H - Min(Uz[wk], Dz[wk])) / h);
  If (nh < 2)
    nh = 2;
  EndIf
  Transfinite Curve{cAm[], cmB[], cCm[], cmBp[], cCmA[], cmAA[], gAB[], gBC[], gCA[]} = nh + 1;
  Transfinite Curve{tA, tB, tC, tG, tmAB, tmBC, tmCA} = nt + 1;
  wS[] = {wU[], wD[], wC[], wB[], wJ[], I1, I2, I3};
  Transfinite Surface{wS[]};
  If (hex == 1)
    Recombine Surface{wS[]};
  EndIf
  If (hex == 0)
    // tet4: Delaunay inside the structured face meshes (see the monoliths' note)
  ElseIf (wflip == 0)
    Transfinite Volume{V1} = {pA[0], pmAB[0], pG[0], pmCA[0], pA[1], pmAB[1], pG[1], pmCA[1]};
    Transfinite Volume{V2} = {pmAB[0], pB[0], pmBC[0], pG[0], pmAB[1], pB[1], pmBC[1], pG[1]};
    Transfinite Volume{V3} = {pG[0], pmBC[0], pC[0], pmCA[0], pG[1], pmBC[1], pC[1], pmCA[1]};
  Else
    Transfinite Volume{V1} = {pA[0], pmCA[0], pG[0], pmAB[0], pA[1], pmCA[1], pG[1], pmAB[1]};
    Transfinite Volume{V2} = {pmAB[0], pG[0], pmBC[0], pB[0], pmAB[1], pG[1], pmBC[1], pB[1]};
    Transfinite Volume{V3} = {pG[0], pmCA[0], pC[0], pmBC[0], pG[1], pmCA[1], pC[1], pmBC[1]};
  EndIf
Return

upF[] = {}; dnF[] = {}; crF[] = {}; baseF[] = {};
For m In {1:NM}
  kl = m - 1; kr = m;
  par = Fmod(m, 2);                 // odd monoliths: nt0 and nz; even: one more of each
  nt = nt0 + 1 - par;
  If (m == 1 || m == NM)
    If (m == 1)
      wk = 1; we = 0; wflip = 0;
    Else
      wk = N; we = NM; wflip = 1;
    EndIf
    Call AbutmentWedge;
    If (m == 1)
      wedge1[] = wvol[]; jointLeft1[] = wJ[];
    Else
      wedgeN[] = wvol[]; jointRightN[] = wJ[];
    EndIf
    upF[] += wU[]; dnF[] += wD[]; crF[] += wC[]; baseF[] += wB[];
  Else
  // left side: joint kl's profiles (their end points are the corners), or the crest end
  If (m > 1)
    pk = kl; pf = 0; Call ProfileCurve;
    cPUl = cv; pUl = cvs; qCUl = cve;
    pk = kl; pf = 1; Call ProfileCurve;
    cPDl = cv; pDl = cvs; qCDl = cve;
  Else
    pUl = newp; Point(pUl) = {CUx[0], CUy[0], H}; qCUl = pUl;
    pDl = newp; Point(pDl) = {CDx[0], CDy[0], H}; qCDl = pDl;
  EndIf
  If (m < NM)
    pk = kr; pf = 0; Call ProfileCurve;
    cPUr = cv; pUr = cvs; qCUr = cve;
    pk = kr; pf = 1; Call ProfileCurve;
    cPDr = cv; pDr = cvs; qCDr = cve;
  Else
    pUr = newp; Point(pUr) = {CUx[NM], CUy[NM], H}; qCUr = pUr;
    pDr = newp; Point(pDr) = {CDx[NM], CDy[NM], H}; qCDr = pDr;
  EndIf
  ak = kl; af = 0; a0 = qCUl; a1 = qCUr; Call CrestArc;
  cAU = cv;
  ak = kl; af = 1; a0 = qCDl; a1 = qCDr; Call CrestArc;
  cAD = cv;
  cRl = newc; Line(cRl) = {qCUl, qCDl};
  cRr = newc; Line(cRr) = {qCUr, qCDr};
  cBU = newc; Line(cBU) = {pUl, pUr};
  cBD = newc; Line(cBD) = {pDl, pDr};
  If (m > 1)
    cFl = newc; Line(cFl) = {pUl, pDl};
  EndIf
  If (m < NM)
    cFr = newc; Line(cFr) = {pUr, pDr};
  EndIf
  // faces (loops as listed in geo/README.md)
  If (m == 1)
    l = newcl; Curve Loop(l) = {cAU, -cPUr, -cBU}; sU = news; Surface(sU) = {l};
    l = newcl; Curve Loop(l) = {cAD, -cPDr, -cBD}; sD = news; Surface(sD) = {l};
    l = newcl; Curve Loop(l) = {cBU, cFr, -cBD, -cRl}; sB = news; Plane Surface(sB) = {l};
  ElseIf (m == NM)
    l = newcl; Curve Loop(l) = {cAU, -cBU, cPUl}; sU = news; Surface(sU) = {l};
    l = newcl; Curve Loop(l) = {cAD, -cBD, cPDl}; sD = news; Surface(sD) = {l};
    l = newcl; Curve Loop(l) = {cBU, cRr, -cBD, -cFl}; sB = news; Plane Surface(sB) = {l};
  Else
    l = newcl; Curve Loop(l) = {cAU, -cPUr, -cBU, cPUl}; sU = news; Surface(sU) = {l};
    l = newcl; Curve Loop(l) = {cAD, -cPDr, -cBD, cPDl}; sD = news; Surface(sD) = {l};
    l = newcl; Curve Loop(l) = {cBU, cFr, -cBD, -cFl}; sB = news; Plane Surface(sB) = {l};
  EndIf
  l = newcl; Curve Loop(l) = {cAU, cRr, -cAD, -cRl}; sC = news; Surface(sC) = {l};
  faces[] = {sU, sD, sB, sC};
  If (m > 1)
    l = newcl; Curve Loop(l) = {cFl, cPDl, -cRl, -cPUl}; sJl = news; Surface(sJl) = {l};
    faces[] += sJl; jointRight[kl] = sJl;   // monolith m's face on joint kl: joint:kl:right
  EndIf
  If (m < NM)
    l = newcl; Curve Loop(l) = {cFr, cPDr, -cRr, -cPUr}; sJr = news; Surface(sJr) = {l};
    faces[] += sJr; jointLeft[kr] = sJr;    // monolith m's face on joint kr: joint:kr:left
  EndIf
  sl = newsl; Surface Loop(sl) = {faces[]};
  v = newv; Volume(v) = {sl};
  mono[m] = v;
  upF[] += sU; dnF[] += sD; crF[] += sC; baseF[] += sB;
  If (m == 1 || m == NM)
    // abutment wedge: unstructured tet4 at the through-thickness size
    MeshSize{ PointsOf{ Volume{v}; } } = ht;
  Else
    hz = H - Min(Min(Uz[kl], Uz[kr]), Min(Dz[kl], Dz[kr]));   // the tallest of its 4 profiles
    nz = Ceil(hz / h);
    If (nz < 2)
      nz = 2;
    EndIf
    nz = nz + 1 - par;
    nw = Ceil(w / h);
    If (nw < 1)
      nw = 1;
    EndIf
    Transfinite Curve{cAU, cAD, cBU, cBD} = nw + 1;
    Transfinite Curve{cPUl, cPDl, cPUr, cPDr} = nz + 1;
    Transfinite Curve{cRl, cRr, cFl, cFr} = nt + 1;
    Transfinite Surface{faces[]};
    If (hex == 1)
      Recombine Surface{faces[]};
      Transfinite Volume{v} = {pUl, pUr, pDr, pDl, qCUl, qCUr, qCDr, qCDl};
    EndIf
    // hex = 0: the structured face meshes, tet4 filled by Delaunay. Gmsh's transfinite split of
    // each cell into 6 tets does not follow the diagonals of the curved (Coons) faces' triangles
    // (measured: 844 face triangles of face:upstream were no tet face), so it is not used.
  EndIf
  EndIf
EndFor

// ------------------------------------------------------------------ rock
// Own points and curves (none shared with the dam). Its top: the dam's foundation faces,
// the up- and downstream valley (the foundation outline extruded along y), the plateaus.
xminR = Min(Ux[0], Dx[0]) - ext*H; xmaxR = Max(Ux[NM], Dx[NM]) + ext*H;
yminR = ymin - ext*H; ymaxR = ymax + ext*H; zminR = -ext*H;
For k In {0:NM}
  RU[k] = newp; Point(RU[k]) = {Ux[k], Uy[k], Uz[k]};
  RD[k] = newp; Point(RD[k]) = {Dx[k], Dy[k], Dz[k]};
  RUf[k] = newp; Point(RUf[k]) = {Ux[k], yminR, Uz[k]};
  RDf[k] = newp; Point(RDf[k]) = {Dx[k], ymaxR, Dz[k]};
  RF[k] = newc; Line(RF[k]) = {RU[k], RD[k]};
  LU[k] = newc; Line(LU[k]) = {RU[k], RUf[k]};
  LD[k] = newc; Line(LD[k]) = {RD[k], RDf[k]};
  If (k > 0)
    RBU[k] = newc; Line(RBU[k]) = {RU[k-1], RU[k]};
    RBD[k] = newc; Line(RBD[k]) = {RD[k-1], RD[k]};
    FU[k] = newc; Line(FU[k]) = {RUf[k-1], RUf[k]};
    FD[k] = newc; Line(FD[k]) = {RDf[k-1], RDf[k]};
  EndIf
EndFor
A1 = newp; Point(A1) = {xminR, yminR, H};  A2 = newp; Point(A2) = {xmaxR, yminR, H};
A3 = newp; Point(A3) = {xmaxR, yminR, zminR}; A4 = newp; Point(A4) = {xminR, yminR, zminR};
B1 = newp; Point(B1) = {xminR, ymaxR, H};  B2 = newp; Point(B2) = {xmaxR, ymaxR, H};
B3 = newp; Point(B3) = {xmaxR, ymaxR, zminR}; B4 = newp; Point(B4) = {xminR, ymaxR, zminR};
lA1 = newc; Line(lA1) = {A1, RUf[0]};   lA2 = newc; Line(lA2) = {RUf[NM], A2};
lA23 = newc; Line(lA23) = {A2, A3};     lA34 = newc; Line(lA34) = {A3, A4}; lA41 = newc; Line(lA41) = {A4, A1};
lB1 = newc; Line(lB1) = {B1, RDf[0]};   lB2 = newc; Line(lB2) = {RDf[NM], B2};
lB23 = newc; Line(lB23) = {B2, B3};     lB34 = newc; Line(lB34) = {B3, B4}; lB41 = newc; Line(lB41) = {B4, B1};
lAB1 = newc; Line(lAB1) = {A1, B1}; lAB2 = newc; Line(lAB2) = {A2, B2};
lAB3 = newc; Line(lAB3) = {A3, B3}; lAB4 = newc; Line(lAB4) = {A4, B4};
farF[] = {};
l = newcl; Curve Loop(l) = {lA41, lA1, FU[{1:NM}], lA2, lA23, lA34}; s = news; Plane Surface(s) = {l}; farF[] += s;
l = newcl; Curve Loop(l) = {lB41, lB1, FD[{1:NM}], lB2, lB23, lB34}; s = news; Plane Surface(s) = {l}; farF[] += s;
l = newcl; Curve Loop(l) = {lAB1, -lB41, -lAB4, lA41}; s = news; Plane Surface(s) = {l}; farF[] += s;
l = newcl; Curve Loop(l) = {lA23, lAB3, -lB23, -lAB2}; s = news; Plane Surface(s) = {l}; farF[] += s;
l = newcl; Curve Loop(l) = {lA34, lAB4, -lB34, -lAB3}; s = news; Plane Surface(s) = {l}; farF[] += s;
topF[] = {};
l = newcl; Curve Loop(l) = {lA1, -LU[0], RF[0], LD[0], -lB1, -lAB1}; s = news; Plane Surface(s) = {l}; topF[] += s;
l = newcl; Curve Loop(l) = {lA2, lAB2, -lB2, -LD[NM], -RF[NM], LU[NM]}; s = news; Plane Surface(s) = {l}; topF[] += s;
rockBase[] = {};
For k In {1:NM}
  l = newcl; Curve Loop(l) = {RBU[k], LU[k], -FU[k], -LU[k-1]}; s = news; Plane Surface(s) = {l}; topF[] += s;
  l = newcl; Curve Loop(l) = {RBD[k], LD[k], -FD[k], -LD[k-1]}; s = news; Plane Surface(s) = {l}; topF[] += s;
  l = newcl; Curve Loop(l) = {RBU[k], RF[k], -RBD[k], -RF[k-1]}; s = news; Plane Surface(s) = {l}; rockBase[] += s;
EndFor
sl = newsl; Surface Loop(sl) = {farF[], topF[], rockBase[]};
rock = newv; Volume(rock) = {sl};
For k In {0:NM}
  MeshSize{RU[k], RD[k]} = hr;
  MeshSize{RUf[k], RDf[k]} = hrf;
EndFor
MeshSize{A1, A2, A3, A4, B1, B2, B3, B4} = hrf;

// ------------------------------------------------------------------ water (water = 1)
// The reservoir as a meshed volume (issue 28; docs/dam_physics.md "Reservoir models"), off by
// default (the default meshes are unchanged). Pool level zw = H - dw; the water is the region
// swept from the dam's upstream face below zw along -y to the far end y = ymin - Lw zw (Lw zw
// upstream of the dam's most upstream point), over the valley (the rock's upstream strips,
// extruded along y) and under the free surface z = zw. One sub-volume per wet monolith
// (between the profiles of its joints on the upstream face, shared inside the water), the two
// bank ends triangular (between the last wet joint and the point where the foundation outline
// crosses zw). Own points and curves: the water does not conform with the dam face (its face
// passes through the same joint profiles and arch at zw, so the two faceted surfaces differ
// only by the meshes' chords) nor with the rock. Tet4 (Delaunay), hw at the dam, hwf far.
// Groups: block:water, water:dam (wet face), water:surface (z = zw), water:far (y = yfar),
// water:bed (valley floor and banks).
// a corner of the wet outline at (wp_x, wp_y, wp_z): its point, its far copy, the line along -y
Macro WCorner
  wpn = newp; Point(wpn) = {wp_x, wp_y, wp_z, hw1};
  wpf = newp; Point(wpf) = {wp_x, yfar, wp_z, hwf1};
  wpl = newc; Line(wpl) = {wpn, wpf};
Return
// an arc of the upstream face at zw from corner (a0, a0f, x aX0) to (a1, a1f, x aX1): near
// spline wan, far line waf
Macro WArc
  ap[] = {a0};
  For ai In {1:3}
    axx = aX0 + (aX1 - aX0) * ai / 4;
    pt = newp; Point(pt) = {axx, wYu + axx*axx/(2*wRu), zw, hw1}; ap[] += pt;
  EndFor
  ap[] += a1;
  wan = newc; Spline(wan) = {ap[]};
  waf = newc; Line(waf) = {a0f, a1f};
Return

If (water == 1)
  zw = H - dw;
  yfar = ymin - Lw * zw;
  hw1 = hw;
  If (hw1 <= 0)
    hw1 = h;
  EndIf
  hwf1 = hwf;
  If (hwf1 <= 0)
    hwf1 = 2 * hw1;
  EndIf
  kw1 = 0; kw2 = 0;
  For k In {1:N}
    If (Uz[k] < zw)
      If (kw1 == 0)
        kw1 = k;
      EndIf
      kw2 = k;
    EndIf
  EndFor
  If (kw1 == 0 || dw >= H)
    Error("arch_dam.geo: water = 1 but no joint's upstream foot is below the pool level H - dw = %g", zw);
    Abort;
  EndIf
  az_z = zw; Call ArchAt;
  wYu = az_Yu; wRu = az_Ru;
  // the bank ends, where the foundation outline crosses zw
  tq = (zw - Uz[kw1]) / (Uz[kw1-1] - Uz[kw1]);
  wp_x = Ux[kw1] + tq*(Ux[kw1-1] - Ux[kw1]); wp_y = Uy[kw1] + tq*(Uy[kw1-1] - Uy[kw1]); wp_z = zw;
  Call WCorner;
  ELn = wpn; ELf = wpf; ELl = wpl; ELx = wp_x;
  tq = (zw - Uz[kw2]) / (Uz[kw2+1] - Uz[kw2]);
  wp_x = Ux[kw2] + tq*(Ux[kw2+1] - Ux[kw2]); wp_y = Uy[kw2] + tq*(Uy[kw2+1] - Uy[kw2]); wp_z = zw;
  Call WCorner;
  ERn = wpn; ERf = wpf; ERl = wpl; ERx = wp_x;
  // each wet joint: foot F, top T (its upstream face at zw), the profile between (near spline,
  // far spline) and the ruled side swept along -y (shared by the two sub-volumes beside it)
  For k In {kw1:kw2}
    wp_x = Ux[k]; wp_y = Uy[k]; wp_z = Uz[k];
    Call WCorner;
    WFn[k] = wpn; WFf[k] = wpf; WFl[k] = wpl;
    fr_k = k; fr_f = 0; fr_z = zw; Call FaceR;
    wp_x = jx[k] + fr_r*jdx[k]; wp_y = jy[k] + fr_r*jdy[k]; wp_z = zw;
    Call WCorner;
    WTn[k] = wpn; WTf[k] = wpf; WTl[k] = wpl; WTx[k] = wp_x;
    pn[] = {WFn[k]}; pf[] = {WFf[k]};
    For pi In {1:np-2}
      fr_z = Uz[k] + (zw - Uz[k]) * pi / (np - 1);
      Call FaceR;
      pt = newp; Point(pt) = {jx[k] + fr_r*jdx[k], jy[k] + fr_r*jdy[k], fr_z, hw1}; pn[] += pt;
      pt = newp; Point(pt) = {jx[k] + fr_r*jdx[k], yfar, fr_z, hwf1}; pf[] += pt;
    EndFor
    pn[] += WTn[k]; pf[] += WTf[k];
    WPn[k] = newc; Spline(WPn[k]) = {pn[]};
    WPf[k] = newc; Spline(WPf[k]) = {pf[]};
    l = newcl; Curve Loop(l) = {WPn[k], WTl[k], -WPf[k], -WFl[k]}; WS[k] = news; Surface(WS[k]) = {l};
  EndFor
  waterV[] = {}; wetS[] = {}; topS[] = {}; farS[] = {}; bedS[] = {};
  // left bank end: EL, F[kw1], T[kw1]
  bn = newc; Line(bn) = {ELn, WFn[kw1]}; bf = newc; Line(bf) = {ELf, WFf[kw1]};
  a0 = ELn; a0f = ELf; aX0 = ELx; a1 = WTn[kw1]; a1f = WTf[kw1]; aX1 = WTx[kw1]; Call WArc;
  l = newcl; Curve Loop(l) = {bn, WPn[kw1], -wan}; s1 = news; Surface(s1) = {l}; wetS[] += s1;
  l = newcl; Curve Loop(l) = {bf, WPf[kw1], -waf}; s2 = news; Plane Surface(s2) = {l}; farS[] += s2;
  l = newcl; Curve Loop(l) = {bn, WFl[kw1], -bf, -ELl}; s3 = news; Plane Surface(s3) = {l}; bedS[] += s3;
  l = newcl; Curve Loop(l) = {wan, WTl[kw1], -waf, -ELl}; s4 = news; Plane Surface(s4) = {l}; topS[] += s4;
  sl = newsl; Surface Loop(sl) = {s1, s2, s3, s4, WS[kw1]}; v = newv; Volume(v) = {sl}; waterV[] += v;
  // the wet monoliths between joints k-1 and k
  For k In {kw1+1:kw2}
    bn = newc; Line(bn) = {WFn[k-1], WFn[k]}; bf = newc; Line(bf) = {WFf[k-1], WFf[k]};
    a0 = WTn[k-1]; a0f = WTf[k-1]; aX0 = WTx[k-1]; a1 = WTn[k]; a1f = WTf[k]; aX1 = WTx[k]; Call WArc;
    l = newcl; Curve Loop(l) = {bn, WPn[k], -wan, -WPn[k-1]}; s1 = news; Surface(s1) = {l}; wetS[] += s1;
    l = newcl; Curve Loop(l) = {bf, WPf[k], -waf, -WPf[k-1]}; s2 = news; Plane Surface(s2) = {l}; farS[] += s2;
    l = newcl; Curve Loop(l) = {bn, WFl[k], -bf, -WFl[k-1]}; s3 = news; Plane Surface(s3) = {l}; bedS[] += s3;
    l = newcl; Curve Loop(l) = {wan, WTl[k], -waf, -WTl[k-1]}; s4 = news; Plane Surface(s4) = {l}; topS[] += s4;
    sl = newsl; Surface Loop(sl) = {s1, s2, s3, s4, WS[k-1], WS[k]}; v = newv; Volume(v) = {sl}; waterV[] += v;
  EndFor
  // right bank end: F[kw2], ER, T[kw2]
  bn = newc; Line(bn) = {WFn[kw2], ERn}; bf = newc; Line(bf) = {WFf[kw2], ERf};
  a0 = WTn[kw2]; a0f = WTf[kw2]; aX0 = WTx[kw2]; a1 = ERn; a1f = ERf; aX1 = ERx; Call WArc;
  l = newcl; Curve Loop(l) = {bn, -wan, -WPn[kw2]}; s1 = news; Surface(s1) = {l}; wetS[] += s1;
  l = newcl; Curve Loop(l) = {bf, -waf, -WPf[kw2]}; s2 = news; Plane Surface(s2) = {l}; farS[] += s2;
  l = newcl; Curve Loop(l) = {bn, ERl, -bf, -WFl[kw2]}; s3 = news; Plane Surface(s3) = {l}; bedS[] += s3;
  l = newcl; Curve Loop(l) = {wan, ERl, -waf, -WTl[kw2]}; s4 = news; Plane Surface(s4) = {l}; topS[] += s4;
  sl = newsl; Surface Loop(sl) = {s1, s2, s3, s4, WS[kw2]}; v = newv; Volume(v) = {sl}; waterV[] += v;
  Printf("arch_dam.geo: water to zw = %.3f m, far end y = %.3f m, wet joints %g..%g", zw, yfar, kw1, kw2);
EndIf

// ------------------------------------------------------------------ groups
Physical Volume("block:monolith:01") = {wedge1[]};
For m In {2:N}
  Physical Volume(Sprintf("block:monolith:%02g", m)) = {mono[m]};
EndFor
Physical Volume(Sprintf("block:monolith:%02g", NM)) = {wedgeN[]};
Physical Volume("block:rock") = {rock};
jointLeft[1] = 0; jointRight[N] = 0;
For k In {1:N}
  If (k == 1)
    Physical Surface(Sprintf("joint:%02g:left", k)) = {jointLeft1[]};
  Else
    Physical Surface(Sprintf("joint:%02g:left", k)) = {jointLeft[k]};
  EndIf
  If (k == N)
    Physical Surface(Sprintf("joint:%02g:right", k)) = {jointRightN[]};
  Else
    Physical Surface(Sprintf("joint:%02g:right", k)) = {jointRight[k]};
  EndIf
EndFor
Physical Surface("face:upstream") = {upF[]};
Physical Surface("face:downstream") = {dnF[]};
Physical Surface("face:crest") = {crF[]};
Physical Surface("interface:dam:base") = {baseF[]};
Physical Surface("interface:rock:base") = {rockBase[]};
Physical Surface("bc:far") = {farF[]};
If (water == 1)
  Physical Volume("block:water") = {waterV[]};
  Physical Surface("water:dam") = {wetS[]};
  Physical Surface("water:surface") = {topS[]};
  Physical Surface("water:far") = {farS[]};
  Physical Surface("water:bed") = {bedS[]};
EndIf

Mesh.MeshSizeExtendFromBoundary = 1;
Mesh.MeshSizeFromCurvature = 0;
Mesh.MeshSizeFromPoints = 1;
// Only the rock is unstructured (tet4, Gmsh's default Delaunay): its smallest tet altitude, 7.0 m
// on the coarse variant and 4.0 m on the default one, is far from setting the explicit step
// (the dam's hex8, 2.2 m through the wedges' thickness, do).
Mesh.Algorithm3D = 1;
If (hex == 0)
  // tet4 dam: HXT and re-optimising every tet below quality 0.6 (Delaunay leaves slivers in the
  // thin monoliths between their structured face meshes: stable dt 9.5e-7 s on the coarse mesh)
  Mesh.Algorithm3D = 10;
  Mesh.OptimizeThreshold = 0.6;
EndIf

// incline.geo -- a slider block on an inclined plane (sliding under gravity, design §6:
// s(t) = 1/2 g (sin beta - mu cos beta) t^2).
//
// Models: slope frame s = (cos b, 0, sin b) (up the slope, rising with x), y = (0, 1, 0),
// n = s x y = (-sin b, 0, cos b) (the plane's upward normal), b = beta.
//   base:   a slab Lb (along s) x Wb (along y) x Tb (along n) whose top face is the
//           inclined plane through the origin: { u s + v y : 0<=u<=Lb, 0<=v<=Wb }.
//   slider: Ls x Ws x Ts, its bottom face on the plane at u in [s0, s0+Ls], centred
//           across the base (v in [(Wb-Ws)/2, (Wb+Ws)/2]).
// Each block is meshed on its own (no shared nodes, non-conforming with the defaults).
// With the defaults the slider starts near the upper end and can slide s0 = 2.8 m,
// i.e. 5.6 base elements, before its lower edge reaches the lower end of the base.
// Units SI (m, degrees for beta); axes x east, y north, z up.
//
// Parameters (override with `gmsh incline.geo -3 -setnumber NAME VALUE`):
//   beta [deg] 30.0  slope angle
//   Lb   [m]   4.0   base length along the slope
//   Wb   [m]   1.0   base width (y)
//   Tb   [m]   0.5   base thickness (normal to the slope)
//   Ls   [m]   1.0   slider length along the slope
//   Ws   [m]   0.5   slider width (y)
//   Ts   [m]   0.5   slider thickness (normal to the slope)
//   s0   [m]   2.8   distance along the slope from the base's lower end to the slider's
//                    lower edge (needs s0 + Ls <= Lb)
//   nb   [-]   8     base elements along the slope
//   nbw  [-]   2     base elements across (y)
//   nbt  [-]   1     base elements through the thickness
//   ns   [-]   3     slider elements along the slope
//   nsw  [-]   2     slider elements across (y)
//   nst  [-]   2     slider elements through the thickness
//   tets [-]   0     0: hex8 with quad4 faces; 1: tet4 with tri3 faces (6 tets per grid cell)
//
// Physical groups:
//   block:base (3), block:slider (3)
//   joint:J:base (2)    the base's whole top face (the inclined plane): nb*nbw quads
//   joint:J:slider (2)  the slider's bottom face: ns*nsw quads
//   bc:base (2)         the base's bottom face

SetFactory("Built-in");
Geometry.AutoCoherence = 0; // never merge coincident entities: blocks must not share nodes
Mesh.MshFileVersion = 4.1;
Mesh.SaveAll = 0;           // only physical entities are written
Mesh.ElementOrder = 1;
// ---- Macro HexBlock: identical in every geo/*.geo except socket.geo (scripts are
// standalone; tests/all/mesh.rs checks the copies agree). `Call HexBlock;` must stand
// on its own line: Gmsh mis-parses statements that follow a Call on the same line.
// A parallelepiped from corner hb_o[] and edge vectors hb_e1[], hb_e2[], hb_e3[] [m]
// (right-handed: (e1 x e2) . e3 > 0) with hb_n1, hb_n2, hb_n3 divisions along them.
// Its own points, curves and surfaces: never shared with another block.
// tets = 0: transfinite hex8 (quad4 faces); tets = 1: the same structured grid with each
// hexahedral cell split into 6 tet4 (each face quad into 2 tri3).
// Out: hb_vol, hb_face[] = {-e1 face, +e1 face, -e2 face, +e2 face, -e3 face, +e3 face}.
Macro HexBlock
  For hb_k In {0:7}
    hb_i = hb_k % 2; hb_j = Floor(hb_k / 2) % 2; hb_l = Floor(hb_k / 4);
    hb_p[hb_k] = newp;
    Point(hb_p[hb_k]) = {hb_o[0] + hb_i*hb_e1[0] + hb_j*hb_e2[0] + hb_l*hb_e3[0],
                         hb_o[1] + hb_i*hb_e1[1] + hb_j*hb_e2[1] + hb_l*hb_e3[1],
                         hb_o[2] + hb_i*hb_e1[2] + hb_j*hb_e2[2] + hb_l*hb_e3[2]};
  EndFor
  // corner P(i,j,l) = hb_p[i + 2j + 4l]; hb_c1[j+2l]: P(0,j,l)->P(1,j,l), etc.
  For hb_k In {0:3}
    hb_a = hb_k % 2; hb_b = Floor(hb_k / 2);
    hb_c1[hb_k] = newc; Line(hb_c1[hb_k]) = {hb_p[2*hb_a + 4*hb_b], hb_p[1 + 2*hb_a + 4*hb_b]};
    hb_c2[hb_k] = newc; Line(hb_c2[hb_k]) = {hb_p[hb_a + 4*hb_b], hb_p[hb_a + 2 + 4*hb_b]};
    hb_c3[hb_k] = newc; Line(hb_c3[hb_k]) = {hb_p[hb_a + 2*hb_b], hb_p[hb_a + 2*hb_b + 4]};
  EndFor
  hb_loop[] = {hb_c2[0], hb_c3[2], -hb_c2[2], -hb_c3[0],   // -e1 (i = 0)
               hb_c2[1], hb_c3[3], -hb_c2[3], -hb_c3[1],   // +e1 (i = 1)
               hb_c1[0], hb_c3[1], -hb_c1[2], -hb_c3[0],   // -e2 (j = 0)
               hb_c1[1], hb_c3[3], -hb_c1[3], -hb_c3[2],   // +e2 (j = 1)
               hb_c1[0], hb_c2[1], -hb_c1[1], -hb_c2[0],   // -e3 (l = 0)
               hb_c1[2], hb_c2[3], -hb_c1[3], -hb_c2[2]};  // +e3 (l = 1)
  For hb_f In {0:5}
    hb_cl = newcl; Curve Loop(hb_cl) = {hb_loop[{4*hb_f : 4*hb_f + 3}]};
    hb_face[hb_f] = news; Plane Surface(hb_face[hb_f]) = {hb_cl};
  EndFor
  hb_sl = newsl; Surface Loop(hb_sl) = {hb_face[]};
  hb_vol = newv; Volume(hb_vol) = {hb_sl};
  Transfinite Curve{hb_c1[]} = hb_n1 + 1;
  Transfinite Curve{hb_c2[]} = hb_n2 + 1;
  Transfinite Curve{hb_c3[]} = hb_n3 + 1;
  Transfinite Surface{hb_face[]};
  If (tets == 0)
    Recombine Surface{hb_face[]};
  EndIf
  Transfinite Volume{hb_vol};
Return

DefineConstant[
  beta = {30.0, Min 0, Max 89, Name "Parameters/beta"},
  Lb   = {4.0, Min 1e-6, Name "Parameters/Lb"},
  Wb   = {1.0, Min 1e-6, Name "Parameters/Wb"},
  Tb   = {0.5, Min 1e-6, Name "Parameters/Tb"},
  Ls   = {1.0, Min 1e-6, Name "Parameters/Ls"},
  Ws   = {0.5, Min 1e-6, Name "Parameters/Ws"},
  Ts   = {0.5, Min 1e-6, Name "Parameters/Ts"},
  s0   = {2.8, Min 0, Name "Parameters/s0"},
  nb   = {8, Min 1, Step 1, Name "Parameters/nb"},
  nbw  = {2, Min 1, Step 1, Name "Parameters/nbw"},
  nbt  = {1, Min 1, Step 1, Name "Parameters/nbt"},
  ns   = {3, Min 1, Step 1, Name "Parameters/ns"},
  nsw  = {2, Min 1, Step 1, Name "Parameters/nsw"},
  nst  = {2, Min 1, Step 1, Name "Parameters/nst"},
  tets = {0, Choices {0 = "hex8", 1 = "tet4"}, Name "Parameters/tets"}
];
If (s0 + Ls > Lb || Ws > Wb)
  Error("incline.geo: the slider (s0 + Ls = %g m, Ws = %g m) must fit on the base (Lb = %g m, Wb = %g m)", s0 + Ls, Ws, Lb, Wb);
  Abort;
EndIf

cb = Cos(beta * Pi / 180); sb = Sin(beta * Pi / 180);
// base: corner at -Tb n, so that its +n face is the plane through the origin
hb_o[] = {Tb * sb, 0, -Tb * cb};
hb_e1[] = {Lb * cb, 0, Lb * sb}; hb_e2[] = {0, Wb, 0}; hb_e3[] = {-Tb * sb, 0, Tb * cb};
hb_n1 = nb; hb_n2 = nbw; hb_n3 = nbt;
Call HexBlock;
base = hb_vol; base_f[] = hb_face[];

hb_o[] = {s0 * cb, (Wb - Ws) / 2, s0 * sb};
hb_e1[] = {Ls * cb, 0, Ls * sb}; hb_e2[] = {0, Ws, 0}; hb_e3[] = {-Ts * sb, 0, Ts * cb};
hb_n1 = ns; hb_n2 = nsw; hb_n3 = nst;
Call HexBlock;
slider = hb_vol; slider_f[] = hb_face[];

Physical Volume("block:base") = {base};
Physical Volume("block:slider") = {slider};
Physical Surface("joint:J:base") = {base_f[5]};
Physical Surface("joint:J:slider") = {slider_f[4]};
Physical Surface("bc:base") = {base_f[4]};

// prism.geo -- a prism along x (1D wave / axial bar checks).
//
// Models: the prism [0,L]x[0,a]x[0,a], one block, structured.
// Units SI (m); axes x east, y north, z up.
//
// Parameters (override with `gmsh prism.geo -3 -setnumber NAME VALUE`):
//   L    [m]  10.0  length along x
//   a    [m]  1.0   side of the square section (y and z)
//   n    [-]  10    elements along x
//   nt   [-]  1     elements across the section, in y and in z (1: a 1D column of cells)
//   tets [-]  0     0: hex8 with quad4 faces; 1: tet4 with tri3 faces (6 tets per grid cell)
//
// Physical groups:
//   block:prism (3)
//   bc:fixed (2)   the x = 0 face
//   load:end (2)   the x = L face
//   bc:sides (2)   the 4 lateral faces (y = 0, y = a, z = 0, z = a)

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
  L    = {10.0, Min 1e-6, Name "Parameters/L"},
  a    = {1.0, Min 1e-6, Name "Parameters/a"},
  n    = {10, Min 1, Step 1, Name "Parameters/n"},
  nt   = {1, Min 1, Step 1, Name "Parameters/nt"},
  tets = {0, Choices {0 = "hex8", 1 = "tet4"}, Name "Parameters/tets"}
];

hb_o[] = {0, 0, 0}; hb_e1[] = {L, 0, 0}; hb_e2[] = {0, a, 0}; hb_e3[] = {0, 0, a};
hb_n1 = n; hb_n2 = nt; hb_n3 = nt;
Call HexBlock;

Physical Volume("block:prism") = {hb_vol};
Physical Surface("bc:fixed") = {hb_face[0]};
Physical Surface("load:end") = {hb_face[1]};
Physical Surface("bc:sides") = {hb_face[{2:5}]};

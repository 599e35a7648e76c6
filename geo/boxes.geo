// boxes.geo -- two stacked boxes with a horizontal joint J at z = 0.
//
// Models: lower box [0,a]x[0,a]x[-hl,0] and upper box [0,a]x[0,a]x[0,hu], each
// meshed on its own (own points, curves, surfaces): the joint faces coincide
// geometrically but share no node, and with nl != nu the meshes do not conform.
// Used for the contact patch test, the tagger (Layer1/Layer2 on quads and triangles)
// and the reader tests.
//
// Units SI (m); axes x east, y north, z up.
//
// Parameters (override with `gmsh boxes.geo -3 -setnumber NAME VALUE`):
//   a    [m]  1.0  side of both boxes in x and y
//   hl   [m]  0.5  height of the lower box
//   hu   [m]  0.5  height of the upper box
//   nl   [-]  4    elements per side (x and y) of the lower box (its top is the joint face)
//   nu   [-]  3    elements per side (x and y) of the upper box (its bottom is the joint face)
//   nz   [-]  2    element layers through each box
//   tets [-]  0    0: hex8 with quad4 faces; 1: tet4 with tri3 faces (6 tets per grid cell)
//
// Physical groups:
//   block:lower (3), block:upper (3)
//   joint:J:lower (2)  top face of the lower box (z = 0): nl*nl quads or 2*nl*nl triangles
//   joint:J:upper (2)  bottom face of the upper box (z = 0): nu*nu quads or 2*nu*nu triangles
//   bc:base (2)        bottom of the lower box (z = -hl)
//   load:top (2)       top of the upper box (z = hu)
//   bc:sides (2)       the 4 lateral faces of both boxes (8 surfaces)

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
  a    = {1.0, Min 1e-6, Name "Parameters/a"},
  hl   = {0.5, Min 1e-6, Name "Parameters/hl"},
  hu   = {0.5, Min 1e-6, Name "Parameters/hu"},
  nl   = {4, Min 1, Step 1, Name "Parameters/nl"},
  nu   = {3, Min 1, Step 1, Name "Parameters/nu"},
  nz   = {2, Min 1, Step 1, Name "Parameters/nz"},
  tets = {0, Choices {0 = "hex8", 1 = "tet4"}, Name "Parameters/tets"}
];

hb_e1[] = {a, 0, 0}; hb_e2[] = {0, a, 0};
hb_n1 = nl; hb_n2 = nl; hb_n3 = nz;
hb_o[] = {0, 0, -hl}; hb_e3[] = {0, 0, hl};
Call HexBlock;
lower = hb_vol; lower_f[] = hb_face[];

hb_n1 = nu; hb_n2 = nu; hb_n3 = nz;
hb_o[] = {0, 0, 0}; hb_e3[] = {0, 0, hu};
Call HexBlock;
upper = hb_vol; upper_f[] = hb_face[];

Physical Volume("block:lower") = {lower};
Physical Volume("block:upper") = {upper};
Physical Surface("joint:J:lower") = {lower_f[5]};
Physical Surface("joint:J:upper") = {upper_f[4]};
Physical Surface("bc:base") = {lower_f[4]};
Physical Surface("load:top") = {upper_f[5]};
Physical Surface("bc:sides") = {lower_f[{0:3}], upper_f[{0:3}]};

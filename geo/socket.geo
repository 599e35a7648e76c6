// socket.geo -- a cylindrical plug in a socket block: a curved joint J (tagger and
// node-to-segment search on a non-planar, non-conforming unstructured interface).
//
// Models: plug = the cylinder x^2 + y^2 <= r^2, 0 <= z <= H; socket = the box
// [-B,B]x[-B,B]x[0,H] minus the same cylinder. The two touch on the curved face
// (the joint J) and are meshed independently with tet4 of sizes hp and hs: they
// share no node, and the joint faces are two different triangulations of the cylinder
// (each node exactly on it; face centroids inside it by up to the chord sagitta).
// OpenCASCADE kernel, no BooleanFragments between plug and socket, so nothing is shared.
// Units SI (m); axes x east, y north, z up (cylinder axis = z).
//
// Parameters (override with `gmsh socket.geo -3 -setnumber NAME VALUE`):
//   r   [m]  0.5   radius of the plug and of the socket's hole
//   H   [m]  1.0   height of plug and socket
//   B   [m]  1.0   half-width of the socket's outer box (needs B > r)
//   hp  [m]  0.15  target element size in the plug
//   hs  [m]  0.25  target element size in the socket
//   netgen [-] 0   1: also run Netgen's tet optimiser (Mesh.OptimizeNetgen) after gmsh's own
//                  (Mesh.Optimize, on by default). Measured (docs/elements.md, "Mesh quality"):
//                  the stable step 1.27x (hp 0.2, hs 0.3) and 1.50x (defaults) larger, with
//                  37 % and 25 % more tets. Default 0 keeps the committed fixture socket_tet.msh.
//
// Physical groups:
//   block:plug (3), block:socket (3)
//   joint:J:plug (2)    the plug's lateral (curved) face
//   joint:J:socket (2)  the socket's inner (curved) face
//   bc:outer (2)        the socket's 4 outer lateral faces (x = +-B, y = +-B)
//   bc:bottom (2)       the socket's bottom face (z = 0, an annulus-like square with a hole)
//   load:top (2)        the plug's top face (z = H)

SetFactory("OpenCASCADE");
Mesh.MshFileVersion = 4.1;
Mesh.SaveAll = 0;           // only physical entities are written
Mesh.ElementOrder = 1;
Mesh.MeshSizeFromCurvature = 0; // sizes come from hp and hs only

DefineConstant[
  r  = {0.5, Min 1e-6, Name "Parameters/r"},
  H  = {1.0, Min 1e-6, Name "Parameters/H"},
  B  = {1.0, Min 1e-6, Name "Parameters/B"},
  hp = {0.15, Min 1e-6, Name "Parameters/hp"},
  hs = {0.25, Min 1e-6, Name "Parameters/hs"},
  netgen = {0, Choices {0 = "gmsh optimiser", 1 = "gmsh + Netgen optimisers"}, Name "Parameters/netgen"}
];
If (netgen == 1)
  Mesh.OptimizeNetgen = 1;
EndIf
If (B <= r)
  Error("socket.geo: the socket half-width B = %g m must exceed the plug radius r = %g m", B, r);
  Abort;
EndIf

plug = newv; Cylinder(plug) = {0, 0, 0, 0, 0, H, r};
box = newv; Box(box) = {-B, -B, 0, 2 * B, 2 * B, H};
hole = newv; Cylinder(hole) = {0, 0, 0, 0, 0, H, r};
socket[] = BooleanDifference{ Volume{box}; Delete; }{ Volume{hole}; Delete; };

// Sort the faces of each volume by their bounding boxes (tol: OCC pads boxes by ~1e-7).
tol = 1e-3 * r;
plug_side[] = {}; plug_top[] = {};
sp[] = Abs(Boundary{ Volume{plug}; });
For k In {0 : #sp[] - 1}
  bb[] = BoundingBox Surface{ sp[k] };
  If (bb[5] - bb[2] > tol)
    plug_side[] += sp[k];
  ElseIf (bb[2] > H / 2)
    plug_top[] += sp[k];
  EndIf
EndFor
sock_inner[] = {}; sock_outer[] = {}; sock_bottom[] = {};
ss[] = Abs(Boundary{ Volume{socket[0]}; });
For k In {0 : #ss[] - 1}
  bb[] = BoundingBox Surface{ ss[k] };
  If (bb[5] - bb[2] > tol && bb[3] - bb[0] > tol && bb[4] - bb[1] > tol)
    sock_inner[] += ss[k];
  ElseIf (bb[5] - bb[2] > tol)
    sock_outer[] += ss[k];
  ElseIf (bb[5] < H / 2)
    sock_bottom[] += ss[k];
  EndIf
EndFor
If (#plug_side[] != 1 || #plug_top[] != 1 || #sock_inner[] != 1 || #sock_outer[] != 4 || #sock_bottom[] != 1)
  Error("socket.geo: unexpected faces (plug side %g, plug top %g, socket inner %g, outer %g, bottom %g)",
        #plug_side[], #plug_top[], #sock_inner[], #sock_outer[], #sock_bottom[]);
  Abort;
EndIf

// Sizes by volume through Constant fields (each including its volume's boundary).
// Not `MeshSize{PointsOf{...}}`: OpenCASCADE attributes are matched by position, so
// the socket's points (coincident with the plug's) would overwrite hp with hs.
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeExtendFromBoundary = 0;
Field[1] = Constant; Field[1].VolumesList = {plug}; Field[1].IncludeBoundary = 1;
Field[1].VIn = hp; Field[1].VOut = 1e22;
Field[2] = Constant; Field[2].VolumesList = {socket[0]}; Field[2].IncludeBoundary = 1;
Field[2].VIn = hs; Field[2].VOut = 1e22;
Field[3] = Min; Field[3].FieldsList = {1, 2};
Background Field = 3;

Physical Volume("block:plug") = {plug};
Physical Volume("block:socket") = {socket[0]};
Physical Surface("joint:J:plug") = {plug_side[]};
Physical Surface("joint:J:socket") = {sock_inner[]};
Physical Surface("bc:outer") = {sock_outer[]};
Physical Surface("bc:bottom") = {sock_bottom[]};
Physical Surface("load:top") = {plug_top[]};

#!/usr/bin/env python3
"""Mesh-quality measurement of docs/elements.md "Mesh quality and the step (slivers)": mesh a
.geo with gmsh's optimiser alone or with Netgen's too, and measure the tets (smallest scaled
Jacobian, house definition of `mesh::quality`; count below the sliver threshold 0.2; smallest
gmsh gamma) and the stable step jointquake computes on the mesh (a zero-duration run).

Usage (from the repository root, with the .venv gmsh and a release build):
  .venv/bin/python scripts/mesh_quality.py GEO KIND NETGEN ALGO3D [-setnumber NAME VALUE ...]
    KIND    wedge | socket | dam: the materials and damping of the scene using the geometry
            (pipelines/wedge.json; the socket tests' 1 GPa plug and socket; pipelines/dam.json)
    NETGEN  0 or 1: Mesh.OptimizeNetgen, set after the .geo is read
    ALGO3D  0: the .geo's Mesh.Algorithm3D; else that algorithm (1 Delaunay, 10 HXT)
e.g. .venv/bin/python scripts/mesh_quality.py geo/wedge.geo wedge 1 1 -setnumber hw 8 -setnumber hr 30
Prints one line. Meshes and scenes go to a temporary directory (kept, path printed).
"""
import json, os, subprocess, sys, tempfile, time
import gmsh
import numpy as np

SCENES = {
    "wedge": {"materials": [{"group": "block:wedge", "E": 1e10, "nu": 0.25, "rho": 2563}, {"group": "block:rock", "E": 1e10, "nu": 0.25, "rho": 2563}],
              "boundary": [{"group": "bc:fixed"}], "damping": {"alpha": 1.2, "mass_groups": ["block:rock"], "beta": 1.6e-4}},
    "socket": {"materials": [{"group": "block:plug", "E": 1e9, "nu": 0.2, "rho": 2000}, {"group": "block:socket", "E": 1e9, "nu": 0.2, "rho": 2000}],
               "boundary": [{"group": "bc:bottom"}]},
    "dam": {"materials": [{"group": "block:monolith:*", "E": 24e9, "nu": 0.17, "rho": 2400}, {"group": "block:rock", "E": 24.5e9, "nu": 0.25, "rho": 2000, "massless": True}],
            "boundary": [{"group": "bc:far"}], "damping": {"ratio": 0.05, "f1": 1.5, "f2": 10.0, "mass_groups": ["block:monolith:*"]}},
}


def scaled_jacobians(P):
    """Smallest corner scaled Jacobian of each tet (corners x sqrt 2: 1 for a regular tet)."""
    sj = np.full(len(P), np.inf)
    for a in range(4):
        o = [b for b in range(4) if b != a]
        if a % 2 == 1:  # keep the edge triple right-handed
            o = [o[1], o[0], o[2]]
        e = [P[:, b] - P[:, a] for b in o]
        det = np.einsum("ij,ij->i", e[0], np.cross(e[1], e[2]))
        l = np.linalg.norm(e[0], axis=1) * np.linalg.norm(e[1], axis=1) * np.linalg.norm(e[2], axis=1)
        sj = np.minimum(sj, det / l * np.sqrt(2))
    return sj


def main():
    geo, kind, netgen, algo = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
    sets = sys.argv[5:]
    work = tempfile.mkdtemp(prefix="mesh_quality_")
    msh = os.path.join(work, "mesh.msh")
    gmsh.initialize(["gmsh"] + sets, readConfigFiles=False)
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.open(geo)
    if netgen:
        gmsh.option.setNumber("Mesh.OptimizeNetgen", 1)
    if algo:
        gmsh.option.setNumber("Mesh.Algorithm3D", algo)
    algo3d = gmsh.option.getNumber("Mesh.Algorithm3D")
    t0 = time.time()
    gmsh.model.mesh.generate(3)
    tm = time.time() - t0
    ntags, coords, _ = gmsh.model.mesh.getNodes()
    pos = {t: i for i, t in enumerate(ntags)}
    X = coords.reshape(-1, 3)
    tags, conn = [], []
    for ty, tg, nd in zip(*gmsh.model.mesh.getElements(3)):
        if ty == 4:
            tags.extend(tg)
            conn.extend(nd)
    P = X[np.array([pos[n] for n in conn]).reshape(-1, 4)]
    sj = scaled_jacobians(P)
    gamma = np.array(gmsh.model.mesh.getElementQualities(tags, "gamma"))
    gmsh.write(msh)
    gmsh.finalize()
    sc = json.loads(json.dumps(SCENES[kind]))
    sc.update({"name": "mesh_quality", "geometry": {"msh": msh}, "time": {"duration": 0.0}, "output": {"frames": False}})
    scene = os.path.join(work, "scene.json")
    json.dump(sc, open(scene, "w"))
    out = os.path.join(work, "out")
    r = subprocess.run(["target/release/jointquake", "run", scene, "--out", out, "--quiet", "--threads", "1"], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"jointquake run failed: {r.stderr[-1000:]}")
    s = json.load(open(os.path.join(out, "summary.json")))
    print(f"{geo} {' '.join(sets)} Algorithm3D {algo3d:.0f} OptimizeNetgen {netgen}: {len(tags)} tets, min SJ {sj.min():.4f} "
          f"({int((sj < 0.2).sum())} below 0.2), min gamma {gamma.min():.4f}, mesh {tm:.1f} s; dt_stable {s['dt_stable']:.4e} s, "
          f"critical element {s['critical_element']} in {s['critical_group']} (SJ {s['critical_scaled_jacobian']:.3f}); files in {work}")


if __name__ == "__main__":
    main()

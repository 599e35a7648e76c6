#!/usr/bin/env python3
"""Cross-check a jointquake output directory with meshio (independent VTU reader).

Usage: check_vtu.py OUT_DIR [--quiet]

Checks: every .pvd lists files that exist; every listed VTU is read by meshio with the
expected arrays (point data displacement/velocity/acceleration with 3 components per point;
cell data stress 9, principal_stress 3, von_mises 1, block_id 1 for volume frames); all
values are finite; principal stresses are ordered; the number of frames equals summary.json;
every history CSV has rows. Exits non-zero with a message naming the file on any failure.
"""
import json
import os
import sys
import xml.etree.ElementTree as ET

import meshio
import numpy as np

VOLUME_POINT = {"displacement": 3, "velocity": 3, "acceleration": 3}
VOLUME_CELL = {"stress": 9, "principal_stress": 3, "von_mises": 1, "block_id": 1}


def fail(msg):
    print(f"check_vtu: FAIL: {msg}", file=sys.stderr)
    sys.exit(1)


def ncomp(a):
    return 1 if a.ndim == 1 else a.shape[1]


def check_volume(path, m):
    for name, k in VOLUME_POINT.items():
        if name not in m.point_data:
            fail(f"{path}: point array {name} missing (has {list(m.point_data)})")
        a = np.asarray(m.point_data[name])
        if a.shape[0] != len(m.points) or ncomp(a) != k:
            fail(f"{path}: point array {name} has shape {a.shape}, expected ({len(m.points)}, {k})")
        if not np.all(np.isfinite(a)):
            fail(f"{path}: point array {name} has non-finite values")
    ncells = sum(len(b.data) for b in m.cells)
    for name, k in VOLUME_CELL.items():
        if name not in m.cell_data:
            fail(f"{path}: cell array {name} missing (has {list(m.cell_data)})")
        a = np.concatenate([np.asarray(b) for b in m.cell_data[name]])
        if a.shape[0] != ncells or ncomp(a) != k:
            fail(f"{path}: cell array {name} has shape {a.shape}, expected ({ncells}, {k})")
        if not np.all(np.isfinite(a)):
            fail(f"{path}: cell array {name} has non-finite values")
    p = np.concatenate([np.asarray(b) for b in m.cell_data["principal_stress"]])
    if np.any(p[:, 0] < p[:, 1] - 1e-9 * np.abs(p).max()) or np.any(p[:, 1] < p[:, 2] - 1e-9 * np.abs(p).max()):
        fail(f"{path}: principal stresses not ordered s1 >= s2 >= s3")


def main():
    if len(sys.argv) < 2:
        fail("usage: check_vtu.py OUT_DIR [--quiet]")
    out = sys.argv[1]
    quiet = "--quiet" in sys.argv
    pvds = [os.path.join(out, f) for f in sorted(os.listdir(out)) if f.endswith(".pvd")]
    for sub in ("joints",):
        d = os.path.join(out, sub)
        if os.path.isdir(d):
            pvds += [os.path.join(d, f) for f in sorted(os.listdir(d)) if f.endswith(".pvd")]
    if not pvds:
        fail(f"{out}: no .pvd file")
    total = 0
    for pvd in pvds:
        root = ET.parse(pvd).getroot()
        sets = root.findall("./Collection/DataSet")
        if not sets:
            fail(f"{pvd}: no DataSet entries")
        times = [float(s.get("timestep")) for s in sets]
        if any(b < a for a, b in zip(times, times[1:])):
            fail(f"{pvd}: time steps not increasing")
        for s in sets:
            f = os.path.join(os.path.dirname(pvd), s.get("file"))
            if not os.path.exists(f):
                fail(f"{pvd}: lists {f}, which does not exist")
            m = meshio.read(f)
            if len(m.points) == 0:
                fail(f"{f}: no points")
            if os.path.dirname(pvd) == out.rstrip("/") or os.path.dirname(pvd) == out:
                check_volume(f, m)
        total += len(sets)
        if not quiet:
            print(f"check_vtu: {pvd}: {len(sets)} frames read by meshio, arrays and shapes OK")
    sj = os.path.join(out, "summary.json")
    if os.path.exists(sj):
        s = json.load(open(sj))
        main_pvd = [p for p in pvds if os.path.dirname(p) == out.rstrip("/")]
        if main_pvd:
            n = len(ET.parse(main_pvd[0]).getroot().findall("./Collection/DataSet"))
            if n != s["frames"]:
                fail(f"{main_pvd[0]}: {n} frames but summary.json says {s['frames']}")
        for h in s.get("histories", []):
            rows = [l for l in open(h) if l and l[0] not in "#t"]
            if not rows:
                fail(f"{h}: no rows")
            a = np.loadtxt(h, delimiter=",", comments=["#", "t,"])
            if a.ndim != 2 or a.shape[1] != 10 or not np.all(np.isfinite(a)):
                fail(f"{h}: expected 10 finite columns, got shape {a.shape}")
    print(f"check_vtu: {len(pvds)} series, {total} VTU files OK ({out})")


if __name__ == "__main__":
    main()

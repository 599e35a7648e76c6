#!/usr/bin/env python3
"""Cross-check a jointquake output directory with meshio (independent VTU reader).

Usage: check_vtu.py OUT_DIR [--quiet]

Checks: every .pvd lists files that exist; every listed VTU is read by meshio with the
expected arrays (volume frames: point data displacement/velocity/acceleration with 3
components per point, cell data stress 9, principal_stress 3, von_mises 1, block_id 1; joint
frames in joints/: point data displacement 3, normal 3, gap, opening, slip,
tangential_displacement, normal_traction, shear_traction, state, tributary_area 1); all values
are finite (except a joint's gap, NaN where a slave node found no master face); principal
stresses are ordered; joint states are 0..3 and openings >= 0; the number of frames of the
volume series and of every joint series equals summary.json, and every joint series has the
volume series' times (one time axis); every history CSV starts with its header (units in the
names) and has rows of finite numbers (monitors: the 10 columns t,u,v,a; joints: the 17
documented columns), its last row at the last frame's time. Frames are binary, zlib-compressed.
Without summary.json (a killed run) the series alone are checked. Exits non-zero with a
message naming the file on any failure.
"""
import json
import os
import sys
import xml.etree.ElementTree as ET

import meshio
import numpy as np

VOLUME_POINT = {"displacement": 3, "velocity": 3, "acceleration": 3}
VOLUME_CELL = {"stress": 9, "principal_stress": 3, "von_mises": 1, "block_id": 1}
JOINT_POINT = {"displacement": 3, "normal": 3, "gap": 1, "opening": 1, "slip": 1, "tangential_displacement": 1,
               "normal_traction": 1, "shear_traction": 1, "state": 1, "lost": 1, "lost_travel": 1,
               "tributary_area": 1}
MONITOR_HEADER = "t [s],ux [m],uy [m],uz [m],vx [m/s],vy [m/s],vz [m/s],ax [m/s^2],ay [m/s^2],az [m/s^2]"
JOINT_HEADER = ("t [s],max_opening [m],max_slip [m],max_tangential_displacement [m],max_penetration [m],open,stick,slip,"
                "bonded,sweeps,normal_force [N],shear_force [N],lost,max_lost_travel [m],contact_work [J],reentries,reentry_work [J]")


def fail(msg):
    print(f"check_vtu: FAIL: {msg}", file=sys.stderr)
    sys.exit(1)


def ncomp(a):
    return 1 if a.ndim == 1 else a.shape[1]


def check_point_arrays(path, m, spec, may_be_non_finite=()):
    """Every array of spec (name -> components) is present, one row per point, finite
    (except the names in may_be_non_finite)."""
    for name, k in spec.items():
        if name not in m.point_data:
            fail(f"{path}: point array {name} missing (has {list(m.point_data)})")
        a = np.asarray(m.point_data[name])
        if a.shape[0] != len(m.points) or ncomp(a) != k:
            fail(f"{path}: point array {name} has shape {a.shape}, expected ({len(m.points)}, {k})")
        if name not in may_be_non_finite and not np.all(np.isfinite(a)):
            fail(f"{path}: point array {name} has non-finite values")


def check_volume(path, m):
    check_point_arrays(path, m, VOLUME_POINT)
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


def check_joint(path, m):
    # the gap is NaN where a slave node found no master face
    check_point_arrays(path, m, JOINT_POINT, may_be_non_finite=("gap",))
    state = np.asarray(m.point_data["state"]).ravel()
    if np.any((state < 0) | (state > 3)):
        fail(f"{path}: joint state outside 0..3")
    if np.any(np.asarray(m.point_data["opening"]) < 0):
        fail(f"{path}: negative opening")
    if np.any(np.asarray(m.point_data["tributary_area"]) <= 0):
        fail(f"{path}: non-positive tributary area")
    lost = np.asarray(m.point_data["lost"]).ravel()
    gap = np.asarray(m.point_data["gap"]).ravel()
    if np.any((lost != 0) != ~np.isfinite(gap)):
        fail(f"{path}: the lost flag is not where the gap is NaN")
    labels = {k: int(np.asarray(v).ravel()[0]) for k, v in m.field_data.items()}
    want = {"state_label_open": 0, "state_label_stick": 1, "state_label_slip": 2, "state_label_bonded": 3}
    if labels != want:
        fail(f"{path}: field data {labels}, expected the state labels {want}")


def check_compressed(path):
    """A frame is binary and zlib-compressed (the header names the compressor, no ascii arrays)."""
    with open(path, "rb") as f:
        head = f.read(400).decode("ascii", "replace")
    if 'compressor="vtkZLibDataCompressor"' not in head:
        fail(f"{path}: not zlib-compressed (header {head[:200]!r})")


def check_history(h, t_end=None):
    lines = [l.rstrip("\n") for l in open(h)]
    base = os.path.basename(h)
    if base.endswith("_forces.csv"):
        return  # the opt-in force diagnostic: its own reader (read_joint_forces) checks it
    joint = base.startswith("joint_")
    header, ncol = (JOINT_HEADER, 17) if joint else (MONITOR_HEADER, 10)
    if lines[0] != header:
        fail(f"{h}: first line {lines[0]!r}, expected the header {header!r}")
    if len(lines) < 2:
        fail(f"{h}: no rows")
    a = np.loadtxt(h, delimiter=",", skiprows=1, ndmin=2)
    if a.shape[1] != ncol or not np.all(np.isfinite(a)):
        fail(f"{h}: expected {ncol} finite columns, got shape {a.shape}")
    if joint and np.any(a[:, 5:9].sum(axis=1) != a[0, 5:9].sum()):
        fail(f"{h}: pairs per state do not add up to the same number of slave nodes on every row")
    if t_end is not None and abs(a[-1, 0] - t_end) > 1e-9 * max(1.0, abs(t_end)):
        fail(f"{h}: last row at t = {a[-1, 0]}, the last frame is at {t_end}")


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
            check_compressed(f)
            m = meshio.read(f)
            if len(m.points) == 0:
                fail(f"{f}: no points")
            if os.path.dirname(pvd) == out.rstrip("/") or os.path.dirname(pvd) == out:
                check_volume(f, m)
            else:
                check_joint(f, m)
        total += len(sets)
        if not quiet:
            print(f"check_vtu: {pvd}: {len(sets)} frames read by meshio, arrays and shapes OK")
    sj = os.path.join(out, "summary.json")
    if os.path.exists(sj):
        s = json.load(open(sj))
        # the volume series and every joint series have one frame per output step
        for p in pvds:
            n = len(ET.parse(p).getroot().findall("./Collection/DataSet"))
            if n != s["frames"]:
                fail(f"{p}: {n} frames but summary.json says {s['frames']}")
        for p in s.get("joint_series", []):
            if s["frames"] > 0 and not os.path.exists(p):
                fail(f"summary.json lists the joint series {p}, which does not exist")
        # one time axis: every joint series has the volume series' times
        axes = {p: [float(d.get("timestep")) for d in ET.parse(p).getroot().findall("./Collection/DataSet")] for p in pvds}
        vol = [p for p in pvds if os.path.dirname(p) in (out, out.rstrip("/"))]
        t_end = None
        if vol:
            t_end = axes[vol[0]][-1]
            for p in pvds:
                if axes[p] != axes[vol[0]]:
                    fail(f"{p}: frame times {axes[p][:4]}... differ from the volume series' {axes[vol[0]][:4]}...")
        t_run = s["steps"] * s["dt"]  # t[N], N = round(duration / dt)
        if s.get("interrupted") is None and vol and abs(t_end - t_run) > 1e-9 * max(1.0, t_run):
            fail(f"{vol[0]}: last frame at t = {t_end}, the run's last step is at {t_run} (N dt)")
        for h in s.get("histories", []):
            check_history(h, t_end)
    print(f"check_vtu: {len(pvds)} series, {total} VTU files OK ({out})")


if __name__ == "__main__":
    main()

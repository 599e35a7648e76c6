#!/usr/bin/env pvpython
"""Open a jointquake run in ParaView itself (pvpython, offscreen under xvfb-run) and check it.

Usage: xvfb-run -a pvpython check_paraview.py OUT_DIR PNG

Loads the volume series (OUT_DIR/<scene>.pvd) and every joint series (OUT_DIR/joints/*.pvd)
together, as a user would, and checks:
- one shared time axis: every series has exactly the volume series' time steps, and the
  animation scene built from all of them has no more positions than the volume series;
- the arrays: volume point data displacement, velocity, acceleration (3 components), cell data
  stress (9), principal_stress (3), von_mises, block_id; joint point data gap, opening, slip,
  tangential_displacement, normal_traction, shear_traction, state, lost, lost_travel,
  tributary_area, and the state labels in the joint files' field data (state_label_open = 0 ...);
- the last time step reads (ParaView decodes the compressed binary frames);
then renders the last step (volume coloured by displacement magnitude, joints by state as
categories) to PNG. Exits non-zero with a message naming the file on any failure.
"""
import glob
import os
import sys

from paraview.simple import (  # noqa: E402  (pvpython provides paraview.simple)
    GetActiveViewOrCreate,
    GetAnimationScene,
    GetColorTransferFunction,
    PVDReader,
    Render,
    ResetCamera,
    SaveScreenshot,
    Show,
    ColorBy,
)

VOLUME_POINT = {"displacement": 3, "velocity": 3, "acceleration": 3}
VOLUME_CELL = {"stress": 9, "principal_stress": 3, "von_mises": 1, "block_id": 1}
JOINT_POINT = {"gap": 1, "opening": 1, "slip": 1, "tangential_displacement": 1, "normal_traction": 1,
               "shear_traction": 1, "state": 1, "lost": 1, "lost_travel": 1, "tributary_area": 1,
               "displacement": 3, "normal": 3}
LABELS = {"state_label_open": 0, "state_label_stick": 1, "state_label_slip": 2, "state_label_bonded": 3}


def fail(msg):
    print(f"check_paraview: FAIL: {msg}", file=sys.stderr)
    sys.exit(1)


def check_arrays(path, info, spec):
    for name, k in spec.items():
        a = info.GetArray(name)
        if a is None:
            fail(f"{path}: array {name} missing")
        if a.GetNumberOfComponents() != k:
            fail(f"{path}: array {name} has {a.GetNumberOfComponents()} components, expected {k}")


def main():
    if len(sys.argv) < 3:
        fail("usage: check_paraview.py OUT_DIR PNG")
    out, png = sys.argv[1], sys.argv[2]
    volume = sorted(glob.glob(os.path.join(out, "*.pvd")))
    joints = sorted(glob.glob(os.path.join(out, "joints", "*.pvd")))
    if len(volume) != 1:
        fail(f"{out}: expected one volume series, found {volume}")
    if not joints:
        fail(f"{out}: no joint series in joints/")
    vr = PVDReader(FileName=volume[0])
    vr.UpdatePipelineInformation()
    times = list(vr.TimestepValues)
    if len(times) < 2:
        fail(f"{volume[0]}: {len(times)} time steps")
    readers = []
    for p in joints:
        r = PVDReader(FileName=p)
        r.UpdatePipelineInformation()
        jt = list(r.TimestepValues)
        if jt != times:
            fail(f"{p}: time steps {jt[:3]}... ({len(jt)}) differ from the volume's {times[:3]}... ({len(times)})")
        readers.append((p, r))
    scene = GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    n_scene = len(scene.TimeKeeper.TimestepValues)
    if n_scene != len(times):
        fail(f"the animation has {n_scene} time positions for {len(times)} frames per series (not one time axis)")

    t_last = times[-1]
    vr.UpdatePipeline(t_last)
    check_arrays(volume[0], vr.PointData, VOLUME_POINT)
    check_arrays(volume[0], vr.CellData, VOLUME_CELL)
    if vr.GetDataInformation().GetNumberOfPoints() == 0:
        fail(f"{volume[0]}: no points at t = {t_last}")
    for p, r in readers:
        r.UpdatePipeline(t_last)
        check_arrays(p, r.PointData, JOINT_POINT)
        fd = r.GetFieldDataInformation()
        got = {}
        for name in LABELS:
            a = fd.GetArray(name)
            if a is None:
                fail(f"{p}: field data {name} missing (the state labels)")
            got[name] = int(a.GetRange(0)[0])
        if got != LABELS:
            fail(f"{p}: state labels {got}, expected {LABELS}")

    view = GetActiveViewOrCreate("RenderView")
    view.ViewSize = [800, 600]
    view.ViewTime = t_last
    d = Show(vr, view)
    ColorBy(d, ("POINTS", "displacement", "Magnitude"))
    for p, r in readers:
        jd = Show(r, view)
        ColorBy(jd, ("POINTS", "state"))
        lut = GetColorTransferFunction("state")
        lut.InterpretValuesAsCategories = 1
        lut.Annotations = ["0", "open", "1", "stick", "2", "slip", "3", "bonded"]
    ResetCamera(view)
    Render(view)
    SaveScreenshot(png, view, ImageResolution=[800, 600])
    if not os.path.exists(png) or os.path.getsize(png) < 1000:
        fail(f"{png}: no image written")
    print(f"check_paraview: {1 + len(readers)} series on one time axis of {len(times)} steps, arrays and state "
          f"labels OK; rendered {png}")


if __name__ == "__main__":
    main()

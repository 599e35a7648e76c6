#!/usr/bin/env pvpython
"""Load a jointquake ParaView state (the dam study's dam.pvsm) in ParaView itself, render its last
time step to a PNG and check the picture is not blank.

Usage: xvfb-run -a pvpython render_pvsm.py STATE.pvsm OUT.png [WIDTH HEIGHT [TIME]]
(TIME: render the time step nearest to TIME [s] instead of the last one.)

Checks, each failing with a message naming the state file:
- the state loads, and its pipeline is what `output::pvsm` writes: a PVDReader of the volume,
  a Threshold that hides blocks (fewer cells out than in), a WarpVector, and one PVDReader per
  joint whose data has the point array `opening`;
- the animation has at least two time steps (the frames), and the last one renders;
- the image is not blank: at least MIN_FRACTION of its pixels differ from the background colour
  (the corner pixel) by more than 24 in some channel, and those pixels hold at least MIN_COLOURS
  distinct colours (quantised to 32 levels a channel): a dam coloured by |u| shows a gradient, an
  empty view or a single flat-coloured object does not pass.
Thresholds: MIN_FRACTION = 0.05 (the dam fills about a third of a 1000 x 700 view after a camera
reset; 5 % is far below that and far above a few stray pixels), MIN_COLOURS = 8.
"""
import sys

from paraview.simple import (  # noqa: E402  (pvpython provides paraview.simple)
    GetActiveViewOrCreate,
    GetAnimationScene,
    GetColorTransferFunction,
    GetDisplayProperties,
    GetScalarBar,
    GetSources,
    GetTimeKeeper,
    LoadState,
    Render,
    ResetCamera,
    SaveScreenshot,
)

MIN_FRACTION = 0.05
MIN_COLOURS = 8


def fail(msg):
    print(f"render_pvsm: FAIL: {msg}", file=sys.stderr)
    sys.exit(1)


def main():
    if len(sys.argv) < 3:
        fail("usage: render_pvsm.py STATE.pvsm OUT.png [WIDTH HEIGHT [TIME]]")
    state, png = sys.argv[1], sys.argv[2]
    size = [int(sys.argv[3]), int(sys.argv[4])] if len(sys.argv) >= 5 else [1000, 700]
    LoadState(state)
    sources = GetSources()
    by_type = {}
    for (name, _), s in sources.items():
        by_type.setdefault(s.GetXMLName(), []).append((name, s))
    readers = by_type.get("PVDReader", [])
    if len(readers) < 2:
        fail(f"{state}: {len(readers)} PVD readers (expected the volume and at least one joint)")
    for kind in ("Threshold", "WarpVector"):
        if kind not in by_type:
            fail(f"{state}: no {kind} in the state")
    _, threshold = by_type["Threshold"][0]
    threshold.UpdatePipeline()
    source = threshold.Input
    source.UpdatePipeline()
    n_in, n_out = source.GetDataInformation().GetNumberOfCells(), threshold.GetDataInformation().GetNumberOfCells()
    if not 0 < n_out < n_in:
        fail(f"{state}: the threshold keeps {n_out} of {n_in} cells (expected the dam without the rock)")
    joints = [(n, r) for n, r in readers if r is not source]
    for name, r in joints:
        r.UpdatePipeline()
        if r.PointData.GetArray("opening") is None:
            fail(f"{state}: joint series {name} has no point array opening")
    scene = GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    times = list(GetTimeKeeper().TimestepValues)
    if len(times) < 2:
        fail(f"{state}: {len(times)} time steps")
    at = times[-1] if len(sys.argv) < 6 else min(times, key=lambda t: abs(t - float(sys.argv[5])))
    scene.AnimationTime = at
    view = GetActiveViewOrCreate("RenderView")
    view.ViewSize = size
    # the colour legend of |u| [m] (the state leaves scalar bars to the user)
    _, warp = by_type["WarpVector"][0]
    GetDisplayProperties(warp, view).SetScalarBarVisibility(view, True)
    GetScalarBar(GetColorTransferFunction("displacement"), view).Title = "|displacement| [m]"
    ResetCamera(view)
    Render(view)
    SaveScreenshot(png, view, ImageResolution=size)
    from vtkmodules.vtkIOImage import vtkPNGReader
    from vtkmodules.util.numpy_support import vtk_to_numpy
    rd = vtkPNGReader()
    rd.SetFileName(png)
    rd.Update()
    img = rd.GetOutput()
    w, h, _ = img.GetDimensions()
    px = vtk_to_numpy(img.GetPointData().GetScalars()).reshape(h * w, -1)[:, :3].astype(int)
    bg = px[0]
    fg = px[(abs(px - bg) > 24).any(axis=1)]
    fraction = len(fg) / len(px)
    colours = len({tuple(c) for c in (fg // 8).tolist()})
    print(f"render_pvsm: {state}: {len(joints)} joints, {len(times)} time steps (rendered t = {at:.4g} s), threshold keeps {n_out} of {n_in} cells; {png}: {w} x {h} px, {100 * fraction:.1f} % non-background pixels in {colours} colours")
    if fraction < MIN_FRACTION:
        fail(f"{png}: {100 * fraction:.2f} % of the pixels differ from the background, below {100 * MIN_FRACTION:.0f} %: the picture is blank")
    if colours < MIN_COLOURS:
        fail(f"{png}: {colours} distinct colours, below {MIN_COLOURS}: no colour map shows")


if __name__ == "__main__":
    main()

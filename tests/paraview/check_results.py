"""ParaView (pvbatch) opens pdcg's results.xdmf of a rupture run as a user would, and checks
what it reads against the HDF5 files themselves (read with h5py, not through ParaView) and
the run's reactions.csv: the time steps, the point fields (displacement, stresses, damage)
bit for bit at every step, damage in [0, 1] and growing, then renders the last step coloured
by damage (displacement magnitude for a run without damage) into a PNG.

With SERIAL_DIR (the output of a distributed run, `mpirun -n N pdcg run`, checked against the
serial run of the same scene): ParaView's fields of RUN_DIR also equal SERIAL_DIR's HDF5 fields
within 1e-10 of each field's largest magnitude (both are direct solves; only the order of the
sums across processes differs, measured ≤ 1e-14 in tests/mpi).

Usage: pvbatch check_results.py RUN_DIR PNG [SERIAL_DIR]"""
import csv
import glob
import os
import sys

import h5py
import numpy as np
from paraview import servermanager
from paraview.simple import (ColorBy, GetActiveViewOrCreate, GetAnimationScene,
                             GetColorTransferFunction, GetScalarBar, OpenDataFile, Render,
                             SaveScreenshot, Show, UpdatePipeline, WarpByVector)
from vtk.util.numpy_support import vtk_to_numpy

run, png = sys.argv[1], sys.argv[2]
serial = sys.argv[3] if len(sys.argv) > 3 else None
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


reader = OpenDataFile(os.path.join(run, "results.xdmf"))
check(reader is not None, "ParaView has a reader for results.xdmf")
if reader is None:
    sys.exit(1)
print("reader:", reader.GetXMLName())
times = list(reader.TimestepValues)
files = sorted(glob.glob(os.path.join(run, "results_*.h5")))
with open(os.path.join(run, "reactions.csv")) as f:
    rows = [r for r in csv.reader(line for line in f if not line.startswith("#"))]
header, rows = rows[0], rows[1:]
t_col = header.index(next(h for h in header if h.split(" ")[0] in ("t", "time")))
# the CSV's step 0 is the unloaded state, which has no result file
csv_times = [float(r[t_col]) for r in rows if int(r[header.index("step")]) > 0]
check(len(times) == len(files) == len(csv_times) and len(times) >= 3,
      f"{len(times)} time steps in ParaView, {len(files)} result files, "
      f"{len(csv_times)} loaded steps in reactions.csv")
# the CSV prints 10 significant digits, the XDMF the double
check(len(times) == len(csv_times) and np.allclose(times, csv_times, rtol=1e-9, atol=0),
      f"ParaView's times {times} are reactions.csv's")

wanted = {"displacement": 3, "first_piola_kirchhoff": 9, "cauchy_stress": 9, "damage": 1}
with h5py.File(files[0], "r") as h5:
    has_damage = "fields/damage" in h5
if serial is None:
    check(has_damage, "the rupture run wrote a damage field")
else:
    del wanted["damage"]  # a run without rupture writes no damage
    serial_files = sorted(glob.glob(os.path.join(serial, "results_*.h5")))
    check([os.path.basename(f) for f in serial_files] == [os.path.basename(f) for f in files],
          f"the same result files as the serial run ({len(serial_files)})")
previous_damage = None
for k, (t, path) in enumerate(zip(times, files)):
    UpdatePipeline(time=t, proxy=reader)
    data = servermanager.Fetch(reader)
    if data.IsA("vtkMultiBlockDataSet"):
        data = data.GetBlock(0)
    with h5py.File(path, "r") as h5:
        ref = h5["points/reference"][...]
        pts = vtk_to_numpy(data.GetPoints().GetData())
        check(pts.shape == ref.shape and np.array_equal(pts, ref),
              f"step {k + 1}: {pts.shape[0]} points at the reference positions of {os.path.basename(path)}")
        for name, ncomp in wanted.items():
            arr = data.GetPointData().GetArray(name)
            if arr is None:
                check(False, f"step {k + 1}: point field {name} in ParaView")
                continue
            # the array as VTK stores it (tensors: 9 components in ParaView's XX, XY, XZ, YX, …
            # order), against the dataset's rows
            got = vtk_to_numpy(arr).reshape(len(ref), -1)
            exp = h5["fields/" + name][...].reshape(len(ref), -1)
            check(arr.GetNumberOfComponents() == ncomp and np.array_equal(got, exp),
                  f"step {k + 1}: {name} ({arr.GetNumberOfComponents()} components) equals the "
                  "HDF5 dataset bit for bit")
            if serial is not None:
                with h5py.File(os.path.join(serial, os.path.basename(path)), "r") as ser:
                    sref = ser["fields/" + name][...].reshape(len(ref), -1)
                    sx = ser["points/reference"][...]
                scale = max(float(np.abs(sref).max()), 1e-300)
                err = float(np.abs(got - sref).max()) / scale
                check(np.array_equal(sx, ref) and err <= 1e-10,
                      f"step {k + 1}: {name} in ParaView = the serial run's within {err:.1e} "
                      "of its largest magnitude (required 1e-10)")
        if not has_damage:
            continue
        damage = vtk_to_numpy(data.GetPointData().GetArray("damage")).copy()
    check(damage.min() >= 0.0 and damage.max() <= 1.0, f"step {k + 1}: damage in [0, 1]")
    if previous_damage is not None:
        check(np.all(damage >= previous_damage), f"step {k + 1}: damage never decreases")
    previous_damage = damage
if has_damage:
    check(previous_damage is not None and previous_damage.max() > 0.2,  # the scene tears the sheet
          f"last step: damage reaches {previous_damage.max():.3f} (> 0.2: bonds broke)")

# the last step on the deformed configuration, points coloured by damage
scene = GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
scene.AnimationTime = times[-1]
view = GetActiveViewOrCreate("RenderView")
view.ViewSize = [800, 800]
view.ViewTime = times[-1]
view.OrientationAxesVisibility = 0
view.Background = [1.0, 1.0, 1.0]
if hasattr(view, "UseColorPaletteForBackground"):
    view.UseColorPaletteForBackground = 0
warp = WarpByVector(Input=reader, Vectors=["POINTS", "displacement"], ScaleFactor=1.0)
display = Show(warp, view)
display.SetRepresentationType("Points")
display.PointSize = 7
display.RenderPointsAsSpheres = 1
colour = "damage" if has_damage else "displacement"
ColorBy(display, ("POINTS", colour) if has_damage else ("POINTS", colour, "Magnitude"))
lut = GetColorTransferFunction(colour)
lut.ApplyPreset("Inferno (matplotlib)", True)
if has_damage:
    lut.RescaleTransferFunction(0.0, 1.0)
display.SetScalarBarVisibility(view, True)
bar = GetScalarBar(lut, view)
bar.Title = colour
bar.ComponentTitle = ""
bar.TitleColor = bar.LabelColor = [0.0, 0.0, 0.0]
view.ResetCamera()
Render(view)
SaveScreenshot(png, view, ImageResolution=[800, 800])
check(os.path.getsize(png) > 10000, f"rendered {png} ({os.path.getsize(png)} bytes)")
import matplotlib.image  # noqa: E402  (after ParaView: its own VTK first)

img = matplotlib.image.imread(png)[..., :3]
drawn = float(np.mean(np.any(img < 0.9, axis=-1)))  # pixels that are not the white background
check(img.shape[:2] == (800, 800) and drawn > 0.01,
      f"the picture is 800 x 800 with {100 * drawn:.1f} % of it drawn (points and colour bar)")
print(f"paraview check: {len(failures)} failures", flush=True)
# os._exit: ParaView's teardown of the render window after the checks can fail on Xvfb's GLX
# (GLXBadContext in X_GLXMakeCurrent) and turn a finished run's status into an X error
os._exit(1 if failures else 0)

"""Checks the 3-D wear views of app/render.py on a synthetic wear field with a known hot spot: a 2 x 1 m plate
whose rate is a Gaussian bump centred at (1.5, 0.3) m. Seen from above, the pixels that show the colour
bar's hottest colours must lie around where the camera puts the hot spot; the other views are written; the
same field on a shared colour scale twice as high shows no pixel of the hottest colours.
Usage: check_wear_views.py RENDER_PY DIR"""
import importlib.util
import json
import os
import shutil
import subprocess
import sys

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy

render_py, folder = sys.argv[1], sys.argv[2]
shutil.rmtree(folder, ignore_errors=True)
os.makedirs(folder)
spec = importlib.util.spec_from_file_location("render", render_py)
render = importlib.util.module_from_spec(spec)
spec.loader.exec_module(render)

# the plate: 80 x 40 cells of two triangles, its normal +z; the rate is highest (1e-3 mm/t) at the hot spot
plane = vtk.vtkPlaneSource()
plane.SetOrigin(0.0, 0.0, 0.0)
plane.SetPoint1(2.0, 0.0, 0.0)
plane.SetPoint2(0.0, 1.0, 0.0)
plane.SetResolution(80, 40)
triangles = vtk.vtkTriangleFilter()
triangles.SetInputConnection(plane.GetOutputPort())
triangles.Update()
surface = triangles.GetOutput()
x = vtk_to_numpy(surface.GetPoints().GetData())
hot = np.array([1.5, 0.3, 0.0])
rate = 1e-3 * np.exp(-np.sum((x - hot) ** 2, axis=1) / (2 * 0.08 ** 2)) + 2e-4 * np.exp(-np.sum((x - [0.4, 0.7, 0]) ** 2, axis=1) / 0.02)
field = numpy_to_vtk(rate, deep=True)
field.SetName("rate_mm_per_t")
surface.GetPointData().AddArray(field)
writer = vtk.vtkXMLPolyDataWriter()
writer.SetFileName(os.path.join(folder, "wear_plate_final.vtp"))
writer.SetInputData(surface)
writer.Write()
with open(os.path.join(folder, "summary.json"), "w") as f:
    json.dump({"wear": {"plate": {"tonnage_t": 100.0, "law": "force_work", "constant": 1e-12}}}, f)

render.ensure_display()
views = render.views_for("plate", [])
done = render.render_wear(surface, views, os.path.join(folder, "probe"), "synthetic hot spot",
                          probes=[hot, hot + [0.1, 0.0, 0.0]])
table = render.table_colours()


def hottest_pixels(path):
    """Pixels of the part whose colour is within 6 levels of one of the colour map's top 5 % of colours."""
    reader = vtk.vtkPNGReader()
    reader.SetFileName(path)
    reader.Update()
    image = reader.GetOutput()
    w, h, _ = image.GetDimensions()
    rgb = vtk_to_numpy(image.GetPointData().GetScalars()).reshape(h, w, -1)[::-1, :, :3].astype(float)  # rows from the top
    left, bottom, box_w, box_h = render.SCENE
    scene = np.zeros((h, w), bool)
    scene[h - bottom - box_h:h - bottom, left:left + box_w] = True  # the colour bar lies outside the part's box
    top = table[int(0.95 * 255):]
    near = np.min(np.linalg.norm(rgb[:, :, None, :] - top[None, None, :, :], axis=3), axis=2) < 6.0
    rows, cols = np.nonzero(near & scene)
    return rows, cols


view, name, places = done[0]
assert view.name == "top", view.name
rows, cols = hottest_pixels(os.path.join(folder, name))
# The scale's top is the field's 99th percentile; the top 5 % of the colours show where the rate exceeds 0.95
# of it, inside radius sigma sqrt(2 ln(peak / (0.95 top))) of the hot spot. The picture's scale comes from a
# second probe 0.1 m along x. The centroid of those pixels must lie within 5 px (about 11 mm) of where the
# camera puts the hot spot, and none farther than that radius plus one element (25 mm) and 3 px of blending.
assert len(rows) > 50, f"only {len(rows)} pixels of the hottest colours"
expected_col, expected_row = places["column"][0], places["row"][0]
px_per_m = np.hypot(places["column"][1] - expected_col, places["row"][1] - expected_row) / 0.1
top = np.percentile(rate, 99.0)
reach_px = (0.08 * np.sqrt(2 * np.log(1e-3 / (0.95 * top))) + 0.025) * px_per_m + 3
assert abs(np.mean(cols) - expected_col) < 5 and abs(np.mean(rows) - expected_row) < 5, \
    (np.mean(cols), np.mean(rows), expected_col, expected_row)
found = (np.mean(cols), np.mean(rows))
spread = np.hypot(cols - expected_col, rows - expected_row).max()
assert spread < reach_px, f"hottest colours up to {spread:.1f} px from the hot spot, expected within {reach_px:.1f} px"
print(f"hottest colours within {spread:.1f} px of the hot spot (limit {reach_px:.1f} px)")

# on a colour scale twice the field's highest, no pixel of the part shows the hottest colours
scaled = render.render_wear(surface, views[:1], os.path.join(folder, "scaled"), "shared scale", vmax=2e-3)
rows, _ = hottest_pixels(os.path.join(folder, scaled[0][1]))
assert len(rows) == 0, f"{len(rows)} pixels of the hottest colours on a scale twice as high"

# the command line: every view of the part written and listed
out = subprocess.run([sys.executable, render_py, "wear", folder], check=True, capture_output=True, text=True).stdout
pictures = json.loads(out.strip().splitlines()[-1])
assert [p[1] for p in pictures] == ["wear_plate_top.png", "wear_plate_oblique.png", "wear_plate_below.png"], pictures
for _, png in pictures:
    assert os.path.getsize(os.path.join(folder, png)) > 20000, png
# a sweep: two variants, the second wearing half as fast; its views are drawn again on the first's scale
sweep = os.path.join(folder, "sweep")
for variant, factor in ((0, 1.0), (1, 0.5)):
    run = os.path.join(sweep, f"variant_{variant:03d}")
    os.makedirs(run)
    field = numpy_to_vtk(rate * factor, deep=True)
    field.SetName("rate_mm_per_t")
    surface.GetPointData().AddArray(field)
    writer.SetFileName(os.path.join(run, "wear_plate_final.vtp"))
    writer.Write()
    shutil.copy(os.path.join(folder, "summary.json"), run)
with open(os.path.join(sweep, "sweep.csv"), "w") as f:
    f.write("variant,shovel.rake_angle_deg,status,wear_plate_m3\n0,60,completed,1e-6\n1,65,completed,0.5e-6\n")
subprocess.run([sys.executable, os.path.join(os.path.dirname(render_py), "report.py"), sweep], check=True,
               stdout=subprocess.DEVNULL)
text = open(os.path.join(sweep, "sweep.md")).read()
assert f"## Wear views on one colour scale (0 to {np.percentile(rate, 99.0):.3g} mm/t)" in text, text
assert "![Wear of the plate: from above](variant_001/wear_plate_top.png)" in text, text
rows, _ = hottest_pixels(os.path.join(sweep, "variant_001", "wear_plate_top.png"))
assert len(rows) == 0, f"the slower variant shows {len(rows)} pixels of the hottest colours on the shared scale"
rows, _ = hottest_pixels(os.path.join(sweep, "variant_000", "wear_plate_top.png"))
assert len(rows) > 50, "the faster variant lost its hot spot"

print(f"wear views: hot spot found at ({found[0]:.1f}, {found[1]:.1f}) px against "
      f"({expected_col:.1f}, {expected_row:.1f}) px; {len(pictures)} views written: ok")

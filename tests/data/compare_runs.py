"""Compares the last ParaView frames and summaries of two runs of one scenario: an uninterrupted run and
one stopped at a checkpoint and resumed. Prints the largest differences; with limits, fails above them.
Usage: compare_runs.py [--limits MAX_SPHERE_MM MAX_ROCK_MM MAX_RELATIVE] WHOLE RESUMED

Runs with Bullet bodies resumed from a checkpoint do not repeat the uninterrupted run bit for bit (Bullet's
contact caches are not saved); tests/CMakeLists.txt states the limits and why."""
import json
import os
import sys
import xml.etree.ElementTree as ET

import vtk
from vtk.util.numpy_support import vtk_to_numpy

args = sys.argv[1:]
limits = None
if args and args[0] == "--limits":
    limits = [float(x) for x in args[1:4]]
    args = args[4:]
whole, resumed = args[0], args[1]


def last_frame(folder, pvd):
    sets = ET.parse(os.path.join(folder, pvd)).getroot().findall("./Collection/DataSet")
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(os.path.join(folder, sets[-1].get("file")))
    reader.Update()
    return float(sets[-1].get("timestep")), reader.GetOutput()


def spheres(folder):
    t, poly = last_frame(folder, "particles.pvd")
    ids = vtk_to_numpy(poly.GetPointData().GetArray("id"))
    x = vtk_to_numpy(poly.GetPoints().GetData())
    return t, {int(i): x[k] for k, i in enumerate(ids)}


tw, sw = spheres(whole)
tr, sr = spheres(resumed)
assert abs(tw - tr) < 1e-9, (tw, tr)
assert sw.keys() == sr.keys(), "the runs hold different spheres"
gaps = sorted(1000.0 * float(((sw[i] - sr[i]) ** 2).sum() ** 0.5) for i in sw)
sphere_mm, sphere_median_mm = gaps[-1], gaps[len(gaps) // 2]
rock_mm = 0.0
if os.path.exists(os.path.join(whole, "rocks.pvd")):
    xw = vtk_to_numpy(last_frame(whole, "rocks.pvd")[1].GetPoints().GetData())
    xr = vtk_to_numpy(last_frame(resumed, "rocks.pvd")[1].GetPoints().GetData())
    assert xw.shape == xr.shape
    rock_mm = 1000.0 * float((((xw - xr) ** 2).sum(axis=1) ** 0.5).max())
a = json.load(open(os.path.join(whole, "summary.json")))
b = json.load(open(os.path.join(resumed, "summary.json")))
relative = {}
for key in ("kinetic_energy_J", "rock_kinetic_energy_J", "bucket_mass_kg"):
    if key in a and a[key]:
        relative[key] = abs(a[key] - b[key]) / abs(a[key])
for part, w in a.get("wear", {}).items():
    relative[f"wear {part}"] = abs(w["volume_m3"] - b["wear"][part]["volume_m3"]) / max(w["volume_m3"], 1e-300)
worst = max(relative.values()) if relative else 0.0
print(f"at t = {tw:.4f} s: spheres differ by at most {sphere_mm:.3g} mm (median {sphere_median_mm:.3g} mm), "
      f"rock vertices by {rock_mm:.3g} mm; "
      + ", ".join(f"{k} by {v:.2e}" for k, v in relative.items()))
if limits:
    assert a["status"] == b["status"] == "completed", (a["status"], b["status"])
    assert sphere_mm <= limits[0], f"spheres differ by {sphere_mm} mm > {limits[0]} mm"
    assert rock_mm <= limits[1], f"rocks differ by {rock_mm} mm > {limits[1]} mm"
    assert worst <= limits[2], f"a summary figure differs by {worst} > {limits[2]}"

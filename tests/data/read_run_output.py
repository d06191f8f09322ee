"""Reads what `dipper run` wrote with VTK's own XML readers and Python's csv and json, and checks it.
Usage: read_run_output.py DIR  (DIR written by dipper run tests/data/scenarios/kill_resume.yaml --stop-after 0.2)."""
import csv
import json
import os
import sys
import xml.etree.ElementTree as ET

import vtk

folder = sys.argv[1]
summary = json.load(open(os.path.join(folder, "summary.json")))
assert summary["status"] == "interrupted", summary["status"]
assert abs(summary["time_s"] - 0.2) < 1e-4, summary["time_s"]

datasets = ET.parse(os.path.join(folder, "particles.pvd")).getroot().findall("./Collection/DataSet")
times = [float(d.get("timestep")) for d in datasets]
assert len(times) == 3 and abs(times[0]) < 1e-12 and abs(times[1] - 0.1) < 1e-4 and abs(times[2] - 0.2) < 1e-4, times

with open(os.path.join(folder, "probes.csv")) as f:
    rows = list(csv.DictReader(f))
for column in ("time_s", "step", "particles", "mass_kg", "kinetic_energy_J", "pair_contacts", "wall_contacts",
               "max_overlap_ratio", "force_floor_z_N", "force_paddle_x_N", "wall_clock_s"):
    assert column in rows[0], f"probes.csv has no column {column}"
assert len(rows) == 21, len(rows)  # t = 0, 0.01, ..., 0.2

for d in datasets:
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(os.path.join(folder, d.get("file")))
    reader.Update()
    poly = reader.GetOutput()
    n = poly.GetNumberOfPoints()
    t = float(d.get("timestep"))
    expected = int(next(r for r in rows if abs(float(r["time_s"]) - t) < 1e-9)["particles"])
    assert n == expected, f"{d.get('file')}: {n} points, probes.csv says {expected}"
    assert poly.GetNumberOfVerts() == n
    data = poly.GetPointData()
    for name, components in (("radius_m", 1), ("velocity_m_per_s", 3), ("angular_velocity_rad_per_s", 3),
                             ("material", 1), ("id", 1)):
        array = data.GetArray(name)
        assert array is not None, f"missing point array {name}"
        assert array.GetNumberOfComponents() == components and array.GetNumberOfTuples() == n, name
    radii = {round(data.GetArray("radius_m").GetValue(i), 9) for i in range(n)}
    assert radii <= {0.04, 0.05}, radii

walls = ET.parse(os.path.join(folder, "wall_paddle.pvd")).getroot().findall("./Collection/DataSet")
assert len(walls) == 3
reader = vtk.vtkXMLPolyDataReader()
reader.SetFileName(os.path.join(folder, walls[-1].get("file")))
reader.Update()
assert reader.GetOutput().GetNumberOfPolys() > 0
report = open(os.path.join(folder, "report.md")).read()
assert report.startswith("# kill_resume: interrupted"), report[:60]
for png in ("kinetic_energy.png", "wall_forces.png", "mass.png"):
    assert f"]({png})" in report and os.path.getsize(os.path.join(folder, png)) > 1000, png
print(f"dipper run output: {len(times)} particle frames, paddle mesh, {len(rows)} probe rows, summary: ok")

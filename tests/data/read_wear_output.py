"""Reads dipper's wear outputs with independent readers and checks what they hold: the surface with VTK's
XML reader, the CSVs with the csv module.
Usage: read_wear_output.py DIR  (DIR written by dipper_write_wear_sample)."""
import csv
import os
import sys

import vtk

folder = sys.argv[1]
summary = dict(line.split() for line in open(os.path.join(folder, "summary.txt")))
tonnage = float(summary["tonnage_t"])
total = float(summary["total_volume_m3"])
assert total > 0 and tonnage > 0, summary

# ---- the surface: fields per triangle and per node, total volume, rate = depth / tonnage
reader = vtk.vtkXMLPolyDataReader()
reader.SetFileName(os.path.join(folder, "plate_wear.vtp"))
reader.Update()
poly = reader.GetOutput()
assert poly.GetNumberOfPolys() == 27 * 13 * 2, poly.GetNumberOfPolys()
cells, nodes = poly.GetCellData(), poly.GetPointData()
for name in ("depth_mm", "wear_volume_m3", "mean_normal_force_N", "mean_tangential_force_N", "contact_steps",
             "impacts", "rate_mm_per_t"):
    assert cells.GetArray(name) is not None, f"missing cell field {name}"
for name in ("depth_mm", "rate_mm_per_t"):
    assert nodes.GetArray(name) is not None, f"missing node field {name}"
volume = cells.GetArray("wear_volume_m3")
vtk_total = sum(volume.GetValue(i) for i in range(volume.GetNumberOfTuples()))
assert abs(vtk_total - total) <= 1e-8 * total, (vtk_total, total)
depth, rate = cells.GetArray("depth_mm"), cells.GetArray("rate_mm_per_t")
for i in range(depth.GetNumberOfTuples()):
    assert abs(rate.GetValue(i) - depth.GetValue(i) / tonnage) <= 1e-8 * max(1e-30, abs(rate.GetValue(i))), i
zmin = min(poly.GetPoint(i)[2] for i in range(poly.GetNumberOfPoints()))
assert zmin < -0.6, f"the pose was not applied: lowest point z = {zmin}"  # 2 m plate tilted 20 deg

# ---- CSVs
points = list(csv.DictReader(open(os.path.join(folder, "points.csv"))))
assert len(points) == 6
for p in points:
    assert abs(float(p["measured_mm_per_t"]) - 1.5 * float(p["simulated_mm_per_t"])) <= 1e-8 * float(p["measured_mm_per_t"]) + 1e-300
section = list(csv.DictReader(open(os.path.join(folder, "section_middle.csv"))))
assert sum(1 for r in section if r["kind"] == "simulated") == 39
assert sum(1 for r in section if r["kind"] == "measured") == 6
print(f"wear outputs read back: {poly.GetNumberOfPolys()} triangles, total {vtk_total:.4g} m^3: ok")

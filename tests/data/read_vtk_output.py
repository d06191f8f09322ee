"""Reads dipper's ParaView output with VTK's own XML readers and checks what it holds.
Usage: read_vtk_output.py DIR  (DIR written by dipper_write_sample_output)."""
import csv
import os
import sys
import xml.etree.ElementTree as ET

import vtk

folder = sys.argv[1]
collection = ET.parse(os.path.join(folder, "particles.pvd")).getroot()
datasets = collection.findall("./Collection/DataSet")
assert len(datasets) == 3, f"expected 3 time steps in particles.pvd, found {len(datasets)}"
times = [float(d.get("timestep")) for d in datasets]
assert times == sorted(times) and times[0] > 0, times

for d in datasets:
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(os.path.join(folder, d.get("file")))
    reader.Update()
    poly = reader.GetOutput()
    n = poly.GetNumberOfPoints()
    assert n == 32, f"{d.get('file')}: {n} points, expected 32"
    assert poly.GetNumberOfVerts() == n
    data = poly.GetPointData()
    for name, components in (("radius_m", 1), ("velocity_m_per_s", 3), ("angular_velocity_rad_per_s", 3),
                             ("material", 1), ("id", 1)):
        array = data.GetArray(name)
        assert array is not None, f"missing point array {name}"
        assert array.GetNumberOfComponents() == components, name
        assert array.GetNumberOfTuples() == n, name
    assert abs(data.GetArray("radius_m").GetValue(0) - 0.1) < 1e-12
    ids = sorted(int(data.GetArray("id").GetValue(i)) for i in range(n))
    assert ids == list(range(n)), "ids are not 0..n-1"

mesh_reader = vtk.vtkXMLPolyDataReader()
mesh_reader.SetFileName(os.path.join(folder, "wall_floor_000002.vtp"))
mesh_reader.Update()
mesh = mesh_reader.GetOutput()
assert mesh.GetNumberOfPolys() == 8, mesh.GetNumberOfPolys()
assert mesh.GetNumberOfPoints() == 9

with open(os.path.join(folder, "world.csv")) as f:
    rows = list(csv.DictReader(f))
assert len(rows) == 3
assert float(rows[-1]["time_s"]) == times[-1] or abs(float(rows[-1]["time_s"]) - times[-1]) < 1e-12
# the compressed arrays: empty ones, and ones over several blocks read back bit for bit
reader = vtk.vtkXMLPolyDataReader()
reader.SetFileName(os.path.join(folder, "empty.vtp"))
reader.Update()
assert reader.GetOutput().GetNumberOfPoints() == 0
reader = vtk.vtkXMLPolyDataReader()
reader.SetFileName(os.path.join(folder, "large.vtp"))
reader.Update()
large = reader.GetOutput()
expected = [tuple(float(v) for v in line.split()) for line in open(os.path.join(folder, "large_positions.txt"))]
assert len(expected) >= 4000 and large.GetNumberOfPoints() == len(expected), (large.GetNumberOfPoints(), len(expected))
assert 24 * len(expected) > 65536  # the positions span more than one compressed block
assert all(large.GetPoint(i) == expected[i] for i in range(len(expected))), "positions differ from the text's"
assert large.GetPointData().GetArray("id").GetValue(len(expected) - 1) == len(expected) - 1

print("VTK read 3 particle frames of 32 points, the floor mesh and the CSV: ok")

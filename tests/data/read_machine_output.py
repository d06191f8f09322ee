"""Reads what `dipper run tests/data/scenarios/machine_small.yaml` wrote (rocks, shovel, wear) with VTK's
XML readers and Python's csv and json, and checks the arrays, their sizes and the probe columns.
Usage: read_machine_output.py DIR"""
import csv
import json
import os
import sys
import xml.etree.ElementTree as ET

import vtk

folder = sys.argv[1]
summary = json.load(open(os.path.join(folder, "summary.json")))
assert summary["status"] == "completed", summary
assert summary["rocks"] > 10, summary["rocks"]
assert summary["passes"] == [], summary["passes"]
# the run's wall clock by phase: each part at least 0, the rocks' share within the walls', Bullet's steps and the
# surfaces' moves present (rocks and the shovel), everything but "other" adding up to at most the wall clock
phases = summary["wall_clock_by_phase_s"]
assert all(v >= 0.0 for k, v in phases.items() if k != "other"), phases
assert phases["of_it_sphere_rock"] <= phases["walls_and_bodies"], phases
assert phases["rigid_bodies"] > 0.0 and phases["surface_motion"] > 0.0 and phases["sphere_pairs"] > 0.0, phases
assert phases["other"] >= -1e-6 * summary["wall_clock_s"], (phases, summary["wall_clock_s"])
assert summary["neighbour_rebuilds"] >= 1, summary["neighbour_rebuilds"]  # at least the first step's
assert "dipper" in summary["wear"] and summary["wear"]["dipper"]["law"] == "force_work", summary["wear"]
by_region = summary["wear"]["dipper"]["volume_by_region_m3"]
assert set(by_region) == {"bottom", "lip", "sides", "top", "teeth", "bars"}, by_region
total = summary["wear"]["dipper"]["volume_m3"]
assert total > 0 and abs(sum(by_region.values()) - total) <= 1e-9 * total, (by_region, total)


def frames(pvd):
    return ET.parse(os.path.join(folder, pvd)).getroot().findall("./Collection/DataSet")


def read(file):
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(os.path.join(folder, file))
    reader.Update()
    return reader.GetOutput()


with open(os.path.join(folder, "probes.csv")) as f:
    rows = list(csv.DictReader(f))
for column in ("rocks", "rock_kinetic_energy_J", "bucket_mass_kg", "fill_factor", "crowd_force_N", "hoist_force_N",
               "dig_force_N", "swing_deg", "door_deg", "tooth_tip_z_m", "wear_dipper_m3", "force_dipper_z_N",
               "force_door_z_N", "wall_s_per_step"):
    assert column in rows[0], f"probes.csv has no column {column}"
assert not any(c.startswith("force_rock") for c in rows[0]), "rock hulls are not listed as walls"
assert len(rows) == 31, len(rows)
assert all(int(r["rocks"]) == summary["rocks"] for r in rows)
assert float(rows[-1]["hoist_force_N"]) > 1e5, rows[-1]["hoist_force_N"]  # the ropes carry the dipper

rock_frames = frames("rocks.pvd")
assert len(rock_frames) == 4, len(rock_frames)  # t = 0, 0.1, 0.2, 0.3
for d in rock_frames:
    poly = read(d.get("file"))
    cells = poly.GetNumberOfPolys()
    assert cells >= 4 * summary["rocks"], cells
    ids = poly.GetCellData().GetArray("rock")
    for name in ("rock", "speed_m_per_s", "size_m"):
        array = poly.GetCellData().GetArray(name)
        assert array is not None and array.GetNumberOfTuples() == cells, name
    assert {int(ids.GetValue(k)) for k in range(cells)} == set(range(summary["rocks"]))
    sizes = {round(poly.GetCellData().GetArray("size_m").GetValue(k), 6) for k in range(cells)}
    assert sizes <= {0.4, 0.6}, sizes  # each rock has its class's equivalent diameter

wear_frames = frames("wear_dipper.pvd")
assert len(wear_frames) == 4, len(wear_frames)
poly = read(wear_frames[-1].get("file"))
cells = poly.GetNumberOfPolys()
for name in ("depth_mm", "wear_volume_m3", "mean_normal_force_N", "mean_tangential_force_N", "contact_steps", "impacts"):
    array = poly.GetCellData().GetArray(name)
    assert array is not None and array.GetNumberOfTuples() == cells, name
assert poly.GetPointData().GetArray("depth_mm").GetNumberOfTuples() == poly.GetNumberOfPoints()
touched = sum(1 for k in range(cells) if poly.GetCellData().GetArray("contact_steps").GetValue(k) > 0)
assert touched > 0, "no contact on the dipper"
for wall in ("wall_dipper.pvd", "wall_door.pvd"):
    assert len(frames(wall)) == 4, wall
assert not any(name.startswith("wall_rock") for name in os.listdir(folder)), "rock hulls are not written as walls"

# the surface at the end in the dipper's own frame (heel at the origin, bottom at z = 0), with its plates
final = read("wear_dipper_final.vtp")
assert final.GetNumberOfPolys() == cells, (final.GetNumberOfPolys(), cells)
lo = [min(final.GetPoint(i)[k] for i in range(final.GetNumberOfPoints())) for k in range(3)]
hi = [max(final.GetPoint(i)[k] for i in range(final.GetNumberOfPoints())) for k in range(3)]
assert -0.5 < lo[0] <= 1e-9 and -0.5 < lo[2] < 0.0 and abs(lo[1] + hi[1]) < 1e-6, (lo, hi)  # plates 0.1-0.2 m thick
plate = final.GetCellData().GetArray("plate")
plates = summary["wear"]["dipper"]["plates"]
assert plates[:5] == ["bottom", "lip", "side_minus_y", "side_plus_y", "top"], plates
assert {int(plate.GetValue(k)) for k in range(cells)} == set(range(len(plates)))
volume = final.GetCellData().GetArray("wear_volume_m3")
assert abs(sum(volume.GetValue(k) for k in range(cells)) - total) <= 1e-9 * total

report = open(os.path.join(folder, "report.md")).read()
for view in ("front", "below", "lip"):  # the 3-D wear views drawn from it (no tonnage yet: wear depth)
    png = f"wear_dipper_{view}.png"
    assert f"]({png})" in report and os.path.getsize(os.path.join(folder, png)) > 20000, png
for png in ("dig_force.png", "bucket.png"):
    assert f"]({png})" in report and os.path.getsize(os.path.join(folder, png)) > 1000, png
# the film: one picture per frame of the run's output
from PIL import Image

film = Image.open(os.path.join(folder, "dig.gif"))
assert film.n_frames == len(frames("particles.pvd")) == 4, film.n_frames
assert film.size == (960, 600), film.size
assert "](dig.gif)" in report, "the report does not link the film"

print(f"dipper run output with rocks and the shovel: {summary['rocks']} rocks in {len(rock_frames)} frames, "
      f"{touched} dipper triangles touched, {len(rows)} probe rows: ok")

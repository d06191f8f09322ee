"""Reads dipper's wear outputs with independent readers and checks what they hold: the surface with VTK's
XML reader, the PNG with a decoder written here on Python's zlib, the CSVs with the csv module.
Usage: read_wear_output.py DIR  (DIR written by dipper_write_wear_sample)."""
import csv
import os
import struct
import sys
import zlib

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

# ---- the PNG: decode it and look at the colour bar and the map
def read_png(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, width = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        crc = struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])[0]
        assert zlib.crc32(kind + body) & 0xffffffff == crc, f"bad CRC in {kind}"
        if kind == b"IHDR":
            width, height, depth_bits, colour, _, _, _ = struct.unpack(">IIBBBBB", body)
            assert depth_bits == 8 and colour == 2
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * 3 + 1
    assert len(raw) == stride * height
    rows = []
    for y in range(height):
        assert raw[y * stride] == 0  # filter type none
        rows.append(raw[y * stride + 1:(y + 1) * stride])
    return width, height, lambda x, y: tuple(rows[y][3 * x:3 * x + 3])

width, height, pixel = read_png(os.path.join(folder, "plate_wear.png"))
assert width == 900, width
# colour bar: x = 20 + map_w + 20 .. + 30 with map_w = 900 - 40 - 30 - 150 = 680; its top is the ramp's top
bar_x = 20 + 680 + 20 + 15
column = [pixel(bar_x, y) for y in range(height)]
coloured = [c for c in column if c != (255, 255, 255) and c != (0, 0, 0)]
assert len(coloured) > 50, "no colour bar"
top, bottom = coloured[0], coloured[-1]
assert top[0] > 150 and top[2] < 30, f"top of the bar should be dark red, is {top}"
assert bottom[2] > 90 and bottom[0] < 30, f"bottom of the bar should be dark blue, is {bottom}"
black = sum(1 for y in range(height) for x in range(bar_x + 20, width) if pixel(x, y) == (0, 0, 0))
assert black > 200, "no tick labels"
map_pixels = [pixel(x, y) for y in range(0, height, 4) for x in range(20, 700, 4)]
assert sum(1 for c in map_pixels if c != (255, 255, 255)) > 0.5 * len(map_pixels) * 0.6, "map mostly empty"
assert len(set(map_pixels)) > 20, "the map has no colour variation"

# ---- CSVs
points = list(csv.DictReader(open(os.path.join(folder, "points.csv"))))
assert len(points) == 6
for p in points:
    assert abs(float(p["measured_mm_per_t"]) - 1.5 * float(p["simulated_mm_per_t"])) <= 1e-8 * float(p["measured_mm_per_t"]) + 1e-300
section = list(csv.DictReader(open(os.path.join(folder, "section_middle.csv"))))
assert sum(1 for r in section if r["kind"] == "simulated") == 39
assert sum(1 for r in section if r["kind"] == "measured") == 6
print(f"wear outputs read back: {poly.GetNumberOfPolys()} triangles, total {vtk_total:.4g} m^3, PNG {width}x{height}: ok")

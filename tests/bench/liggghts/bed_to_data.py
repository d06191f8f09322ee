#!/usr/bin/env python3
"""Writes a dipper_bench_bed cache (the settled bed) as a LIGGGHTS data file for bed.in.

The cache holds a 64-bit particle count, then per particle position, velocity and angular velocity
(nine little-endian doubles). All spheres are r = 0.1 m, 3700 kg/m3, in the 10 m x 5 m box.
Usage: bed_to_data.py CACHE DATA
"""
import struct
import sys


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: bed_to_data.py CACHE DATA")
    cache, data = sys.argv[1], sys.argv[2]
    with open(cache, "rb") as f:
        count = struct.unpack("<q", f.read(8))[0]
        rows = []
        for _ in range(count):
            chunk = f.read(72)
            if len(chunk) != 72:
                sys.exit("%s: truncated after %d of %d particles" % (cache, len(rows), count))
            rows.append(struct.unpack("<9d", chunk))
    top = max(r[2] for r in rows)
    with open(data, "w") as o:
        o.write("dipper_bench_bed settled bed\n\n%d atoms\n1 atom types\n\n" % count)
        o.write("0 10 xlo xhi\n0 5 ylo yhi\n0 %.6f zlo zhi\n\nAtoms\n\n" % (top + 1.0))
        for k, r in enumerate(rows):
            o.write("%d 1 0.2 3700 %.17g %.17g %.17g\n" % (k + 1, r[0], r[1], r[2]))
        o.write("\nVelocities\n\n")
        for k, r in enumerate(rows):
            o.write("%d %.17g %.17g %.17g %.17g %.17g %.17g\n" % ((k + 1,) + r[3:9]))


if __name__ == "__main__":
    main()

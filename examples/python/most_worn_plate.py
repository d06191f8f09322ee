#!/usr/bin/env python3
"""Which plate of the dipper wears most: reads a finished run's wear field from its checkpoint and ranks the
dipper's plates by mean wear rate (mm per tonne dug) and by worn volume.

    PYTHONPATH=build/python python3 examples/python/most_worn_plate.py out/loading_quick

The run must have a wear surface on the dipper (loading_quick.yaml, bucket_wear.yaml and the wear-bar sweeps have).
"""
import argparse
import sys

import numpy as np

import dipper


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run", help="a run folder with a checkpoint (out/loading_quick after scripts/demo.sh)")
    args = ap.parse_args()

    sim = dipper.Simulation.from_checkpoint(args.run)
    dippers = [w for w in sim.wear() if w.part == "dipper"]
    if not dippers:
        sys.exit(f"{args.run}: the run has no wear surface on the dipper")
    w = dippers[0]
    if not w.tonnage_t > 0:
        sys.exit(f"{args.run}: no material has been dug yet at t = {sim.time_s:.2f} s")

    # triangle areas, then each plate's area, worn volume and mean depth
    v = w.vertices_m[w.triangles]
    area = 0.5 * np.linalg.norm(np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]), axis=1)
    plates = len(w.plate_names)
    plate_area = np.bincount(w.triangle_plate, weights=area, minlength=plates)
    plate_volume = np.bincount(w.triangle_plate, weights=w.triangle_volume_m3, minlength=plates)
    worn = plate_area > 0
    rate_mm_per_t = np.where(worn, 1000.0 * plate_volume / np.where(worn, plate_area, 1.0) / w.tonnage_t, 0.0)

    print(f"{args.run}: t = {sim.time_s:.2f} s, {w.tonnage_t:.1f} t dug, wear law {w.law}, {1e6 * w.volume_m3:.3f} cm3 worn in all")
    print(f"{'plate':>14} {'area m2':>9} {'volume cm3':>11} {'mean mm/t':>11}")
    for k in np.argsort(-rate_mm_per_t):
        print(f"{w.plate_names[k]:>14} {plate_area[k]:9.2f} {1e6 * plate_volume[k]:11.4f} {rate_mm_per_t[k]:11.3e}")
    top = int(np.argmax(rate_mm_per_t))
    # where on it: the deepest triangle of that plate, in the world frame where the dipper stands now
    on_top = np.flatnonzero(w.triangle_plate == top)
    deepest = on_top[np.argmax(w.triangle_depth_m[on_top])]
    centre = v[deepest].mean(axis=0)
    world = w.rotation @ centre + np.asarray(w.origin_m)
    print(f"most worn: {w.plate_names[top]} ({rate_mm_per_t[top]:.3e} mm/t on average); its deepest element "
          f"{1000.0 * w.triangle_depth_m[deepest]:.3e} mm at {np.round(centre, 2).tolist()} m in the dipper's frame "
          f"({np.round(world, 2).tolist()} m in the world now)")


if __name__ == "__main__":
    main()

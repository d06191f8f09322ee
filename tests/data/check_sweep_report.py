"""Checks the sweep report of app/report.py on sweep tables made here: a parameter repeated over seeds gets a
table of the seeds' means and ranges and one figure; a single varied parameter keeps its figure and gets no
means table; a variant that did not complete (empty cells) is left out of the means.
Usage: check_sweep_report.py REPORT_PY DIR"""
import csv
import os
import shutil
import subprocess
import sys

report, folder = sys.argv[1], sys.argv[2]
shutil.rmtree(folder, ignore_errors=True)

columns = ["variant", "shovel.wear_bars", "seed", "status", "pass1_mass_kg", "pass1_mean_dig_force_N",
           "pass1_mean_interface_force_N", "wear_dipper_bottom_m3"]
# mass (kg), dig force (N), interface force (N), bottom wear (m3) per variant; seeds 7 and 8 per dipper
table = [("baseline", 7, "completed", 70000, 4.0e6, 2.0e6, 1.0e-6),
         ("baseline", 8, "completed", 74000, 4.4e6, 2.2e6, 1.2e-6),
         ("transverse", 7, "completed", 66000, 5.0e6, 2.5e6, 0.4e-6),
         ("transverse", 8, "failed", "", "", "", ""),
         ("diagonal", 7, "completed", 60000, 4.6e6, 2.1e6, 0.3e-6),
         ("diagonal", 8, "completed", 64000, 5.2e6, 2.3e6, 0.5e-6)]


def write(name, rows, header):
    path = os.path.join(folder, name)
    os.makedirs(path)
    with open(os.path.join(path, "sweep.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        for k, r in enumerate(rows):
            w.writerow([k] + list(r))
    subprocess.run([sys.executable, report, path], check=True, stdout=subprocess.DEVNULL)
    text = open(os.path.join(path, "sweep.md")).read()
    figure = os.path.join(path, "sweep.png")
    return text, figure


text, figure = write("seeds", table, columns)
assert os.path.getsize(figure) > 1000 and open(figure, "rb").read(8) == b"\x89PNG\r\n\x1a\n", "no figure"
lines = text.splitlines()
means = [l for l in lines if l.startswith("| baseline | 2 |") or l.startswith("| transverse | 2 |") or l.startswith("| diagonal | 2 |")]
assert len(means) == 3, text
# baseline: mass 72 t (70 to 74), dig force 4.2 MN (4 to 4.4), interface 2.1 MN, bottom wear 1.1 mm3 (1 to 1.2)
assert means[0] == "| baseline | 2 | 72 (70 to 74) | 4.2 (4 to 4.4) | 2.1 (2 to 2.2) | 1100 (1000 to 1200) |", means[0]
# transverse: the failed seed is left out of the mean
assert means[1] == "| transverse | 2 | 66 (66 to 66) | 5 (5 to 5) | 2.5 (2.5 to 2.5) | 400 (400 to 400) |", means[1]
assert means[2] == "| diagonal | 2 | 62 (60 to 64) | 4.9 (4.6 to 5.2) | 2.2 (2.1 to 2.3) | 400 (300 to 500) |", means[2]
assert "Over the seeds (7, 8)" in text, text

# one varied parameter, the others fixed: a figure against it and no means table
single = [("baseline", 7, "completed", 70000, 4.0e6, 2.0e6, 1.0e-6),
          ("transverse", 7, "completed", 66000, 5.0e6, 2.5e6, 0.4e-6)]
text, figure = write("single", single, columns)
assert os.path.exists(figure), "no figure for one varied parameter"
assert "Over the seeds" not in text, text

# two parameters varied besides the seed: no figure to draw, the table only
double = [("baseline", 7, "completed", 70000, 4.0e6, 2.0e6, 1.0e-6),
          ("transverse", 8, "completed", 66000, 5.0e6, 2.5e6, 0.4e-6)]
text, figure = write("double", double, ["variant", "shovel.wear_bars", "shovel.rake_angle_deg", "status", "pass1_mass_kg",
                                        "pass1_mean_dig_force_N", "pass1_mean_interface_force_N", "wear_dipper_bottom_m3"])
assert not os.path.exists(figure), "a figure for two varied parameters"
print("sweep report: ok")

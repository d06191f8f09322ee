"""Writes DIR/report.md and its PNG figures from what `dipper run` left in DIR (summary.json, probes.csv).
Usage: python3 report.py DIR"""
import csv
import json
import os
import sys

folder = sys.argv[1]
summary = json.load(open(os.path.join(folder, "summary.json")))
with open(os.path.join(folder, "probes.csv")) as f:
    rows = list(csv.DictReader(f))
columns = list(rows[0].keys()) if rows else []
series = {c: [float(r[c]) for r in rows] for c in columns}
t = series.get("time_s", [])

figures = []
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    def figure(name, title, ylabel, curves, log=False):
        fig, ax = plt.subplots(figsize=(7, 3.6), dpi=110)
        for label, values in curves:
            ax.plot(t, values, label=label, linewidth=1.2)
        ax.set_xlabel("time [s]")
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        if log:
            ax.set_yscale("log")
        ax.grid(True, alpha=0.3)
        if len(curves) > 1:
            ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(folder, name))
        plt.close(fig)
        figures.append((title, name))

    if t:
        figure("kinetic_energy.png", "Kinetic energy of the particles", "kinetic energy [J]",
               [("kinetic energy", [max(v, 1e-12) if v == v else float("nan") for v in series["kinetic_energy_J"]])],
               log=True)
        walls = sorted({c[len("force_"):-len("_z_N")] for c in columns if c.startswith("force_") and c.endswith("_z_N")})
        figure("wall_forces.png", "Force of the particles on each wall (magnitude)", "force [kN]",
               [(w, [(series[f"force_{w}_x_N"][k] ** 2 + series[f"force_{w}_y_N"][k] ** 2 +
                      series[f"force_{w}_z_N"][k] ** 2) ** 0.5 / 1000.0 for k in range(len(t))]) for w in walls])
        regions = [c for c in columns if c.endswith("_mass_kg") and c != "mass_kg"]
        figure("mass.png", "Particle mass in the world and in probe regions", "mass [t]",
               [("all particles", [v / 1000.0 for v in series["mass_kg"]])] +
               [(c[:-len("_mass_kg")], [v / 1000.0 for v in series[c]]) for c in regions])
    note = ""
except ImportError:
    note = "matplotlib is not installed (Debian: python3-matplotlib), so this report has no figures.\n"

def g(value, scale=1.0):
    """A number of summary.json for the table; a diverged run may have left some as null."""
    return "not finite" if value is None else f"{value * scale:.4g}"


lines = [f"# {summary['name']}: {summary['status']}", ""]
if summary.get("message"):
    lines += [f"> {summary['message']}", ""]
lines += ["| quantity | value |", "| --- | --- |",
          f"| simulated time | {summary['time_s']:.6g} s of {summary['duration_s']:.6g} s |",
          f"| steps | {summary['steps']} of {summary['step_s']:.4g} s |",
          f"| particles | {summary['particles']} ({g(summary['mass_kg'], 1e-3)} t) |",
          f"| kinetic energy at the end | {g(summary['kinetic_energy_J'])} J |",
          f"| threads, wall-clock time | {summary['threads']}, {summary['wall_clock_s']:.4g} s |",
          f"| particle-steps per second | {summary['particle_steps_per_s']:.4g} |"]
for wall, f in summary["wall_forces_N"].items():
    lines.append(f"| force on {wall} | ({g(f[0], 1e-3)}, {g(f[1], 1e-3)}, {g(f[2], 1e-3)}) kN |")
for region, m in summary["region_mass_kg"].items():
    lines.append(f"| mass in {region} | {g(m)} kg |")
lines.append("")
if note:
    lines += [note]
for title, name in figures:
    lines += [f"## {title}", "", f"![{title}]({name})", ""]
lines += ["ParaView: open `particles.pvd` (glyph the points by `radius_m`) and the `wall_*.pvd` series.", ""]
with open(os.path.join(folder, "report.md"), "w") as f:
    f.write("\n".join(lines))
print(f"report: {os.path.join(folder, 'report.md')} with {len(figures)} figures")

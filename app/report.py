"""Writes DIR/report.md and its PNG figures from what `dipper run` left in DIR (summary.json, probes.csv),
or DIR/sweep.md and sweep.png from what `dipper sweep` left there (sweep.csv).
Usage: python3 report.py DIR"""
import csv
import json
import math
import os
import re
import subprocess
import sys
import textwrap

folder = sys.argv[1]


def wear_views(run_folder, vmax=None):
    """Draws the 3-D wear views of a run folder with render.py in a child process (a VTK window that loses its
    display aborts its process). Returns ([(title, file name)], why none were drawn or "")."""
    render = os.path.join(os.path.dirname(os.path.abspath(__file__)), "render.py")
    command = [sys.executable, render, "wear", run_folder] + (["--vmax", repr(vmax)] if vmax else [])
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=900)
    except (OSError, subprocess.TimeoutExpired) as e:
        return [], str(e)
    if done.returncode != 0:
        lines = [l for l in done.stderr.strip().splitlines() if l.strip()]
        return [], lines[-1] if lines else f"render.py returned {done.returncode}"
    return [tuple(p) for p in json.loads(done.stdout.strip().splitlines()[-1])], ""


def make_film(run_folder):
    """The run's frames as a film (render.py film, in a child process). Returns (what render.py wrote, why
    there is no film or ""); runs with fewer than two frames get none and no reason."""
    pvd = os.path.join(run_folder, "particles.pvd")
    if not os.path.exists(pvd) or open(pvd).read().count("<DataSet") < 2:
        return None, ""
    render = os.path.join(os.path.dirname(os.path.abspath(__file__)), "render.py")
    try:
        done = subprocess.run([sys.executable, render, "film", run_folder], capture_output=True, text=True, timeout=3600)
    except (OSError, subprocess.TimeoutExpired) as e:
        return None, str(e)
    if done.returncode != 0:
        lines = [l for l in done.stderr.strip().splitlines() if l.strip()]
        return None, lines[-1] if lines else f"render.py returned {done.returncode}"
    film = json.loads(done.stdout.strip().splitlines()[-1])
    film["key_frames"] = [tuple(k) for k in film["key_frames"]]
    return film, ""


def last_frame(run_folder, series):
    """The VTK file of a .pvd series' last frame, read with VTK; None without the series or VTK."""
    path = os.path.join(run_folder, series)
    if not os.path.exists(path):
        return None
    try:
        import vtk
        import xml.etree.ElementTree as ET
    except ImportError:
        return None
    frames = ET.parse(path).getroot().findall("./Collection/DataSet")
    if not frames:
        return None
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(os.path.join(run_folder, frames[-1].get("file")))
    reader.Update()
    return reader.GetOutput()


def wear_maximum(run_folder):
    """The top of a run folder's wear colour scale as render.py sets it (render.wear_maximum); 0 when there
    is no wear surface or VTK is missing."""
    try:
        sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
        import render
    except ImportError:
        return 0.0
    finally:
        sys.path.pop(0)
    return render.wear_maximum(run_folder)


def sweep_report(folder):
    """A sweep folder: sweep.md with the table, and when one parameter varies (besides `seed`) sweep.png of the
    first pass's mass, dig and interface force and the dipper bottom's wear (or the repose angle, or the final
    mass) against it. With several seeds per value, sweep.md also gets the seeds' means and ranges and the
    figure shows each seed and the mean."""
    with open(os.path.join(folder, "sweep.csv")) as f:
        rows = list(csv.DictReader(f))
    columns = list(rows[0].keys()) if rows else []
    parameters = columns[1:columns.index("status")] if "status" in columns else []
    shown = parameters + [c for c in ("status", "pass1_mass_kg", "pass1_fill_factor", "pass1_mean_dig_force_N",
                                      "pass1_mean_interface_force_N", "pass1_mean_interface_force_without_lip_N", "repose_angle_deg", "wear_dipper_m3", "wear_dipper_bottom_m3", "wear_dipper_bars_m3", "mass_kg")
                          if c in columns]
    lines = [f"# Sweep: {os.path.basename(os.path.abspath(folder))}", "", "| " + " | ".join(shown) + " |",
             "|" + " --- |" * len(shown)]
    for r in rows:
        lines.append("| " + " | ".join(r[c] for c in shown) + " |")
    lines.append("")

    def number(text):
        try:
            return float(text)
        except ValueError:
            return float("nan")  # a variant that did not complete leaves its cells empty

    quantities = [("pass1_mass_kg", "mass in the dipper, pass 1 [t]", 1e-3),
                  ("pass1_mean_dig_force_N", "mean dig force, pass 1 [MN]", 1e-6),
                  ("pass1_mean_interface_force_N", "mean interface force, pass 1 [MN]", 1e-6),
                  ("pass1_mean_interface_force_without_lip_N", "the same without the lip, pass 1 [MN]", 1e-6),
                  ("wear_dipper_bottom_m3", "wear of the dipper's bottom [mm3]", 1e9)]
    quantities = ([q for q in quantities if q[0] in columns] or
                  ([("repose_angle_deg", "angle of repose [deg]", 1.0)] if "repose_angle_deg" in columns else []) or
                  [("mass_kg", "mass [t]", 1e-3)])
    quantities = [q for q in quantities if q[0] in columns]  # a table with none of them gets no figure
    # the parameter the figure is drawn against: the one that varies, seeds being repeats of each value
    varied = [p for p in parameters if len({r[p] for r in rows}) > 1]
    seeds = "seed" in varied and len(varied) > 1
    axis = [p for p in varied if p != "seed"] if seeds else varied
    groups = {}  # value of the axis parameter -> its rows, in the sweep's order
    if len(axis) == 1:
        for r in rows:
            groups.setdefault(r[axis[0]], []).append(r)
    if seeds and groups:
        key = axis[0]
        lines += [f"Over the seeds ({', '.join(sorted({r['seed'] for r in rows}, key=number))}): mean (lowest to highest)", "",
                  "| " + " | ".join([key, "variants"] + [q[1] for q in quantities]) + " |",
                  "|" + " --- |" * (2 + len(quantities))]
        for value, members in groups.items():
            cells = [value, str(len(members))]
            for column, _, scale in quantities:
                ys = [number(m[column]) * scale for m in members]
                ys = [y for y in ys if y == y]
                cells.append(f"{sum(ys) / len(ys):.4g} ({min(ys):.4g} to {max(ys):.4g})" if ys else "-")
            lines.append("| " + " | ".join(cells) + " |")
        lines.append("")
    figures = 0
    if groups and quantities:
        try:
            import matplotlib

            matplotlib.use("Agg")
            import matplotlib.pyplot as plt

            key = axis[0]
            labels = list(groups.keys())

            def position(label):
                text = label.strip("[] ")
                try:
                    return float(text.split(",")[0])  # a number, or the first component of a vector
                except ValueError:
                    return None

            xs = [position(l) for l in labels]
            categorical = any(x is None for x in xs)
            if categorical:
                xs = list(range(len(labels)))
            fig, axes = plt.subplots(1, len(quantities), figsize=(4.2 * len(quantities), 3.4), dpi=110)
            axes = axes if len(quantities) > 1 else [axes]
            for ax, (column, label, scale) in zip(axes, quantities):
                means = []
                for x, value in zip(xs, labels):
                    ys = [number(m[column]) * scale for m in groups[value]]
                    done = [y for y in ys if y == y]
                    means.append(sum(done) / len(done) if done else float("nan"))
                    if seeds:
                        ax.plot([x] * len(ys), ys, "o", color="0.6", markersize=4,
                                label="one seed" if x == xs[0] else None)
                ax.plot(xs, means, "o-", color="tab:blue", label="mean of the seeds" if seeds else None)
                ax.set_xlabel(key)
                ax.set_ylabel(label)
                if categorical:
                    ax.set_xticks(xs)
                    ax.set_xticklabels(labels)
                ax.grid(True, alpha=0.3)
                if seeds and ax is axes[0]:
                    ax.legend(fontsize=8)
            fig.tight_layout()
            fig.savefig(os.path.join(folder, "sweep.png"))
            plt.close(fig)
            lines += ["![sweep](sweep.png)", ""]
            figures = 1
        except ImportError:
            lines += ["matplotlib is not installed (Debian: python3-matplotlib), so this report has no figure.", ""]
    # the variants' wear views drawn again on one colour scale, so that they compare at a glance
    runs = [(os.path.join(folder, f"variant_{int(r['variant']):03d}"), r) for r in rows if r.get("variant", "").isdigit()]
    runs = [(d, r) for d, r in runs if os.path.isdir(d)]
    top = max([wear_maximum(d) for d, _ in runs] + [0.0])
    if top > 0.0:
        lines += [f"## Wear views on one colour scale (0 to {top:.3g} mm/t)", ""]
        for r, row in runs:
            views, why = wear_views(r, top)
            label = ", ".join(f"{p} = {row[p]}" for p in parameters)
            if why:
                lines += [f"variant {row['variant']} ({label}): no wear views ({why})", ""]
                continue
            lines += [f"variant {row['variant']} ({label}):", ""] + \
                     [f"![{title}]({os.path.basename(r)}/{name})" for title, name in views] + [""]
    with open(os.path.join(folder, "sweep.md"), "w") as f:
        f.write("\n".join(lines))
    print(f"report: {os.path.join(folder, 'sweep.md')} with {figures} figure{'s' if figures != 1 else ''}")


if not os.path.exists(os.path.join(folder, "summary.json")) and os.path.exists(os.path.join(folder, "sweep.csv")):
    sweep_report(folder)
    sys.exit(0)
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
        ax.set_title(textwrap.fill(title, 64), fontsize=10)  # long titles wrap instead of running off the figure
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
               [(c[:-len("_mass_kg")], [v / 1000.0 for v in series[c]]) for c in regions
                if c != "bucket_mass_kg"])
        if "dig_force_N" in series:
            figure("dig_force.png", "Drive forces of the shovel (moving average) and the material's force on the dipper",
                   "force [MN]",
                   [(label, [v / 1e6 for v in series[c]]) for label, c in
                    (("dig force (eq. 11)", "dig_force_N"), ("hoist", "hoist_force_N"), ("crowd", "crowd_force_N"),
                     ("interface force on dipper and door", "interface_force_N"),
                     ("the same without the lip (thesis Fig. 19)", "interface_force_without_lip_N")) if c in series])
            fig, ax = plt.subplots(figsize=(7, 3.6), dpi=110)
            ax.plot(t, [v / 1000.0 for v in series["bucket_mass_kg"]], linewidth=1.2, color="tab:blue")
            ax.set_xlabel("time [s]")
            ax.set_ylabel("mass in the dipper [t]")
            ax.grid(True, alpha=0.3)
            # the fill factor is the mass over a constant (bulk density x struck volume): a second scale
            ratios = [f / (m / 1000.0) for m, f in zip(series["bucket_mass_kg"], series["fill_factor"]) if m > 0]
            if ratios:
                k = ratios[0]
                right = ax.secondary_yaxis("right", functions=(lambda m: m * k, lambda f: f / k))
                right.set_ylabel("fill factor")
            ax.set_title("Material in the dipper")
            fig.tight_layout()
            fig.savefig(os.path.join(folder, "bucket.png"))
            plt.close(fig)
            figures.append(("Material in the dipper", "bucket.png"))
        passes = summary.get("passes", [])
        if passes:
            # the thesis' loading of the same shovel and ore (Paper A, full-size model): 85, 80 and 68 t in
            # passes 1 to 3; beside any run that loads (not the wear cycle, which empties over the pile)
            thesis = [85.0, 80.0, 68.0]
            loads = True
            try:
                import yaml

                with open(os.path.join(folder, "scenario.yaml")) as f:
                    given = yaml.safe_load(f) or {}
                loads = (given.get("shovel") or {}).get("motion", "swing") != "dig_and_return"
            except (ImportError, OSError):
                pass  # without PyYAML or the scenario's copy: drawn beside the thesis' passes
            number = [p["pass"] for p in passes]
            fig, ax = plt.subplots(figsize=(6.4, 3.6), dpi=110)
            width = 0.38 if loads else 0.7
            ax.bar([k - (width / 2 if loads else 0) for k in number], [p["mass_kg"] / 1000.0 for p in passes],
                   width=width, color="tab:brown", label="this run")
            if loads:
                shown = [k for k in number if k <= len(thesis)] or [1]
                ax.bar([k + width / 2 for k in shown], [thesis[k - 1] for k in shown], width=width, color="0.65",
                       label="thesis, full-size model (Paper A)")
                for k in shown:
                    ax.annotate(f"{thesis[k - 1]:.0f} t", (k + width / 2, thesis[k - 1]), ha="center", va="bottom", fontsize=8)
                ax.legend(fontsize=8, loc="upper left", ncol=2)
            for k, p in zip(number, passes):
                ax.annotate(f"{p['mass_kg'] / 1000.0:.1f} t", (k - (width / 2 if loads else 0), p["mass_kg"] / 1000.0),
                            ha="center", va="bottom", fontsize=8)
            ax.set_xlabel("pass")
            ax.set_ylabel("mass when the door opened [t]")
            ax.set_xticks(number)
            ax.set_xlim(min(number) - 0.6, max(number) + 0.6)
            ax.set_ylim(0, 1.3 * max([p["mass_kg"] / 1000.0 for p in passes] + (thesis if loads else [])))
            ax.set_title("Mass per pass")
            ax.grid(True, axis="y", alpha=0.3)
            fig.tight_layout()
            fig.savefig(os.path.join(folder, "mass_per_pass.png"))
            plt.close(fig)
            figures.append(("Mass per pass", "mass_per_pass.png"))
    fit = summary.get("repose_fit")
    if fit:
        # the pile's surface as the repose probe read it at the end, and the line fitted to its slope
        along, surface, fitted = fit["bin_centre_m"], fit["surface_m"], fit["fitted"]
        fig, ax = plt.subplots(figsize=(8, 4.4), dpi=110)
        # the pile itself at the end, seen across the slope: each sphere as a circle of its radius, each rock's
        # hull as its faces
        axis = "xyz".index(fit["along"])
        particles = last_frame(folder, "particles.pvd")
        if particles is not None and particles.GetNumberOfPoints():
            from matplotlib.collections import EllipseCollection, PolyCollection
            from vtk.util.numpy_support import vtk_to_numpy

            x = vtk_to_numpy(particles.GetPoints().GetData())
            r = vtk_to_numpy(particles.GetPointData().GetArray("radius_m"))
            ax.add_collection(EllipseCollection(2 * r, 2 * r, 0.0, units="xy", offsets=list(zip(x[:, axis], x[:, 2])),
                                                transOffset=ax.transData, facecolors="0.78", edgecolors="0.55",
                                                linewidths=0.2))
            rocks = last_frame(folder, "rocks.pvd")
            if rocks is not None and rocks.GetNumberOfPolys():
                corners = vtk_to_numpy(rocks.GetPoints().GetData())
                faces = vtk_to_numpy(rocks.GetPolys().GetConnectivityArray()).reshape(-1, 3)
                ax.add_collection(PolyCollection(corners[faces][:, :, [axis, 2]], facecolors="0.62", edgecolors="none"))
            ax.autoscale_view()
        ax.plot([s for s, f in zip(along, fitted) if not f], [z for z, f in zip(surface, fitted) if not f], "o",
                markersize=3, color="0.6", label="top of a bin, off the slope")
        ax.plot([s for s, f in zip(along, fitted) if f], [z for z, f in zip(surface, fitted) if f], "o",
                markersize=3, color="tab:brown", label="top of a bin on the slope (fitted)")
        ends = [min(s for s, f in zip(along, fitted) if f), max(s for s, f in zip(along, fitted) if f)]
        ax.plot(ends, [fit["intercept_m"] + fit["slope"] * s for s in ends], color="tab:blue", linewidth=1.5,
                label=f"fitted line: {summary['repose_angle_deg']:.1f}°")
        # the thesis' calibration pile (Paper A Fig. 12: 34.8°, from which its muck pile was cut), through the
        # middle of the fitted line and falling the same way
        middle = sum(ends) / 2.0
        z_middle = fit["intercept_m"] + fit["slope"] * middle
        thesis_slope = math.copysign(math.tan(math.radians(34.8)), fit["slope"])
        ax.plot(ends, [z_middle + thesis_slope * (s - middle) for s in ends], "--", color="tab:red", linewidth=1.2,
                label="the thesis' pile: 34.8°")
        ax.set_xlabel(f"{fit['along']} [m]")
        ax.set_ylabel("surface height [m]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
        ax.set_title("The pile at the end, its surface and the angle of repose")
        fig.tight_layout()
        fig.savefig(os.path.join(folder, "repose.png"))
        plt.close(fig)
        figures.append(("The pile at the end, its surface and the angle of repose", "repose.png"))
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
if "repose_angle_deg" in summary:
    fit = summary.get("repose_fit")
    if fit:
        lines.append(f"| angle of repose | {g(summary['repose_angle_deg'])}° (line through {sum(fit['fitted'])} bins, "
                     f"rms residual {g(fit['rms_residual_m'])} m) |")
    else:
        lines.append("| angle of repose | none: no pile slope in the probe's window |")
if "passes" in summary:
    lines += ["", "| pass | dig phase [s] | mass when the door opened [t] | fill factor | mean dig force over the dig [MN] | peak [MN] "
              "| mean interface force over the dig [MN] | peak [MN] | mean without the lip [MN] | peak [MN] |",
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for p in summary["passes"]:
        lines.append(f"| {p['pass']} | {g(p.get('dig_start_s', p['start_s']))} to {g(p['dig_end_s'])} | {g(p['mass_kg'], 1e-3)} | "
                     f"{g(p['fill_factor'])} | {g(p['mean_dig_force_N'], 1e-6)} | {g(p['peak_dig_force_N'], 1e-6)} | "
                     f"{g(p['mean_interface_force_N'], 1e-6) if 'mean_interface_force_N' in p else '–'} | "
                     f"{g(p['peak_interface_force_N'], 1e-6) if 'peak_interface_force_N' in p else '–'} | "
                     f"{g(p['mean_interface_force_without_lip_N'], 1e-6) if 'mean_interface_force_without_lip_N' in p else '–'} | "
                     f"{g(p['peak_interface_force_without_lip_N'], 1e-6) if 'peak_interface_force_without_lip_N' in p else '–'} |")
    if not summary["passes"]:
        lines.append("| (no dump yet) | | | | | | | | | |")
    lines += ["", "Dig force: sqrt(F_crowd² + F_hoist²) of the drives (thesis eq. 11). Interface force: the resultant of the "
              "material's force on dipper and door; without the lip: the same less the force on the lip and its teeth, what thesis Paper B "
              "Fig. 19 plots (\"acting on the bucket (excluding lip)\")."]
for part, w in summary.get("wear", {}).items():
    lines += ["", f"Wear of {part} ({w['law']}, constant {g(w['constant'])}): volume {g(w['volume_m3'])} m³, "
              f"deepest {g(w['max_depth_mm'])} mm."]
    m = w.get("measured")
    points_csv = os.path.join(folder, f"wear_{part}_points.csv")
    if m:
        lines += ["", f"Measured at {m['points']} points: mean {g(m['mean_measured_mm_per_t'])} mm/t against "
                  f"{g(m['mean_simulated_mm_per_t'])} mm/t simulated (correlation {g(m['correlation'])}); the constant that "
                  f"makes the means agree is {g(m['calibrated_constant'])} ({g(m['calibrated_constant_low'])} to "
                  f"{g(m['calibrated_constant_high'])} within the gauge and position uncertainty), {g(m['scale'])} times "
                  f"the one used. Per point: `wear_{part}_points.csv`."]
        if os.path.exists(points_csv) and note == "":
            with open(points_csv) as f:
                pts = list(csv.DictReader(f))
            measured = [float(p["measured_mm_per_t"]) for p in pts]
            simulated = [float(p["simulated_mm_per_t"]) for p in pts]
            fig, ax = plt.subplots(figsize=(4.6, 4.2), dpi=110)
            ax.plot(measured, simulated, "o", label=f"constant {g(w['constant'])}")
            ax.plot(measured, [x * m["scale"] for x in simulated], "s", label=f"calibrated {g(m['calibrated_constant'])}")
            top = max(measured + [x * m["scale"] for x in simulated]) * 1.1
            ax.plot([0, top], [0, top], "k--", linewidth=0.8)
            ax.set_xlabel("measured wear rate [mm/t]")
            ax.set_ylabel("simulated wear rate [mm/t]")
            ax.set_title(f"Measured and simulated wear: {part}")
            ax.legend(fontsize=8)
            ax.grid(True, alpha=0.3)
            fig.tight_layout()
            fig.savefig(os.path.join(folder, f"wear_{part}_measured.png"))
            plt.close(fig)
            figures.append((f"Measured and simulated wear of {part}", f"wear_{part}_measured.png"))
    sections = w.get("sections", {})
    if sections:
        lines += ["", "| section | samples | mean simulated [mm/t] | highest [mm/t] | measured points | their mean [mm/t] | simulated there [mm/t] |",
                  "| --- | --- | --- | --- | --- | --- | --- |"]
        for name, sec in sections.items():
            lines.append(f"| {name} | {sec['samples']} | {g(sec['mean_simulated_mm_per_t'])} | {g(sec['max_simulated_mm_per_t'])} | "
                         f"{sec['measured_points']} | {g(sec.get('mean_measured_mm_per_t')) if 'mean_measured_mm_per_t' in sec else '–'} | "
                         f"{g(sec.get('mean_simulated_at_points_mm_per_t')) if 'mean_simulated_at_points_mm_per_t' in sec else '–'} |")
        if note == "":
            scale = m["scale"] if m else None
            fig, axes = plt.subplots(len(sections), 1, figsize=(6.4, 2.3 * len(sections) + 0.6), dpi=110, squeeze=False)
            for ax, name in zip(axes[:, 0], sections):
                with open(os.path.join(folder, f"wear_{part}_section_{name}.csv")) as f:
                    rows = list(csv.DictReader(f))
                sim = [r for r in rows if r["kind"] == "simulated"]
                mea = [r for r in rows if r["kind"] == "measured"]
                s_arc = [float(r["arc_length_m"]) for r in sim]
                s_rate = [float(r["simulated_mm_per_t"]) for r in sim]
                ax.plot(s_arc, s_rate, "-", label=f"simulated, constant {g(w['constant'])}")
                if scale:
                    ax.plot(s_arc, [x * scale for x in s_rate], "--", label=f"simulated, calibrated {g(m['calibrated_constant'])}")
                if mea:
                    ax.plot([float(r["arc_length_m"]) for r in mea], [float(r["measured_mm_per_t"]) for r in mea], "ko", label="measured")
                ax.set_title(f"section {name}", fontsize=9)
                ax.set_ylabel("wear rate [mm/t]")
                ax.grid(True, alpha=0.3)
            axes[-1, 0].set_xlabel("distance along the section [m]")
            axes[0, 0].legend(fontsize=7)
            fig.tight_layout()
            fig.savefig(os.path.join(folder, f"wear_{part}_sections.png"))
            plt.close(fig)
            figures.append((f"Wear rate of {part} along its sections", f"wear_{part}_sections.png"))
views, why = wear_views(folder) if summary.get("wear") else ([], "")
figures += views
if why:
    note += f"The 3-D wear views could not be drawn: {why}\n"
film, why = make_film(folder)
if film:
    figures += film["key_frames"]
if why:
    note += f"The film of the run could not be made: {why}\n"
lines.append("")
if note:
    lines += [note]
for title, name in figures:
    lines += [f"## {title}", "", f"![{title}]({name})", ""]
if film:
    lines += [f"The dig as a film: [`{film['film']}`]({film['film']}) ({film['frames']} frames, spheres and rocks "
              "coloured by speed, the dig force with the time marked).", ""]
lines += ["ParaView: open `particles.pvd` (glyph the points by `radius_m`), the `wall_*.pvd` series, and where present "
          "`rocks.pvd` and `wear_*.pvd` (fields depth_mm, rate_mm_per_t, mean_normal_force_N).", ""]
with open(os.path.join(folder, "report.md"), "w") as f:
    f.write("\n".join(lines))
print(f"report: {os.path.join(folder, 'report.md')} with {len(figures)} figures")

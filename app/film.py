"""The dig as a film: every frame of a run's VTK output (spheres and rocks coloured by speed, the machine's
meshes) with its time and the dig force as an inset, written as an animated GIF (DIR/dig.gif), and the frames
of the first pass's start of dig, end of dig and door opening as PNGs. Run through `render.py film DIR`."""
import json
import os

import numpy as np

from render import BACKGROUND, read_csv, read_polydata


def series_frames(folder, pvd):
    """[(time, file)] of a .pvd series; [] without it."""
    import xml.etree.ElementTree as ET

    path = os.path.join(folder, pvd)
    if not os.path.exists(path):
        return []
    return [(float(d.get("timestep")), d.get("file")) for d in ET.parse(path).getroot().findall("./Collection/DataSet")]


FILM_WIDTH, FILM_HEIGHT = 960, 600
SPEED_TOP = 4.0  # m/s: the top of the film's speed colours (digging is slower, free fall after the dump faster)


def film(folder, every=1):
    """Renders every `every`-th frame of the run in `folder` into dig.gif, and the frames nearest the first
    pass's start of dig, end of dig (bucket full) and door opening into film_<moment>.png. Returns
    {"film": name, "frames": count, "key_frames": [(title, name)]}."""
    import vtk
    from PIL import Image, ImageDraw
    from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy

    frames = series_frames(folder, "particles.pvd")[::every]
    if not frames:
        raise RuntimeError(f"{folder}: no particles.pvd, nothing to film")
    walls = {name[len("wall_"):-len(".pvd")]: dict(series_frames(folder, name))
             for name in sorted(os.listdir(folder)) if name.startswith("wall_") and name.endswith(".pvd")}
    rocks = dict(series_frames(folder, "rocks.pvd"))
    summary_path = os.path.join(folder, "summary.json")
    summary = json.load(open(summary_path)) if os.path.exists(summary_path) else {}

    def read(file):
        return read_polydata(os.path.join(folder, file)) if file else None

    # what moves: a wall whose points differ between its first and last frames
    moving = {}
    for name, by_time in walls.items():
        files = list(by_time.values())
        first, last = read(files[0]), read(files[-1])
        moving[name] = not np.array_equal(vtk_to_numpy(first.GetPoints().GetData()), vtk_to_numpy(last.GetPoints().GetData()))

    # one camera for the whole film, from the side of the dig (-y), a little above, holding the material
    # and the machine at the first and the last frame
    boxes = []
    for t, file in (frames[0], frames[-1]):
        poly = read(file)
        if poly.GetNumberOfPoints():
            boxes.append(np.array(poly.GetBounds()))
        for name, by_time in walls.items():
            if moving[name]:
                boxes.append(np.array(read(by_time.get(t) or list(by_time.values())[-1]).GetBounds()))
    lo = np.min([b[0::2] for b in boxes], axis=0)
    hi = np.max([b[1::2] for b in boxes], axis=0)

    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(FILM_WIDTH, FILM_HEIGHT)
    window.SetMultiSamples(0)
    renderer = vtk.vtkRenderer()
    renderer.SetBackground(*BACKGROUND)
    renderer.SetBackground2(0.98, 0.98, 0.99)
    renderer.GradientBackgroundOn()
    window.AddRenderer(renderer)
    camera = renderer.GetActiveCamera()
    centre = (lo + hi) / 2.0
    size = float(np.linalg.norm(hi - lo))
    direction = np.array([0.25, -1.0, 0.45])
    direction /= np.linalg.norm(direction)
    camera.SetFocalPoint(*centre)
    camera.SetPosition(*(centre + direction * 3.0 * size))
    camera.SetViewUp(0.0, 0.0, 1.0)
    camera.SetViewAngle(30.0)
    renderer.ResetCamera(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])
    camera.Zoom(1.45)

    from matplotlib import colormaps

    speed_table = vtk.vtkLookupTable()
    speed_table.SetNumberOfTableValues(256)
    speed_table.SetRange(0.0, SPEED_TOP)
    cmap = colormaps["viridis"]
    for k in range(256):
        r, g, b, _ = cmap(k / 255.0)
        speed_table.SetTableValue(k, r, g, b, 1.0)
    speed_table.Build()
    ball = vtk.vtkSphereSource()
    ball.SetRadius(1.0)
    ball.SetThetaResolution(10)
    ball.SetPhiResolution(8)
    glyphs = vtk.vtkGlyph3D()
    glyphs.SetSourceConnection(ball.GetOutputPort())
    glyphs.SetScaleModeToScaleByScalar()
    glyphs.SetScaleFactor(1.0)
    glyphs.SetColorModeToColorByScalar()
    glyph_mapper = vtk.vtkPolyDataMapper()
    glyph_mapper.SetInputConnection(glyphs.GetOutputPort())
    glyph_mapper.SetLookupTable(speed_table)
    glyph_mapper.UseLookupTableScalarRangeOn()
    glyph_mapper.SetScalarModeToUsePointFieldData()
    glyph_mapper.SelectColorArray("speed_m_per_s")
    spheres = vtk.vtkActor()
    spheres.SetMapper(glyph_mapper)
    renderer.AddActor(spheres)

    rock_mapper = vtk.vtkPolyDataMapper()
    rock_mapper.SetLookupTable(speed_table)
    rock_mapper.UseLookupTableScalarRangeOn()
    rock_mapper.SetScalarModeToUseCellFieldData()
    rock_mapper.SelectColorArray("speed_m_per_s")
    rock_actor = vtk.vtkActor()
    rock_actor.SetMapper(rock_mapper)
    rock_actor.GetProperty().SetEdgeVisibility(False)

    wall_actors = {}
    for name in walls:
        mapper = vtk.vtkPolyDataMapper()
        mapper.ScalarVisibilityOff()
        actor = vtk.vtkActor()
        actor.SetMapper(mapper)
        actor.GetProperty().SetColor(*((0.45, 0.47, 0.5) if moving[name] else (0.7, 0.72, 0.75)))
        actor.GetProperty().SetOpacity(1.0 if moving[name] else 0.18)
        actor.GetProperty().SetSpecular(0.3 if moving[name] else 0.0)
        renderer.AddActor(actor)
        wall_actors[name] = (actor, mapper)

    bar = vtk.vtkScalarBarActor()
    bar.SetLookupTable(speed_table)
    bar.SetTitle("speed [m/s]")
    bar.SetNumberOfLabels(5)
    bar.SetLabelFormat("%-#4.1f")
    bar.SetOrientationToHorizontal()
    bar.SetPosition(0.015, 0.78)
    bar.SetWidth(0.33)
    bar.SetHeight(0.15)
    bar.SetBarRatio(0.3)
    bar.SetTextPositionToPrecedeScalarBar()
    bar.UnconstrainedFontSizeOn()
    for prop, size_pt in ((bar.GetTitleTextProperty(), 14), (bar.GetLabelTextProperty(), 12)):
        prop.SetColor(0.0, 0.0, 0.0)
        prop.SetFontSize(size_pt)
        prop.SetShadow(False)
        prop.SetItalic(False)
    renderer.AddViewProp(bar)
    stamp = vtk.vtkTextActor()
    stamp.SetDisplayPosition(16, FILM_HEIGHT - 34)
    stamp.GetTextProperty().SetFontSize(20)
    stamp.GetTextProperty().SetBold(True)
    stamp.GetTextProperty().SetColor(0.0, 0.0, 0.0)
    renderer.AddViewProp(stamp)

    inset, to_pixel = dig_force_inset(folder)
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    pictures, times = [], []
    name = summary.get("name", os.path.basename(os.path.abspath(folder)))
    for t, file in frames:
        particles = read(file)
        if particles.GetNumberOfPoints():
            v = vtk_to_numpy(particles.GetPointData().GetArray("velocity_m_per_s"))
            speed = numpy_to_vtk(np.linalg.norm(v, axis=1), deep=True)
            speed.SetName("speed_m_per_s")
            particles.GetPointData().AddArray(speed)
            particles.GetPointData().SetActiveScalars("radius_m")
        glyphs.SetInputData(particles)
        for wall, by_time in walls.items():
            actor, mapper = wall_actors[wall]
            mapper.SetInputData(read(by_time.get(t)) if t in by_time else vtk.vtkPolyData())
        if t in rocks:
            rock_mapper.SetInputData(read(rocks[t]))
            if not renderer.HasViewProp(rock_actor):
                renderer.AddActor(rock_actor)
        stamp.SetInput(f"{name}   t = {t:5.1f} s")
        renderer.ResetCameraClippingRange()
        window.Render()
        grab.Modified()
        grab.Update()
        image = grab.GetOutput()
        w, h, _ = image.GetDimensions()
        rgb = vtk_to_numpy(image.GetPointData().GetScalars()).reshape(h, w, 3)[::-1]
        picture = Image.fromarray(np.ascontiguousarray(rgb))
        if inset is not None:
            picture.paste(inset, (FILM_WIDTH - inset.width - 10, 10))
            x = to_pixel(t)
            if x is not None:
                draw = ImageDraw.Draw(picture)
                top, bottom = to_pixel.rows
                draw.line([(FILM_WIDTH - inset.width - 10 + x, 10 + top), (FILM_WIDTH - inset.width - 10 + x, 10 + bottom)],
                          fill=(200, 30, 30), width=2)
        pictures.append(picture)
        times.append(t)
    window.Finalize()

    gif = "dig.gif"
    step_s = (times[-1] - times[0]) / max(1, len(times) - 1)
    # played at about 4 times real speed, at most 10 frames a second
    duration_ms = max(100, int(round(1000.0 * step_s / 4.0)))
    palette = [p.convert("P", palette=Image.ADAPTIVE, colors=256) for p in pictures]
    palette[0].save(os.path.join(folder, gif), save_all=True, append_images=palette[1:], duration=duration_ms, loop=0,
                    optimize=True)
    keys = []
    passes = summary.get("passes") or []
    if passes:
        first = passes[0]
        for moment, title, key in (("start_of_dig", "start of the dig", "dig_start_s"),
                                   ("bucket_full", "the dipper full (end of the dig)", "dig_end_s"),
                                   ("door_open", "the door open", "dump_s")):
            if first.get(key) is None:
                continue
            k = int(np.argmin([abs(t - first[key]) for t in times]))
            if key == "dump_s":  # the first frame after the door opened: the load falling
                later = [j for j, t in enumerate(times) if t >= first[key]]
                k = min(later[:2][-1:] or [k])
            file = f"film_{moment}.png"
            pictures[k].save(os.path.join(folder, file))
            keys.append((f"The dig at {times[k]:.1f} s: {title}", file))
    return {"film": gif, "frames": len(pictures), "key_frames": keys}


def dig_force_inset(folder):
    """A small plot of the dig force over the run (probes.csv), as a PIL image, and a map from time to its
    pixel column (None outside the plot; `.rows`: the plot's top and bottom rows). (None, None) without a
    dig force."""
    path = os.path.join(folder, "probes.csv")
    if not os.path.exists(path):
        return None, None
    rows = read_csv(path)
    if not rows or "dig_force_N" not in rows[0]:
        return None, None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from PIL import Image

    t = [float(r["time_s"]) for r in rows]
    force = [float(r["dig_force_N"]) / 1e6 for r in rows]
    fig, ax = plt.subplots(figsize=(3.3, 1.6), dpi=100)
    ax.plot(t, force, color="tab:blue", linewidth=1.0)
    ax.set_xlim(t[0], t[-1])
    ax.set_ylim(0, max(force + [1e-9]) * 1.1)
    ax.set_xlabel("time [s]", fontsize=8)
    ax.set_title("dig force [MN] (thesis eq. 11)", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(True, alpha=0.3)
    fig.patch.set_alpha(0.85)
    fig.tight_layout(pad=0.6)
    fig.canvas.draw()
    width, height = fig.canvas.get_width_height()
    image = Image.frombuffer("RGBA", (width, height), fig.canvas.buffer_rgba(), "raw", "RGBA", 0, 1).convert("RGB")
    box = ax.get_window_extent()  # pixels from the figure's lower left
    x0, x1, t0, t1 = box.x0, box.x1, t[0], t[-1]
    plt.close(fig)

    def to_pixel(time):
        if not (t0 <= time <= t1) or t1 <= t0:
            return None
        return x0 + (time - t0) / (t1 - t0) * (x1 - x0)

    to_pixel.rows = (height - box.y1, height - box.y0)
    return image, to_pixel

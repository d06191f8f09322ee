"""Pictures of a run drawn from its VTK files with VTK's renderer off screen: each wear surface as the shaded
3-D part coloured by wear rate (mm/t) or depth (mm), from three views, with a colour bar, the plates named,
a length scale, the axes of the part's frame and, where a calibration gave them, the measured points and the
sections.

The dig as a film: film.py beside this file.

Needs Debian's python3-vtk9, python3-numpy, python3-matplotlib and python3-pil; without a display it starts
its own Xvfb (Debian's xvfb).
Usage: python3 render.py wear DIR [--vmax V]    (draws every DIR/wear_<part>_final.vtp; prints what it wrote)
       python3 render.py film DIR               (DIR/dig.gif and DIR/film_<moment>.png; prints what it wrote)
A VTK render window that loses its display aborts the process, so the report runs this as a child process."""
import atexit
import csv
import json
import math
import os
import re
import subprocess
import sys

import numpy as np

WIDTH, HEIGHT = 1400, 1000
# the part is drawn in this box of the picture (pixels: left, bottom, width, height); the title above it and
# the colour bar to its right stay clear of it
SCENE = (0, 70, 1180, 820)
BACKGROUND = (0.86, 0.88, 0.91)
COLOUR_MAP = "YlOrRd"  # pale for unworn steel, dark red where it wears most


def ensure_display():
    """Points DISPLAY at an X server: the one given, or an Xvfb of our own that ends with this process."""
    if os.environ.get("DISPLAY"):
        return
    read_end, write_end = os.pipe()
    try:
        server = subprocess.Popen(["Xvfb", "-displayfd", str(write_end), "-nolisten", "tcp", "-screen", "0",
                                   f"{WIDTH + 200}x{HEIGHT + 200}x24"], pass_fds=(write_end,),
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    except FileNotFoundError:
        raise RuntimeError("no display and no Xvfb to draw on (Debian: apt-get install xvfb)")
    os.close(write_end)
    number = b""
    while not number.endswith(b"\n"):
        c = os.read(read_end, 1)
        if not c:
            raise RuntimeError("Xvfb did not start")
        number += c
    os.close(read_end)
    os.environ["DISPLAY"] = ":" + number.decode().strip()
    atexit.register(server.terminate)


def lookup_table(vmax):
    """The colour map sampled into a VTK lookup table over [0, vmax]."""
    import vtk
    from matplotlib import colormaps

    cmap = colormaps[COLOUR_MAP]
    table = vtk.vtkLookupTable()
    table.SetNumberOfTableValues(256)
    table.SetRange(0.0, vmax)
    for k in range(256):
        r, g, b, _ = cmap(k / 255.0)
        table.SetTableValue(k, r, g, b, 1.0)
    table.Build()
    return table


def table_colours():
    """The 256 colours of the map as 0..255 RGB rows (what a face turned to the light shows)."""
    from matplotlib import colormaps

    cmap = colormaps[COLOUR_MAP]
    return np.array([[round(255 * c) for c in cmap(k / 255.0)[:3]] for k in range(256)], dtype=float)


def read_polydata(path):
    import vtk

    if not os.path.exists(path):
        raise RuntimeError(f"{path}: no such file")
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


def read_surface(path):
    surface = read_polydata(path)
    if surface.GetNumberOfPolys() == 0:
        raise RuntimeError(f"{path}: no triangles")
    return surface


def array(data, name):
    from vtk.util.numpy_support import vtk_to_numpy

    a = data.GetArray(name)
    return None if a is None else vtk_to_numpy(a)


def triangles_of(surface):
    """(vertices, triangles as index rows, centroids, unit normals, areas) of a triangle surface."""
    from vtk.util.numpy_support import vtk_to_numpy

    x = vtk_to_numpy(surface.GetPoints().GetData()).astype(float)
    cells = vtk_to_numpy(surface.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    a, b, c = x[cells[:, 0]], x[cells[:, 1]], x[cells[:, 2]]
    n = np.cross(b - a, c - a)
    twice_area = np.linalg.norm(n, axis=1)
    normals = n / np.maximum(twice_area, 1e-300)[:, None]
    return x, cells, (a + b + c) / 3.0, normals, twice_area / 2.0


def region_of(plate_name):
    """The label a plate is shown under: teeth and bars as one region each."""
    if re.fullmatch(r"tooth_\d+", plate_name):
        return "teeth"
    if re.fullmatch(r"bar_\d+", plate_name):
        return "wear bars"
    return {"side_minus_y": "side (-y)", "side_plus_y": "side (+y)"}.get(plate_name, plate_name)


class View:
    """A camera for a part: `toward_camera` from the focus, `up` in the picture, and the region (plate names;
    empty: the whole part) that fills the picture."""

    def __init__(self, name, title, toward_camera, up, focus_plates=(), margin=1.08):
        self.name, self.title = name, title
        self.toward_camera = np.array(toward_camera, float) / np.linalg.norm(toward_camera)
        self.up = np.array(up, float)
        self.focus_plates, self.margin = focus_plates, margin


def views_for(part, plate_names):
    """Three views of a part, by what it is: the dipper, its door, or any other surface."""
    if part == "dipper" and plate_names:
        teeth_and_lip = [p for p in plate_names if p == "lip" or p.startswith("tooth_")]
        return [View("front", "into the bucket from the front", (1.0, 0.45, 0.75), (0, 0, 1)),
                View("below", "the bottom from below", (0.0, 0.0, -1.0), (1, 0, 0)),
                View("lip", "the lip and teeth, close up", (1.0, 0.55, 0.9), (0, 0, 1), teeth_and_lip, 1.15)]
    if part == "door":
        return [View("inside", "the inside (material side)", (1.0, 0.4, 0.3), (0, 0, 1)),
                View("outside", "the outside", (-1.0, -0.4, 0.3), (0, 0, 1)),
                View("below", "from below", (0.3, 0.2, -1.0), (1, 0, 0))]
    return [View("top", "from above", (0.0, 0.0, 1.0), (0, 1, 0)),
            View("oblique", "from above at an angle", (-0.8, -1.0, 1.1), (0, 0, 1)),
            View("below", "from below", (0.0, 0.0, -1.0), (0, 1, 0))]


def nice_length(target):
    """1, 2 or 5 times a power of ten, at most `target`."""
    power = 10.0 ** math.floor(math.log10(target))
    for m in (5.0, 2.0, 1.0):
        if m * power <= target:
            return m * power
    return power


def project(camera, box, points):
    """World points to the picture's pixel columns, rows from its top, and depth in [0, 1] (as the z-buffer
    holds it), for a camera that draws into `box` (left, bottom, width, height in pixels)."""
    left, bottom, width, height = box
    m = camera.GetCompositeProjectionTransformMatrix(width / height, -1.0, 1.0)
    p = np.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)])
    h = np.c_[points, np.ones(len(points))] @ p.T
    ndc = h[:, :3] / h[:, 3:4]
    col = left + (ndc[:, 0] + 1.0) / 2.0 * width
    row_up = bottom + (ndc[:, 1] + 1.0) / 2.0 * height
    return col, HEIGHT - row_up, (ndc[:, 2] + 1.0) / 2.0


def render_wear(surface, views, out_prefix, heading, field="rate_mm_per_t", vmax=None, plate_names=(),
                points=None, sections=None, probes=None):
    """Writes out_prefix + "_<view>.png" for each view. `points`: rows (x, y, z, measured value) drawn as
    spheres coloured by the measured value; `sections`: {name: polyline points}. `probes`: world points whose
    pixel places (column, row from the top) are returned per view, for checking the pictures.
    Returns [(view, file name, {probe pixel places})]."""
    import vtk

    values = array(surface.GetPointData(), field)
    if values is None:
        raise RuntimeError(f"the surface has no point field '{field}'")
    highest = float(values.max())
    top = float(vmax) if vmax else colour_top(values)
    if not vmax and points is not None and len(points):
        top = max(top, max(p[3] for p in points))  # the measured points on the same scale, none above its top
    top = top if top > 0.0 else 1.0
    unit = "mm/t" if field == "rate_mm_per_t" else "mm"
    quantity = "wear rate" if field == "rate_mm_per_t" else "wear depth"
    table = lookup_table(top)
    x, cells, centroids, normals, areas = triangles_of(surface)
    lo, hi = x.min(axis=0), x.max(axis=0)
    size = float(np.linalg.norm(hi - lo))
    plate = array(surface.GetCellData(), "plate")

    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(WIDTH, HEIGHT)
    window.SetMultiSamples(0)
    window.SetNumberOfLayers(3)
    # layer 0: the background, the titles, the colour bar and the length scale; layer 1: the part, clipped
    # to its box, with the names of its plates; layer 2: the axes
    frame = vtk.vtkRenderer()
    frame.SetBackground(*BACKGROUND)
    frame.SetBackground2(0.98, 0.98, 0.99)
    frame.GradientBackgroundOn()
    frame.SetLayer(0)
    window.AddRenderer(frame)
    renderer = vtk.vtkRenderer()
    left, bottom, box_w, box_h = SCENE
    renderer.SetViewport(left / WIDTH, bottom / HEIGHT, (left + box_w) / WIDTH, (bottom + box_h) / HEIGHT)
    renderer.SetLayer(1)
    window.AddRenderer(renderer)

    mapper = vtk.vtkPolyDataMapper()
    mapper.SetInputData(surface)
    mapper.SetScalarModeToUsePointFieldData()
    mapper.SelectColorArray(field)
    mapper.SetLookupTable(table)
    mapper.UseLookupTableScalarRangeOn()
    mapper.InterpolateScalarsBeforeMappingOn()
    mapper.ScalarVisibilityOn()
    mesh = vtk.vtkActor()
    mesh.SetMapper(mapper)
    # a face turned to the camera shows the colour bar's colour exactly: all light is diffuse from a headlight
    mesh.GetProperty().SetAmbient(0.5)
    mesh.GetProperty().SetDiffuse(0.5)
    mesh.GetProperty().SetSpecular(0.0)
    renderer.AddActor(mesh)

    section_labels = []
    for name, line in (sections or {}).items():
        if len(line) < 2:
            continue
        poly = vtk.vtkPolyData()
        pts = vtk.vtkPoints()
        for p in line:
            pts.InsertNextPoint(*p)
        poly.SetPoints(pts)
        polyline = vtk.vtkCellArray()
        polyline.InsertNextCell(len(line))
        for k in range(len(line)):
            polyline.InsertCellPoint(k)
        poly.SetLines(polyline)
        tube = vtk.vtkTubeFilter()
        tube.SetInputData(poly)
        tube.SetRadius(0.0035 * size)
        tube.SetNumberOfSides(10)
        tube_mapper = vtk.vtkPolyDataMapper()
        tube_mapper.SetInputConnection(tube.GetOutputPort())
        tube_mapper.ScalarVisibilityOff()
        tube_actor = vtk.vtkActor()
        tube_actor.SetMapper(tube_mapper)
        tube_actor.GetProperty().SetColor(0.1, 0.3, 0.75)
        renderer.AddActor(tube_actor)
        section_labels.append((f"section {name}", np.array(line[-1], float)))

    bar = vtk.vtkScalarBarActor()
    bar.SetLookupTable(table)
    bar.SetTitle(f"{quantity} [{unit}]")
    bar.SetNumberOfLabels(6)
    bar.SetLabelFormat("%-#7.3g")
    bar.SetOrientationToVertical()
    bar.SetPosition(0.86, 0.08)
    bar.SetWidth(0.12)
    bar.SetHeight(0.66)
    bar.SetBarRatio(0.28)
    bar.SetVerticalTitleSeparation(12)
    bar.UnconstrainedFontSizeOn()
    for prop, size_pt, bold in ((bar.GetTitleTextProperty(), 18, True), (bar.GetLabelTextProperty(), 16, False)):
        prop.SetColor(0.0, 0.0, 0.0)
        prop.SetFontSize(size_pt)
        prop.SetBold(bold)
        prop.SetItalic(False)
        prop.SetShadow(False)
    frame.AddViewProp(bar)

    def text(value, x, y, size_pt=16, bold=False, justify="left", box=False, on=frame):
        """A text at pixel (x, y) of `on`'s box, from its lower left."""
        actor = vtk.vtkTextActor()
        actor.SetInput(value)
        actor.SetDisplayPosition(int(x), int(y))
        prop = actor.GetTextProperty()
        prop.SetFontSize(size_pt)
        prop.SetBold(bold)
        prop.SetColor(0.0, 0.0, 0.0)
        prop.SetJustification({"left": 0, "centre": 1, "right": 2}[justify])
        prop.SetVerticalJustificationToCentered() if box else prop.SetVerticalJustificationToBottom()
        if box:
            prop.SetBackgroundColor(1.0, 1.0, 1.0)
            prop.SetBackgroundOpacity(0.75)
            prop.SetFrame(True)
            prop.SetFrameColor(0.3, 0.3, 0.3)
        on.AddViewProp(actor)
        return actor

    def marker(x, y, lookup, value, radius_px=9):
        """A disc at pixel (x, y) of the part's box in the colour of `value`, with a black ring."""
        actors = []
        for r, colour in ((radius_px + 2.5, (0.0, 0.0, 0.0)), (radius_px, None)):
            disc = vtk.vtkRegularPolygonSource()
            disc.SetNumberOfSides(28)
            disc.SetRadius(r)
            disc.SetCenter(x, y, 0.0)
            disc_mapper = vtk.vtkPolyDataMapper2D()
            disc_mapper.SetInputConnection(disc.GetOutputPort())
            actor = vtk.vtkActor2D()
            actor.SetMapper(disc_mapper)
            if colour is None:
                rgb = [0.0, 0.0, 0.0]
                lookup.GetColor(min(value, lookup.GetRange()[1]), rgb)
                colour = rgb
            actor.GetProperty().SetColor(*colour)
            renderer.AddViewProp(actor)
            actors.append(actor)
        return actors

    # the axes of the part's frame, in a corner, turned with the camera
    triad_renderer = vtk.vtkRenderer()
    triad_renderer.SetViewport(0.0, 0.0, 0.14, 0.2)
    triad_renderer.SetLayer(2)
    triad_renderer.InteractiveOff()
    window.AddRenderer(triad_renderer)
    axes = vtk.vtkAxesActor()
    axes.SetShaftTypeToCylinder()
    axes.SetTotalLength(1.0, 1.0, 1.0)
    for caption in (axes.GetXAxisCaptionActor2D(), axes.GetYAxisCaptionActor2D(), axes.GetZAxisCaptionActor2D()):
        caption.GetCaptionTextProperty().SetColor(0.0, 0.0, 0.0)
        caption.GetCaptionTextProperty().SetShadow(False)
        caption.GetCaptionTextProperty().SetFontSize(14)
        caption.GetTextActor().SetTextScaleModeToNone()
    triad_renderer.AddActor(axes)

    camera = renderer.GetActiveCamera()
    camera.ParallelProjectionOn()
    written = []
    for view in views:
        if view.focus_plates and plate is not None:
            wanted = [k for k, n in enumerate(plate_names) if n in view.focus_plates]
            chosen = np.isin(plate.astype(int), wanted)
            focus_points = x[np.unique(cells[chosen])] if chosen.any() else x
        else:
            focus_points = x
        f_lo, f_hi = focus_points.min(axis=0), focus_points.max(axis=0)
        centre = (f_lo + f_hi) / 2.0
        # the parallel scale that holds the focus box's corners with a margin, seen along the view
        direction = view.toward_camera
        up = view.up - direction * np.dot(view.up, direction)
        up /= np.linalg.norm(up)
        right = np.cross(up, direction)
        corners = np.array([[a, b, c] for a in (f_lo[0], f_hi[0]) for b in (f_lo[1], f_hi[1]) for c in (f_lo[2], f_hi[2])])
        half_h = np.abs((corners - centre) @ up).max()
        half_w = np.abs((corners - centre) @ right).max()
        scale = view.margin * max(half_h, half_w * box_h / box_w)
        camera.SetFocalPoint(*centre)
        camera.SetPosition(*(centre + direction * 4.0 * size))
        camera.SetViewUp(*up)
        camera.SetParallelScale(scale)
        renderer.ResetCameraClippingRange()
        triad_camera = triad_renderer.GetActiveCamera()
        triad_camera.SetFocalPoint(0.0, 0.0, 0.0)
        triad_camera.SetPosition(*(direction * 10.0))
        triad_camera.SetViewUp(*up)
        triad_renderer.ResetCamera()
        triad_camera.Zoom(1.25)

        # what is drawn over the surface this view: set, drawn, and taken off after its picture
        overlay = []
        overlay.append(text(heading, 24, HEIGHT - 44, 20, bold=True))
        overlay.append(text(f"{view.title}. Light from the viewer; unworn steel is the palest colour; "
                            f"{'values above the scale' if highest > top else 'the top of the scale'}: darkest "
                            f"(highest {highest:.3g} {unit})", 24, HEIGHT - 74, 16))
        metres = nice_length(0.25 * 2.0 * scale * box_w / box_h)
        pixels = metres / (2.0 * scale) * box_h
        scale_points = vtk.vtkPoints()
        for px, py in ((WIDTH * 0.18, 40), (WIDTH * 0.18 + pixels, 40), (WIDTH * 0.18, 34), (WIDTH * 0.18, 46),
                       (WIDTH * 0.18 + pixels, 34), (WIDTH * 0.18 + pixels, 46)):
            scale_points.InsertNextPoint(px, py, 0.0)
        scale_lines = vtk.vtkCellArray()
        for a, b in ((0, 1), (2, 3), (4, 5)):
            scale_lines.InsertNextCell(2)
            scale_lines.InsertCellPoint(a)
            scale_lines.InsertCellPoint(b)
        scale_poly = vtk.vtkPolyData()
        scale_poly.SetPoints(scale_points)
        scale_poly.SetLines(scale_lines)
        scale_mapper = vtk.vtkPolyDataMapper2D()
        scale_mapper.SetInputData(scale_poly)
        scale_actor = vtk.vtkActor2D()
        scale_actor.SetMapper(scale_mapper)
        scale_actor.GetProperty().SetColor(0.0, 0.0, 0.0)
        scale_actor.GetProperty().SetLineWidth(3)
        frame.AddViewProp(scale_actor)
        overlay.append(scale_actor)
        label = f"{metres * 1000:.0f} mm" if metres < 1.0 else f"{metres:g} m"
        overlay.append(text(label, WIDTH * 0.18 + pixels / 2.0, 52, 16, justify="centre"))

        window.Render()
        # names where they can be seen: the visible part of each plate region nearest its visible middle
        from vtk.util.numpy_support import vtk_to_numpy

        depth = vtk.vtkFloatArray()
        window.GetZbufferData(0, 0, WIDTH - 1, HEIGHT - 1, depth)
        zbuffer = vtk_to_numpy(depth).reshape(HEIGHT, WIDTH)[::-1]  # rows from the top
        def visible(world_points, tolerance=2e-3):
            col, row, z = project(camera, SCENE, world_points)
            inside = (col >= left + 40) & (col < left + box_w - 40) & (row >= HEIGHT - bottom - box_h + 12) & (row < HEIGHT - bottom - 12)
            seen = np.zeros(len(world_points), bool)
            ci, ri = np.clip(col.astype(int), 0, WIDTH - 1), np.clip(row.astype(int), 0, HEIGHT - 1)
            seen[inside] = z[inside] <= zbuffer[ri[inside], ci[inside]] + tolerance
            return seen, col, row

        if plate is not None and len(plate_names):
            facing = normals @ direction > 0.2
            seen, col, row = visible(centroids + normals * 1e-3 * size)
            regions = {}
            for k, name in enumerate(plate_names):
                regions.setdefault(region_of(name), []).append(k)
            placed = []
            for region, members in regions.items():
                mine = np.isin(plate.astype(int), members) & facing & seen
                if areas[mine].sum() < 0.004 * areas.sum():
                    continue
                middle = np.average(centroids[mine], axis=0, weights=areas[mine])
                candidates = np.flatnonzero(mine)
                best = candidates[np.argmin(np.linalg.norm(centroids[candidates] - middle, axis=1))]
                c, r = col[best], row[best]
                if any(abs(c - pc) < 90 and abs(r - pr) < 24 for pc, pr in placed):
                    r += 28  # two names at one place: the second just below
                placed.append((c, r))
                overlay.append(text(region, c - left, HEIGHT - r - bottom, 15, justify="centre", box=True, on=renderer))
        if section_labels:
            seen, col, row = visible(np.array([p for _, p in section_labels]), tolerance=2e-2)
            for (name, _), c, r, shown in zip(section_labels, col, row, seen):
                if shown:
                    overlay.append(text(name, c + 12 - left, HEIGHT - r - bottom, 14, box=True, on=renderer))
        if points is not None and len(points):
            # the measured points where they can be seen: discs in their measured rate's colour, ringed in black
            seen, col, row = visible(np.array([p[:3] for p in points], float), tolerance=5e-3)
            for (_, _, _, value), c, r, shown in zip(points, col, row, seen):
                if shown:
                    overlay += marker(c - left, HEIGHT - r - bottom, table, value)
            overlay.append(text("discs: the measured points, in their measured rate's colour on the same scale", 24,
                                HEIGHT - 100, 15))
        window.Render()

        grab = vtk.vtkWindowToImageFilter()
        grab.SetInput(window)
        grab.SetInputBufferTypeToRGB()
        grab.ReadFrontBufferOff()
        grab.Update()
        writer = vtk.vtkPNGWriter()
        name = f"{out_prefix}_{view.name}.png"
        writer.SetFileName(name)
        writer.SetInputConnection(grab.GetOutputPort())
        writer.Write()
        places = {}
        if probes is not None:
            col, row, _ = project(camera, SCENE, np.asarray(probes, float))
            places = {"column": col.tolist(), "row": row.tolist()}
        written.append((view, os.path.basename(name), places))
        for actor in overlay:
            frame.RemoveViewProp(actor)
            renderer.RemoveViewProp(actor)
    window.Finalize()
    return written


def colour_top(values):
    """The top of a wear picture's colour scale: the 99th percentile of the nodal values, so that a few
    corners (a tooth's tip) do not leave the rest of the part in one pale colour; what lies above shows the
    top colour. The highest value when the percentile is 0."""
    top = float(np.percentile(values, 99.0)) if len(values) else 0.0
    return top if top > 0.0 else float(values.max()) if len(values) else 0.0


def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def wear_pictures(folder, vmax=None):
    """Every DIR/wear_<part>_final.vtp drawn; returns [(title, file name)] for the report."""
    summary_path = os.path.join(folder, "summary.json")
    summary = json.load(open(summary_path)) if os.path.exists(summary_path) else {}
    pictures = []
    for name in sorted(os.listdir(folder)):
        m = re.fullmatch(r"wear_(.+)_final\.vtp", name)
        if not m:
            continue
        part = m.group(1)
        info = summary.get("wear", {}).get(part, {})
        surface = read_surface(os.path.join(folder, name))
        field = "rate_mm_per_t" if surface.GetPointData().GetArray("rate_mm_per_t") is not None else "depth_mm"
        plates = info.get("plates", [])
        points = None
        points_csv = os.path.join(folder, f"wear_{part}_points.csv")
        if field == "rate_mm_per_t" and os.path.exists(points_csv):
            points = [(float(r["x_m"]), float(r["y_m"]), float(r["z_m"]), float(r["measured_mm_per_t"]))
                      for r in read_csv(points_csv)]
        sections = {}
        for section in info.get("sections", {}):
            rows = read_csv(os.path.join(folder, f"wear_{part}_section_{section}.csv"))
            sections[section] = [(float(r["x_m"]), float(r["y_m"]), float(r["z_m"])) for r in rows if r["kind"] == "simulated"]
        if field == "rate_mm_per_t":
            heading = f"Wear rate of the {part} after {info.get('tonnage_t', 0):.4g} t"
        else:
            heading = f"Wear depth of the {part} (no material dumped yet)"
        measured = info.get("measured")
        if points is not None and measured and measured.get("scale") and not vmax:
            # beside measured points the surface shows the calibrated wear (the laws are linear in their
            # constant), so that the pattern and the points compare on one scale
            values = array(surface.GetPointData(), field)
            values *= measured["scale"]
            surface.GetPointData().GetArray(field).Modified()
            heading += f"  ({info['law'].replace('_', ' ')}, calibrated constant {measured['calibrated_constant']:.3g}, " \
                       f"{measured['scale']:.3g} x the run's)"
        elif "law" in info:
            heading += f"  ({info['law'].replace('_', ' ')}, constant {info['constant']:.3g})"
        if vmax:
            heading += "  - colour scale shared with the other variants"
        for view, file_name, _ in render_wear(surface, views_for(part, plates), os.path.join(folder, f"wear_{part}"),
                                              heading, field, vmax, plates, points, sections):
            pictures.append((f"Wear of the {part}: {view.title}", file_name))
    return pictures


def wear_maximum(folder):
    """The top of the colour scale (colour_top) over the folder's final wear surfaces, mm/t; 0 without any."""
    top = 0.0
    for name in os.listdir(folder):
        if re.fullmatch(r"wear_(.+)_final\.vtp", name):
            values = array(read_surface(os.path.join(folder, name)).GetPointData(), "rate_mm_per_t")
            if values is not None and len(values):
                top = max(top, colour_top(values))
    return top


def main(argv):
    if len(argv) < 3 or argv[1] not in ("wear", "film"):
        print(__doc__, file=sys.stderr)
        return 2
    ensure_display()
    if argv[1] == "film":
        from film import film

        print(json.dumps(film(argv[2])))
        return 0
    vmax = None
    if "--vmax" in argv:
        k = argv.index("--vmax") + 1
        try:
            vmax = float(argv[k])
        except (IndexError, ValueError):
            print(f"render.py: --vmax needs a number of mm/t above 0; got {argv[k] if k < len(argv) else 'nothing'}",
                  file=sys.stderr)
            return 2
        if not vmax > 0.0:
            print(f"render.py: --vmax needs a number of mm/t above 0; got {argv[k]}", file=sys.stderr)
            return 2
    pictures = wear_pictures(argv[2], vmax)
    print(json.dumps(pictures))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

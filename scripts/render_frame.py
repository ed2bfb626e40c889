"""Renders one frame of an fdem run to a PNG with ParaView (run it with pvbatch).

    pvbatch scripts/render_frame.py INPUT PNG [options]

INPUT is a frames.pvd series (or one .vtu/.pvtu frame); 1-rank runs write .vtu frames, N-rank runs
.pvtu files that gather one piece per rank, and both read the same. The frame is chosen by
--time (simulated seconds, the nearest frame), --index (frame number, negative from the end) or
the last frame by default. The mesh is coloured by --field (point or cell array, e.g.
displacement, velocity, von_mises, damage; vectors by --component, Magnitude by default) with a
scalar bar; --overlay adds other series at the same time (cracks.pvd: the faces of broken joints,
contacts.pvd: contact points), each in one colour or coloured by one of its arrays.

The camera looks along --view (from the camera towards the scene, default 0 1 0: the x-z plane
seen from -y) with --up (default 0 0 1), fitted to the scene, then --zoom (> 1 closer) and
--focus X Y Z / --pan DX DY DZ move it. Examples:

    pvbatch scripts/render_frame.py out/tower/frames.pvd tower.png --time 0.3 \\
        --field velocity --view 1 2 -0.6 --zoom 1.3
    pvbatch scripts/render_frame.py out/disc/frames.pvd disc.png --field damage --range 0 1 \\
        --overlay out/disc/cracks.pvd --view 0 0 -1 --up 0 1 0
"""
import argparse
import math
import os
import sys

from paraview import servermanager
from paraview.simple import (ColorBy, GetActiveViewOrCreate, GetAnimationScene, GetColorTransferFunction,
                             GetOpacityTransferFunction, GetScalarBar, Glyph, OpenDataFile,
                             PVDReader, Render, SaveScreenshot, Show, Text,
                             UpdatePipeline)


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("input", help="frames.pvd, or a .vtu/.pvtu frame")
    p.add_argument("png", help="output picture")
    which = p.add_mutually_exclusive_group()
    which.add_argument("--time", type=float, help="simulated time of the frame (nearest frame)")
    which.add_argument("--index", type=int, help="frame number, negative from the end")
    p.add_argument("--field", default="displacement",
                   help="array to colour by; none: one solid colour (with a coloured overlay)")
    p.add_argument("--component", default="Magnitude",
                   help="Magnitude, X, Y, Z or a component number (vectors and tensors)")
    p.add_argument("--range", type=float, nargs=2, metavar=("MIN", "MAX"),
                   help="colour range (default: the range of the shown frame)")
    p.add_argument("--colormap", default="Viridis (matplotlib)", help="ParaView colour preset")
    p.add_argument("--log-scale", action="store_true", help="logarithmic colour scale")
    p.add_argument("--field-title", help="scalar bar title (default: field and component)")
    p.add_argument("--overlay", action="append", default=[], metavar="SERIES[:FIELD]",
                   help="another series (cracks.pvd, contacts.pvd) shown at the same time, in "
                        "--overlay-color or coloured by FIELD; may repeat")
    p.add_argument("--overlay-title", help="scalar bar title of a coloured overlay")
    p.add_argument("--overlay-color", type=float, nargs=3, default=[0.85, 0.1, 0.1],
                   metavar=("R", "G", "B"))
    p.add_argument("--overlay-width", type=float, default=3.0,
                   help="line width of the overlay's edges (px)")
    p.add_argument("--overlay-points", type=float, default=0.0, metavar="SIZE",
                   help="draw an overlay's points as spheres of this size (m), e.g. contacts")
    p.add_argument("--opacity", type=float, default=1.0, help="opacity of the mesh")
    p.add_argument("--edges", action="store_true", help="draw the mesh edges")
    p.add_argument("--view", type=float, nargs=3, default=[0.0, 1.0, 0.0],
                   metavar=("DX", "DY", "DZ"), help="direction the camera looks along")
    p.add_argument("--up", type=float, nargs=3, default=[0.0, 0.0, 1.0],
                   metavar=("UX", "UY", "UZ"))
    p.add_argument("--zoom", type=float, default=1.0, help="> 1 moves the camera closer")
    p.add_argument("--focus", type=float, nargs=3, metavar=("X", "Y", "Z"),
                   help="point the camera looks at (default: the centre of the scene)")
    p.add_argument("--pan", type=float, nargs=3, default=[0.0, 0.0, 0.0],
                   metavar=("DX", "DY", "DZ"), help="shift camera and focus (m)")
    p.add_argument("--parallel", action="store_true", help="parallel projection")
    p.add_argument("--title", help="text at the top left (default: the run and the time)")
    p.add_argument("--size", type=int, nargs=2, default=[1200, 800], metavar=("W", "H"))
    return p.parse_args(argv)


def open_series(path):
    """A reader for a .pvd series or a single frame file."""
    if path.endswith(".pvd"):
        return PVDReader(FileName=path)
    reader = OpenDataFile(path)
    if reader is None:
        sys.exit(f"render_frame.py: ParaView cannot read {path}")
    return reader


def frame_time(reader, args):
    """Simulated time of the chosen frame (None for a reader without time steps)."""
    times = list(getattr(reader, "TimestepValues", []) or [])
    if isinstance(times, float):
        times = [times]
    if not times:
        return None
    if args.time is not None:
        return min(times, key=lambda t: abs(t - args.time))
    if args.index is not None:
        return times[args.index]
    return times[-1]


def association_of(reader, name):
    """('POINTS' | 'CELLS', number of components) of an array, or exit with the names there are."""
    for assoc, arrays in (("POINTS", reader.PointData), ("CELLS", reader.CellData)):
        if name in arrays.keys():
            return assoc, arrays[name].GetNumberOfComponents()
    names = list(reader.PointData.keys()) + list(reader.CellData.keys())
    sys.exit(f"render_frame.py: no array '{name}' in {reader.FileName}; there are {names}")


def component_spec(component, n_components):
    """ColorBy's component argument and the index LookupTable ranges use (-1 = magnitude)."""
    if n_components == 1:
        return None, 0
    named = {"magnitude": -1, "x": 0, "y": 1, "z": 2, "xx": 0, "yy": 4, "zz": 8, "xy": 1,
             "xz": 2, "yz": 5}
    key = component.lower()
    index = named[key] if key in named else int(component)
    if index < 0:
        return "Magnitude", -1
    labels = ["X", "Y", "Z"] if n_components == 3 else [str(i) for i in range(n_components)]
    return labels[index], index


def data_range(source, assoc, name, index, time):
    """Range of an array (component index, -1 = magnitude) at a time, over all pieces."""
    source.UpdatePipeline(time)
    info = source.GetDataInformation().DataInformation
    arrays = (info.GetPointDataInformation() if assoc == "POINTS"
              else info.GetCellDataInformation())
    array = arrays.GetArrayInformation(name)
    return array.GetComponentRange(index)


def add_overlays(args, view, time, bar_position):
    """Shows the --overlay series at the same time."""
    for spec in args.overlay:
        path, _, field = spec.partition(":")
        if not os.path.exists(path):
            sys.exit(f"render_frame.py: no overlay series {path}")
        overlay = open_series(path)
        UpdatePipeline(time=time, proxy=overlay)
        shown = overlay
        if args.overlay_points > 0:
            shown = Glyph(Input=overlay, GlyphType="Sphere")
            shown.ScaleArray = ["POINTS", "No scale array"]
            shown.ScaleFactor = args.overlay_points
            shown.GlyphMode = "All Points"
        od = Show(shown, view)
        od.Representation = "Surface" if args.overlay_points > 0 else "Surface With Edges"
        od.LineWidth = args.overlay_width
        od.EdgeColor = args.overlay_color
        if field:
            o_assoc, o_components = association_of(overlay, field)
            if o_components == 1:
                ColorBy(od, (o_assoc, field))
            else:
                ColorBy(od, (o_assoc, field, "Magnitude"))
            o_lut = GetColorTransferFunction(field)
            o_lut.ApplyPreset("Inferno (matplotlib)", True)
            o_low, o_high = data_range(overlay, o_assoc, field, 0 if o_components == 1 else -1,
                                       time)
            o_lut.RescaleTransferFunction(o_low, max(o_high, o_low + 1e-12))
            od.SetScalarBarVisibility(view, True)
            o_bar = GetScalarBar(o_lut, view)
            o_bar.Title = args.overlay_title or field
            o_bar.ComponentTitle = ""
            o_bar.TitleColor = o_bar.LabelColor = [0.1, 0.1, 0.1]
            o_bar.WindowLocation = "Any Location"
            o_bar.Position = bar_position
            o_bar.ScalarBarLength = 0.3
            o_bar.TitleFontSize = 16
            o_bar.LabelFontSize = 14
            o_bar.RangeLabelFormat = "%-#.3g"
        else:
            od.ColorArrayName = ["POINTS", ""]  # one solid colour
            od.AmbientColor = od.DiffuseColor = args.overlay_color


def finish(args, reader, view, time, what):
    """Title, camera, picture."""
    run = os.path.basename(os.path.dirname(os.path.abspath(args.input)))
    title = args.title if args.title is not None else run
    if time is not None:
        title += f"   t = {time:.4g} s"
    label = Text(Text=title)
    ld = Show(label, view)
    ld.WindowLocation = "Upper Left Corner"
    ld.FontSize = 20
    ld.Color = [0.1, 0.1, 0.1]

    # Camera: along --view, fitted to the scene, then zoomed and panned.
    # Fitted by hand to the mesh as it is at the shown time (ParaView's ResetCamera may use the
    # bounds of another frame): the bounding sphere fills the smaller of the two view angles.
    norm = math.sqrt(sum(c * c for c in args.view)) or 1.0
    direction = [c / norm for c in args.view]
    reader.UpdatePipeline(time)
    bounds = reader.GetDataInformation().GetBounds()
    centre = [(bounds[2 * i] + bounds[2 * i + 1]) / 2 for i in range(3)]
    radius = 0.5 * math.sqrt(sum((bounds[2 * i + 1] - bounds[2 * i]) ** 2 for i in range(3)))
    radius = radius or 1.0
    view_angle = 30.0  # degrees, vertical (ParaView's default)
    aspect = args.size[0] / args.size[1]
    half = math.radians(view_angle / 2)
    half = min(half, math.atan(math.tan(half) * aspect))
    distance = radius / math.sin(half)
    view.CameraViewAngle = view_angle
    view.CameraFocalPoint = centre
    view.CameraPosition = [c - distance * d for c, d in zip(centre, direction)]
    view.CameraViewUp = args.up
    view.CameraParallelProjection = 1 if args.parallel else 0
    view.CameraParallelScale = radius
    Render(view)
    camera = view.GetActiveCamera()
    if args.focus:
        shift = [f - c for f, c in zip(args.focus, camera.GetFocalPoint())]
        camera.SetFocalPoint(*[c + s for c, s in zip(camera.GetFocalPoint(), shift)])
        camera.SetPosition(*[c + s for c, s in zip(camera.GetPosition(), shift)])
    if any(args.pan):
        camera.SetFocalPoint(*[c + s for c, s in zip(camera.GetFocalPoint(), args.pan)])
        camera.SetPosition(*[c + s for c, s in zip(camera.GetPosition(), args.pan)])
    camera.Zoom(args.zoom)
    Render(view)
    os.makedirs(os.path.dirname(os.path.abspath(args.png)), exist_ok=True)
    SaveScreenshot(args.png, view, ImageResolution=args.size, TransparentBackground=0)
    print(f"{args.png}: {args.input} at t = {time}, {what}")


def main(argv):
    args = parse_args(argv)
    view = GetActiveViewOrCreate("RenderView")
    view.ViewSize = args.size
    view.OrientationAxesVisibility = 1
    view.Background = [1.0, 1.0, 1.0]
    try:  # ParaView >= 5.10 uses the palette unless told to use the view's own background
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass

    reader = open_series(args.input)
    time = frame_time(reader, args)
    if time is not None:
        # The animation time, not only the view's: the camera fit uses the bounds at that time.
        scene = GetAnimationScene()
        scene.UpdateAnimationUsingDataTimeSteps()
        scene.AnimationTime = time
        view.ViewTime = time
    UpdatePipeline(time=time, proxy=reader)
    display = Show(reader, view)
    display.Representation = "Surface With Edges" if args.edges else "Surface"
    display.EdgeColor = [0.25, 0.25, 0.25]
    display.Opacity = args.opacity
    if args.field == "none":  # one solid colour; an overlay carries the field
        display.ColorArrayName = ["POINTS", ""]
        display.AmbientColor = display.DiffuseColor = [0.82, 0.80, 0.76]
        add_overlays(args, view, time, bar_position=[0.89, 0.08])
        finish(args, reader, view, time, "solid")
        return
    assoc, n_components = association_of(reader, args.field)
    component, index = component_spec(args.component, n_components)
    if component is None:
        ColorBy(display, (assoc, args.field))
    else:
        ColorBy(display, (assoc, args.field, component))
    lut = GetColorTransferFunction(args.field)
    lut.ApplyPreset(args.colormap, True)
    low, high = args.range if args.range else data_range(reader, assoc, args.field, index, time)
    if high <= low:  # a uniform field: widen so the bar is readable
        high = low + (abs(low) * 1e-3 or 1e-12)
    if args.log_scale:
        low = max(low, high * 1e-4)
        lut.UseLogScale = 1
    lut.RescaleTransferFunction(low, high)
    GetOpacityTransferFunction(args.field).RescaleTransferFunction(low, high)
    try:
        lut.AutomaticRescaleRangeMode = "Never"
    except AttributeError:
        pass
    display.SetScalarBarVisibility(view, True)
    bar = GetScalarBar(lut, view)
    bar.Title = args.field_title or (args.field if component is None
                                     else f"{args.field} ({component.lower()})")
    bar.ComponentTitle = ""
    bar.TitleColor = bar.LabelColor = [0.1, 0.1, 0.1]
    bar.TitleFontSize = 18
    bar.LabelFontSize = 15
    bar.ScalarBarLength = 0.4
    bar.WindowLocation = "Any Location"
    bar.Position = [0.89, 0.08]
    bar.RangeLabelFormat = "%-#.3g"

    add_overlays(args, view, time, bar_position=[0.78, 0.08])
    finish(args, reader, view, time, f"{args.field} {'' if component is None else component} "
           f"in [{low:.4g}, {high:.4g}]")


if __name__ == "__main__":
    main(sys.argv[1:])

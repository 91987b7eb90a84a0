"""Off-screen pyvista pictures of the FEM mode shapes, read from the VTU the pipeline exports.

The VTU holds the solid (legs and platform) with one point-data displacement vector per mode
(`mode_1`, `mode_2`, ... or any 3-component array whose name carries the mode number) and the
frequencies in field data. Each picture shows the deformed solid (scaled for visibility, coloured
by displacement magnitude) over the undeformed outline.
"""
from __future__ import annotations

import math
import os
import re
from pathlib import Path
from typing import NamedTuple

import numpy as np

from common.errors import ComputeError

VIEW = (22.0, -60.0)  # elevation, azimuth (deg): the same view as the beam pictures
WINDOW = (620, 560)
_MODE_NAME = re.compile(r"mode\D{0,3}(\d+)", re.I)


class RenderError(ComputeError):
    """A mode-shape picture could not be made (message is one line)."""


class Platform(NamedTuple):
    """The platform as the pictures draw it when the mode file has no platform solid (a rigid
    platform is not meshed): a disk through the joint centres A_i about its centre o, moved in
    each mode by the FEM's own platform motion."""

    joints: np.ndarray  # (legs, 3) A_i, m
    centre: np.ndarray  # (3,) o, m
    radius: float
    thickness: float
    # mode (1-based) -> (translation of o (3,), rotation (3,))
    motion: dict[int, tuple[np.ndarray, np.ndarray]]


def _quiet_vtk():
    import vtk

    vtk.vtkObject.GlobalWarningDisplayOff()
    try:
        vtk.vtkLogger.SetStderrVerbosity(vtk.vtkLogger.VERBOSITY_OFF)
    except AttributeError:
        pass
    return vtk


def mode_arrays(mesh) -> dict[int, str]:
    """{mode number (1-based): point-data array name} of the 3-component mode fields."""
    found = {}
    for name in mesh.point_data.keys():
        arr = mesh.point_data[name]
        match = _MODE_NAME.search(name)
        if match and arr.ndim == 2 and arr.shape[1] == 3:
            found[int(match.group(1))] = name
    if found and min(found) == 0:  # zero-based names
        found = {k + 1: v for k, v in found.items()}
    return dict(sorted(found.items()))


def file_frequencies(mesh) -> list[float] | None:
    for name in mesh.field_data.keys():
        if "freq" in name.lower():
            return [float(x) for x in np.ravel(mesh.field_data[name])]
    return None


def read_modes(path: Path):
    """(mesh, {mode: array name}, frequencies or None); RenderError if unreadable."""
    if not Path(path).is_file():
        raise RenderError(f"{path}: FEM mode file not found")
    _quiet_vtk()
    import pyvista as pv

    try:
        mesh = pv.read(str(path))
    except Exception as exc:  # noqa: BLE001  (vtk/meshio raise anything)
        raise RenderError(f"{path}: cannot read FEM mode file ({exc})") from None
    modes = mode_arrays(mesh)
    if not modes:
        raise RenderError(f"{path}: no 3-component 'mode_<k>' point arrays "
                          f"(found {list(mesh.point_data.keys())})")
    return mesh, modes, file_frequencies(mesh)


def render_modes(path: Path, modes: list[int], labels: dict[int, str], out: dict[int, Path],
                 scale_fraction: float = 0.1, platform: Platform | None = None
                 ) -> list[float] | None:
    """One PNG per requested mode: deformed (scaled) over the undeformed surface, with the
    `platform` disk when the file has no platform solid.

    Returns the frequencies stored in the file (None if it has none).
    """
    os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")
    mesh, arrays, file_hz = read_modes(path)
    import pyvista as pv

    pv.OFF_SCREEN = True
    missing = [k for k in modes if k not in arrays]
    if missing:
        raise RenderError(f"{path}: no displacement field for mode(s) {missing}")
    try:
        surface = mesh.extract_surface(nonlinear_subdivision=1, algorithm="dataset_surface")
        size = float(max(np.ptp(surface.points, axis=0)))
        outline = surface.extract_feature_edges(feature_angle=35, boundary_edges=True,
                                                non_manifold_edges=False,
                                                manifold_edges=False)
        disk = None
        if platform is not None and not _covers_platform(surface, platform):
            disk = _platform_disk(platform)
        # pyvista annotates window_size as list[int]; it takes any pair
        plotter = pv.Plotter(off_screen=True, window_size=WINDOW)  # type: ignore[arg-type]
        try:
            for k in modes:
                u = np.asarray(surface.point_data[arrays[k]], float)
                amp = float(np.linalg.norm(u, axis=1).max())
                scale = scale_fraction * size / amp if amp > 0 else 0.0
                deformed = surface.copy()
                deformed.points = surface.points + scale * u
                deformed.point_data["|u|"] = np.linalg.norm(u, axis=1) / max(amp, 1e-300)
                plotter.clear_actors()
                # pyvista types this method by functools.wraps of an unbound one
                plotter.set_background("white")  # type: ignore[arg-type]
                plotter.add_mesh(surface, color="#bbbbbb", opacity=0.18, lighting=False)
                plotter.add_mesh(outline, color="#888888", line_width=1)
                plotter.add_mesh(deformed, scalars="|u|", cmap="viridis", clim=(0, 1),
                                 show_scalar_bar=False, smooth_shading=True)
                if disk is not None and platform is not None:  # a disk: a platform drawn
                    moved = disk.copy()
                    t, w = platform.motion[k]
                    moved.points = disk.points + scale * (
                        t + np.cross(w, disk.points - platform.centre))
                    plotter.add_mesh(disk, color="#bbbbbb", opacity=0.18, lighting=False)
                    plotter.add_mesh(moved, color="#8a8fa0", smooth_shading=True)
                _camera(plotter, surface)
                image = plotter.screenshot(return_img=True)
                if image is None:  # cropping None would raise the same (a RenderError below)
                    raise TypeError("the off-screen plotter returned no picture")
                _save_labelled(image, labels.get(k, f"mode {k}"), out[k])
        finally:
            plotter.close()
    except RenderError:
        raise
    except Exception as exc:  # noqa: BLE001
        raise RenderError(f"{path}: off-screen rendering failed ({type(exc).__name__}: "
                          f"{' '.join(str(exc).split())})") from None
    for k in modes:
        if not out[k].is_file() or out[k].stat().st_size == 0:
            raise RenderError(f"{out[k]}: off-screen rendering produced no picture")
    return file_hz


def _covers_platform(surface, platform: Platform) -> bool:
    """Is the platform meshed (solid material at its centre)?"""
    gap = np.linalg.norm(surface.points - platform.centre, axis=1).min()
    return float(gap) < 0.25 * platform.radius


def _platform_disk(platform: Platform):
    """The platform as a pyvista disk on the joint centres' plane."""
    import pyvista as pv

    a = platform.joints
    normal = np.cross(a[1] - a[0], a[2] - a[0])
    normal /= np.linalg.norm(normal)
    return pv.Cylinder(center=platform.centre + 0.5 * platform.thickness * normal,
                       direction=normal, radius=platform.radius, height=platform.thickness,
                       resolution=60).triangulate()


def _save_labelled(image: np.ndarray, label: str, path: Path, margin: int = 8) -> None:
    """Crop the white border, put the label above the picture, write the PNG."""
    from PIL import Image, ImageDraw, ImageFont

    ink = np.any(image[..., :3] < 245, axis=2)
    rows, cols = np.flatnonzero(ink.any(axis=1)), np.flatnonzero(ink.any(axis=0))
    if len(rows) == 0:
        raise RenderError(f"{path}: off-screen rendering produced an empty picture")
    r0, r1 = max(rows[0] - margin, 0), min(rows[-1] + margin + 1, image.shape[0])
    c0, c1 = max(cols[0] - margin, 0), min(cols[-1] + margin + 1, image.shape[1])
    picture = Image.fromarray(np.ascontiguousarray(image[r0:r1, c0:c1, :3]))
    font = ImageFont.load_default(size=30)
    head = 42
    canvas = Image.new("RGB", (max(picture.width, 300), picture.height + head), "white")
    canvas.paste(picture, ((canvas.width - picture.width) // 2, head))
    ImageDraw.Draw(canvas).text((6, 4), label, fill="black", font=font)
    tmp = path.with_name(path.name + ".tmp.png")
    canvas.save(tmp)
    os.replace(tmp, path)


def _camera(plotter, surface) -> None:
    elev, azim = (math.radians(a) for a in VIEW)
    direction = np.array([math.cos(elev) * math.cos(azim), math.cos(elev) * math.sin(azim),
                          math.sin(elev)])
    centre = np.asarray(surface.center)
    plotter.camera_position = [tuple(centre + 5 * direction), tuple(centre), (0, 0, 1)]
    plotter.reset_camera()
    plotter.camera.zoom(1.25)

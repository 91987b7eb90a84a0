"""Synthetic modal tests: a campaign made by one of our models with hidden scene values and
stated noise, to verify correlation and identification against a known truth
(`python -m modaltest.synthesize`, tests/test_modaltest.py, campaigns/).

The sensors: triaxial, on the platform's top face (six at 0.8 r2, every 60 degrees) and on every
leg's surface at 30 % and 70 % of its length (facing away from the machine's axis), each node
placed at the pose tested, in mm in the base frame. The noise: each frequency times
(1 + N(0, sigma_f)); each shape entry plus N(0, sigma_s max|shape|), seeded.
"""
from __future__ import annotations

import argparse
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from analytical.kinematics import PoseGeometry, pose_geometry
from analytical.params import Manipulator, Pose
from scene import Scene
from scene.address import resolve, with_values
from scene.load import parse_scene
from scene.toml_table import read_toml

from . import uff
from .models import analytical_field, fem_field
from .placement import ModeField
from .pretest import prediction


@dataclass(frozen=True)
class PoseTested:
    name: str
    height_mm: float
    azimuth_deg: float
    tilt_deg: float

    @property
    def pose(self) -> Pose:
        return Pose(height=self.height_mm * 1e-3, azimuth=math.radians(self.azimuth_deg),
                    tilt=math.radians(self.tilt_deg))


def sensor_points(manipulator: Manipulator, geometry: PoseGeometry) -> np.ndarray:
    """(n, 3) sensor positions (m, base frame) at this pose."""
    points = []
    r = 0.8 * manipulator.platform_radius
    if manipulator.platform_shape != "disk":
        r = 0.4 * manipulator.platform_radius  # inside the triangle A1A2A3
    for k in range(6):
        a = math.radians(60.0 * k + 30.0)
        local = np.array([r * math.cos(a), r * math.sin(a), 0.5 * manipulator.platform_thickness])
        points.append(geometry.platform_centre + geometry.rotation @ local)
    leg = manipulator.leg
    for i in range(geometry.leg_count):
        e = geometry.leg_directions[i]
        base = geometry.base_points[i]
        out = base - np.array([0.0, 0.0, base[2]])
        out = out - (out @ e) * e
        out /= np.linalg.norm(out)
        for t in (0.3, 0.7):
            along = t * geometry.leg_lengths[i]
            if leg.stepped:
                radius = 0.5 * (leg.housing_outer_diameter if along <= leg.housing_length
                                else leg.rod_outer_diameter)
            else:
                radius = 0.5 * manipulator.leg_diameter
            points.append(base + along * e + radius * out)
    return np.array(points)


def test_modes(field: ModeField, manipulator: Manipulator, geometry: PoseGeometry, modes: int,
               frequency_noise: float, shape_noise: float,
               rng: np.random.Generator) -> tuple[uff.Nodes, uff.Modes]:
    """The model's lowest `modes` modes at the sensors, with noise (fractions)."""
    nodes, exact = prediction(field, manipulator, geometry, sensor_points(manipulator, geometry),
                              modes, 1e-6, "synthetic sensors")
    shapes = exact.shapes / np.abs(exact.shapes).max(axis=0)
    shapes = shapes + shape_noise * rng.standard_normal(shapes.shape)
    hz = exact.frequencies_hz * (1.0 + frequency_noise * rng.standard_normal(len(shapes.T)))
    order = np.argsort(hz)
    return nodes, uff.Modes(hz[order], None, exact.dofs, shapes[:, order])


def test_frfs(field: ModeField, manipulator: Manipulator, geometry: PoseGeometry, modes: int,
              damping_ratio: float, resolution_hz: float) -> tuple[uff.Nodes, uff.Frfs]:
    """Receptances of the model's lowest `modes` modes at the sensors (triaxial), from one
    excitation dof (the one every mode moves most evenly), by modal superposition of the
    mass-normalised modes with a modal damping ratio: H_jk = sum_r phi_jr phi_kr /
    (w_r^2 - w^2 + 2 i zeta w_r w), on 0 Hz to 1.25 times the highest mode."""
    nodes, exact = prediction(field, manipulator, geometry, sensor_points(manipulator, geometry),
                              modes, 1e-6, "synthetic sensors")
    phi, hz, dofs = exact.shapes, exact.frequencies_hz, exact.dofs
    ref = int(np.argmax(np.min(np.abs(phi) / np.abs(phi).max(axis=0), axis=1)))
    f = np.arange(0.0, 1.25 * hz[-1], resolution_hz)
    w, wr = 2 * np.pi * f, 2 * np.pi * hz
    h = (phi[:, None, :] * phi[ref, None, None, :]
         / (wr**2 - w[:, None] ** 2 + 2j * damping_ratio * wr * w[:, None])[None]).sum(axis=2)
    count = len(dofs.node)
    reference = uff.Dofs(np.full(count, dofs.node[ref]), np.tile(dofs.direction[ref], (count, 1)))
    return nodes, uff.Frfs(f, dofs, reference, h)


def hidden_scene(raw: dict, scene_path: str, hidden: dict[str, float]) -> Scene:
    return parse_scene(with_values(raw, {resolve(k): v for k, v in hidden.items()}), scene_path)


def write_campaign(scene_path: Path, hidden: dict[str, float], points: Sequence[PoseTested],
                   directory: Path, identify: Sequence[str], model: str = "analytical",
                   modes: int = 6, frequency_noise: float = 0.0, shape_noise: float = 0.0,
                   seed: int = 1, extra: str = "", name: str = "synthetic modal test",
                   made_at: str = "", frf_damping: float | None = None,
                   frf_resolution: float = 0.1) -> Path:
    """A campaign file and its UFF files in `directory`, made by `model` ("analytical": the
    scene's settings; "fem": its solid at the default mesh size) on the scene with the
    `hidden` values (edge units); returns the campaign file. With `frf_damping` each pose's
    file holds receptances (UFF 58, that modal damping ratio, `frf_resolution` Hz lines)
    instead of modes."""
    raw = read_toml(scene_path)
    scene = hidden_scene(raw, str(scene_path), hidden)
    rng = np.random.default_rng(seed)
    sizes: list[str] = []
    directory.mkdir(parents=True, exist_ok=True)
    relative = os.path.relpath(Path(scene_path).resolve(), directory.resolve())
    lines = [f'scene = "{Path(relative).as_posix()}"']
    for tp in points:
        geometry = pose_geometry(scene.manipulator, tp.pose)
        field: ModeField
        if model == "fem":
            field = fem_field(scene, geometry, modes)
        else:
            field = analytical_field(scene.manipulator, tp.pose, geometry, scene.analytical,
                                     modes)
        file_name = f"{tp.name}.unv"
        if frf_damping is None:
            nodes, test = test_modes(field, scene.manipulator, geometry, modes,
                                     frequency_noise, shape_noise, rng)
            uff.write_uff(directory / file_name, nodes, test,
                          description=f"synthetic: {model} model, pose {tp.name}")
        else:
            nodes, frfs = test_frfs(field, scene.manipulator, geometry, modes, frf_damping,
                                    frf_resolution)
            uff.write_uff(directory / file_name, nodes, frfs=frfs,
                          description=f"synthetic FRFs: {model} model, pose {tp.name}")
        lines += ["", "[[pose]]", f'name = "{tp.name}"', f"height_mm = {tp.height_mm!r}",
                  f"azimuth_deg = {tp.azimuth_deg!r}", f"tilt_deg = {tp.tilt_deg!r}",
                  f'data = "{file_name}"']
        if model == "fem":
            mesh = getattr(field, "mesh_size", None)
            sizes.append(f"{tp.name}: {mesh * 1e3:.4g} mm, {getattr(field, 'dofs', 0)} dofs"
                         if mesh else tp.name)
    if identify:
        lines += ["", "[identify]", "keys = [" + ", ".join(f'"{k}"' for k in identify) + "]"]
    made_by = ("our solid FEM (fem_reference) at the scene's mesh size" if model == "fem"
               else "the analytical model at the scene's settings")
    header = ["# A synthetic modal test, not a measurement: made by",
              f"# `python -m modaltest.synthesize` with {made_by},",
              "# hidden scene values and noise (provenance.toml).", "",
              f'name = "{name}"']
    path = directory / "campaign.toml"
    path.write_text("\n".join(header + lines) + "\n" + extra, encoding="utf-8")
    provenance = [
        "# How this campaign was made (read by tests/test_modaltest.py)",
        f'model = "{model}"',
        f"frequency_noise_percent = {100 * frequency_noise!r}",
        f"shape_noise_percent_of_largest = {100 * shape_noise!r}",
        f"seed = {seed}", f"modes = {modes}", f'made_at = "{made_at}"',
        f"fem_meshes = {sizes!r}".replace("'", '"'),
        "", "[hidden]  # the scene values the test was made with (edge units)"]
    provenance += [f'"{k}" = {float(v)!r}' for k, v in hidden.items()]
    (directory / "provenance.toml").write_text("\n".join(provenance) + "\n", encoding="utf-8")
    return path


def _commit() -> str:
    """The checkout's commit the campaign was made at (a developer tool, run in a clone)."""
    import subprocess
    try:
        return subprocess.run(["git", "describe", "--always", "--dirty"], capture_output=True,
                              text=True, cwd=Path(__file__).parent, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m modaltest.synthesize", description=__doc__)
    p.add_argument("--scene", required=True, type=Path)
    p.add_argument("--out", required=True, type=Path)
    p.add_argument("--model", choices=("analytical", "fem"), default="fem")
    p.add_argument("--hidden", nargs="+", required=True, metavar="KEY=VALUE")
    p.add_argument("--identify", nargs="*", default=[], metavar="KEY")
    p.add_argument("--pose", nargs="+", required=True, metavar="NAME:Z_MM:AZ_DEG:TILT_DEG")
    p.add_argument("--modes", type=int, default=6)
    p.add_argument("--frequency-noise-percent", type=float, default=1.0)
    p.add_argument("--shape-noise-percent", type=float, default=5.0)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--name", default="synthetic modal test")
    p.add_argument("--append", default="", metavar="TOML",
                   help="text added to the campaign file (e.g. its [analytical] model)")
    a = p.parse_args(argv)
    hidden = {k: float(v) for k, v in (h.split("=", 1) for h in a.hidden)}
    points = [PoseTested(n, float(z), float(az), float(t))
              for n, z, az, t in (s.split(":") for s in a.pose)]
    path = write_campaign(a.scene, hidden, points, a.out, a.identify, a.model, a.modes,
                          a.frequency_noise_percent / 100, a.shape_noise_percent / 100, a.seed,
                          a.append.replace("\\n", "\n"), a.name, _commit())
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""A modal test campaign file (TOML): the machine tested (its scene), the poses it was tested at
with their UFF files, how test and model modes are paired, and which scene keys to identify.

```toml
scene = "machine.toml"             # relative to this file
geometry = "geometry.unv"          # optional: nodes (15/2411), coordinate systems (2420/18)
[[pose]]
name = "mid"
height_mm = 600.0
azimuth_deg = 25.0
tilt_deg = 8.0
data = "mid.unv"                   # UFF: modes (55) or FRFs (58) (+ nodes, or the geometry's)
[identify]                         # optional
keys = ["stiffness.actuator_axial_n_per_um", "stiffness.base_joint_translational_n_per_um"]
```
Every key is declared below (`docs/campaigns.md` is generated from these declarations).
Everything is checked when the file is read, before any model is solved: the scene, each
pose's reach, each UFF file (read, and with FRFs its modes identified), each node's body,
each key to identify and its bounds. Units at this edge as in scenes; SI inside.
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import MISSING, dataclass, field, replace
from pathlib import Path
from typing import Any, Callable

import numpy as np

from analytical.kinematics import PoseError, PoseGeometry, pose_geometry
from analytical.params import ModelOptions, Pose
from common.settings import MAX_MODES, setting, spec_of, text_problem
from scene import Scene
from scene.address import Address, edited_text, resolve, with_values
from scene.cases import CaseSettings
from scene.load import SceneError, parse_scene
from scene.toml_table import Table, read_toml, short

from . import uff
from .campaign_files import geometries
from .campaign_files import relative as _relative
from .ema import EmaError, EmaSettings, extract
from .placement import Placement, place

MAX_POSES = 50  # a campaign's poses at most (each one model solve per evaluation)
MAX_EMA_POINTS = 10_000_000  # FRF values in one pose's band: about a minute of LSCF at order 60
# (1 s measured for 1.5e5 values, 36 FRFs x 4059 lines; linear in the values)


def _pose_setting(name: str, doc: str, default: Any = MISSING) -> Any:
    """A pose key declared as the scene case's, with its own meaning."""
    return field(default=default,
                 metadata={"setting": replace(spec_of(CaseSettings, name), doc=doc)})


@dataclass(frozen=True)
class CampaignSettings:
    """The campaign file's own keys."""

    scene: str = setting(kind=str, doc="the scene file of the machine tested, relative to the "
                         "campaign file")
    name: str = setting("modal test campaign", kind=str, doc="title of the campaign")
    geometry: str = setting("", kind=str, doc="a UFF file of the test's geometry, relative to "
                            "the campaign file: nodes (dataset 15 or 2411) and the coordinate "
                            "systems they use (2420 or 18; Cartesian), units from its 164 (else "
                            "mm); every pose's data file may then hold modes or FRFs alone, its "
                            "own nodes winning for the labels both define, and a data file "
                            "without a 164 takes this file's units. Empty: none")
    node_tolerance: float = setting(
        0.010, unit="mm", minimum=0.0, maximum=1.0,
        doc="a test node lies on a body (the platform or a leg) when inside it or at most this "
        "far from its surface; nearer bodies win, a tie goes to the platform")


@dataclass(frozen=True)
class PoseSettings:
    """One [[pose]]: where the machine stood and the file of what was measured there."""

    name: str = setting(kind=str, doc="name of the pose (unique; names its rows in every "
                        "output)")
    height: float = _pose_setting("height", "z of the platform centre o during the test")
    data: str = setting(kind=str, doc="the UFF file of this pose, relative to the campaign "
                        "file: modes (55) or FRFs (58; modes identified with sdypy-EMA by "
                        "[ema]) and, unless a geometry file gives them, nodes (dataset 15 or "
                        "2411; mm unless a 164 units record says otherwise; a node's "
                        "definition and displacement coordinate systems, 2420 or 18, turn its "
                        "position and its direction codes into the base frame)")
    geometry: str = setting("", kind=str, doc="this pose's geometry file (as the top-level "
                            "geometry, which it replaces for this pose: the nodes move with the "
                            "machine). Empty: the campaign's")
    azimuth: float = _pose_setting("azimuth", "phi, direction of the tilt axis (Eq. 1)",
                                   default=0.0)
    tilt: float = _pose_setting("tilt", "theta, tilt of the platform (Eq. 1)", default=0.0)


@dataclass(frozen=True)
class CorrelationSettings:
    """[correlation]: how test modes and model modes are paired."""

    min_mac: float = setting(0.6, minimum=0.0, maximum=1.0,
                             doc="least MAC of a pair: a test mode whose best candidate is "
                             "below it stays unpaired")
    max_frequency_deviation_percent: float = setting(
        30.0, minimum=0.0, exclusive_minimum=True, maximum=100.0,
        doc="largest |f_model / f_test - 1| of a pair, %: a shape that matches at a frequency "
        "this far off is another mode seen through too few sensors")
    extra_model_modes: int = setting(6, kind=int, minimum=0, maximum=MAX_MODES,
                                     doc="model modes solved beyond the test's count, so a test "
                                     "that missed modes still finds its partners")


@dataclass(frozen=True)
class IdentifySettings:
    """[identify]: scene keys fitted to the paired frequencies of every pose together."""

    keys: tuple[str, ...] = setting((), kind=tuple, item=str,
                                    doc="scene keys to identify ('table.key', any number of "
                                    "[manipulator], [material], [leg], [stiffness], [payload]); "
                                    "bounds per key in [identify.bounds] as \"key\" = [low, high] "
                                    "in its unit, else initial / bound_factor to initial * "
                                    "bound_factor within the key's declared range")
    bound_factor: float = setting(10.0, minimum=1.0, exclusive_minimum=True, maximum=1e6,
                                  doc="default bounds of a key: its initial value divided and "
                                  "multiplied by this")
    frequency_noise_percent: float = setting(
        0.0, minimum=0.0, maximum=50.0,
        doc="standard deviation of a test frequency, %; 0: estimated from the fit's residuals "
        "(which then also carry the model's own error)")
    max_evaluations: int = setting(60, kind=int, minimum=1, maximum=1000,
                                   doc="model evaluations of the fit at most (each solves "
                                   "every pose once)")
    identifiable_within_percent: float = setting(
        10.0, minimum=0.0, exclusive_minimum=True, maximum=1000.0,
        doc="a key is identifiable when its 95 % interval (its profile likelihood's for a key "
        "correlated beyond 0.9 with another), taken at the noise's one-sided 95 % upper bound "
        "when the noise is estimated, lies within this of its value either side, % (and it "
        "does not sit at a bound of its search); otherwise it is flagged, its value not to be "
        "trusted")


@dataclass(frozen=True)
class EmaTable:
    """[ema]: modal identification from FRFs (sdypy-EMA, LSCF poles and LSFD residues); used by
    poses whose file holds FRFs (58)."""

    lower: float = setting(0.0, unit=None, scene_name="lower_hz", minimum=0.0, maximum=1e6,
                           doc="lower end of the band, Hz (0: the FRFs' first line above 0 Hz)")
    upper: float = setting(0.0, unit=None, scene_name="upper_hz", minimum=0.0, maximum=1e6,
                           doc="upper end of the band, Hz (0: the FRFs' last line)")
    model_order: int = setting(60, kind=int, minimum=5, maximum=400,
                               doc="highest polynomial order of the LSCF stabilisation chart")


@dataclass(frozen=True)
class TestPose:
    name: str
    pose: Pose
    geometry: PoseGeometry
    data: str  # the UFF file as resolved
    source: str  # what the modes come from
    modes: uff.Modes  # at the measured dofs
    nodes: uff.Nodes
    placements: list[Placement]
    # modes from FRFs: each frequency's standard uncertainty (relative), its scatter over the
    # stabilisation chart's stable orders (modaltest.ema); None: modes as the file gives them
    frequency_uncertainty: np.ndarray | None = None


@dataclass(frozen=True)
class Parameter:
    address: Address
    initial: float  # edge unit, the scene's value (0: a rigid spring)
    low: float
    high: float

    @property
    def start(self) -> float:
        """Where the fit starts: the scene's value, or for a rigid spring the geometric
        middle of its bounds."""
        return self.initial if self.initial > 0.0 else math.sqrt(self.low * self.high)


@dataclass(frozen=True)
class Campaign:
    path: str
    name: str
    scene_path: str
    scene: Scene
    raw_scene: dict
    poses: tuple[TestPose, ...]
    correlation: CorrelationSettings
    identify: IdentifySettings
    parameters: tuple[Parameter, ...]
    node_tolerance: float
    analytical: ModelOptions  # the campaign's [analytical], else the scene's
    analytical_given: bool

    def scene_with(self, values: dict[Address, float]) -> Scene:
        """The campaign's scene with addressed keys set (edge units), parsed and checked."""
        return parse_scene(with_values(self.raw_scene, values), self.scene_path)


@dataclass(frozen=True)
class _PoseEntry:
    spec: PoseSettings
    where: str
    pose: Pose
    geometry: PoseGeometry


def _pose_entry(table: Table, scene: Scene) -> _PoseEntry:
    """A [[pose]] read and its reach checked (no file read yet)."""
    spec = table.settings(PoseSettings)
    table.done()
    where = table.where
    pose = Pose(height=spec.height, azimuth=spec.azimuth, tilt=spec.tilt)
    try:
        geometry = pose_geometry(scene.manipulator, pose)
    except PoseError as exc:
        raise SceneError(f"{where} (height_mm = {spec.height * 1e3:g}, azimuth_deg = "
                         f"{math.degrees(spec.azimuth):g}, tilt_deg = "
                         f"{math.degrees(spec.tilt):g}): the machine cannot reach this pose: "
                         f"{exc}") from None
    return _PoseEntry(spec, where, pose, geometry)


def _pose(entry: _PoseEntry, campaign_dir: Path, scene: Scene, ema: EmaTable | None,
          tolerance: float, geometry: uff.Geometry | None = None) -> TestPose:
    """A pose's test data read (its modes identified from FRFs) and its nodes placed; the
    nodes from its file, else from `geometry` (the campaign's or the pose's geometry file)."""
    spec, where = entry.spec, entry.where
    path = _relative(campaign_dir, spec.data, f"{where}.data")
    typed = f"{where}.data = {short(spec.data)}"  # every refusal of the file names the key
    try:
        return _read_pose(entry, path, typed, scene, ema, tolerance, geometry)
    except (uff.UffError, EmaError) as exc:
        raise SceneError(f"{typed}: {exc}") from None


def _read_pose(entry: _PoseEntry, path: Path, typed: str, scene: Scene,
               ema: EmaTable | None, tolerance: float,
               nodes_from: uff.Geometry | None = None) -> TestPose:
    spec, pose, geometry = entry.spec, entry.pose, entry.geometry
    content = uff.read_uff(path, shown="", geometry=nodes_from)
    uncertainty = None
    if content.modes is not None:
        modes = content.modes
        source = "modes (UFF 55)"
    else:
        assert content.frfs is not None  # read_uff refuses a file with neither
        axis = content.frfs.frequency_hz
        lower = ema.lower if ema is not None and ema.lower > 0 else float(axis[axis > 0][0])
        upper = ema.upper if ema is not None and ema.upper > 0 else float(axis[-1])
        if not upper > lower:
            raise SceneError(f"{typed}: [ema] lower_hz {lower:g} is not below the FRFs' last "
                             f"line {upper:g} Hz")
        settings = EmaSettings(lower_hz=float(lower), upper_hz=float(upper),
                               model_order=ema.model_order if ema is not None else 60)
        band = (axis >= settings.lower_hz) & (axis <= settings.upper_hz)
        points = int(band.sum()) * len(content.frfs.values)
        if points > MAX_EMA_POINTS:  # LSCF's cost grows with FRFs x lines (x order^2)
            raise SceneError(f"{typed}: {len(content.frfs.values)} FRFs x "
                             f"{int(band.sum())} lines in the band = {points:,} values; at most "
                             f"{MAX_EMA_POINTS:,} are identified in one pose (measured 1 s "
                             "for 1.5e5 at order 60): narrow [ema] lower_hz/upper_hz or "
                             "give fewer FRFs")
        found = extract(content.frfs, settings)
        modes, uncertainty = found.modes, found.frequency_scatter
        source = (f"FRFs (UFF 58), modes identified in {settings.lower_hz:g}-"
                  f"{settings.upper_hz:g} Hz (pLSCF up to {2 * settings.model_order} poles, "
                  f"sdypy-EMA's LSFD): {found.describe()}")
    measured = set(int(n) for n in modes.dofs.node)
    keep = [i for i, n in enumerate(content.nodes.ids) if int(n) in measured]
    nodes = uff.Nodes(content.nodes.ids[keep], content.nodes.xyz[keep])
    placements = place(scene.manipulator, geometry, nodes.ids, nodes.xyz, tolerance, typed)
    return TestPose(spec.name, pose, geometry, str(path), source, modes, nodes, placements,
                    uncertainty)


def _varies_alone(parameter: Parameter, raw_scene: dict, scene: Scene, text: str,
                  where: str) -> None:
    """The key, moved, gives the machine the scene file would give with that value (so the
    fit's machines are the scene's: a key of the other architecture, or one another key
    derives, is refused here), and the scene file's text can be rewritten with it
    (identified.toml)."""
    address = parameter.address
    value = parameter.start * 1.01 if parameter.start * 1.01 <= parameter.high else (
        parameter.start * 0.99)
    try:
        parsed = parse_scene(with_values(raw_scene, {address: value}), scene.path).manipulator
        moved = address.applied(scene.manipulator, value)
    except (SceneError, ValueError) as exc:
        raise SceneError(f"{where} cannot be varied on this scene: {exc}") from None
    if parsed != moved:
        raise SceneError(f"{where} cannot be varied alone on this scene: other values of it "
                         "derive from it")
    try:
        edited = tomllib.loads(edited_text(text, {address: value}))
        ok = edited[address.table][address.key] == value
    except (tomllib.TOMLDecodeError, KeyError, TypeError):
        ok = False
    if not ok:
        raise SceneError(f"{where}: the scene file {scene.path} gives [{address.table}] in a "
                         "form identified.toml cannot be written from (a dotted or quoted key, "
                         "an inline table); write it as `key = value` lines under "
                         f"[{address.table}]")


def _parameters(ident: Table, settings: IdentifySettings, scene: Scene, raw_scene: dict,
                text: str, where: str) -> tuple[Parameter, ...]:
    bounds_t = ident.table("bounds", {})
    bounds_t.used.update(bounds_t.data)
    out = []
    seen: set[str] = set()
    for key in settings.keys:
        address = resolve(key, f"{where}.keys:")
        if address.name in seen:
            raise SceneError(f"{where}.keys: {key!r} is given twice")
        seen.add(address.name)
        initial = address.value(scene)
        given = bounds_t.data.get(key)
        if not initial > 0.0 and given is None:
            raise SceneError(f"{where}.keys: {key!r} is {initial:g} in the scene "
                             f"({'rigid' if address.table == 'stiffness' else 'zero'}): a key "
                             "is fitted in log space; give its [identify.bounds] (the fit "
                             "starts at their geometric middle) or a positive value in the "
                             "scene")
        if given is None:
            low, high = initial / settings.bound_factor, initial * settings.bound_factor
            spec = address.spec
            if spec.minimum is not None:
                low = max(low, spec.edge(spec.minimum) * (1.0 + 1e-9))
            if spec.maximum is not None:
                high = min(high, spec.edge(spec.maximum))
        else:
            if (not isinstance(given, list) or len(given) != 2
                    or not all(isinstance(b, (int, float)) and not isinstance(b, bool)
                               and math.isfinite(b) for b in given)
                    or not 0.0 < given[0] < given[1]):
                raise SceneError(f"{where}.bounds.{key} = {short(given)}: expected [low, high], "
                                 "two finite positive numbers, low below high")
            for b in given:
                why = address.problem(b)
                if why is not None:
                    raise SceneError(f"{where}.bounds.{key} = {short(given)}: {b!r} {why}")
            low, high = float(given[0]), float(given[1])
            if initial > 0.0 and not low <= initial <= high:
                raise SceneError(f"{where}.bounds.{key} = {short(given)}: excludes the initial "
                                 f"value {initial:g} {address.unit} the scene gives")
        parameter = Parameter(address, initial, low, high)
        _varies_alone(parameter, raw_scene, scene, text, f"{where}.keys: {key!r}")
        out.append(parameter)
    unknown = sorted(set(bounds_t.data) - set(settings.keys))
    if unknown:
        raise SceneError(f"{where}.bounds: {unknown[0]!r} is not one of keys")
    return tuple(out)


def load_campaign(path: str | Path, need_keys: bool = False,
                  before_data: Callable[[Scene], None] | None = None) -> Campaign:
    """Read and check a campaign, its scene, poses, files and nodes; SceneError (one line)
    on any problem, before any model is solved. The cheap checks come first (every key, every
    pose's reach, `need_keys`: an [identify] with keys, then `before_data`, the caller's own),
    then the files are read (and modes identified from FRFs) and their nodes placed."""
    path = Path(path)
    raw = read_toml(path, "campaign file")
    where = str(path)
    top = Table(raw, where)
    settings = top.settings(CampaignSettings)
    for name in ("name",):
        why = text_problem(getattr(settings, name))
        if why is not None:
            raise SceneError(f"{where}.{name}: {why}")
    scene_path = _relative(path.parent, settings.scene, f"{where}.scene")
    raw_scene = read_toml(scene_path, f"{where}.scene = {settings.scene!r}: scene file")
    scene = parse_scene(raw_scene, str(scene_path))

    tables = {}
    for key, cls in (("correlation", CorrelationSettings), ("identify", IdentifySettings)):
        t = top.table(key, {})
        tables[key] = (t, t.settings(cls))
    ana_t = top.table("analytical", {})
    analytical = (ana_t.settings(ModelOptions, {"joint_coupling": scene.fem.coupling},
                                 modes=scene.fidelity.modes)
                  if "analytical" in raw else scene.analytical)
    ana_t.done()
    ema_t = top.table("ema", {})
    ema_table = ema_t.settings(EmaTable)
    ema_t.done()
    ema = None
    if "ema" in raw:
        if ema_table.upper and not ema_table.upper > ema_table.lower:
            raise SceneError(f"{where}.ema: upper_hz {ema_table.upper:g} must lie above lower_hz "
                             f"{ema_table.lower:g}")
        ema = ema_table  # each pose's band from it and its FRFs' axis (0: the axis's end)

    pose_list = top.get("pose", None)
    if not isinstance(pose_list, list) or not pose_list:
        raise SceneError(f"{where}.pose: missing: give at least one [[pose]] with its data")
    if len(pose_list) > MAX_POSES:
        raise SceneError(f"{where}.pose: {len(pose_list)} poses; at most {MAX_POSES}")
    entries = [_pose_entry(Table(entry, f"{where}.pose[{k}]"), scene)
               for k, entry in enumerate(pose_list)]
    names = [e.spec.name for e in entries]
    for name in names:
        why = text_problem(name)
        if why is not None or not name.strip():
            raise SceneError(f"{where}.pose: name {short(name)}: {why or 'empty'}")
    if len(set(names)) != len(names):
        raise SceneError(f"{where}.pose: names {names} repeat; each pose needs its own name")

    ident_t, identify = tables["identify"]
    if need_keys and not identify.keys:
        raise SceneError(f"{where}.identify.keys: none; nothing to identify")
    text = scene_path.read_text(encoding="utf-8")
    parameters = _parameters(ident_t, identify, scene, raw_scene, text, f"{where}.identify")
    for key in ("correlation", "identify"):
        tables[key][0].done()
    top.done()
    if before_data is not None:
        before_data(scene)
    files = geometries([(f"{where}.geometry", settings.geometry)] + [
        (f"{e.where}.geometry", e.spec.geometry) for e in entries], path.parent)
    poses = [_pose(e, path.parent, scene, ema, settings.node_tolerance,
                   files.get(e.spec.geometry or settings.geometry)) for e in entries]
    return Campaign(str(path), settings.name, str(scene_path), scene, raw_scene, tuple(poses),
                    tables["correlation"][1], identify, parameters, settings.node_tolerance,
                    analytical, "analytical" in raw)


DECLARED = ((CampaignSettings, "top level", "The campaign's own keys."),
            (PoseSettings, "[[pose]]", "One entry per pose tested: where the machine stood "
             "and the file of what was measured there."),
            (CorrelationSettings, "[correlation]", "How test modes and model modes are paired "
             "(modaltest/correlate.py): by shape and frequency, never by order alone; a group "
             "of near-repeated modes (within 2 %) is compared as a subspace."),
            (IdentifySettings, "[identify]", "Scene keys fitted to the paired frequencies of "
             "every pose together, in log space, bounded, with eigenvalue sensitivities; 95 % "
             "intervals and identifiability (modaltest/identify.py). Optional."),
            (EmaTable, "[ema]", "Modes from FRFs: poly-reference LSCF poles (every "
             "reference together) read from a stabilisation chart (a pole stable over 5 "
             "consecutive orders within 1 % in frequency and 10 % in damping; close modes "
             "kept apart), sdypy-EMA's LSFD residues, shapes from every reference "
             "(modaltest/ema.py). Optional; used "
             "by poses whose file holds FRFs."),
            (ModelOptions, "[analytical]", "The analytical model correlated and fitted "
             "(optional; as a scene's [analytical], docs/scenes.md); default: the scene's."))

"""Hard cases of the analytical model: physics and numerics claims, each with its tolerance,
measured (issue 12: "test numerical stability on hard cases").

Every claim is a function of a scene returning a `Row` (case, claim, tolerance, measured);
`evaluate(scene)` runs the ones that take seconds, for the report's "Hard cases" section.
tests/test_hard.py (marker `hard`) asserts every one of them on the paper's machine, and adds
the FEM's hard cases (repeated pairs over mesh sizes, residuals, retried eigen solves).
The machines are the scene's, changed with dataclasses.replace (slender or stocky legs, a thin
plate, other metals, turned layouts, lower joint limits).
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, replace
import math

import numpy as np

from analytical.batch_model import (assemble_batch, batch_frequencies, batch_modes,
                                    probe_shapes, standard_form)
from analytical.kinematics import PoseError, pose_geometry
from analytical.model import analyse, natural_frequencies
from analytical.params import Manipulator, Material, ModelOptions, Pose
from analytical.pose_batch import pose_batch
from analytical.tracking import family_values, track_path
from analytical.reach import (WorkspaceError, layer_heights, max_tilts, regular_radii,
                              regular_radius, sample_poses)
from common.modes import clusters

from scene import Scene

SEED = 20231201


@dataclass(frozen=True)
class Row:
    case: str
    claim: str
    tolerance: float
    measured: float
    unit: str = ""
    note: str = ""

    @property
    def passed(self) -> bool:
        return bool(self.measured <= self.tolerance)

    def to_dict(self) -> dict:
        return {**asdict(self), "passed": self.passed}


def turned(m: Manipulator, angle: float) -> Manipulator:
    """The same machine with its leg layout turned by `angle` (rad) about z."""
    return replace(m, leg_angles=tuple(a + angle for a in m.leg_angles))


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


# --- repeated eigenvalues --------------------------------------------------------------------

def repeated_pairs(scene: Scene, runs: int = 1000, modes: int = 8) -> Row:
    """Level poses have the mechanism's three-fold symmetry, so their modes come in exactly
    repeated pairs. Over `runs` random layout turns, heights and rigid rotations of the whole
    machine, every pair of the unturned machine stays repeated (relative split below 1e-9) and
    every frequency stays the unturned machine's (to 1e-9)."""
    m, opts = scene.manipulator, replace(scene.analytical, modes=modes)
    rng = np.random.default_rng(SEED)
    heights = layer_heights(m, 2)
    worst = 0.0
    for _ in range(runs):
        z = float(rng.uniform(*heights))
        reference = natural_frequencies(m, Pose(z), opts)
        groups = [g for g in clusters(reference, 1e-6) if len(g) > 1 and g[-1] < modes - 1]
        machine = turned(m, float(rng.uniform(0, 2 * math.pi)))
        geometry = pose_geometry(machine, Pose(z)).transformed(random_rotation(rng),
                                                               rng.standard_normal(3))
        f = analyse(machine, Pose(z), opts, geometry=geometry).frequencies_hz
        split = max((f[g[-1]] / f[g[0]] - 1 for g in groups), default=0.0)
        worst = max(worst, split, float(np.max(np.abs(f / reference - 1))))
    return Row("repeated pairs, 1,000 random symmetric poses",
               "every repeated pair of a level pose stays repeated and every frequency stays "
               "put under layout turns, heights and rigid rotations", 1e-9, worst, "relative")


def turned_layout(scene: Scene, poses: int = 300) -> Row:
    """A layout turned by gamma, posed at azimuth phi + gamma, is the same machine turned:
    its frequencies equal the unturned ones at phi (to 1e-9), at random tilted poses."""
    m, opts = scene.manipulator, scene.analytical
    rng = np.random.default_rng(SEED + 1)
    worst = 0.0
    for pose in sample_poses(m, poses, rng):
        gamma = float(rng.uniform(0, 2 * math.pi))
        f = natural_frequencies(turned(m, gamma),
                                Pose(pose.height, pose.azimuth + gamma, pose.tilt), opts)
        worst = max(worst, float(np.max(np.abs(f / natural_frequencies(m, pose, opts) - 1))))
    return Row("leg layout turned", "frequencies of a turned layout equal the unturned ones at "
               "the turned azimuth (300 random poses)", 1e-9, worst, "relative")


# --- eigen-solutions checked ----------------------------------------------------------------

def eigen_residuals(scene: Scene, elements=(1, 2, 3, 5, 10)) -> Row:
    """Every eigenpair the analytical model returns satisfies K x = omega^2 M x to a relative
    residual |K x - omega^2 M x| / |K x| below 1e-8, over the scene's cases, s = 1..10 and
    both beam theories (M-orthonormality is checked by solve_modes to 1e-6 and measured in
    the test to 1e-10)."""
    worst = 0.0
    for case in scene.cases.values():
        for s in elements:
            for beam in ("euler-bernoulli", "timoshenko"):
                opts = replace(scene.analytical, elements=s, beam=beam,
                               modes=min(12, 18 * s))
                try:
                    modal = analyse(scene.manipulator, case.pose, opts).modal
                except PoseError:
                    continue
                worst = max(worst, float(modal.residuals.max()))
    return Row("eigen-solutions checked", "relative residual of every analytical eigenpair "
               "(scene cases, s = 1..10, both beam theories)", 1e-8, worst, "relative")


def mode_count(scene: Scene) -> Row:
    """Asking for n modes returns exactly n, for every n from 1 to the 18 s coordinates."""
    case = next(iter(scene.cases.values()))
    s = scene.analytical.elements
    wrong = sum(len(natural_frequencies(scene.manipulator, case.pose,
                                        replace(scene.analytical, modes=n))) != n
                for n in range(1, 18 * s + 1))
    return Row("mode count", "modes returned minus modes asked, every n = 1..18 s", 0.0,
               float(wrong), "modes")


def no_spurious_zero_mode(scene: Scene, poses: int = 2000) -> Row:
    """No mode collapses towards zero anywhere in the workspace: at random reachable poses the
    lowest frequency stays above a third of the level pose's at the same height (a spurious
    mechanism or a lost constraint would send it to zero). Measured as the worst shortfall
    below 1/3 (0 when it holds)."""
    m, opts = scene.manipulator, replace(scene.analytical, modes=1)
    sample = sample_poses(m, poses, np.random.default_rng(SEED + 2))
    z = np.array([p.height for p in sample])

    def f1(azimuths, tilts):
        batch = pose_batch(m, z, azimuths, tilts)
        return batch_frequencies(standard_form(assemble_batch(m, batch, opts)), 1)[:, 0]

    ratio = f1([p.azimuth for p in sample], [p.tilt for p in sample]) / f1(0.0, 0.0)
    lowest = float(ratio.min())
    return Row("no spurious near-zero mode", "f1 at 2,000 random poses over f1 of the level "
               "pose at that height stays above 1/3 (measured: 1/3 minus the lowest ratio)",
               0.0, max(0.0, 1 / 3 - lowest), note=f"lowest ratio {lowest:.3f}")


# --- continuity and tracking ----------------------------------------------------------------

def _path_modes(m: Manipulator, opts: ModelOptions, start: Pose, end: Pose, steps: int):
    """Frequencies (n, w), probe shapes (n, d, w), and d lambda / dt (n, w) along a straight
    path in (height, azimuth, tilt); the derivative by Hellmann-Feynman, x^T (dK - lambda dM) x
    with dK, dM central differences of the assembled matrices."""
    t = np.linspace(0.0, 1.0, steps)
    ends = np.array([[start.height, start.azimuth, start.tilt],
                     [end.height, end.azimuth, end.tilt]])

    def at(tt):
        p = ends[0] + np.outer(tt, ends[1] - ends[0])
        return assemble_batch(m, pose_batch(m, p[:, 0], p[:, 1], p[:, 2]), opts)

    h = 1e-6
    plus, minus = at(t + h), at(t - h)
    d_k = (plus.stiffness - minus.stiffness) / (2 * h)
    d_m = (plus.mass - minus.mass) / (2 * h)
    model = at(t)
    form = standard_form(model)
    hz, x = batch_modes(form, np.arange(steps), opts.modes)
    lam = (2 * math.pi * hz) ** 2
    rate = (np.einsum("nia,nij,nja->na", x, d_k, x)
            - lam * np.einsum("nia,nij,nja->na", x, d_m, x))
    return t, hz, probe_shapes(model, x), rate


def straight_path(m: Manipulator, steps: int = 120) -> tuple[Pose, Pose, str]:
    """A straight path across the workspace: from a quarter to three quarters of the layer
    band in height, azimuth 0.3 -> 2.6 rad, tilt from 20 % to 80 % of the smaller regular
    radius of its two ends. The workspace need not be convex in (height, azimuth, tilt): where
    a pose of the path (at `steps` points) is unreachable, the tilts are halved until every
    pose is (level poses over the band always are). The note says so where it happened."""
    z = layer_heights(m, 5)
    radius = float(regular_radii(m, [z[1], z[3]]).min())
    t = np.linspace(0.0, 1.0, steps)
    for scale in 0.5 ** np.arange(12):
        start = Pose(float(z[1]), 0.3, 0.2 * radius * scale)
        end = Pose(float(z[3]), 2.6, 0.8 * radius * scale)
        path = pose_batch(m, start.height + t * (end.height - start.height),
                          start.azimuth + t * (end.azimuth - start.azimuth),
                          start.tilt + t * (end.tilt - start.tilt))
        if path.feasible.all():
            return start, end, ("" if scale == 1 else f"tilts scaled by {scale:g} to keep "
                                "every pose of the path reachable")
    return (Pose(float(z[1]), 0.3, 0.0), Pose(float(z[3]), 2.6, 0.0),
            "level poses only: no tilted straight path of this machine is reachable")


def continuity(scene: Scene, steps: int = 120, modes: int = 6) -> Row:
    """Along a straight path in (height, azimuth, tilt), every followed family moves by what
    its derivative explains: each step's change of omega^2 differs from the trapezoid of the
    Hellmann-Feynman derivatives at its ends by less than 2 % of the change (no jump). The
    first six families are followed among nine modes, so one crossing a higher mode stays
    followed."""
    m, opts = scene.manipulator, replace(scene.analytical, modes=modes + 3)
    start, end, note = straight_path(m, steps)
    t, hz, shapes, rate = _path_modes(m, opts, start, end, steps)
    order, quality = track_path(hz, shapes)
    kept = np.minimum.accumulate(quality[:, :modes] >= 0.5, axis=0)[1:]  # not left the modes
    lam = family_values((2 * math.pi * hz) ** 2, order)[:, :modes]
    slope = family_values(rate, order)[:, :modes]
    step = np.diff(lam, axis=0)
    predicted = np.diff(t)[:, None] * 0.5 * (slope[1:] + slope[:-1])
    mismatch = np.abs(step - predicted) / np.maximum(np.abs(step), 1e-9 * lam[1:])
    return Row("continuity along a straight pose path", "each step's change of every family's "
               f"omega^2 against the trapezoid of its derivatives ({steps} steps)", 0.02,
               float(mismatch[kept].max()), "relative", note)


def near_crossing(scene: Scene, steps: int = 60) -> Row:
    """Level poses keep the three-fold symmetry, so families of different symmetry cross
    exactly as the height changes (on the paper's machine a repeated pair falls through a
    threefold leg mode near z = 248.5 mm). Tilted by 1e-4 rad the symmetry is broken and the
    crossing becomes a near-crossing. Followed by shape through it, no family swaps with
    another: every step keeps every family's shape (MAC, or subspace MAC inside a repeated
    group) above 0.9."""
    m, opts = scene.manipulator, replace(scene.analytical, modes=9)
    heights = layer_heights(m, 41)
    _, hz, shapes, _ = _path_modes(m, opts, Pose(heights[0]), Pose(heights[-1]),
                                   len(heights))
    order, _ = track_path(hz, shapes)
    swapped = np.flatnonzero(np.any(order[1:] != order[:-1], axis=1))
    if not len(swapped):
        return Row("near-crossing tracked without swaps", "no two of the first nine families "
                   "cross at level poses: nothing to test", 0.1, 0.0)
    k = int(swapped[0])
    start = Pose(float(heights[k]), 0.4, 1e-4)
    end = Pose(float(heights[k + 1]), 0.4, 1e-4)
    if not pose_batch(m, np.linspace(start.height, end.height, steps), 0.4,
                      1e-4).feasible.all():
        return Row("near-crossing tracked without swaps", "the machine cannot tilt by 1e-4 rad "
                   "at the crossing: nothing to test", 0.1, 0.0)
    _, hz, shapes, _ = _path_modes(m, opts, start, end, steps)
    _, quality = track_path(hz, shapes)
    return Row("near-crossing tracked without swaps", "1 - the lowest MAC of a followed "
               f"family between neighbouring poses, {steps} steps through the near-crossing at "
               f"{1e3 * heights[k]:.1f}-{1e3 * heights[k + 1]:.1f} mm, tilt 1e-4 rad", 0.1,
               float(1.0 - quality.min()))


# --- geometry --------------------------------------------------------------------------------

def _ratio_over_poses(m_a, opts_a, m_b, opts_b, poses) -> np.ndarray:
    return np.array([natural_frequencies(m_a, p, opts_a) / natural_frequencies(m_b, p, opts_b)
                     for p in poses])


def beam_theory_gap(scene: Scene, slenderness: float, poses: int = 50) -> float:
    """Largest |f Timoshenko / f Euler-Bernoulli - 1| over six modes and random poses of the
    scene's machine with legs of L/d = `slenderness` (L at the middle level pose)."""
    m = scene.manipulator
    length = pose_geometry(m, Pose(float(layer_heights(m, 3)[1]))).leg_lengths[0]
    machine = replace(m, leg_diameter=length / slenderness)
    sample = sample_poses(machine, poses, np.random.default_rng(SEED + 3))  # may raise
    ratio = _ratio_over_poses(machine, replace(scene.analytical, beam="timoshenko", modes=6),
                              machine, replace(scene.analytical, beam="euler-bernoulli",
                                               modes=6), sample)
    return float(np.abs(ratio - 1).max())


def slender_legs(scene: Scene) -> Row:
    """Slender legs (L/d = 30 at mid height): shear deformation and rotary inertia scale with
    (d/L)^2, so Euler-Bernoulli and Timoshenko beams agree within 1 % on six modes (the test
    also checks the (d/L)^2 scaling against L/d = 60)."""
    case = "slender legs, L/d = 30"
    try:
        gap = beam_theory_gap(scene, 30.0)
    except WorkspaceError as exc:
        return _untestable(case, 0.01, exc)
    return Row(case, "|f Timoshenko / f Euler-Bernoulli - 1|, six modes, 50 poses", 0.01, gap,
               "relative")


def _untestable(case: str, tolerance: float, exc: Exception) -> Row:
    """The row of a claim whose changed machine reaches no pose to test it at."""
    return Row(case, "nothing to test: the changed machine reaches no pose", tolerance, 0.0,
               note=str(exc))


def stocky_legs(scene: Scene) -> Row:
    """Stocky legs (L/d = 3 at mid height): shear flexibility and rotary inertia only lower
    the frequencies, so Timoshenko is below Euler-Bernoulli on every mode at every pose
    (measured: the largest f_T / f_EB - 1, which must not exceed rounding, 1e-9)."""
    m = scene.manipulator
    z = float(layer_heights(m, 3)[1])
    length = pose_geometry(m, Pose(z)).leg_lengths[0]
    stocky = replace(m, leg_diameter=length / 3)
    try:
        poses = sample_poses(stocky, 50, np.random.default_rng(SEED + 4))
    except WorkspaceError as exc:
        return _untestable("stocky legs, L/d = 3", 1e-9, exc)
    ratio = _ratio_over_poses(stocky, replace(scene.analytical, beam="timoshenko", modes=6),
                              stocky, replace(scene.analytical, beam="euler-bernoulli",
                                              modes=6), poses)
    return Row("stocky legs, L/d = 3", "largest f Timoshenko / f Euler-Bernoulli - 1, six "
               "modes, 50 poses", 1e-9, float((ratio - 1).max()), "relative")


def thin_plate(scene: Scene) -> Row:
    """A 5 mm platform (half the scene's, if that is thinner) is lighter than the scene's and
    nothing stiffer is lost (the platform is rigid in the model), so no frequency falls
    (Courant-Fischer: less mass never lowers an eigenvalue). Measured: the largest fall,
    1 - f(thin) / f(scene's plate), against rounding (1e-9). A thinner plate only moves away
    from the base, so every pose of the scene's machine stays reachable."""
    m = scene.manipulator
    thickness = min(THIN_PLATE, 0.5 * m.platform_thickness)
    thin = replace(m, platform_thickness=thickness)
    poses = sample_poses(m, 50, np.random.default_rng(SEED + 5))
    opts = replace(scene.analytical, modes=6)
    ratio = _ratio_over_poses(thin, opts, m, opts, poses)
    return Row(f"thin plate, {thickness * 1e3:g} mm", "largest fall of a frequency from the "
               f"{m.platform_thickness * 1e3:g} mm plate to the {thickness * 1e3:g} mm one, 50 "
               "poses", 1e-9, float(max(0.0, (1 - ratio).max())), "relative")


THIN_PLATE = 0.005  # m


ALUMINIUM = (70e9, 2700.0)  # E (Pa), rho (kg/m^3)
TITANIUM = (113.8e9, 0.342, 4430.0)  # Ti-6Al-4V: E (Pa), Poisson ratio, rho


def aluminium_scaling(scene: Scene) -> Row:
    """With steel's Poisson ratio, an aluminium machine has K scaled by E and M by rho: every
    frequency scales by sqrt(E rho_steel / (E_steel rho)) exactly (to 1e-9)."""
    m = scene.manipulator
    e, rho = ALUMINIUM
    scale = e / m.material.youngs_modulus
    aluminium = replace(m, material=Material(e, m.material.shear_modulus * scale, rho))
    expected = math.sqrt(scale * m.material.density / rho)
    poses = sample_poses(m, 30, np.random.default_rng(SEED + 6))
    ratio = _ratio_over_poses(aluminium, scene.analytical, m, scene.analytical, poses)
    return Row("aluminium", "|f_Al / f_steel / sqrt(E_Al rho_steel / (E_steel rho_Al)) - 1|, "
               "steel's Poisson ratio", 1e-9, float(np.abs(ratio / expected - 1).max()),
               "relative")


def titanium_scaling(scene: Scene) -> Row:
    """A titanium machine (Ti-6Al-4V, its own Poisson ratio 0.342), Euler-Bernoulli legs:
    K = E K_E + G K_G with both parts positive semi-definite and M proportional to rho, so by
    Courant-Fischer every frequency ratio to steel lies between sqrt(E ratio / rho ratio) and
    sqrt(G ratio / rho ratio). No mode deviates from the sqrt(E / rho) scaling by more than a
    pure torsion mode would: |1 - sqrt((1 + nu_steel) / (1 + nu_Ti))| = 1.6 %."""
    m = scene.manipulator
    e, nu, rho = TITANIUM
    titanium = replace(m, material=Material(e, e / (2 * (1 + nu)), rho))
    expected = math.sqrt(e / m.material.youngs_modulus * m.material.density / rho)
    bound = abs(1 - math.sqrt((1 + m.material.poisson_ratio) / (1 + nu)))
    poses = sample_poses(m, 30, np.random.default_rng(SEED + 7))
    opts = replace(scene.analytical, beam="euler-bernoulli")
    ratio = _ratio_over_poses(titanium, opts, m, opts, poses)
    return Row("titanium", "|f_Ti / f_steel / sqrt(E ratio / rho ratio) - 1| against the pure "
               "torsion bound |1 - sqrt((1 + nu_steel) / (1 + nu_Ti))|, Euler-Bernoulli",
               bound + 1e-9, float(np.abs(ratio / expected - 1).max()), "relative")


# --- workspace boundary and joint limits ----------------------------------------------------

def boundary_ring(scene: Scene, layers: int = 5, azimuths: int = 72) -> Row:
    """On the regular workspace's boundary (tilt theta_r(z) at every azimuth theta_r was
    found on) every pose is reachable and solves with residual below 1e-8; 1e-5 rad further
    out, the azimuth that bounds theta_r is unreachable. Measured: the worst residual, or 1
    for a pose on the wrong side."""
    m, opts = scene.manipulator, scene.analytical
    phis = np.linspace(0, 2 * math.pi, azimuths, endpoint=False)
    worst = 0.0
    for z in layer_heights(m, layers):
        radius = regular_radius(m, float(z), azimuths)
        bounding = phis[np.argmin(max_tilts(m, float(z), phis))]
        for phi in phis:
            try:
                modal = analyse(m, Pose(float(z), float(phi), radius), opts).modal
            except PoseError:
                return Row("workspace boundary", "a boundary pose is unreachable", 0.0, 1.0)
            worst = max(worst, float(modal.residuals.max()))
        if pose_batch(m, z, bounding, radius + 1e-5).feasible[0]:
            return Row("workspace boundary", "the boundary is not where theta_r says", 0.0, 1.0)
    return Row("workspace boundary", "residual at every boundary pose (5 layers x 72 "
               "azimuths); beyond it unreachable", 1e-8, worst, "relative")


LIMITS = {  # limit -> (the phrase PoseError uses, a change that makes it bind somewhere)
    "actuator_min": ("outside the actuator range", {}),
    "actuator_max": ("outside the actuator range", {}),
    "s_joint_max": ("S-joint", {}),
    "r_joint_max": ("R-joint", {"r_joint_max": math.radians(15.0)}),
}


def limit_pose(m: Manipulator, limit: str) -> Pose:
    """A pose where `limit` of Eq. (25) binds: the largest tilt reachable at some (height,
    azimuth), found to 1e-12 rad, with `limit` the constraint closest to violation there."""
    for z in np.linspace(0.0, 1.0, 41)[1:] * (m.actuator_max + m.base_radius):
        phis = np.linspace(0, 2 * math.pi, 24, endpoint=False)
        tilts = max_tilts(m, float(z), phis, 1e-12)
        poses = pose_batch(m, z, phis, tilts)
        for k in np.flatnonzero(poses.feasible & (tilts > 0)):
            margins = {
                "actuator_min": (poses.leg_lengths[k] - m.actuator_min).min(),
                "actuator_max": (m.actuator_max - poses.leg_lengths[k]).min(),
                "s_joint_max": (m.s_joint_max - np.abs(poses.s_joint_angles[k])).min(),
                "r_joint_max": (m.r_joint_max - np.abs(poses.r_joint_angles[k])).min(),
            }
            if min(margins, key=margins.get) == limit:
                return Pose(float(z), float(phis[k]), float(tilts[k]))
    raise ValueError(f"no pose of this machine has {limit} binding")


def joint_limit(scene: Scene, limit: str) -> Row:
    """At a pose where one limit of Eq. (25) binds, the model solves as anywhere else: the
    frequencies 1e-6 rad inside the limit differ from those at the limit by less than 1e-4
    (relative), i.e. nothing jumps at the edge (the test also checks that 1e-6 rad beyond the
    pose is refused, naming the limit)."""
    m = replace(scene.manipulator, **LIMITS[limit][1])
    case = (f"joint limit {limit} ({scene.manipulator.base_joint}-"
            f"{scene.manipulator.platform_joint})")
    try:
        pose = limit_pose(m, limit)
    except ValueError as exc:
        return Row(case, "nothing to test", 1e-4, 0.0, note=str(exc))
    inside = replace(pose, tilt=pose.tilt - 1e-6)
    f_edge = natural_frequencies(m, pose, scene.analytical)
    f_in = natural_frequencies(m, inside, scene.analytical)
    return Row(case, "relative change of every frequency over the last 1e-6 rad before the "
               "limit", 1e-4,
               float(np.abs(f_edge / f_in - 1).max()), "relative")


CHEAP = (repeated_pairs, turned_layout, eigen_residuals, mode_count, no_spurious_zero_mode,
         continuity, near_crossing, slender_legs, stocky_legs, thin_plate, aluminium_scaling,
         titanium_scaling, boundary_ring)


def _row(task) -> dict:
    claim, scene, argument = task
    return (claim(scene) if argument is None else claim(scene, argument)).to_dict()


def evaluate(scene: Scene, workers: int = 1) -> list[dict]:
    """The analytical hard cases of `scene` (about ten seconds of one core): rows for the
    report, in the order of CHEAP then LIMITS, the claims spread over `workers` processes."""
    from runtime.sweep import map_tasks

    tasks = [(claim, scene, None) for claim in CHEAP]
    tasks += [(joint_limit, scene, limit) for limit in LIMITS]
    rows = map_tasks(_row, tasks, workers)
    for (claim, _, argument), row in zip(tasks, rows):
        if "error" in row and "claim" not in row:
            raise RuntimeError(f"hard case {claim.__name__}"
                               f"{'' if argument is None else f' ({argument})'}: {row['error']}")
    return rows

"""The report's set-up tables: the manipulator, the fidelity asked, the calibrated values, the
poses and the environment of the run (what was computed, with what, where)."""
from __future__ import annotations

from typing import Literal

from results import Results

from .cells import Cells, head
from .results import escape

MANIPULATOR_ROWS = (  # key, label, unit, decimals
    ("base_radius_mm", "base radius r1", "mm", 1),
    ("platform_radius_mm", "platform radius r2", "mm", 1),
    ("leg_diameter_mm", "leg diameter d", "mm", 1),
    ("platform_thickness_mm", "platform thickness h", "mm", 1),
    ("youngs_modulus_gpa", "Young's modulus E", "GPa", 1),
    ("shear_modulus_gpa", "shear modulus G", "GPa", 1),
    ("poisson_ratio", "Poisson's ratio ν", "–", 3),
    ("density_kg_m3", "density ρ", "kg/m³", 0),
    ("s_joint_max_deg", "S-joint limit α_max", "deg", 1),
    ("r_joint_max_deg", "R-joint limit β_max", "deg", 1),
)


def setup_tables(results: Results, c: Cells) -> dict:
    return {"manipulator": manipulator_table(results, c), "fidelity": fidelity_table(results, c),
            "calibrated": calibrated_table(results, c), **pose_tables(results, c),
            "environment": environment_tables(results, c)}


def manipulator_table(results: Results, c: Cells) -> dict:
    m = results["scene"]["manipulator"]
    q = "/scene/manipulator"
    unit = lambda text: c.text(literal=text, cls="unit")  # noqa: E731
    rows = [[c.text(literal=label), c.num(f"{q}/{key}", digits), unit(u)]
            for key, label, u, digits in MANIPULATOR_ROWS]
    rows += [[c.text(literal=f"leg {i + 1} angle on the base"),
              c.num(f"{q}/leg_angles_deg/{i}", 1), unit("deg")]
             for i, _ in enumerate(m["leg_angles_deg"])]
    rows += [[c.text(literal="architecture"), c.text(f"{q}/architecture"), unit("")]]
    if m["rail_angle_deg"] is not None:  # a 3-PRS (analytical/architecture.py)
        rows += [[c.text(literal="rail angle from the base plane"),
                  c.num(f"{q}/rail_angle_deg", 1), unit("deg")],
                 [c.text(literal="leg length, joint to joint"),
                  c.num(f"{q}/leg_length_range_mm/0", 1), unit("mm")]]
        labels = ("slider travel minimum s_min", "slider travel maximum s_max")
    else:
        labels = ("actuator minimum L_min", "actuator maximum L_max")
    rows += [[c.text(literal=label), c.num(f"{q}/actuator_range_mm/{i}", 0), unit("mm")]
             for i, label in enumerate(labels)]
    rows += [[c.text(literal=label), c.text(f"{q}/{key}"), unit("")]
             for key, label in (("base_joint", "joint at the base"),
                                ("platform_joint", "joint at the platform"),
                                ("platform_shape", "platform shape"))]
    if m["payload"]["mass_kg"] > 0:  # a payload fixed to the platform (common/payload.py)
        p = f"{q}/payload"
        rows += [[c.text(literal="payload mass"), c.num(f"{p}/mass_kg", 2), unit("kg")]]
        rows += [[c.text(literal=f"payload centre {axis} (platform frame)"),
                  c.num(f"{p}/centre_mm/{i}", 1), unit("mm")] for i, axis in enumerate("xyz")]
        rows += [[c.text(literal=f"payload inertia about its centre, {axis}"),
                  c.num(f"{p}/inertia_kg_m2/{i}", 3), unit("kg m²")]
                 for i, axis in enumerate("xyz")]
    if m["leg"]["housing_length_mm"] > 0:  # an actuator leg (common/leg_profile.py)
        rows += [[c.text(literal=label), c.num(f"{q}/leg/{key}", 1), unit("mm")]
                 for key, label in LEG_ROWS]
    for key, label, u in STIFFNESS_ROWS:  # joint and drive springs (common/stiffness.py)
        if m["stiffness"][key] > 0:
            rows += [[c.text(literal=label), c.sci(f"{q}/stiffness/{key}"), unit(u)]]
    return {"head": [head("parameter", "value", "unit")], "rows": rows, "cls": "params"}


LEG_ROWS = (("housing_length_mm", "leg housing length, from the base joint"),
            ("housing_outer_diameter_mm", "housing outer diameter"),
            ("housing_inner_diameter_mm", "housing bore (0: solid)"),
            ("rod_outer_diameter_mm", "rod outer diameter"),
            ("rod_inner_diameter_mm", "rod bore (0: solid)"))
StiffnessKey = Literal["actuator_axial_n_per_um", "base_joint_translational_n_per_um",
                       "base_joint_rotational_nm_per_urad",
                       "platform_joint_translational_n_per_um",
                       "platform_joint_rotational_nm_per_urad"]  # the keys of results.Stiffness
STIFFNESS_ROWS: tuple[tuple[StiffnessKey, str, str], ...] = (
    ("actuator_axial_n_per_um", "drive axial stiffness (screw, nut, bearings)", "N/µm"),
    ("base_joint_translational_n_per_um", "base joint translational stiffness", "N/µm"),
    ("base_joint_rotational_nm_per_urad", "base joint rotational stiffness", "N m/µrad"),
    ("platform_joint_translational_n_per_um", "platform joint translational stiffness", "N/µm"),
    ("platform_joint_rotational_nm_per_urad", "platform joint rotational stiffness",
     "N m/µrad"))


def fidelity_table(results: Results, c: Cells) -> dict:
    """The settings the run used: the analytical model and FEM size of results.json's
    `fidelity` block (chosen by the run, or the scene's own, checked), not the scene's
    defaults."""
    q = "/fidelity/analytical"
    rows = [[c.text(literal="analytical: model used"), c.text(f"{q}/setting")],
            [c.text(literal="analytical: elements per leg s"), c.num(f"{q}/elements", None)]]
    rows += [[c.text(literal=f"analytical: {label}"), c.text(f"{q}/{key}")]
             for key, label in (("beam", "beam theory"), ("shear", "shear coefficient"),
                                ("joint_ends", "joint ends"),
                                ("platform_inertia", "platform inertia"))]
    rows += [[c.text(literal="modes compared"), c.num("/fidelity/modes", None)],
             [c.text(literal="tolerance (%)"), c.num("/fidelity/tolerance_percent", None)],
             [c.text(literal="FEM: mesh size h (mm)"), c.num("/fidelity/fem/mesh_size_mm", 1)]]
    rows += [[c.text(literal=f"FEM: refinement size {i + 1} (mm)"),
              c.num(f"/scene/fem/refinement_mm/{i}", 1)]
             for i, _ in enumerate(results["scene"]["fem"]["refinement_mm"])]
    tetrahedra = "" if results["scene"]["fem"]["legs"] == "tetrahedra" else \
        ", tetrahedral legs and plate only"  # the harmonic meridians grade their own corners
    rows += [[c.text(literal=f"FEM: rim element size (× h{tetrahedra})"),
              c.num("/scene/fem/rim_factor", 2)],
             [c.text(literal=f"FEM: rim zone (mm{tetrahedra})"),
              c.num("/scene/fem/rim_zone_mm", 1)]]
    rows += [[c.text(literal=f"FEM: {label}"), c.text(f"/scene/fem/{key}")]
             for key, label in (("legs", "legs discretised by"), ("platform", "platform"),
                                ("coupling", "joint coupling"))]
    return {"head": [head("setting", "value")], "rows": rows, "cls": "params"}


def calibrated_table(results: Results, c: Cells) -> dict:
    q = "/scene/calibrated"
    return {"head": [head("parameter", "value", "why")], "cls": "calibrated",
            "rows": [[c.text(f"{q}/{i}/name"), c.text(f"{q}/{i}/value", cls="text nowrap"),
                      c.text(f"{q}/{i}/reason", cls="text reason")]
                     for i, _ in enumerate(results["scene"]["calibrated"])]}


def pose_tables(results: Results, c: Cells) -> dict:
    poses_rows, joints_rows = [], []
    legs = range(len(results["cases"][0]["pose"]["leg_lengths_mm"]))
    for i, _ in enumerate(results["cases"]):
        p = f"/cases/{i}/pose"
        poses_rows.append([c.text(f"/cases/{i}/name"), c.num(f"{p}/height_mm", 1),
                           c.text(f"{p}/height_origin"), c.num(f"{p}/azimuth_deg", 1),
                           c.num(f"{p}/tilt_deg", 1)]
                          + [c.num(f"{p}/centre_mm/{k}", 1) for k in range(3)]
                          + [c.num(f"{p}/actuation_mm/{k}", 1) for k in legs])
        joints_rows.append([c.text(f"/cases/{i}/name")]
                           + [c.num(f"{p}/s_joint_angles_deg/{k}", 2) for k in legs]
                           + [c.num(f"{p}/r_joint_angles_deg/{k}", 2) for k in legs])
    n = len(legs)
    prs = results["scene"]["manipulator"]["architecture"] == "3-PRS"
    group, symbol = ("slider travels s_i (mm)", "s") if prs else ("leg lengths L_i (mm)", "L")
    poses = {"cls": "poses", "rows": poses_rows, "head": [
        head("case", "height z", "", "azimuth φ", "tilt θ", "platform centre o (mm)",
             group, spans=[1, 1, 1, 1, 1, 3, n]),
        head("", "(mm)", "origin", "(deg)", "(deg)", "x", "y", "z",
             *[f"{symbol}{k + 1}" for k in legs])]}
    joints = {"cls": "joints", "rows": joints_rows, "head": [
        head("case", "S-joint angles α_i (deg)", "R-joint angles β_i (deg)", spans=[1, n, n]),
        head("", *[f"α{k + 1}" for k in legs], *[f"β{k + 1}" for k in legs])]}
    return {"poses": poses, "joints": joints}


def environment_tables(results: Results, c: Cells) -> dict:
    """What ran and where (version, commit, scene hash, machine), and the library versions:
    two tables side by side."""
    env = results["environment"]
    run = [[c.text(literal="project version"), c.text("/environment/project_version")],
           [c.text(literal="git commit"), c.text("/environment/git_commit")],
           [c.text(literal="scene file sha256"), c.text("/scene/sha256")]]
    run += [[c.text(literal=label), c.text(f"/environment/{key}")]
            for key, label in (("date", "date of the run"), ("python", "Python"),
                               ("platform", "platform"), ("machine", "machine"),
                               ("cpu_count", "CPU cores"))]
    libraries = [[c.text(literal=name),
                  c.text(f"/environment/versions/{escape(name)}") if version
                  else c.text(literal="not installed")]
                 for name, version in env["versions"].items()]
    return {"run": {"head": [head("item", "value")], "rows": run, "cls": "params env"},
            "libraries": {"head": [head("library", "version")], "rows": libraries,
                          "cls": "params env"}}

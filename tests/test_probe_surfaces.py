"""The probe of issue 49, kept: round 5's leftovers on the newest surfaces (test campaigns, UFF
files, `rps frf`, `[uncertainty]`, `[tool]`, `[damping]`, design files, `--cache`, `rps verify`).

Each bad input is refused with exit status 2 and one line on stderr that names what was typed
(the option, the scene or campaign key, or the file and its record) and why, within seconds;
nothing on stdout, nothing written, and no warning of numpy or any library: every command here
runs with warnings turned into errors, so a raw RuntimeWarning fails the test. What used to be
refused wrongly is shown to run (the uncertainty command into its own output).
"""
from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

from modaltest import uff
from modaltest.synthesize import PoseTested, write_campaign
from rps import app as cli
from tests.conftest import PAPER_SCENE, ROOT, refused

# warnings of numpy or any library never reach the user raw: each is an error here
pytestmark = pytest.mark.filterwarnings("error")

ACTUATOR = ROOT / "scenes" / "actuator-legs.toml"
POSE = PoseTested("mid", 640.0, 30.0, 10.0)


def run(argv) -> int:
    """The command in this process (every warning an error: the module's mark)."""
    try:
        return cli.main([str(a) for a in argv])
    except SystemExit as exc:
        return int(exc.code)


def everything_under(folder: Path) -> list[str]:
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*"))


def scene_with(tmp_path: Path, source: Path, extra: str = "", *changes) -> Path:
    text = source.read_text(encoding="utf-8")
    for old, new in changes:
        assert old in text, old
        text = text.replace(old, new, 1)
    path = tmp_path / "scene.toml"
    path.write_text(text + extra, encoding="utf-8")
    return path


# ---------------------------------------------------------------- campaigns and UFF files
@pytest.fixture(scope="module")
def modes_campaign(tmp_path_factory) -> Path:
    """A one-pose campaign of mode shapes (UFF 55) made by the analytical model."""
    return write_campaign(ACTUATOR, {}, [POSE], tmp_path_factory.mktemp("modes"), [])


@pytest.fixture(scope="module")
def frf_campaign(tmp_path_factory) -> Path:
    """A one-pose campaign of receptances (UFF 58, 2 % damping) made by the analytical model."""
    return write_campaign(ACTUATOR, {}, [POSE], tmp_path_factory.mktemp("frfs"), [],
                          frf_damping=0.02)


def with_data(campaign: Path, tmp_path: Path, data: str) -> Path:
    """The campaign, copied into tmp_path with its pose's data file named `data` (its scene
    path made absolute)."""
    text = campaign.read_text(encoding="utf-8")
    scene = text.split('scene = "', 1)[1].split('"', 1)[0]
    text = text.replace(f'scene = "{scene}"',
                        f'scene = "{(campaign.parent / scene).resolve().as_posix()}"')
    text = text.replace(f'data = "{POSE.name}.unv"', f'data = "{data}"')
    path = tmp_path / "campaign.toml"
    path.write_text(text, encoding="utf-8")
    return path


def correlate_refused(capsys, campaign: Path, tmp_path: Path, *needles: str) -> str:
    before = everything_under(tmp_path)
    line = refused(capsys, ["correlate", "--campaign", campaign, "--out", tmp_path / "out"],
                   *needles)
    assert everything_under(tmp_path) == before
    return line


def test_a_data_file_that_is_a_link_loop_is_one_line(capsys, tmp_path, modes_campaign):
    os.symlink(tmp_path / "loop-b.unv", tmp_path / "loop-a.unv")
    os.symlink(tmp_path / "loop-a.unv", tmp_path / "loop-b.unv")
    campaign = with_data(modes_campaign, tmp_path, "loop-a.unv")
    correlate_refused(capsys, campaign, tmp_path, "pose[0].data = 'loop-a.unv'",
                      "symbolic link that leads nowhere")


def test_a_data_file_that_is_not_a_file_is_named_as_typed(capsys, tmp_path, modes_campaign):
    campaign = with_data(modes_campaign, tmp_path, "/dev/stdin")
    correlate_refused(capsys, campaign, tmp_path, "pose[0].data = '/dev/stdin'")


def test_a_uff_file_cut_short_is_refused_not_read_in_part(capsys, tmp_path, modes_campaign):
    whole = (modes_campaign.parent / f"{POSE.name}.unv").read_bytes()
    for cut in (len(whole) // 2, int(len(whole) * 0.8), len(whole) - 30):
        (tmp_path / "cut.unv").write_bytes(whole[:cut])
        campaign = with_data(modes_campaign, tmp_path, "cut.unv")
        correlate_refused(capsys, campaign, tmp_path, "pose[0].data = 'cut.unv'",
                          "cut short")


@pytest.mark.parametrize("variant", ["crlf", "cr", "no final newline", "nul padding",
                                     "ctrl-z", "blank lines"])
def test_a_whole_uff_file_as_other_software_ends_it_is_read(tmp_path, modes_campaign, variant):
    """Line endings and end-of-file padding as Windows tools, old systems and FAT copies
    leave them are not a file cut short; the same file cut inside a dataset still is."""
    whole = (modes_campaign.parent / f"{POSE.name}.unv").read_bytes()
    text = {"crlf": whole.replace(b"\n", b"\r\n"), "cr": whole.replace(b"\n", b"\r"),
            "no final newline": whole.rstrip(b"\n"), "nul padding": whole + b"\0" * 512,
            "ctrl-z": whole + b"\x1a", "blank lines": whole + b"\n   \n\n"}[variant]
    (tmp_path / "whole.unv").write_bytes(text)
    expected = uff.read_uff(modes_campaign.parent / f"{POSE.name}.unv").modes.frequencies_hz
    assert np.array_equal(uff.read_uff(tmp_path / "whole.unv").modes.frequencies_hz, expected)
    (tmp_path / "cut.unv").write_bytes(text[:int(len(text) * 0.7)])
    with pytest.raises(uff.UffError, match="cut short"):
        uff.read_uff(tmp_path / "cut.unv")


def _modes_file(tmp_path: Path, campaign: Path, edit) -> Path:
    content = uff.read_uff(campaign.parent / f"{POSE.name}.unv")
    modes = content.modes
    hz, shapes = np.array(modes.frequencies_hz), np.array(modes.shapes)
    edit(hz, shapes)
    sets = uff._mode_sets  # noqa: SLF001 - the writer's own record builder, bypassing Modes
    records = sets(uff.Modes(np.abs(hz) + 1.0, None, modes.dofs, shapes + 1.0),
                   set(content.nodes.ids.tolist()), "edited")
    for r, record in enumerate(records):  # the edited values, as a file may hold them
        record["freq"] = float(hz[r])
        order = list(dict.fromkeys(modes.dofs.node.tolist()))
        grid = np.zeros((len(order), 3))
        for i, (node, code) in enumerate(zip(modes.dofs.node.tolist(),
                                             modes.dofs.codes().tolist())):
            grid[order.index(node), abs(code) - 1] = math.copysign(1, code) * shapes[i, r]
        record["r1"], record["r2"], record["r3"] = grid[:, 0], grid[:, 1], grid[:, 2]
    path = tmp_path / "edited.unv"
    import pyuff
    nodes = content.nodes
    pyuff.UFF(str(path)).write_sets([
        {"type": 2411, "node_nums": nodes.ids, "def_cs": np.zeros(len(nodes.ids), int),
         "disp_cs": np.zeros(len(nodes.ids), int), "color": np.zeros(len(nodes.ids), int),
         "x": nodes.xyz[:, 0] * 1e3, "y": nodes.xyz[:, 1] * 1e3, "z": nodes.xyz[:, 2] * 1e3},
        *records], mode="add")
    return path


@pytest.mark.parametrize("edit, needles", [
    (lambda hz, shapes: hz.__setitem__(1, 0.0), ("mode 2", "frequency 0 Hz")),
    (lambda hz, shapes: hz.__setitem__(0, -12.0), ("mode 1", "frequency -12 Hz")),
    (lambda hz, shapes: shapes.__setitem__((slice(None), 2), 0.0),
     ("mode 3", "zero at every node")),
])
def test_a_test_mode_at_0_hz_or_with_no_shape_is_refused(capsys, tmp_path, modes_campaign, edit,
                                                          needles):
    _modes_file(tmp_path, modes_campaign, edit)
    campaign = with_data(modes_campaign, tmp_path, "edited.unv")
    correlate_refused(capsys, campaign, tmp_path, "pose[0].data = 'edited.unv'", *needles)


def _frf_file(tmp_path: Path, campaign: Path, shift_hz: float = 0.0,
              value: complex | None = None) -> None:
    content = uff.read_uff(campaign.parent / f"{POSE.name}.unv")
    frfs = content.frfs
    values = np.array(frfs.values)
    if value is not None:
        values[3, 40] = value
    uff.write_uff(tmp_path / "frf.unv", content.nodes,
                  frfs=uff.Frfs(frfs.frequency_hz + shift_hz, frfs.dofs, frfs.reference, values))


def test_an_frf_axis_off_the_0_hz_grid_gives_the_same_modes(capsys, tmp_path, frf_campaign):
    """The poly-reference LSCF takes any frequency axis (its basis is z = exp(i w pi / w_top)):
    the same receptances on an axis shifted by 0.37 of a line give the same modes."""
    from modaltest.campaign import load_campaign

    content = uff.read_uff(frf_campaign.parent / f"{POSE.name}.unv")
    step = float(np.diff(content.frfs.frequency_hz[:2])[0])
    _frf_file(tmp_path, frf_campaign, shift_hz=0.37 * step)
    campaign = with_data(frf_campaign, tmp_path, "frf.unv")
    shifted = load_campaign(campaign).poses[0].modes.frequencies_hz
    on_grid = load_campaign(frf_campaign).poses[0].modes.frequencies_hz
    assert len(shifted) == len(on_grid) and np.allclose(shifted, on_grid, rtol=2e-3)


def test_a_receptance_no_structure_has_is_refused_by_the_reader(capsys, tmp_path, frf_campaign):
    _frf_file(tmp_path, frf_campaign, value=complex(1.7976931348623157e308, 0.0))
    campaign = with_data(frf_campaign, tmp_path, "frf.unv")
    correlate_refused(capsys, campaign, tmp_path, "pose[0].data = 'frf.unv'", "(58, FRF 4)",
                      "a receptance of 1.8e+308 m/N")


def test_a_cache_that_is_a_file_is_refused_by_every_command_that_takes_it(capsys, tmp_path,
                                                                         modes_campaign):
    a_file = tmp_path / "a-file"
    a_file.write_text("not a directory")
    campaign = with_data(modes_campaign, tmp_path, f"{modes_campaign.parent}/{POSE.name}.unv")
    for command in (["correlate", "--campaign", campaign, "--out", tmp_path / "o"],
                    ["identify", "--campaign", campaign, "--out", tmp_path / "o"],
                    ["analytical"], ["workspace", "--layers", "1"]):
        refused(capsys, [*command, "--cache", a_file], f"--cache {a_file}: exists and is not a "
                "directory")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a-file", "campaign.toml"]


# ---------------------------------------------------------------- scenes: tool, damping, radii
@pytest.mark.parametrize("point, needles", [
    ("[0.0, 0.0, 100000.0]", ("tool.point_mm = [0.0, 0.0, 100000.0]",
                              "beyond the machine's reach", "rule 'tool envelope'")),
    ("[0.0, 0.0, -700.0]", ("tool.point_mm = [0.0, 0.0, -700.0]", "below the base plane",
                            "rule 'tool envelope'")),
])
def test_a_tool_point_beyond_the_machine_is_refused(capsys, tmp_path, point, needles):
    scene = scene_with(tmp_path, PAPER_SCENE, f"\n[tool]\npoint_mm = {point}\n")
    refused(capsys, ["frf", "--scene", scene, "--out", tmp_path / "out"], *needles)
    assert everything_under(tmp_path) == ["scene.toml"]


def test_a_tool_point_within_the_envelope_runs(capsys, tmp_path):
    scene = scene_with(tmp_path, PAPER_SCENE, "\n[tool]\npoint_mm = [50.0, 0.0, -150.0]\n")
    assert run(["frf", "--scene", scene, "--out", tmp_path / "out", "--lines", "200"]) == 0
    capsys.readouterr()


def test_a_tool_below_the_base_at_the_lowest_poses_only_runs_with_a_warning(capsys, tmp_path):
    """Above the base plane at every case but below it at the level band's lowest poses: a
    ring-shaped base may clear it, so the scene runs, and says so."""
    scene = scene_with(tmp_path, PAPER_SCENE, "\n[tool]\npoint_mm = [0.0, 0.0, -400.0]\n")
    assert run(["analytical", "--scene", scene]) == 0
    err = capsys.readouterr().err
    assert "below the base plane" in err and "rule 'tool envelope'" in err


@pytest.mark.parametrize("table", [
    "rayleigh_alpha_per_s = 0.0\nrayleigh_beta_s = 0.0\n", "rayleigh_alpha_per_s = 0.0\n", ""])
def test_damping_that_damps_nothing_is_refused_never_replaced(capsys, tmp_path, table):
    scene = scene_with(tmp_path, PAPER_SCENE, f"\n[damping]\n{table}")
    line = refused(capsys, ["frf", "--scene", scene, "--out", tmp_path / "out"],
                   "damping:", "declares no damping")
    assert "0.02" not in line or "leave [damping] out" in line


def test_a_band_that_holds_no_resonance_is_refused(capsys, tmp_path):
    refused(capsys, ["frf", "--top-hz", "0.001", "--out", tmp_path / "out"],
            "--top-hz 0.001: below the first resonance at the tool")
    assert not (tmp_path / "out").exists()


def test_radii_no_leg_can_span_are_named_as_typed(capsys, tmp_path):
    scene = scene_with(tmp_path, PAPER_SCENE, "", ("platform_radius_mm = 200.0",
                                                   "platform_radius_mm = 1e5"))
    refused(capsys, ["analytical", "--scene", scene], "platform_radius_mm = 100000 mm",
            "base_radius_mm = 300 mm", "no level pose")


# ---------------------------------------------------------------- design files
def test_design_directions_without_their_constraint_are_refused(capsys, tmp_path):
    text = (ROOT / "designs" / "3prs-head.toml").read_text(encoding="utf-8")
    scene = text.split('scene = "', 1)[1].split('"', 1)[0]
    text = text.replace(f'scene = "{scene}"',
                        f'scene = "{(ROOT / "designs" / scene).resolve().as_posix()}"')
    assert "min_dynamic_stiffness" not in text and "[constraints]" in text
    text = text.replace("[constraints]", '[constraints]\ndirections = ["x"]', 1)
    design = tmp_path / "design.toml"
    design.write_text(text, encoding="utf-8")
    refused(capsys, ["design", "--design", design, "--out", tmp_path / "d.json"],
            "constraints.directions = ['x']", "min_dynamic_stiffness_n_per_um")


# ---------------------------------------------------------------- output folders
def test_verify_refuses_a_folder_of_someone_else_s_files(capsys, tmp_path, monkeypatch):
    import studies.fem_verification

    def must_not_run(*args, **kwargs):
        raise AssertionError("the benchmarks started before the folder was checked")

    monkeypatch.setattr(studies.fem_verification, "verification_record", must_not_run)
    theirs = tmp_path / "theirs"
    theirs.mkdir()
    (theirs / "thesis.tex").write_text("mine")
    refused(capsys, ["verify", "--out", theirs, "--cache", tmp_path / "c"],
            f"--out {theirs}: holds thesis.tex", "not an output directory")
    assert everything_under(tmp_path) == ["theirs", "theirs/thesis.tex"]


def test_verify_writes_beside_a_run_s_files_and_keeps_them(capsys, tmp_path, monkeypatch):
    import studies.fem_verification

    record = {"cases": [], "passed": True, "seconds": 1.0}
    monkeypatch.setattr(studies.fem_verification, "verification_record",
                        lambda cache, progress: record)
    out = tmp_path / "out"
    out.mkdir()
    (out / "results.json").write_text("{}")
    for _ in range(2):  # and again into its own output
        assert run(["verify", "--out", out, "--cache", tmp_path / "c"]) == 0
    capsys.readouterr()
    assert sorted(p.name for p in out.iterdir()) == ["results.json", "verification.json"]


def test_uncertainty_runs_again_into_its_own_output(capsys, tmp_path):
    out = tmp_path / "u"
    for _ in range(2):
        assert run(["uncertainty", "--samples", "64", "--out", out]) == 0, \
            capsys.readouterr().err
    capsys.readouterr()
    assert sorted(p.name for p in out.iterdir()) == ["uncertainty.json"]


def test_every_record_a_command_stages_marks_its_folder_as_an_output():
    """A command that writes DIR/<file> can run again into DIR: every declared output file
    (results.outputs, the design's, the bench's) is one of runtime.outdir.OUTPUT_MARKERS."""
    from pipeline.bench_records import BENCH
    from results.outputs import OUTPUTS
    from runtime.outdir import OUTPUT_MARKERS
    from studies.design import DESIGN

    files = {o.file for o in (*OUTPUTS, DESIGN, BENCH) if o.file.endswith(".json")}
    assert {"frf.json", "uncertainty.json", "verification.json"} <= files
    assert files <= set(OUTPUT_MARKERS), files - set(OUTPUT_MARKERS)

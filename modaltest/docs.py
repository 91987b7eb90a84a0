"""docs/campaigns.md, generated from the declarations that read campaign files
(`modaltest.campaign`), as docs/scenes.md is from the scene's; `rps scene-docs` writes both
and tests/test_scene_docs.py fails when either is stale."""
from __future__ import annotations

from pathlib import Path

from scene.docs import ROOT, section

from .campaign import DECLARED
from .placement import __doc__ as PLACEMENT

DOC = ROOT / "docs" / "campaigns.md"

HEADER = """# Test campaign files

A test campaign (`rps correlate --campaign FILE`, `rps identify --campaign FILE`) is the
machine tested (its scene), the poses it was tested at and the Universal File Format (UFF)
file of each: node coordinates (dataset 15 or 2411), and mode shapes (55) or frequency response
functions (58). Paths are relative to the campaign file. Units at this edge as in scenes:
millimetres and degrees; a UFF file's node coordinates are in millimetres in the machine's base
frame (origin at the base centre, z up) unless its dataset 164 gives other units, and its shapes
and FRFs are along the base frame's x, y, z. Everything is checked when the file is read, before
any model is solved: a node on no body of the machine, a pose the machine cannot reach, a
malformed file, a key that is not a number of the scene, bounds that exclude the scene's value:
one line naming it, exit status 2.

```toml
scene = "machine.toml"
[[pose]]
name = "mid"
height_mm = 600.0
azimuth_deg = 25.0
tilt_deg = 8.0
data = "mid.unv"
[identify]
keys = ["stiffness.actuator_axial_n_per_um", "stiffness.base_joint_rotational_nm_per_urad"]
[identify.bounds]
"stiffness.actuator_axial_n_per_um" = [20.0, 2000.0]
```

Generated from the declarations by `python -m rps scene-docs`; do not edit by hand.
"""


def render() -> str:
    lines = [HEADER]
    for cls, title, intro in DECLARED:
        lines += section(title, intro, (cls,))
    lines += ["## Where a node lies and how it moves", ""]
    for paragraph in (PLACEMENT or "").split("\n\n")[:2]:
        lines += [" ".join(paragraph.split()), ""]
    return "\n".join(lines)


def write(path: Path = DOC) -> Path:
    from common.atomic import write_text_atomic
    return write_text_atomic(path, render())

"""What an installed copy needs: every data file declared as package data, caches outside the
installation, paths independent of the working directory, and a base install (numpy, scipy)
that is enough for the analytical model. (`.ci/wheel-check` builds and installs the wheel.)"""
from __future__ import annotations

import fnmatch
import subprocess
import sys
import tomllib

from common.locations import cache_root, checkout_root, default_scene, scenes_dir
from tests.conftest import ROOT

PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))


def packaged_files() -> set[str]:
    """Wheel paths of the package data pyproject.toml declares (the files it would ship)."""
    tool = PYPROJECT["tool"]["setuptools"]
    out = set()
    for package in tool["packages"]:
        source = ROOT / tool.get("package-dir", {}).get(package, package.replace(".", "/"))
        patterns = tool["package-data"].get(package, []) + tool["package-data"].get("*", [])
        for path in source.iterdir():
            if path.is_file() and any(fnmatch.fnmatch(path.name, p) for p in patterns):
                out.add(f"{package.replace('.', '/')}/{path.name}")
    return out


def test_every_data_file_is_package_data():
    shipped = packaged_files()
    data = [p for p in (ROOT / "scenes").glob("*.toml")]
    assert data and all(f"pipeline/scenes/{p.name}" in shipped for p in data)
    templates = [p for p in (ROOT / "reports" / "templates").iterdir() if p.is_file()]
    assert templates and all(f"reports/templates/{p.name}" in shipped for p in templates)
    from tests.test_architecture import FLOORS

    for package in FLOORS:
        assert f"{package}/py.typed" in shipped, package


def test_every_package_of_the_tree_is_in_the_wheel():
    """A package directory (an __init__.py) missing from pyproject's list would be left out of
    the wheel silently."""
    listed = set(PYPROJECT["tool"]["setuptools"]["packages"])
    found = {".".join(p.parent.relative_to(ROOT).parts) for p in ROOT.glob("*/**/__init__.py")
             if p.parent.relative_to(ROOT).parts[0] not in ("tests", "build", ".venv")}
    assert found <= listed, sorted(found - listed)


def test_every_room_is_in_every_list_that_names_the_rooms():
    """The rooms are declared once (tests/test_architecture.py's ROOMS); the lists a tool
    reads from pyproject.toml (the wheel's packages, the type checker's, the linter's first
    party) name every room, and no package that is not one."""
    from tests.test_architecture import ROOMS

    rooms = set(ROOMS)
    tool = PYPROJECT["tool"]
    lists = {"setuptools packages": {p for p in tool["setuptools"]["packages"] if "." not in p},
             "mypy packages": set(tool["mypy"]["packages"]),
             "ruff known-first-party": set(tool["ruff"]["lint"]["isort"]["known-first-party"])}
    for name, listed in lists.items():
        assert listed == rooms, (name, sorted(rooms - listed), sorted(listed - rooms))
    on_disk = {p.parent.name for p in ROOT.glob("*/__init__.py")} - {"tests"}
    assert on_disk == rooms, (sorted(on_disk - rooms), sorted(rooms - on_disk))


def test_installed_scene_paths_match_the_package_layout(tmp_path):
    """Installed (no checkout beside the packages), the scenes are where pyproject.toml puts
    them: pipeline/scenes inside the package."""
    site = tmp_path / "site-packages"
    site.mkdir()
    assert checkout_root(site) is None
    mapped = PYPROJECT["tool"]["setuptools"]["package-dir"]["pipeline.scenes"]
    assert mapped == "scenes" and scenes_dir(site) == site / "pipeline" / "scenes"
    assert default_scene(site) == site / "pipeline" / "scenes" / "paper.toml"


def test_the_checkout_keeps_its_caches_and_scenes_beside_it():
    assert checkout_root() == ROOT
    assert cache_root() == ROOT / ".cache"
    assert default_scene() == ROOT / "scenes" / "paper.toml" and default_scene().is_file()


def test_an_installed_copy_caches_in_the_user_cache_directory(tmp_path):
    site = tmp_path / "site-packages"
    site.mkdir()
    cache = cache_root(site)
    assert site not in cache.parents and "rps-elastodynamics" in cache.parts


def test_a_checkout_needs_both_its_project_file_and_its_git(tmp_path):
    (tmp_path / "pyproject.toml").write_text("")
    assert checkout_root(tmp_path) is None
    (tmp_path / ".git").write_text("gitdir: elsewhere\n")  # a worktree's .git is a file
    assert checkout_root(tmp_path) == tmp_path


def test_the_base_dependencies_are_numpy_and_scipy_only():
    names = [d.split(">")[0].split("=")[0].split("<")[0].strip()
             for d in PYPROJECT["project"]["dependencies"]]
    assert sorted(names) == ["numpy", "scipy"]
    extras = PYPROJECT["project"]["optional-dependencies"]
    assert {"gmsh==4.15.2", "scikit-fem==12.0.2"} <= set(extras["fem"])
    assert PYPROJECT["project"]["scripts"]["rps"] == "rps.app:main"


# import names of the extras' distributions (and of VTK, which pyvista brings)
EXTRA_MODULES = {"gmsh": "gmsh", "scikit-fem": "skfem", "meshio": "meshio",
                 "platformdirs": "platformdirs", "rich": "rich", "matplotlib": "matplotlib",
                 "pyvista": "pyvista", "pillow": "PIL", "jinja2": "jinja2",
                 "weasyprint": "weasyprint", "vtk": "vtk", "joblib": "joblib",
                 "dask[distributed]": "distributed", "pydantic": "pydantic",
                 "plotly": "plotly", "salib": "SALib"}


def test_the_analytical_model_loads_nothing_of_the_extras():
    """Everything `analytical` and `common` load at import and while computing a case: no
    module of an extra and none of the FEM, pipeline or report packages."""
    extras = PYPROJECT["project"]["optional-dependencies"]
    declared = {d.split("=")[0].split(">")[0].strip().lower()
                for name in ("fem", "report") for d in extras[name]}
    assert declared <= set(EXTRA_MODULES)
    code = """
import sys
import analytical, common.atomic, common.locations, common.plate, common.rigid_body
import common.settings
from analytical import Manipulator, Material, Pose, natural_frequencies
m = Manipulator(0.3, 0.2, 0.1, 0.02, Material(200e9, 77e9, 7820.0))
print(natural_frequencies(m, Pose(0.5436))[0])
print(" ".join(sorted({name.split(".")[0] for name in sys.modules})))
"""
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=ROOT, timeout=120)
    assert proc.returncode == 0, proc.stderr
    f1, loaded = proc.stdout.splitlines()
    assert abs(float(f1) - 115.35) < 0.01  # case1's first mode, as in the README
    forbidden = set(EXTRA_MODULES.values()) | {"meshing", "fem_reference", "pipeline",
                                               "reports"}
    assert not forbidden & set(loaded.split()), forbidden & set(loaded.split())

"""The house: rooms on floors, each importing only the rooms it declares, no circles, no module
too long to read.

ROOMS is the one declaration: the project's packages from the bottom up, and for each the
rooms it may import (always below it: the report reads results, the run never imports the
report, the FEM never imports the analytical model). Each room's README quotes its own line
("**May import:**", the project rooms it names before "Never" or "Nothing"), and a test holds
the two together. The graph is read from the source (every import, at the top of a module or
inside a function), so a lazy import cannot hide an arrow."""
from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
ROOMS: dict[str, frozenset[str]] = {
    "common": frozenset(),
    "chatter": frozenset({"common"}),
    "meshing": frozenset({"common"}),
    "fem_reference": frozenset({"common", "meshing"}),
    "verification": frozenset({"meshing", "fem_reference"}),
    "joint_ends": frozenset({"common", "meshing", "fem_reference"}),
    "analytical": frozenset({"common", "joint_ends"}),
    "scene": frozenset({"common", "meshing", "fem_reference", "analytical", "chatter"}),
    "results": frozenset({"common"}),
    "runtime": frozenset({"common"}),
    "solvers": frozenset({"common", "meshing", "fem_reference", "analytical", "scene",
                          "results", "runtime"}),
    "studies": frozenset({"common", "verification", "analytical", "scene", "results", "runtime",
                          "solvers", "chatter"}),
    "modaltest": frozenset({"common", "fem_reference", "analytical", "scene", "results",
                            "solvers"}),
    "pipeline": frozenset({"common", "meshing", "fem_reference", "analytical", "scene",
                           "results", "runtime", "solvers", "studies", "chatter"}),
    "reports": frozenset({"common", "results", "runtime"}),
    "rps": frozenset({"common", "meshing", "fem_reference", "analytical", "scene", "results",
                      "runtime", "solvers", "studies", "modaltest", "pipeline", "reports",
                      "chatter"}),
}
FLOORS = tuple(ROOMS)
MAX_LINES = 450


def modules() -> dict[str, Path]:
    found = {}
    for package in FLOORS:
        for path in sorted((ROOT / package).rglob("*.py")):
            parts = path.relative_to(ROOT).with_suffix("").parts
            found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return found


def imports(name: str, path: Path, known) -> set[str]:
    """The project modules `name` imports (relative imports resolved)."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")[:len(package.split(".")) - node.level + 1]
                base = ".".join(parts + ([base] if base else []))
            targets = [base] + [f"{base}.{a.name}" for a in node.names]
        else:
            continue
        out |= {t for t in targets if t in known and t != name}
    return out


@pytest.fixture(scope="module")
def graph() -> dict[str, set[str]]:
    known = modules()
    return {name: imports(name, path, known) for name, path in known.items()}


def room(module: str) -> str:
    return module.split(".")[0]


def floor(module: str) -> int:
    return FLOORS.index(room(module))


def test_every_package_is_on_a_floor():
    packages = {p.parent.name for p in ROOT.glob("*/__init__.py")} - {"tests"}
    assert packages == set(FLOORS), packages ^ set(FLOORS)


def test_every_room_is_allowed_only_rooms_below_it():
    up = sorted(f"{name} -> {other}" for name, allowed in ROOMS.items() for other in allowed
                if other not in ROOMS or floor(other) >= floor(name))
    assert not up, up


def cross_room(graph: dict[str, set[str]]) -> list[tuple[str, str]]:
    """(module, imported module) of every import from one room into another."""
    return [(m, t) for m, targets in graph.items() for t in targets if room(t) != room(m)]


def arrows_outside_the_rules(graph: dict[str, set[str]], rooms: dict) -> list[str]:
    """Every import from one room into another that the importing room does not declare (an
    arrow up a floor among them: a room declares only rooms below it, tested above)."""
    return sorted(f"{m} -> {t}" for m, t in cross_room(graph) if room(t) not in rooms[room(m)])


def test_every_room_imports_only_the_rooms_it_declares(graph):
    assert not arrows_outside_the_rules(graph, ROOMS), arrows_outside_the_rules(graph, ROOMS)


def test_every_declared_arrow_is_used(graph):
    """The declaration is the house as built, not a wish: a room that stops importing another
    loses the right in the same change."""
    used: dict[str, set[str]] = {name: set() for name in ROOMS}
    for m, t in cross_room(graph):
        used[room(m)].add(room(t))
    unused = {name: sorted(allowed - used[name]) for name, allowed in ROOMS.items()
              if allowed - used[name]}
    assert not unused, unused


def test_an_undeclared_arrow_would_be_found():
    """Not vacuous: reports importing the analytical model is below it, and still refused."""
    graph = {"reports.page": {"analytical.model", "results.schema"}}
    assert arrows_outside_the_rules(graph, ROOMS) == ["reports.page -> analytical.model"]


def quoted_rooms(readme: str) -> set[str]:
    """The project rooms a README's "**May import:**" paragraph names (in backticks) before
    its "Never"."""
    text = readme.split("**May import:**", 1)[1].split("\n\n", 1)[0]
    allowed = re.split(r"\b(?:never|nothing)\b", text, maxsplit=1, flags=re.IGNORECASE)[0]
    return {name.split(".")[0] for name in re.findall(r"`([A-Za-z_][\w.]*)`", allowed)
            if name.split(".")[0] in ROOMS}


def test_a_readme_rule_is_read_up_to_its_never():
    text = ("# x\n\n**May import:** `common`, `results.schema` (and numpy). Never `reports`\n"
            "or `analytical`.\n\nLater: `pipeline`.")
    assert quoted_rooms(text) == {"common", "results"}
    assert quoted_rooms("**May import:** `meshing`. Nothing above it: not `studies`.") == {
        "meshing"}


def test_every_readme_quotes_its_rooms_rule():
    wrong = {}
    for name, allowed in ROOMS.items():
        text = (ROOT / name / "README.md").read_text(encoding="utf-8")
        if "**May import:**" not in text:
            wrong[name] = "no **May import:** paragraph"
        elif quoted_rooms(text) != set(allowed):
            wrong[name] = f"README names {sorted(quoted_rooms(text))}, declared {sorted(allowed)}"
    assert not wrong, wrong


def circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in graph:
        if v not in index:
            visit(v)
    return found


def test_no_import_circles(graph):
    assert not circles(graph), circles(graph)


def test_a_circle_would_be_found():
    """The check is not vacuous: two modules importing each other are reported, a chain not."""
    assert circles({"a.x": {"a.y"}, "a.y": {"a.x"}, "a.z": {"a.x"}}) == [["a.x", "a.y"]]
    assert circles({"a.x": {"a.y"}, "a.y": {"a.z"}, "a.z": set()}) == []


def test_no_module_is_longer_than_one_idea():
    long = {name: n for name, path in modules().items()
            if (n := len(path.read_text(encoding="utf-8").splitlines())) > MAX_LINES}
    assert not long, long


def test_every_room_says_what_it_holds_and_may_import():
    missing = [p for p in FLOORS if not (ROOT / p / "README.md").is_file()]
    assert not missing, missing
    for package in FLOORS:
        text = (ROOT / package / "README.md").read_text(encoding="utf-8").lower()
        assert "import" in text and "copy" in text, f"{package}/README.md: what it may " \
            "import and the example to copy"


def test_every_study_declares_its_record_once_and_the_registry_is_made_from_them():
    """The registry's records are the studies' own (one per key, one title per anchor); a
    study may type its record in its own module, and a record the results room types for the
    report (`Studies`, `Case`) is the type its study declares, never one without its study;
    every section of a study is one the report can place."""
    from results import Case, Studies, study_type
    from studies import RECORDS, STUDIES

    assert RECORDS == tuple(s.record for s in STUDIES)
    assert len({r.key for r in RECORDS}) == len(RECORDS)
    typed = set(Studies.__annotations__) | (set(Case.__annotations__)
                                             - set(Case.__required_keys__))
    assert typed <= {r.key for r in RECORDS}, typed - {r.key for r in RECORDS}
    for r in RECORDS:
        if r.key in typed:
            assert r.type == study_type(r.scope, r.key), r.key
    assert all(r.section is not None for r in RECORDS if r.scope == "scene")

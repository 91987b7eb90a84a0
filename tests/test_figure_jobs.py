"""The report's figures are drawn once: a picture is keyed by what it shows, not by where it is
written; a changed input redraws exactly its figure; a damaged entry is drawn again; the
parallel and the serial drawings are the same files."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from reports.figure_jobs import Job, draw

CALLS: list[str] = []


def line_plot(values, path: Path, title: str = "") -> float:
    """A tiny drawing that records its call and returns a JSON-able value."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    CALLS.append(path.name)
    fig, ax = plt.subplots(figsize=(2, 1.5))
    ax.plot(np.asarray(values, float))
    ax.set_title(title)
    fig.savefig(path, dpi=50)
    plt.close(fig)
    return float(np.sum(values))


def refuses(path: Path) -> None:
    raise ValueError("nothing to draw")


def _jobs(directory: Path, values=((1, 2, 3), (3, 1, 2))) -> list[Job]:
    directory.mkdir(parents=True, exist_ok=True)
    return [Job(line_plot, (directory / f"fig{k}.png",), (list(v), directory / f"fig{k}.png"),
                {"title": f"figure {k}"}) for k, v in enumerate(values)]


def test_a_second_drawing_into_another_directory_draws_nothing_and_gives_the_same_files(
        tmp_path):
    CALLS.clear()
    first = draw(_jobs(tmp_path / "run1"), tmp_path / "cache")
    assert len(CALLS) == 2 and not any(o.cached for o in first)
    second = draw(_jobs(tmp_path / "run2"), tmp_path / "cache")
    assert len(CALLS) == 2, "nothing redrawn"
    assert all(o.cached for o in second)
    assert [o.value for o in second] == [o.value for o in first] == [6.0, 6.0]
    for k in range(2):
        assert (tmp_path / "run2" / f"fig{k}.png").read_bytes() == \
            (tmp_path / "run1" / f"fig{k}.png").read_bytes()


def test_a_changed_input_redraws_exactly_its_figure(tmp_path):
    draw(_jobs(tmp_path / "run1"), tmp_path / "cache")
    CALLS.clear()
    outcomes = draw(_jobs(tmp_path / "run2", ((1, 2, 3), (3, 1, 2.5))), tmp_path / "cache")
    assert CALLS == ["fig1.png"]
    assert [o.cached for o in outcomes] == [True, False]


def test_an_input_file_enters_the_key_by_its_contents_and_an_output_by_its_place(tmp_path):
    from reports.figure_jobs import _code, job_key

    data = tmp_path / "modes.vtu"
    data.write_text("a")
    code = _code()
    key = job_key(Job(line_plot, (tmp_path / "a.png",), ([1, 2], tmp_path / "a.png", data)),
                  code)
    moved = job_key(Job(line_plot, (tmp_path / "b.png",), ([1, 2], tmp_path / "b.png", data)),
                    code)
    assert moved == key, "the output's path is not what the picture shows"
    data.write_text("b")
    assert job_key(Job(line_plot, (tmp_path / "a.png",), ([1, 2], tmp_path / "a.png", data)),
                   code) != key


def test_a_damaged_picture_is_drawn_again(tmp_path, capsys):
    draw(_jobs(tmp_path / "run1"), tmp_path / "cache")
    for png in (tmp_path / "cache" / "figures").glob("*.png"):
        png.write_bytes(b"not a png")
    CALLS.clear()
    outcomes = draw(_jobs(tmp_path / "run2"), tmp_path / "cache")
    assert len(CALLS) == 2 and not any(o.cached for o in outcomes)
    assert (tmp_path / "run2" / "fig0.png").read_bytes()[:4] == b"\x89PNG"


def test_an_expected_failure_is_returned_not_raised_and_not_cached(tmp_path):
    out = tmp_path / "never.png"
    outcomes = draw([Job(refuses, (out,), (out,))], tmp_path / "cache")
    assert isinstance(outcomes[0].error, ValueError)
    assert not list((tmp_path / "cache").glob("figures/*.json"))


@pytest.mark.slow
def test_parallel_drawing_gives_the_serial_files(tmp_path):
    serial = draw(_jobs(tmp_path / "serial"), None, workers=1)
    parallel = draw(_jobs(tmp_path / "parallel"), None, workers=2)
    assert [o.value for o in serial] == [o.value for o in parallel]
    for k in range(2):
        assert (tmp_path / "serial" / f"fig{k}.png").read_bytes() == \
            (tmp_path / "parallel" / f"fig{k}.png").read_bytes()


@pytest.mark.slow
def test_drawing_in_parallel_in_a_forked_child_of_a_process_with_a_pool_does_not_hang(
        tmp_path):
    """The run draws its report in a forked child (common.worker.stoppable) after its sweeps
    used joblib's reusable pool; joblib's pool inherited by the child hung it forever."""
    from joblib import Parallel, delayed

    from common.worker import stoppable

    Parallel(n_jobs=2, backend="loky")(delayed(abs)(-k) for k in range(4))
    outcomes = stoppable(draw, _jobs(tmp_path / "child"), None, 2)
    assert [o.value for o in outcomes] == [6.0, 6.0]

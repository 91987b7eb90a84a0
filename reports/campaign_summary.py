"""The test campaign beside a run, as the run's report names it (issue 54: the whole chain in
one report): `make` correlates and identifies its campaign into out/correlation/ and
out/identification/ beside out/results.json; the report reads those records (checked against
their declared types, results.campaign_records), says what they found and links their pages.
A record that does not read is said as a note, never fatal: the run's own report stands."""
from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

from results.campaign_records import Correlation, Identification

from .campaign_pages import CampaignDataError, check

CORRELATION = Path("correlation") / "correlation.json"
IDENTIFICATION = Path("identification") / "identification.json"


def _read(path: Path, kind: Any, notes: list[str]) -> dict | None:
    if not path.is_file():
        return None
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        check(data, kind, path.name)
    except (OSError, ValueError, CampaignDataError) as exc:
        notes.append(f"The test campaign's {path.parent.name} beside the results is not "
                     f"shown: {' '.join(str(exc).split())}")
        return None
    return data


def _same_scene(campaign_scene: str, scene_path: str, scene_sha256: str) -> bool:
    """Whether the campaign's scene is the run's: by the file's digest where the campaign's
    scene file can be read from here (the record names it relative to the run's folder),
    else by its file name."""
    try:
        digest = hashlib.sha256(Path(campaign_scene).read_bytes()).hexdigest()
    except OSError:
        return Path(campaign_scene).name == Path(scene_path).name
    return digest == scene_sha256


def campaign_summary(results_path: Path, scene_path: str, scene_sha256: str,
                     notes: list[str]) -> dict | None:
    """The campaign's correlation (and identification, when there) beside `results_path`:
    what the report's section and summary say; None when the run has none beside it."""
    folder = Path(results_path).parent
    correlation = _read(folder / CORRELATION, Correlation, notes)
    if correlation is None:
        return None
    identification = _read(folder / IDENTIFICATION, Identification, notes)
    if identification is not None and identification["campaign"] != correlation["campaign"]:
        notes.append(f"The identification beside the results is of campaign "
                     f"{identification['campaign']}, the correlation of "
                     f"{correlation['campaign']}: only the correlation is shown.")
        identification = None
    same = _same_scene(correlation["scene"], scene_path, scene_sha256)
    s = correlation["summary"]
    after = None
    if identification is not None and identification.get("correlation_after"):
        after = identification["correlation_after"]["summary"]["mean_abs_error_percent"]
    identified = None
    if identification is not None:
        identified = [{"key": p["key"], "unit": p["unit"], "initial": p["initial"],
                       "value": p["value"], "interval": p["ci95"],
                       "identifiable": p["identifiable"], "reason": p["reason"]}
                      for p in identification["parameters"]]
    return {
        "campaign": correlation["campaign"], "scene": correlation["scene"],
        "machine": ("this scene's machine" if same else
                    f"another machine than this report's: {Path(correlation['scene']).stem}"),
        "same_machine": same, "model": correlation["model"]["description"],
        "poses": len(correlation["poses"]), "pairs": s["pairs"],
        "unpaired": s["unpaired_test_modes"], "mean_error_percent": s["mean_abs_error_percent"],
        "max_error_percent": s["max_abs_error_percent"], "min_mac": s["min_mac"],
        "mean_error_after_percent": after,
        "rms_before_percent": (identification or {}).get("residual_rms_percent_before"),
        "rms_after_percent": (identification or {}).get("residual_rms_percent_after"),
        "identified": identified,
        "correlation_page": (CORRELATION.parent / "correlation.html").as_posix(),
        "identification_page": (None if identification is None else
                                (IDENTIFICATION.parent / "identification.html").as_posix()),
    }

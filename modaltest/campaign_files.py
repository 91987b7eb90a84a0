"""The files a campaign names: where a key's file is (`relative`) and the geometry files read
once each (`geometries`: a campaign's or a pose's `geometry`, `uff.read_geometry`)."""
from __future__ import annotations

from pathlib import Path

from common.settings import text_problem
from scene.load import SceneError
from scene.toml_table import short

from . import uff


def relative(top: Path, text: str, where: str) -> Path:
    """The file a campaign key names, relative to the campaign's folder (links resolved where
    they lead somewhere; a link loop is returned as it is, for its reader to refuse)."""
    why = text_problem(text)
    if why is not None or not text.strip():
        raise SceneError(f"{where} = {short(text)}: {why or 'empty'}")
    path = (top / text).absolute()  # ".." left for resolve(): after the links, as the OS does
    try:
        return path.resolve()
    except (RuntimeError, OSError):  # a symbolic link loop (RuntimeError before Python 3.13)
        return path


def geometries(keys: list[tuple[str, str]], campaign_dir: Path) -> dict[str, uff.Geometry]:
    """The geometry files of (key, text given) pairs, an empty text none, each file read once,
    by its text; a refusal is one line naming the key."""
    out: dict[str, uff.Geometry] = {}
    for key, text in keys:
        if text and text not in out:
            try:
                out[text] = uff.read_geometry(relative(campaign_dir, text, key), shown="")
            except uff.UffError as exc:
                raise SceneError(f"{key} = {short(text)}: {exc}") from None
    return out

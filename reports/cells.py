"""Table cells: numbers formatted for print, each carrying the JSON pointer of the value it
shows in results.json (`data-src` in the HTML; tests check every one), and the column
alignment of every table."""
from __future__ import annotations

import math

from results import Results

from .results import resolve

MINUS = "\u2212"
THIN = "\u2009"


def decimal(value: float, digits: int, signed: bool = False) -> str:
    text = f"{value:+.{digits}f}" if signed else f"{value:.{digits}f}"
    if text.lstrip("+-").strip("0.") == "":  # -0.00 -> 0.00
        text = f"{0.0:.{digits}f}"
    return text.replace("-", MINUS)


def significant(value: float, figures: int = 3) -> int:
    """Decimals that show `figures` significant figures of value."""
    if value == 0 or not math.isfinite(value):
        return 2
    return max(0, figures - 1 - int(math.floor(math.log10(abs(value)))))


def cell(text: str, cls: str = "text", src: str | None = None, scale: str | None = None,
         colspan: int | None = None, suffix: str = "") -> dict:
    return {"text": text, "cls": cls, "src": src, "scale": scale, "colspan": colspan,
            "suffix": suffix}


def head(*labels, spans=None) -> list[dict]:
    """One header row; `spans` are the column spans of the labels."""
    spans = spans or [1] * len(labels)
    return [{"text": t, "colspan": s} for t, s in zip(labels, spans)]


def missing() -> dict:
    return cell("–", "num missing")


class Cells:
    """Table cells whose values come from the results document by JSON pointer."""

    def __init__(self, results: Results):
        self.results = results

    def _value(self, pointer: str):
        try:
            return resolve(self.results, pointer)
        except (KeyError, IndexError, TypeError):
            return None

    def num(self, pointer: str, digits: int | None = 2, scale: float = 1.0,
            signed: bool = False) -> dict:
        """A number; digits None: integers in full, others to three significant figures."""
        value = self._value(pointer)
        if value is None or isinstance(value, bool) or not isinstance(value, (int, float)):
            return missing()
        v = value * scale
        if isinstance(value, int) and digits is None and scale == 1:
            text = f"{value:,}".replace(",", THIN)
        else:
            text = decimal(v, significant(v) if digits is None else digits, signed)
        return cell(text, "num", pointer, None if scale == 1 else repr(scale))

    def sci(self, pointer: str, figures: int = 3) -> dict:
        """A number of any magnitude (a residual of 1e-13 beside a tolerance of 0.02): plain
        decimals between 1e-3 and 1e4, else scientific notation, `figures` significant."""
        value = self._value(pointer)
        if value is None or isinstance(value, bool) or not isinstance(value, (int, float)):
            return missing()
        if value == 0 or 1e-3 <= abs(value) < 1e4:
            text = decimal(value, significant(value, figures) if value else 0)
        else:
            text = f"{value:.{figures - 1}e}".replace("e-0", "e-").replace("e+0", "e")
            text = text.replace("e+", "e").replace("-", MINUS)
        return cell(text, "num", pointer)

    def text(self, pointer: str | None = None, literal: str | None = None,
             cls: str = "text") -> dict:
        if pointer is None:
            return cell(literal or "", cls)
        value = self._value(pointer)
        return cell("–", cls) if value is None else cell(str(value), cls, pointer)


def align(tables) -> None:
    """Give every table the alignment of its columns (from its first body row) and keep short
    tables on one page with their caption."""
    for table in tables:
        first = next((r for r in table["rows"] if isinstance(r, list)), None)
        if first is None:
            first = next((r["cells"] for r in table["rows"]
                          if isinstance(r, dict) and r.get("cells")), [])
        sides = [side for c in first
                 for side in ["right" if "num" in c["cls"] else "left"] * (c["colspan"] or 1)]
        if len(table["rows"]) <= 16 and "keep-table" not in table.get("cls", "").split():
            table["cls"] = table.get("cls", "") + " keep-table"  # once: pages render twice
        for row in table["head"]:
            col = 0
            for h in row:
                span = h.get("colspan") or 1
                h["cls"] = "group" if span > 1 else (sides[col] if col < len(sides) else "")
                col += span


def tables_in(obj):
    """Every table (a dict with "head" and "rows") inside a template context."""
    if isinstance(obj, dict):
        if "rows" in obj and "head" in obj:
            yield obj
        for v in obj.values():
            yield from tables_in(v)
    elif isinstance(obj, list):
        for v in obj:
            yield from tables_in(v)

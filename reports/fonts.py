"""The report's fonts, shipped with the project's own set-up: matplotlib's DejaVu Sans and
DejaVu Sans Mono (the figures' fonts too), declared to WeasyPrint by file, so report.pdf lays
out the same pages on every machine whatever fonts it has installed (issue 54: the same commit
gave 39 pages on a machine with DejaVu only and 36 where Chromium had brought Liberation Sans).

report.html names the same families first and falls back to the reader's sans-serif: a browser
reflows, so its page does not depend on them."""
from __future__ import annotations

from pathlib import Path

SANS = "Report Sans"
MONO = "Report Mono"
# (family, file, weight, style) in matplotlib's mpl-data/fonts/ttf
FACES = ((SANS, "DejaVuSans.ttf", "normal", "normal"),
         (SANS, "DejaVuSans-Bold.ttf", "bold", "normal"),
         (SANS, "DejaVuSans-Oblique.ttf", "normal", "italic"),
         (SANS, "DejaVuSans-BoldOblique.ttf", "bold", "italic"),
         (MONO, "DejaVuSansMono.ttf", "normal", "normal"),
         (MONO, "DejaVuSansMono-Bold.ttf", "bold", "normal"))


def font_directory() -> Path:
    """matplotlib's own TrueType folder (a dependency of the report, never the system's)."""
    import matplotlib

    return Path(matplotlib.get_data_path()) / "fonts" / "ttf"


def font_faces() -> str:
    """The @font-face rules of the report's families, by file URL; FileNotFoundError naming
    the file when matplotlib's fonts are not where they belong."""
    folder = font_directory()
    rules = []
    for family, name, weight, style in FACES:
        path = folder / name
        if not path.is_file():
            raise FileNotFoundError(f"the report's font {path} is missing (matplotlib's "
                                    "fonts; reinstall matplotlib)")
        rules.append(f'@font-face {{ font-family: "{family}"; src: url("{path.as_uri()}"); '
                     f"font-weight: {weight}; font-style: {style}; }}")
    return "\n".join(rules)

"""A scene's cases: one pose each, with the paper's rows for it where there are any, and the
[calibration.height] value a case may take its height from (read by `load.parse_scene`)."""
from __future__ import annotations

import math
from dataclasses import dataclass

from common.errors import InputError
from common.settings import MAX_ANGLE, MAX_LENGTH, setting

# A structural mode of a machine of this kind lies far below 1 MHz (the paper's: 0.1-1 kHz).
MAX_FREQUENCY = 1e6  # Hz


@dataclass(frozen=True)
class CaseSettings:
    """One pose of a [cases.NAME] table, and the paper's rows for it where there are any."""

    height: float = setting(unit="mm", minimum=0.0, exclusive_minimum=True, maximum=MAX_LENGTH,
                            doc='z of the platform centre o, or "calibrated" for '
                            "[calibration.height]")
    description: str = setting(None, kind=str, doc="title of the case (default: its name)")
    azimuth: float = setting(0.0, unit="deg", minimum=-MAX_ANGLE, maximum=MAX_ANGLE,
                             doc="phi, direction of the tilt axis (Eq. 1; one turn either way "
                             "reaches every direction)")
    tilt: float = setting(0.0, unit="deg", minimum=-math.pi / 2, maximum=math.pi / 2,
                          doc="theta, tilt of the platform (Eq. 1; beyond 90 degrees the "
                          "platform would face the base)")
    paper_fea_hz: tuple[float, ...] | None = setting(
        None, kind=tuple, minimum=0.0, exclusive_minimum=True, maximum=MAX_FREQUENCY,
        doc="the paper's FEA frequencies for this pose (Table I), Hz")
    paper_theory_hz: tuple[float, ...] | None = setting(
        None, kind=tuple, minimum=0.0, exclusive_minimum=True, maximum=MAX_FREQUENCY,
        doc="the paper's theoretical frequencies for this pose (Table I), Hz")
    paper_error_percent: tuple[float, ...] | None = setting(
        None, kind=tuple, minimum=-100.0, maximum=100.0,
        doc="the paper's errors as printed (Table I), %")


@dataclass(frozen=True)
class HeightCalibration:
    """[calibration.height]: a value the paper leaves wrong or open, with its reason."""

    value: float = setting(unit="mm", minimum=0.0, exclusive_minimum=True, maximum=MAX_LENGTH,
                           doc="the calibrated platform height")
    reason: str = setting(kind=str, paragraphs=True,
                          doc="why and how it was calibrated (required, non-empty)")


PAPER_ROWS = ("paper_fea_hz", "paper_theory_hz", "paper_error_percent")
PAPER_ROWS_RULE = ("a case's paper_fea_hz, paper_theory_hz and paper_error_percent, where "
                   "given, have one length (one value per mode); the first [fidelity] modes "
                   "of them are compared")


def check_paper_rows(spec: CaseSettings, where: str, modes: int) -> None:
    """The paper's rows of a case, where given, have one length (one value per mode; the
    first `modes` are compared, the rest are kept as printed)."""
    given = {key: row for key in PAPER_ROWS if (row := getattr(spec, key)) is not None}
    lengths = {len(row) for row in given.values()}
    if len(lengths) > 1:
        shown = ", ".join(f"{key} {len(row)}" for key, row in given.items())
        raise InputError(f"{where}: the paper's rows differ in length ({shown} values); give "
                         "one value per mode in each")

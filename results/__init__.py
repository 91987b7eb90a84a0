"""The results file (`out/results.json`): its schema, declared once, the rules for reading it,
and the tables made from it. The run writes it, the reports read it; this room sits below both
and imports nothing of the project but `common` (README.md).

    import results
    checked = results.read("out/results.json", studies.RECORDS)  # one line if refused
"""
from __future__ import annotations

from .case_records import *  # noqa: F401,F403
from .declare import Record, Section, Table, csv_text, stub, table_rows, unique  # noqa: F401
from .lobe_records import *  # noqa: F401,F403
from .outputs import OUTPUTS, Output  # noqa: F401
from .rules import best_error, mode_ranges, worst_by_mode_range, worst_in_mode_ranges  # noqa: F401
from .schema import Results, dumps, nesting_depth, read, study_type, validated  # noqa: F401
from .study_records import *  # noqa: F401,F403
from .tool_records import *  # noqa: F401,F403
from .types import *  # noqa: F401,F403
from .types import LOW_MODES, MAX_DEPTH, MAX_FREQUENCY_HZ, SCHEMA_VERSION  # noqa: F401
from .uncertainty_records import *  # noqa: F401,F403

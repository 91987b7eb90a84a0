"""Where each study's record is shown: the report section (anchor and title) of every study key,
declared once. The studies' declarations (`studies.STUDIES`) and the report both read it; it
lives here, beside the schema of the records it names, so the report reads it without
importing the studies (nor the models they run)."""
from __future__ import annotations

# study key (results.studies[key] or results.cases[][key]) -> (report anchor, section title);
# None: shown inside each case's section
PAPER_READING = ("studies", "Reading the paper: angle conventions and height calibration")
SECTIONS: dict[str, tuple[str, str] | None] = {
    "reachable_workspace": ("scene", "Scene and set-up"),
    "workspace_validation": ("validation", "The model against the FEM over the workspace"),
    "models": None,
    "element_convergence": ("convergence", "Convergence"),
    "fem_variants": None,
    "speed_vs_error": ("speed", "Speed vs error"),
    "height_calibration": PAPER_READING,
    "angle_conventions": PAPER_READING,
    "workspace": ("workspace", "Workspace maps"),
    "joint_orders": ("joint-orders", "Joint orders"),
    "joint_couplings": ("joint-couplings", "Joint faces: rigid and distributing couplings"),
    "hard_cases": ("hard-cases", "Hard cases: numerical stability and physics checks"),
    "lowest_modes": ("lowest-modes", "What sets the lowest modes: drive, joints and legs"),
    "fem_verification": ("verification", "Verifying the referee: published benchmarks"),
}


def section_titles() -> dict[str, str]:
    """Report anchor -> title of every section that shows a study."""
    return {anchor: title for anchor, title in filter(None, SECTIONS.values())}

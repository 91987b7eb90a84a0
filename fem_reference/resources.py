"""Will a FEM solve fit in memory? An estimate of its peak, made before meshing.

The peak of `solve_pose` is the factorisation of K - sigma M (SuperLU, eigen.py) on top of the
mesh, the matrices and the constraint map that the process already holds:

    peak ~ BASE + PER_DOF n + BYTES_PER_ENTRY * n * (FILL_PER_SECTION (d / h)^2 + FILL_FLOOR)

with n the degrees of freedom (estimated from volume and surface before meshing), d the leg
diameter and h the element size. The factor's fill per dof grows with the size of a separator,
a cross-section of a leg, (d / h)^2 elements across (measured below); a fixed power of n does
not follow the geometry (at equal n a stocky leg fills 1.7 times more per dof than the paper's).

Measured (this machine, gmsh 4.15.2, SuperLU MMD_AT_PLUS_A, case 1 of each scene, rigid
platform unless named; "peak": ru_maxrss of one process doing one solve in-process, in MiB):

    scene            h (mm)  dofs n   (d/h)^2  nnz(L+U)  fill/dof  before LU   peak
    paper              40      7,998     6.25    1.70e6     213      214 MB     231 MB
    paper              32     13,212     9.77    3.02e6     229      249 MB     279 MB
    paper              25     26,289    16.0    11.5e6      437      347 MB     443 MB
    paper              20     45,210    25.0    23.9e6      529      495 MB     646 MB
    paper              16     83,562    39.1    65.1e6      779      789 MB    1259 MB
    paper              14    117,969    51.0     109e6      927     1063 MB    1833 MB
    paper              12    176,262    69.4     239e6     1354     1519 MB    3371 MB
    paper              10    293,136   100       639e6     2180     2438 MB    7852 MB
    stocky (d 150)     20     76,611    56.3     102e6     1329      759 MB    1581 MB
    stocky (d 150)     16    142,086    87.9     244e6     1714     1292 MB    3266 MB
    slender (d 30)     10     46,962     9.0    11.2e6      239      427 MB     493 MB
    paper, elastic     16    108,327    39.1    92.4e6      853     1368 MB    2006 MB

- fill per dof: 20 (d/h)^2 + 60 fits every row within 20 %; 23 (d/h)^2 + 80 lies above all.
- before LU: 143 MB + 7.8 kB per dof on the rigid-platform rows (within 5 %): mesh, basis,
  K, M, T, reduced K and M (the elastic plate's assembly holds more, covered by the margin of
  the LU term); the base is taken as 200 MB (the interpreter and its libraries).
- LU: 6.6 to 10.5 bytes per stored entry (8-byte values, row indices shared by supernodes;
  SuperLU grows its arrays by copying, so the ratio rises with size: 8.9 at 10 mm).
The constants below are the upper values (fill 23 (d/h)^2 + 80 per dof, 12 bytes per entry):
the estimate lies above every measured peak, by 5 to 48 % (10.9 GB against 8.23 GB at 10 mm),
and agrees with the one larger run on record, `fem --size 9` (395k dofs), which passed 15.7 GB
after 10 minutes and was still growing (issue 11): estimated here 17.1 GB.

Graded meshes (issue 13: rim_factor 0.4, rim_zone 0.15 d, rim_grading 1, Netgen-optimised;
case 1, one solve in-process, peak of the process or its solver child) fill less per dof than
their global size suggests (the refinement is local to the rims, the leg's middle sections stay
at h), so the same formula stays above them with the dof estimate of fem_reference.model:

    scene            h (mm)  dofs n   estimated n   peak      estimate
    paper              25     32,160     28,565*    0.40 GB   0.58 GB
    paper              20     53,142     50,950*    0.69 GB   1.00 GB
    paper              16     93,438     91,948*    1.28 GB   2.00 GB
    stocky (d 150)     32     34,131     46,699     0.45 GB   0.89 GB
    stocky (d 150)     24     69,006     90,016     0.96 GB   1.96 GB
    slender (d 30)    7.5     87,390    111,425     0.91 GB   1.67 GB
    (* estimated before the dof constants were re-fitted; now 10-36 % above the raw count)

The harmonic legs (harmonic.py) factor 2D meridian matrices, whose fill grows like n log n:
measured the same way (paper, case 1, rigid coupling; "estimated n" is the DOF guard's
estimate, harmonic.estimate_raw_dofs, 1.5 times the raw count):

    h (mm)   raw dofs   estimated n   peak      peak - base per estimated dof
      20       21,870        33,247    225 MB     (the base alone)
      10       73,737       112,336    365 MB     1.5 kB
       6      197,451       299,806    706 MB     1.7 kB
       4      431,892       665,957   1426 MB     1.8 kB
       3      751,923     1,178,569   2452 MB     1.9 kB

The per-dof cost rises by about 0.1 kB per doubling of n; HARMONIC_BYTES_PER_DOF = 3 kB stays
above that trend to beyond 10^8 dofs (a 0.5 mm mesh of the paper's legs: 4e7 dofs, 120 GB).

The limit is half the memory available now (MemAvailable, or a cgroup's remaining limit if
lower): the machine is shared, the estimate scatters by tens of per cent, and the rest of the
run keeps its own memory.
"""
from __future__ import annotations

import os
from pathlib import Path

from common.errors import InputError

BASE_BYTES = 200e6  # the interpreter with numpy, scipy, gmsh, scikit-fem: 100-200 MB
BYTES_PER_DOF = 7.8e3
FILL_PER_SECTION = 23.0  # stored LU entries per dof and per (d / h)^2 ...
FILL_FLOOR = 80.0  # ... plus these per dof
BYTES_PER_ENTRY = 12.0
MEMORY_FRACTION = 0.5  # half of the memory available (see above)
HARMONIC_BYTES_PER_DOF = 3e3  # per estimated raw dof of the harmonic legs (see above)


class MemoryLimitError(InputError):
    """The solve would need more memory than the limit (one line: size, estimate, limit)."""


def peak_bytes(dofs: float, leg_diameter: float, size: float) -> float:
    """Estimated peak memory (bytes) of a solve with `dofs` unknowns at element size `size`."""
    fill = dofs * (FILL_PER_SECTION * (leg_diameter / size) ** 2 + FILL_FLOOR)
    return BASE_BYTES + BYTES_PER_DOF * dofs + BYTES_PER_ENTRY * fill


def available_bytes() -> float | None:
    """Memory this process may still use: MemAvailable, or less under a cgroup limit."""
    found = []
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                found.append(float(line.split()[1]) * 1024)
    except (OSError, ValueError, IndexError):
        pass
    for limit, usage in (("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
                         ("/sys/fs/cgroup/memory/memory.limit_in_bytes",
                          "/sys/fs/cgroup/memory/memory.usage_in_bytes")):
        try:
            found.append(float(Path(limit).read_text()) - float(Path(usage).read_text()))
        except (OSError, ValueError):  # absent, or "max" (no limit)
            pass
    if not found:
        try:
            found.append(float(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")))
        except (OSError, ValueError, AttributeError):
            return None
    return max(0.0, min(found))


def harmonic_peak_bytes(dofs: float) -> float:
    """Estimated peak memory (bytes) of a harmonic-leg solve with `dofs` estimated raw dofs."""
    return BASE_BYTES + HARMONIC_BYTES_PER_DOF * dofs


def check_memory(dofs: float, width: float, size: float,
                 available: float | None = None, harmonic: bool = False,
                 share: float = 1.0) -> float:
    """The estimated peak (bytes); MemoryLimitError if it exceeds `share` of MEMORY_FRACTION
    of the memory available (measured now unless given): n solves at once take 1 / n each,
    since each measures the memory before the others have taken theirs. `harmonic`: the 2D
    meridian solve. `width`: the leg diameter, or the widest body's (guard.section_width)."""
    need = harmonic_peak_bytes(dofs) if harmonic else peak_bytes(dofs, width, size)
    free = available_bytes() if available is None else available
    if free is not None and need > share * MEMORY_FRACTION * free:
        of = "half" if share == 1.0 else f"{share:.3g} of half"
        raise MemoryLimitError(
            f"mesh_size_mm = {size * 1e3:g}: the solve needs about {need / 1e9:.3g} GB "
            f"({int(dofs):,} dofs, from the measured LU fill: fem_reference/resources.py), "
            f"above the limit of {share * MEMORY_FRACTION * free / 1e9:.3g} GB ({of} of the "
            f"{free / 1e9:.3g} GB available{'' if share == 1.0 else ', one of parallel solves'})"
            f"; use a coarser mesh{'' if share == 1.0 else ' or fewer workers'}")
    return need

"""The command line `rps` (`python -m rps`): a thin layer over the scene, the solvers, the run
and the report (README.md). The top floor: nothing imports it."""
import os

# The analytical model solves dense problems of 18 s coordinates (54 at s = 3): OpenBLAS
# threads only add overhead there (measured: s = 10 pose 8.0 ms with 2 threads, 3.6 ms with 1),
# and the sparse FEM solve is no slower with one. Set before numpy loads; a user's own setting wins.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

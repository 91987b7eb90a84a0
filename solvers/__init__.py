"""The models as the studies use them: each solve through the result cache, paired by shape.

- `compare`: one analytical or FEM solve of a pose (cached), and the error table of a pair;
- `pairing`: modes paired by MAC on shared stations, repeated pairs as 2-D subspaces;
- `refinement`: the FEM at several sizes and its extrapolated limit; the cache filled ahead;
- `settings`: the analytical settings compared throughout (one constructor of their labels);
- `timing`: wall time per pose of an analytical setting, measured once per machine and code.

Below the studies and the run; above the models, the scene, the results schema and `runtime`.
"""

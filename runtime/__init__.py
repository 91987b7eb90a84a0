"""The machinery a run stands on, below the studies, the run and the reports: the content-keyed
result cache (`cache`), the staged, atomically swapped output folder (`outdir`) and the sweep
of cached tasks over worker processes (`sweep`). No physics: it imports only `common`, and it
is not part of the code fingerprint that keys the cache (editing it recomputes nothing)."""

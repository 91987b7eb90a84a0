"""One base for every error the project raises on purpose.

The command lines catch `RpsError` (and OSError: a full disk, a denied write) and print its one
line (exit 2); anything else that escapes is a bug and keeps its traceback. Two kinds, so
callers that only care about "bad input" or "the computation could not be done" can say so;
each also derives from the builtin it replaced, so `except ValueError` in a caller keeps
working:

- `InputError` (a ValueError): what was given is refused: a scene key, an option, a pose the
  machine cannot reach, a mesh too large for this machine, a results file of another schema;
- `ComputeError` (a RuntimeError): the input was fine but a step failed: gmsh, an eigen solve
  that did not converge, a worker that died, a figure that could not be drawn.
"""
from __future__ import annotations


class RpsError(Exception):
    """An error the pipeline raises on purpose, with a one-line message for the user."""


class InputError(RpsError, ValueError):
    """Refused input: the message names what was given first, then why."""


class ComputeError(RpsError, RuntimeError):
    """A step failed on valid input: the message names the step and the cause."""

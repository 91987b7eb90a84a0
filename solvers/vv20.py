"""A comparison stated as ASME V&V 20-2009 states a validation: the comparison error
E = S - D beside the validation uncertainty u_val = sqrt(u_num^2 + u_input^2 + u_D^2), all
standard uncertainties (%), and a verdict worded by them (k = 2, about 95 %).

- u_num from a stated error bound b (the FEM's, the larger of Richardson's step and the GCI;
  the beam model's, its change when its elements are doubled): b / sqrt(3), the standard
  uncertainty of a bound with nothing more known (GUM, JCGM 100:2008, 4.3.7: a rectangular
  distribution).
- u_input: the model's frequency standard deviation over the scene's [uncertainty].
- u_D: the test's (the identification's frequency noise); none against the FEM.

Against the FEM the model and the reference share the inputs, so u_input does not blur E: it
is the scale at which the model's error would change what can be said about the machine.
Against a test it is V&V 20's input uncertainty proper.
"""
from __future__ import annotations

import math

COVERAGE = 2.0  # k of the verdict's expanded uncertainties (about 95 %)


def from_bound(bound: float | None) -> float | None:
    """The standard uncertainty of an error bound (%), or None without one."""
    return None if bound is None else abs(bound) / math.sqrt(3.0)


def u_val(u_num: float | None, u_input: float | None, u_d: float | None) -> float:
    return math.sqrt(sum(u * u for u in (u_num, u_input, u_d) if u is not None))


def verdict(e: float, u_num: float | None, u_validation: float, reference: str = "the FEM"
            ) -> str:
    """V&V 20's reading of one comparison: is E resolved at all (against 2 u_num), and does it
    matter (against 2 u_val)?"""
    if u_num is not None and abs(e) <= COVERAGE * u_num:
        return (f"not resolved: |E| {abs(e):.3g} % within 2 u_num ({COVERAGE * u_num:.3g} %), "
                "the numerical uncertainty")
    if abs(e) <= COVERAGE * u_validation:
        return (f"within 2 u_val ({COVERAGE * u_validation:.3g} %): at these tolerances the "
                f"model's difference from {reference} does not matter")
    return (f"the model's error matters: delta_model = {e:.3g} +- "
            f"{COVERAGE * u_validation:.3g} % (E beyond 2 u_val)")

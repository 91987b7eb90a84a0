"""[uncertainty]: the scene's inputs as random variables, for the propagation of input
uncertainty through the fast model (`rps uncertainty`, the run's uncertainty studies).

    [uncertainty]
    samples = 1024
    "material.youngs_modulus_gpa" = { distribution = "normal", cv_percent = 2.0, source = "..." }
    "material.shear_modulus_gpa" = { follows = "material.youngs_modulus_gpa" }
    "stiffness.actuator_axial_n_per_um" = { distribution = "lognormal", cv_percent = 30.0 }
    "payload.mass_kg" = { distribution = "uniform", low = 25.0, high = 31.0 }

Every other key of the table is a scene address (`scene.address`: a number of [manipulator],
[material], [leg], [stiffness] or [payload]), its inline table one `InputSpec`. A normal or
lognormal input has the scene's value as its mean; a uniform one spans the scene's value
plus or minus a tolerance, or low..high around it (the key's edge unit). An input that
`follows` another moves by the same factor (E and G under a fixed Poisson's ratio): it is not
an input of its own, its effect is counted in its leader's Sobol' indices.

Every distribution is cut at its TAIL quantiles (the design's unit values are clipped there).
Each input's two ends (its followers with it, the others at the scene's values) are checked in
the key's declared range when the scene is read, and as whole machines (`check_ends`: the
scene's plausibility rules) by whoever propagates, before any solve.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from common.settings import declared, setting

from .errors import SceneError

if TYPE_CHECKING:
    from .address import Address

DISTRIBUTIONS = ("normal", "lognormal", "uniform")
TAIL = 1e-6  # a distribution's support: its TAIL .. 1 - TAIL quantiles (4.75 sd of a normal)
MAX_NORMAL_CV = 20.0  # %: a wider normal input reaches 5 % of its mean at the tail (lognormal)
MAX_CV = 200.0  # %: a lognormal input within a factor of about 20 at the tails
MIN_CV = 0.01  # %
MAX_SAMPLES = 1 << 16


@dataclass(frozen=True)
class UncertaintySettings:
    """[uncertainty]'s own keys (every other key is an uncertain input)."""

    samples: int = setting(
        1024, kind=int, minimum=64, maximum=MAX_SAMPLES,
        doc="base points N of the scrambled Sobol' design (a power of two keeps its balance; "
        "the model runs N (d + 2) times for d independent inputs, Saltelli's scheme; the "
        "statistics' sampling errors fall as 1 / sqrt(N) or faster)")
    seed: int = setting(
        20260101, kind=int, minimum=0, maximum=2**31 - 1,
        doc="seed of the design's scrambling and of the bootstrap (the same seed, the same "
        "numbers)")


@dataclass(frozen=True)
class InputSpec:
    """One uncertain input (an inline table under its scene key)."""

    distribution: str = setting(
        "", kind=str, choices=DISTRIBUTIONS,
        doc="normal (mean the scene's value, cv_percent at most "
        f"{MAX_NORMAL_CV:g}), lognormal (mean the scene's value, cv_percent: a positive "
        "quantity known within a factor, e.g. a bearing's stiffness) or uniform (low..high); "
        "leave it out with `follows`")
    cv: float = setting(
        None, unit=None, scene_name="cv_percent", minimum=MIN_CV, maximum=MAX_CV,
        doc="coefficient of variation, standard deviation over mean, in percent (normal, "
        "lognormal)")
    plus_minus: float = setting(
        None, minimum=0.0, maximum=1e12, exclusive_minimum=True,
        doc="uniform: the scene's value plus or minus this, in the key's own edge unit (a "
        "drawing's tolerance: it follows the scene's value wherever a design or an "
        "identification moves it)")
    low: float = setting(None, minimum=-1e12, maximum=1e12,
                         doc="uniform: the lowest value, in the key's own edge unit (a range "
                         "fixed in absolute terms: a scene value moved outside it is refused)")
    high: float = setting(None, minimum=-1e12, maximum=1e12,
                          doc="uniform: the highest value, in the key's own edge unit")
    follows: str = setting(
        "", kind=str,
        doc="another uncertain key (with a distribution) this one moves with, by the same "
        "factor: value = scene value x leader's sample / leader's scene value (E and G under a "
        "fixed Poisson's ratio)")
    source: str = setting("", kind=str, paragraphs=True,
                          doc="where the tolerance comes from (a standard, a datasheet, a "
                          "measurement): the report shows it")


@dataclass(frozen=True)
class UncertainInput:
    """One independent input: its address, its scene value (edge unit) and its distribution,
    with the addresses that follow it."""

    address: "Address"
    nominal: float
    spec: InputSpec
    followers: tuple[tuple["Address", float], ...] = ()  # (address, its scene value)

    @property
    def name(self) -> str:
        return self.address.name

    def quantile(self, u) -> np.ndarray:
        """The input's values (edge unit) at unit values `u`, clipped to the TAIL quantiles."""
        u = np.clip(np.asarray(u, float), TAIL, 1.0 - TAIL)
        spec, mean = self.spec, self.nominal
        if spec.distribution == "uniform":
            low, high = self.bounds
            return low + (high - low) * u
        from scipy.special import ndtri

        cv = spec.cv / 100.0
        if spec.distribution == "normal":
            return mean * (1.0 + cv * ndtri(u))
        s = math.sqrt(math.log1p(cv * cv))  # lognormal: log-sd s, arithmetic mean `mean`
        return mean * np.exp(s * ndtri(u) - 0.5 * s * s)

    @property
    def bounds(self) -> tuple[float, float]:
        """A uniform input's low..high (edge unit)."""
        spec = self.spec
        if spec.plus_minus is not None:
            return self.nominal - spec.plus_minus, self.nominal + spec.plus_minus
        assert spec.low is not None and spec.high is not None
        return spec.low, spec.high

    @property
    def support(self) -> tuple[float, float]:
        low, high = self.quantile([0.0, 1.0])
        return float(low), float(high)

    def describe(self) -> str:
        spec = self.spec
        if spec.distribution == "uniform":
            low, high = self.bounds
            text = (f"uniform {low:g} .. {high:g}" if spec.plus_minus is None else
                    f"uniform {self.nominal:g} +- {spec.plus_minus:g}")
        else:
            text = f"{spec.distribution}, mean {self.nominal:g}, cv {spec.cv:g} %"
        return f"{text} {self.address.unit}" + (
            " (with " + ", ".join(f.name for f, _ in self.followers) + ")"
            if self.followers else "")


@dataclass(frozen=True)
class Uncertainty:
    """The scene's [uncertainty]: its settings and its independent inputs, in file order."""

    settings: UncertaintySettings
    inputs: tuple[UncertainInput, ...]

    @property
    def names(self) -> list[str]:
        return [i.name for i in self.inputs]

    @property
    def tables(self) -> set[str]:
        """The scene tables the inputs and their followers move."""
        return {a.table for i in self.inputs for a in (i.address, *(f for f, _ in i.followers))}

    def values(self, unit) -> list[tuple["Address", np.ndarray]]:
        """(address, values in its edge unit) of every input and follower at the unit values
        `unit` (n, d): a follower scaled by its leader's factor."""
        unit = np.atleast_2d(np.asarray(unit, float))
        out = []
        for k, item in enumerate(self.inputs):
            v = item.quantile(unit[:, k])
            out.append((item.address, v))
            for follower, nominal in item.followers:
                out.append((follower, nominal * v / item.nominal))
        return out


def parse(table: Any, manipulator, where: str) -> Uncertainty:
    """[uncertainty] from its `Table` (scene.toml_table), around the values of `manipulator` (the
    scene's machine); SceneError in one line on any problem."""
    from .address import resolve

    settings = table.settings(UncertaintySettings)
    declared_keys = {spec.scene_key(name) for name, spec, _ in declared(UncertaintySettings)}
    leaders: dict[str, tuple[Any, float, InputSpec]] = {}
    followed: dict[str, list] = {}
    for key in list(table.data):
        if key in declared_keys:
            continue
        sub = table.table(key)
        address = resolve(key, where=f"{where}.{key}: key")
        spec = sub.settings(InputSpec)
        given = set(sub.data)
        sub.done()
        nominal = address.read(manipulator)
        here = f"{where}.{key}"
        if spec.follows:
            if given - {"follows", "source"}:
                raise SceneError(f"{here}: follows = {spec.follows!r} with "
                                 f"{sorted(given - {'follows', 'source'})[0]}: a follower "
                                 "has no distribution of its own")
            if nominal == 0.0:
                raise SceneError(f"{here} follows {spec.follows!r} but its scene value is 0: "
                                 "it cannot move by a factor")
            followed.setdefault(resolve(spec.follows, where=f"{here}.follows").name,
                                []).append((address, nominal, here))
            continue
        leaders[address.name] = (address, nominal, _checked(spec, given, nominal, here))
    inputs = []
    for name, items in followed.items():
        if name not in leaders:
            raise SceneError(f"{items[0][2]}.follows = {name!r}: that key has no distribution "
                             "in [uncertainty] (a follower follows an input)")
    for name, (address, nominal, spec) in leaders.items():
        items = followed.get(name, [])
        if items and nominal == 0.0:
            raise SceneError(f"{items[0][2]}.follows = {name!r}: its leader's scene value is 0, "
                             "so no factor moves the follower (give the leader a value)")
        inputs.append(UncertainInput(address, nominal, spec, tuple((a, n) for a, n, _ in items)))
    if not inputs:
        raise SceneError(f"{where}: no uncertain input (give one as \"table.key\" = "
                         "{ distribution = ..., ... })")
    table.done()
    for item in inputs:  # each input's ends in its key's declared range (the machine: check_ends)
        for end, moved in ends(item):
            for address, v in moved:
                why = address.problem(v)
                if why is not None:
                    raise SceneError(f"{where}.\"{item.name}\": at its {end} end "
                                     f"{address.name} = {v:.6g} {address.unit}: {why}")
    return Uncertainty(settings, tuple(inputs))


def ends(item: UncertainInput) -> list[tuple[str, list[tuple["Address", float]]]]:
    """("low" | "high", [(address, value)] of the input and its followers) at its two ends."""
    return [(end, [(item.address, value)] + [(a, n * value / item.nominal)
                                             for a, n in item.followers])
            for end, value in zip(("low", "high"), item.support)]


def _checked(spec: InputSpec, given: set, nominal: float, here: str) -> InputSpec:
    if "distribution" not in given:
        raise SceneError(f"{here}: missing distribution (one of {', '.join(DISTRIBUTIONS)}), "
                         "or follows = another key")
    if spec.distribution == "uniform":
        if "plus_minus" in given:
            if given & {"cv_percent", "low", "high"}:
                raise SceneError(f"{here}: a uniform input takes plus_minus, or low and high, "
                                 "not both (nor cv_percent)")
            return spec
        if spec.low is None or spec.high is None or given & {"cv_percent"}:
            raise SceneError(f"{here}: a uniform input takes low and high, or plus_minus (the "
                             "key's unit), not cv_percent")
        if not spec.low < spec.high:
            raise SceneError(f"{here}: low = {spec.low:g} is not below high = {spec.high:g}")
        if not spec.low <= nominal <= spec.high:
            raise SceneError(f"{here}: the scene's value {nominal:g} is outside low..high = "
                             f"{spec.low:g}..{spec.high:g} (the range is around the scene's "
                             "value)")
        return spec
    if spec.cv is None or given & {"low", "high", "plus_minus"}:
        raise SceneError(f"{here}: a {spec.distribution} input takes cv_percent (its mean is "
                         "the scene's value), not low, high or plus_minus")
    if nominal <= 0.0:
        raise SceneError(f"{here}: a {spec.distribution} input around the scene's value "
                         f"{nominal:g}: needs a positive value (give the key a value, or a "
                         "uniform range)")
    if spec.distribution == "normal" and spec.cv > MAX_NORMAL_CV:
        raise SceneError(f"{here}: cv_percent = {spec.cv:g} for a normal input: at most "
                         f"{MAX_NORMAL_CV:g} (its tail would reach zero; use lognormal)")
    return spec


def check_ends(uncertainty: Uncertainty, raw: dict, where: str, parse) -> None:
    """Each input at its two support ends (its followers with it, every other input at the
    scene's value) as a machine `parse` (scene.parse_scene) accepts: the whole-machine rules
    (analytical.plausibility), a fraction of a second a machine, so the commands that
    propagate call it, not every reader of the scene. SceneError in one line naming the key,
    the end and why."""
    from .address import with_values

    plain = {k: v for k, v in raw.items() if k != "uncertainty"}
    for item in uncertainty.inputs:
        for end, moved in ends(item):
            value = moved[0][1]
            try:
                parse(with_values(plain, dict(moved)), f"{where} with {item.name} = {value:.6g}")
            except SceneError as exc:
                raise SceneError(f"{where}.uncertainty.\"{item.name}\": at its {end} end "
                                 f"{value:.6g} {item.address.unit} the machine is refused: "
                                 f"{exc}") from None

"""What an effect is: its parameters, how it changes a simulation, how it is reported, and how `prove` hides it.

One `Effect` carries everything the other modules read about it (`discovery.fit` its parameters and `apply`,
`discovery.report` its `describe`, words, phrase and service setting, `discovery.conceal` and `discovery.prove` its
`hiding`), so a new effect is one module of this package plus its tests.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal, TypeVar

import numpy as np
from golfflight.discovery.schema import CorrectionSettings
from golfflight.discovery.simulator import Correction, Setup
from golfflight.flight.air import Air
from golfflight.flight.reference_aero import ReferenceParameters
from golfflight.flight.wind import Wind

if TYPE_CHECKING:
    from golfflight.shots.synth import LaunchTable


@dataclass(frozen=True)
class Parameter:
    """One internal parameter of an effect."""

    name: str
    unit: str
    null: float
    low: float
    high: float
    typical: float
    """Typical size of a real effect: the scale the optimiser works in."""
    step: float
    """Finite-difference step: large enough to step over the integrator's landing kinks."""


Reported = tuple[dict[str, float], dict[str, float]]

Kind = Literal["venue", "monitor", "ball", "form"]
"""What an effect says about the recordings: a condition of the venue (air, wind, ground), a bias of the launch
monitor's launch values, another ball than a baseline session's, or the model's form (its coefficients or a learned
correction: the recordings' physics differs from the model's in form). Venue and monitor findings are what a user
acts on; a form finding says the model itself differs, whatever the venue."""

KINDS: dict[Kind, str] = {
    "venue": "a condition of the venue",
    "monitor": "a bias of the launch monitor",
    "ball": "another ball",
    "form": "the model's form",
}


@dataclass(frozen=True)
class Context:
    """What reporting needs beyond the parameters: the air the model assumed."""

    density_kg_m3: float
    temperature_c: float


@dataclass(frozen=True)
class World:
    """The reference world a concealed set is flown in (`discovery.conceal`): air, wind, landing ground, aerodynamics."""

    air: Air
    wind: Wind
    ground_m: float
    params: ReferenceParameters
    wind_profile: Literal["uniform", "log"]
    """The profile a hidden wind follows (its speed stated at 10 m for a log profile)."""


T = TypeVar("T")


def unchanged(_: object, world: T) -> T:
    """A world (or recorded launches, or a model's Setup) the effect leaves as it is."""
    return world


Draw = Callable[[np.random.Generator], dict[str, float]]
"""A plausible truth of an effect, in the report's parameters, drawn in a fixed order."""


@dataclass(frozen=True)
class Hiding:
    """How `prove` hides the effect in synthetic recordings: a plausible truth (the report's parameters) and the
    recorded launches, the reference world and the diagnosed model's own flights with that truth."""

    draw: Draw
    """A realistic size and direction (the campaign's truth)."""
    recorded: Callable[[dict[str, float], LaunchTable], LaunchTable]
    """What the launch monitor records of the true launches (a launch bias: recorded = true - offset, or / scale)."""
    reference: Callable[[dict[str, float], World], World]
    """The reference world with the effect."""
    model: Callable[[np.ndarray, Setup], Setup]
    """The model's own flights of the true launches with the effect, from internal parameters [N, k]: for most
    effects their `apply`."""


Phrase = Callable[[dict[str, float], dict[str, float]], str]
"""Reported parameters and their 1-sigma uncertainties in words, with units."""

Setting = Callable[[CorrectionSettings, dict[str, float], Context, float | None], None]
"""Puts a fitted effect's reported parameters into the service settings (with the assumed air and, for a wind, the
log profile's uniform-equivalent factor)."""


@dataclass(frozen=True)
class Effect:
    """A named effect with its parameters, how it changes a simulation and how its parameters are reported."""

    name: str
    parameters: tuple[Parameter, ...]
    apply: Callable[[np.ndarray, Setup], Setup]
    describe: Callable[[np.ndarray, np.ndarray, Context], Reported]
    summary: str
    correction: Correction | None = None
    """Extra acceleration the simulator adds (the learned correction); library effects have none."""
    kind: Kind = "form"
    words: str = ""
    """The effect in a reader's words ('launch angle reading'); empty: its name with spaces."""
    phrase: Phrase | None = None
    """The fitted effect in words with its size ± 1 sigma; None: its parameters listed."""
    setting: Setting | None = None
    """Its service setting (`discovery.report.service_settings`); None: none."""
    from_reported: Callable[[dict[str, float]], np.ndarray] | None = None
    """Reported parameters as the internal vector; None: those named as the internal parameters."""
    hiding: Hiding | None = None
    """How `prove` hides it (`discovery.conceal`); None: it is never hidden."""
    stand_ins: tuple[str, ...] = ()
    """Other effects whose fit names this one when it is hidden (`prove.fitted_as`: either air variant for air)."""

    @property
    def null(self) -> np.ndarray:
        return np.array([p.null for p in self.parameters])

    @property
    def size(self) -> int:
        return len(self.parameters)

    def internal(self, reported: dict[str, float]) -> np.ndarray:
        """A drawn truth or a fit in the report's parameters as the internal parameter vector."""
        if self.from_reported is not None:
            return self.from_reported(reported)
        return np.array([reported[p.name] for p in self.parameters])


def apply_all(effects: tuple[Effect, ...], theta: np.ndarray, conditions: Setup) -> Setup:
    """Apply several effects; theta [N, sum of their sizes] holds their parameters side by side."""
    start = 0
    for effect in effects:
        conditions = effect.apply(theta[:, start : start + effect.size], conditions)
        start += effect.size
    return conditions

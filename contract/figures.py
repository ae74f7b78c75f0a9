"""The figures of a flight's outcome, defined once: each one's name, unit, meaning and imperial twin, and where the
engine's outcome record (`ShotFlight`, `BatchFlights`, by field name) holds it.

Every form of a result is derived from `FIGURES`: the HTTP result models (`contract.results`, each NAME_m with NAME_yd
and each NAME_mps with NAME_mph beside it, `with_imperial`), the flat columns of `golfflight simulate` and `sweep`
(`contract.columns`) and the table `golfflight fly` prints. A new figure is one `Figure` here; a field of the outcome
record that is no figure is named in `NOT_FIGURES` with the reason (`unreported_fields` finds one that is neither).
"""

from __future__ import annotations

import dataclasses
import functools
import typing
from dataclasses import dataclass
from operator import attrgetter

from golfflight.flight.constants import MPH_TO_MPS, YARD_M

IMPERIAL_TWINS = (("_m", "_yd", YARD_M), ("_mps", "_mph", MPH_TO_MPS))
"""(SI suffix, imperial suffix, SI units per imperial unit): every result number named NAME_m (a length) gets
NAME_yd beside it, every NAME_mps (a speed) NAME_mph: the one place the results' imperial fields are defined."""


@functools.cache
def twin_of(name: str) -> tuple[str, float] | None:
    """(the imperial twin's name, SI units per imperial unit) of a result number, or None if it has none (kept per
    name: every shot's result asks for the same few dozen)."""
    for si, imperial, unit in IMPERIAL_TWINS:
        if name.endswith(si):
            return name.removesuffix(si) + imperial, unit
    return None


def with_imperial(numbers: dict) -> dict:
    """`numbers` with each SI length and speed followed by its imperial twin (`IMPERIAL_TWINS`): value / unit."""
    out = {}
    for name, value in numbers.items():
        out[name] = value
        twin = twin_of(name)
        if twin is not None:
            out[twin[0]] = value / twin[1]
    return out


@dataclass(frozen=True)
class Point:
    """A point of the flight on the ground, reported as one object (`model` in the HTTP result) of its coordinate
    figures, and as NAME_x_m, NAME_y_m, ... in columns; `description` is the object's schema description (line
    breaks as its docstring had them)."""

    name: str
    model: str
    description: str


LANDING = Point(
    "landing",
    "Landing",
    "Where the ball comes down, on its ground's plane (the tee's elevation unless the ground's elevation); metres\n"
    "with yards alongside.",
)
REST = Point(
    "rest", "RestPoint", "Where the ball comes to rest after bouncing and rolling; metres with yards alongside."
)


@dataclass(frozen=True)
class Figure:
    """One number of a flight's outcome: its name in every output (SI, NAME_UNIT; the imperial twin follows from it,
    `twin_of`), its unit and the words `golfflight fly` prints it with, what it means (the HTTP schema's
    description), where the outcome record holds it when not under its own name (`source`, dotted into `rest`), its
    type, the point it is a coordinate of (reported inside that object over HTTP), and whether the flat flight (down
    to the tee's elevation, beside one that lands higher or lower) reports it too."""

    name: str
    unit: str
    label: str
    description: str | None = None
    source: str | None = None
    kind: type = float
    point: Point | None = None
    flat: bool = False

    @property
    def record_field(self) -> str:
        """The outcome record's field that holds it (dotted into `rest`)."""
        return self.source or self.name

    @property
    def coordinate(self) -> str:
        """The name inside its point's object (x_m for landing_x_m); the name itself when it is no coordinate."""
        return self.name if self.point is None else self.name.removeprefix(self.point.name + "_")

    @property
    def twin(self) -> str | None:
        """The imperial twin's name (carry_yd for carry_m), or None."""
        twin = twin_of(self.name)
        return None if twin is None else twin[0]


ACROSS = "right (+) of the target line"
ALONG = "down the target line"

FIGURES: tuple[Figure, ...] = (
    Figure("landing_x_m", "m", "landing across", ACROSS, point=LANDING, flat=True),
    Figure("landing_y_m", "m", "landing along", ALONG, point=LANDING, flat=True),
    Figure("carry_m", "m", "carry", "horizontal distance from the tee to the landing point", flat=True),
    Figure("lateral_m", "m", "lateral", "landing point right (+) or left (-) of the target line", flat=True),
    Figure("apex_m", "m", "apex", "greatest height"),
    Figure("apex_time_s", "s", "apex time"),
    Figure("flight_time_s", "s", "flight time", flat=True),
    Figure("landing_angle_deg", "deg", "landing angle", "descent angle below the horizontal", flat=True),
    Figure("landing_speed_mps", "m/s", "landing speed"),
    Figure("landing_spin_rpm", "rpm", "landing spin"),
    Figure("total_m", "m", "total", "horizontal distance from the tee to the rest point (carry and roll)",
           source="rest.total_m"),
    Figure("roll_m", "m", "roll", "total minus carry: the run after landing (negative: the ball came back)",
           source="rest.roll_m"),
    Figure("rest_x_m", "m", "rest across", ACROSS, source="rest.x_m", point=REST),
    Figure("rest_y_m", "m", "rest along", ALONG, source="rest.y_m", point=REST),
    Figure("bounces", "", "bounces", "hops after the landing before the ball rolls", source="rest.bounces", kind=int),
)
"""Every figure of a flight rolled to rest, in the order the HTTP result and the columns give them."""

FLAT_FIGURES = tuple(figure for figure in FIGURES if figure.flat)
"""The figures of the flat flight (down to z = 0: TrackMan's), beside a flight whose ground is higher or lower."""

NOT_FIGURES = {
    "states": "the integrator's states: a result's trajectory when one is asked for, resampled (`contract.flying`)",
    "rest.ground_time_s": "time from the landing to the rest: the engine's, not part of the contract's result",
    "rolled": "a batch's bookkeeping: which shots were rolled to rest (the others' rest figures are NaN)",
    "errors": "a batch's bookkeeping: why a shot failed (its own result, `ShotFailure`)",
}
"""Fields of the outcome records that are deliberately no figure, and why."""


def outcome_fields(record: type, prefix: str = "") -> list[str]:
    """The fields of an outcome record (a dataclass), a nested dataclass's (`rest: Rest | None`) dotted as rest.x_m,
    rest.y_m, ...; a field named in NOT_FIGURES is not opened."""
    hints = typing.get_type_hints(record)
    names = []
    for field in dataclasses.fields(record):
        name = prefix + field.name
        nested = [t for t in (hints[field.name], *typing.get_args(hints[field.name])) if dataclasses.is_dataclass(t)]
        if nested and name not in NOT_FIGURES:
            names += outcome_fields(nested[0], name + ".")
        else:
            names.append(name)
    return names


def unreported_fields(record: type) -> list[str]:
    """Fields of an outcome record (a dataclass such as ShotFlight or BatchFlights) that no figure reports and
    NOT_FIGURES does not name: each is a figure missing from `FIGURES`."""
    sources = {figure.record_field for figure in FIGURES}
    return [name for name in outcome_fields(record) if name not in sources and name not in NOT_FIGURES]


_READERS = tuple((figure.name, attrgetter(figure.record_field)) for figure in FIGURES)
_FLAT_READERS = tuple((figure.name, attrgetter(figure.record_field)) for figure in FLAT_FIGURES)


def flight_numbers(flight) -> dict:
    """The figures of a flight rolled to rest by name, imperial twins alongside (`with_imperial`), from one
    ShotFlight (floats) or a batch's `BatchFlights` (arrays)."""
    return with_imperial({name: read(flight) for name, read in _READERS})


def flat_numbers(flight) -> dict:
    """The flat flight's figures (`FLAT_FIGURES`) of a flight flown down to z = 0, as `flight_numbers`."""
    return with_imperial({name: read(flight) for name, read in _FLAT_READERS})

"""What comes back for a shot: pydantic result models, their figures' fields derived from `contract.figures.FIGURES`
(each figure with its description, NAME_m followed by NAME_yd and NAME_mps by NAME_mph, a point's coordinates as one
object), so a figure added there is in every result, the OpenAPI schema and the viewer's event schema at once."""

from __future__ import annotations

from typing import Literal

from golfflight.contract.figures import FIGURES, FLAT_FIGURES, LANDING, REST, Figure, Point
from golfflight.contract.requests import AirRequest, GroundRequest, ReferenceAir, WindRequest
from pydantic import BaseModel, Field, create_model


def _point_model(point: Point) -> type[BaseModel]:
    """The object of a point's coordinates: each coordinate (x_m, y_m), then their imperial twins (x_yd, y_yd)."""
    coordinates = [figure for figure in FIGURES if figure.point == point]
    fields = {figure.coordinate: (figure.kind, Field(description=figure.description)) for figure in coordinates}
    fields |= {figure.twin.removeprefix(point.name + "_"): (float, ...) for figure in coordinates if figure.twin}
    return create_model(point.model, __doc__=point.description, __module__=__name__, **fields)


POINT_MODELS: dict[str, type[BaseModel]] = {
    point.name: _point_model(point) for point in dict.fromkeys(figure.point for figure in FIGURES if figure.point)
}
"""A point's name (landing, rest) -> the model of its coordinates."""

Landing = POINT_MODELS[LANDING.name]
RestPoint = POINT_MODELS[REST.name]


def _figure_fields(figures: tuple[Figure, ...], described: bool = True) -> dict:
    """Model fields of `figures` in their order: each with its imperial twin after it, a point's coordinates as the
    point's object where its first coordinate stands; `described` False leaves out the descriptions (the flat
    flight's schema has never had them)."""
    fields: dict = {}
    for figure in figures:
        if figure.point is not None:
            fields.setdefault(figure.point.name, (POINT_MODELS[figure.point.name], ...))
            continue
        fields[figure.name] = (figure.kind, Field(description=figure.description if described else None))
        if figure.twin:
            fields[figure.twin] = (float, ...)
    return fields


class TrajectoryPoint(BaseModel):
    t_s: float
    x_m: float
    y_m: float
    z_m: float


FlightResult = create_model(
    "FlightResult",
    __doc__="One flight to its landing on its ground (at the tee's elevation, \"flat\", unless the ground's "
    "elevation), then bounced and rolled to rest: every figure of `contract.figures.FIGURES`, each length in metres "
    "with yards alongside (NAME_m, NAME_yd), the landing speed in m/s with mph alongside.",
    __module__=__name__,
    **_figure_fields(FIGURES),
    trajectory=(
        list[TrajectoryPoint] | None,
        Field(
            None, description="only when asked for: the flight, the bounces (an impact twice: in and out) and the roll"
        ),
    ),
)


class NormalizedFlight(FlightResult):
    """The same launch flown in calm reference air."""

    conditions: ReferenceAir


FlatFlight = create_model(
    "FlatFlight",
    __doc__='The same flight down to the tee\'s elevation ("flat", TrackMan\'s figures), beside one that lands higher '
    "or\nlower.",
    __module__=__name__,
    **_figure_fields(FLAT_FIGURES, described=False),
)


ConditionSource = Literal["shot", "bay", "shot and bay", "default"]
"""Where a condition flown in came from: the shot's own, the bay's, the shot's air quantities over the bay's, or the
default (ICAO standard air, calm, a level fairway at the tee's height)."""


class FlownIn(BaseModel):
    """What a shot flown by the service flew in and how: the air, wind and ground as flown, where each came from, and
    whether it was rolled as a putt (with the putter selected, a note says why a shot was flown as a full one)."""

    air: AirRequest = Field(description="the air flown in ({}: ICAO standard air)")
    air_from: ConditionSource
    wind: WindRequest = Field(description="the wind flown in (speed 0: calm)")
    wind_from: ConditionSource
    ground: GroundRequest = Field(description="the ground it came down, bounced and rolled on")
    ground_from: ConditionSource
    putt: bool = Field(False, description="rolled on the ground from the start (a connector's shot with the putter "
                       "selected)")
    note: str | None = Field(None, description="how the shot was read, when that is not what one would guess: a "
                             "connector's shot with the putter selected that no putt can be is flown as a full shot")


class ShotResult(FlightResult):
    """The flight in the conditions given, and in reference conditions when asked for; a served shot says what it
    flew in (`flown_in`)."""

    normalized: NormalizedFlight | None = None
    flat: FlatFlight | None = Field(
        None, description="only when the ground's elevation (elevation_m or elevation_ft) is not 0: the flight to z = 0"
    )
    flown_in: FlownIn | None = Field(None, description="the service's answers only: the conditions it flew in, "
                                     "where each came from, and whether it was a putt")


class ShotFailure(BaseModel):
    """A batch shot the engine could not fly (the rest of the batch is unaffected)."""

    error: str = Field(description="why, e.g. the ball was still in the air at the simulation cap")


class BatchResult(BaseModel):
    results: list[ShotResult | ShotFailure]

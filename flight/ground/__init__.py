"""The ground phase: a landed ball bounces (Penner's impact model) and rolls to rest on a plane through its landing
point, level or sloped. Pure NumPy, batch-first; `ground_phase` is the entry point, `SURFACES` the one table of
surface parameters; `putt_phase` skids and rolls a putt that starts on the ground."""

from golfflight.flight.ground.phase import GroundPath, GroundPhase, OneRest, ground_phase, ground_phase_one
from golfflight.flight.ground.putt import SKID_FRICTION, PuttPhase, putt_phase
from golfflight.flight.ground.spec import LEVEL_FAIRWAY, GroundSpec, batch_surface, elevations
from golfflight.flight.ground.surfaces import (
    SURFACES,
    Surface,
    check_slope_held,
    green_rolling_resistance,
    holding_slope_deg,
    surface,
)

__all__ = [
    "LEVEL_FAIRWAY",
    "SKID_FRICTION",
    "SURFACES",
    "GroundPath",
    "GroundPhase",
    "GroundSpec",
    "OneRest",
    "PuttPhase",
    "Surface",
    "batch_surface",
    "check_slope_held",
    "elevations",
    "green_rolling_resistance",
    "ground_phase",
    "ground_phase_one",
    "holding_slope_deg",
    "putt_phase",
    "surface",
]

"""Report cells shared by the training-side generated docs (tables and sections: `shots.markdown`)."""

from __future__ import annotations

from golfflight.flight.constants import YARD_M


def metres_yards(value_m: float | None, digits: int = 2) -> tuple[str, str]:
    """A length as two table cells, metres and yards ('–' when there is none)."""
    if value_m is None:
        return "–", "–"
    return f"{value_m:.{digits}f}", f"{value_m / YARD_M:.{digits}f}"

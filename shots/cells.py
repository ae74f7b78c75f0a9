"""Cells of a shot export, shared by the loaders: a row that cannot become a record (its drop reason), a cell that
is not what its column must hold, the finite-number parse both kinds of file use, and a Date cell's time."""

from __future__ import annotations

import math
from datetime import datetime

from golfflight.errors import InputError

DATE_FORMATS = ("%m/%d/%Y %I:%M:%S %p", "%Y-%m-%d %H:%M:%S", "%Y-%m-%dT%H:%M:%S")


class BadRow(InputError):
    """A row that cannot become a canonical record; the message is the drop reason."""


class MalformedCell(BadRow):
    """A cell that is not what its column must hold; `cell` names the column and quotes the text."""

    def __init__(self, reason: str, column: str, text: str):
        super().__init__(reason)
        self.cell = f"column '{column}': {text!r}"


def finite_number(text: str, column: str, missing: tuple[str, ...] = ("",)) -> float | None:
    """The cell's text as a float; None where it is one of `missing`, MalformedCell where it is not finite."""
    text = text.strip()
    if text in missing:
        return None
    try:
        value = float(text)
    except ValueError:
        raise MalformedCell(f"'{column}' is not a number", column, text) from None
    if not math.isfinite(value):
        raise MalformedCell(f"'{column}' is not a number", column, text)
    return value


def when(text: str) -> tuple[str, str]:
    """(timestamp, session) from a Date cell: ISO time and its day, or the raw text and its first word."""
    for fmt in DATE_FORMATS:
        try:
            moment = datetime.strptime(text, fmt)
        except ValueError:
            continue
        return moment.isoformat(), moment.date().isoformat()
    return text, text.split()[0] if text.split() else ""

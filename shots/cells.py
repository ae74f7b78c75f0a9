"""Cells of a shot export, shared by the loaders: a row that cannot become a record (its drop reason), a cell that
is not what its column must hold, and the finite-number parse both kinds of file use."""

from __future__ import annotations

import math


class BadRow(Exception):
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

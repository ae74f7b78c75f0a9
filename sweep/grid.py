"""A sweep's launches as a grid: the cartesian product of value lists, one per column, generated a range of rows at a
time (a grid of a billion rows costs nothing until its rows are asked for).

Each axis is `COLUMN=SPEC` with the columns of a launches file (`contract.columns`) and SPEC one of
- `START:STOP:COUNT`: COUNT evenly spaced numbers from START to STOP, both included (`ball_speed_mps=30:80:11`);
- `V1,V2,...`: a list of numbers or words (`wind_from_deg=0,90,180,270`, `ground_surface=fairway,green`);
- `V`: one value, the same in every row (`altitude_m=1600`).
The first axis varies slowest: row i is numpy.unravel_index(i, counts) into the axes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from golfflight.contract.columns import REQUEST_COLUMNS, TEXT_COLUMNS, cell_value, check, request_of_cells
from golfflight.errors import InputError


class GridError(InputError):
    """A grid axis that cannot be read or holds a value the request model refuses."""


@dataclass(frozen=True)
class Axis:
    column: str
    values: tuple


def _number(text: str, axis: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise GridError(f"--grid {axis}: {text!r} is not a number") from None
    if not math.isfinite(value):
        raise GridError(f"--grid {axis}: {text!r} is not a finite number")
    return value


def parse_axis(text: str) -> Axis:
    """One `COLUMN=SPEC` argument (module docstring)."""
    column, equals, spec = text.partition("=")
    column, spec = column.strip(), spec.strip()
    if not equals or not column or not spec:
        raise GridError(f"--grid {text!r}: write COLUMN=START:STOP:COUNT, COLUMN=V1,V2,... or COLUMN=V")
    if column not in REQUEST_COLUMNS:
        raise GridError(f"--grid {text!r}: {column!r} is not a launch or condition column; one of {REQUEST_COLUMNS}")
    if ":" in spec:
        parts = spec.split(":")
        if len(parts) != 3:
            raise GridError(f"--grid {text!r}: a range is START:STOP:COUNT")
        start, stop = _number(parts[0], text), _number(parts[1], text)
        count = _number(parts[2], text)
        if count != int(count) or count < 1:
            raise GridError(f"--grid {text!r}: COUNT must be a whole number of at least 1 (got {parts[2]!r})")
        if count == 1 and start != stop:
            raise GridError(f"--grid {text!r}: one value cannot span {start:g} to {stop:g}; give COUNT >= 2")
        return Axis(column, tuple(np.linspace(start, stop, int(count)).tolist()))
    words = [w.strip() for w in spec.split(",")]
    if any(not w for w in words):
        raise GridError(f"--grid {text!r}: an empty value in the list")
    values = tuple(words if column in TEXT_COLUMNS else (cell_value(w) for w in words))
    if len(set(values)) != len(values):
        raise GridError(f"--grid {text!r}: a value is listed twice")
    return Axis(column, values)


@dataclass(frozen=True)
class Grid:
    """Axes of a cartesian product; rows by index, first axis slowest."""

    axes: tuple[Axis, ...]

    @classmethod
    def parse(cls, specs: list[str]) -> Grid:
        """A grid from `--grid` arguments, each axis checked against the request model (`check_values`)."""
        axes = tuple(parse_axis(spec) for spec in specs)
        columns = [axis.column for axis in axes]
        repeated = sorted({c for c in columns if columns.count(c) > 1})
        if repeated:
            raise GridError(f"--grid: {', '.join(repeated)} given more than once")
        grid = cls(axes)
        grid.check_values()
        return grid

    @property
    def columns(self) -> list[str]:
        return [axis.column for axis in self.axes]

    @property
    def counts(self) -> tuple[int, ...]:
        return tuple(len(axis.values) for axis in self.axes)

    def __len__(self) -> int:
        return math.prod(self.counts)

    def rows(self, start: int, stop: int) -> dict[str, list]:
        """Rows start..stop-1 as column lists."""
        index = np.unravel_index(np.arange(start, stop), self.counts)
        return {axis.column: [axis.values[i] for i in at.tolist()] for axis, at in zip(self.axes, index, strict=True)}

    def arrays(self, start: int, stop: int) -> dict:
        """Rows start..stop-1 as columns, as `rows` gives them: a NumPy float64 array for an axis of numbers (as
        Arrow reads Python floats), a list for any other."""
        index = np.unravel_index(np.arange(start, stop), self.counts)
        columns = {}
        for axis, at in zip(self.axes, index, strict=True):
            numbers = all(type(value) is float for value in axis.values)
            columns[axis.column] = np.array(axis.values)[at] if numbers else [axis.values[i] for i in at.tolist()]
        return columns

    def check_values(self) -> None:
        """Refuse the grid before anything flies if the request model refuses row 0 or any axis value in it (each
        value is tried in row 0 with the others fixed), naming the axis, the value and the allowed range."""
        first = {column: values[0] for column, values in self.rows(0, 1).items()}
        problems = check(request_of_cells(first))
        if isinstance(problems, list):
            raise GridError(f"--grid, first row {first}: {'; '.join(problems)}")
        for axis in self.axes:
            for value in axis.values[1:]:
                problems = check(request_of_cells({**first, axis.column: value}))
                if isinstance(problems, list):
                    raise GridError(f"--grid {axis.column}={value!r}: {'; '.join(problems)}")

"""The worker side of a sweep: a table of input rows in, a table of the same rows with their flights out.

One `SweepWorker` holds one FlightEngine (ONNX Runtime on one thread: the workers are the parallelism) and is what every
engine runs: called in each process of the local pool, and as Ray Data's callable class (one per actor). A piece's
rows are checked against the request model and flown a column at a time (`sweep.rows`: the verdicts, problem lines
and numbers of each row through the request model and the batch `golfflight simulate` flies, `contract.flying`,
without a request object a row); a row the request model refuses keeps its place with the reason in `problem` and no
flight, for the driver to report with the row's place in the input (only the driver knows it)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property
from typing import Protocol

from golfflight.contract.columns import (
    AIR_DENSITY,
    ELEVATION_COLUMNS,
    TEXT_COLUMNS,
    cell_value,
    is_flag_set,
    result_columns,
)
from golfflight.errors import InputError
from golfflight.flight.problem import Engine

PROBLEM = "problem"
"""Column of a worker's table: why the request model refused the row (lines), null for a row that flew."""

ROW = "row"
"""First column of the results: the row's index in the input, from 0 (a grid's row number)."""

OBSERVED_PREFIX = "observed_"
"""An input column with a result's name (a canonical file's observed apex_m, flight_time_s, landing_angle_deg) is
written with this prefix."""


@dataclass(frozen=True)
class Layout:
    """The columns of a sweep's input and so of its results: the input's, echoed, then the flight's."""

    columns: tuple[str, ...]

    @cached_property
    def results(self) -> list[str]:
        """The air density flown, then the flight's columns (as `golfflight simulate` gives them)."""
        flat = any(column in self.columns for column in ELEVATION_COLUMNS)
        return [AIR_DENSITY, *result_columns(normalized="normalized" in self.columns, flat=flat)]

    @cached_property
    def echoed(self) -> list[str]:
        """Output names of the input columns."""
        return [OBSERVED_PREFIX + c if c in self.results else c for c in self.columns]

    def schema(self, with_problem: bool = False):
        """The results' Arrow schema (with a worker's `problem` column, or the file's leading `row`)."""
        import pyarrow as pa

        def kind(column: str):
            if column in TEXT_COLUMNS or column == "error":
                return pa.string()
            if column == "normalized":
                return pa.bool_()
            return pa.int64() if column.endswith("bounces") else pa.float64()

        fields = [pa.field(name, kind(column)) for name, column in zip(self.echoed, self.columns, strict=True)]
        fields += [pa.field(name, kind(name)) for name in self.results]
        return pa.schema([*fields, pa.field(PROBLEM, pa.string())] if with_problem else [pa.field(ROW, pa.int64()), *fields])


def _number(value) -> float | None:
    """A numeric column's value, or None where the cell is blank or not a number."""
    value = cell_value(value)
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def echo(column: str, value):
    """An input cell as its results column holds it: text, a flag, or a number (None where blank)."""
    if column in TEXT_COLUMNS:
        return None if value is None or value == "" else str(value)
    if column == "normalized":
        return None if cell_value(value) is None else is_flag_set(cell_value(value))
    return _number(value)


class ColumnsEngine(Engine, Protocol):
    """What a worker flies its rows with: `FlightEngine`, or another engine of the one protocol
    (`flight.problem.Engine`: `flight.torch_engine.TorchEngine`, given by the command line) with the SHA-256 of the
    bundle's graph."""

    sha256: str


class SweepWorker:
    """A flight engine for one worker: `flyer(piece)` flies a piece of a source (module docstring)."""

    def __init__(self, bundle_dir: str, sha256: str, source, engine: ColumnsEngine | None = None,
                 make_engine: Callable[[str], ColumnsEngine] | None = None):
        """Load the bundle at `bundle_dir` (its own path on each node of a cluster) with ONNX Runtime, or with
        `make_engine` (a Ray actor's torch engine, `flight.torch_engine.TorchEngineMaker`), or take `engine`
        already loaded, and refuse it unless its ONNX graph is the one the driver checked (`sha256`); `source`
        (`sweep.sources`) turns pieces into rows."""
        from golfflight.flight.engine import FlightEngine

        if engine is None:
            engine = FlightEngine(bundle_dir, batch_threads=1) if make_engine is None else make_engine(bundle_dir)
        self.engine = engine
        if self.engine.sha256 != sha256:
            raise InputError(f"{bundle_dir}: this worker's model ({self.engine.sha256[:12]}) is not the driver's "
                             f"({sha256[:12]}); every node needs the same bundle at the same path")
        self.source = source
        self.layout = Layout(tuple(source.columns))

    def __call__(self, piece):
        return self.fly_table(self.source.expand(piece))

    def fly_table(self, table):
        """The rows of `table` (the layout's input columns) with their flights, in order (a pyarrow.Table): checked
        and flown a column at a time (`sweep.rows`), each refused row with the request model's own problem lines."""
        import numpy as np
        import pyarrow as pa
        from golfflight.sweep.rows import check_rows, fly_checked

        layout = self.layout
        table = table.select(list(layout.columns))
        n = table.num_rows
        checked = check_rows(table)
        flew = checked.valid
        flown = np.flatnonzero(flew)
        problems = np.full(n, None, dtype=object)
        problems[list(checked.problems)] = ["\n".join(lines) for lines in checked.problems.values()]
        schema = layout.schema(with_problem=True)
        out = {}
        for name, column in zip(layout.echoed, layout.columns, strict=True):
            out[name] = _echoed(table[column], column, flew, schema.field(name).type, checked.columns.get(column))
        flights = fly_checked(self.engine, checked) if len(flown) else None  # a chunk of invalid rows flies nothing
        for name in layout.results:
            if flights is None:
                out[name] = pa.nulls(n, schema.field(name).type)
                continue
            if name == "error":
                errors = np.full(n, None, dtype=object)
                errors[flown] = flights.errors
                out[name] = pa.array(errors, pa.string())
                continue
            values, present = flights.values[name], flights.present[name]
            full, valid = np.zeros(n, dtype=values.dtype), np.zeros(n, dtype=bool)
            full[flown], valid[flown] = values, present
            out[name] = pa.array(full, schema.field(name).type, mask=~valid)
        out[PROBLEM] = pa.array(problems, pa.string())
        return pa.table(out, schema=schema)


def _echoed(array, column: str, flew, kind, checked=None):
    """An input column as the results hold it (`echo`), null where the row did not fly: a numeric Arrow column as it
    is (cast to float64), a number column already read (`checked`, a `sweep.rows.Column`: a flown row's cells are
    numbers or blank) from its numbers, any other each distinct cell once."""
    import numpy as np
    import pyarrow as pa
    import pyarrow.compute as pc
    from golfflight.sweep.rows import distinct

    if column not in TEXT_COLUMNS and column != "normalized" and (
        pa.types.is_floating(array.type) or pa.types.is_integer(array.type)
    ):
        return pc.if_else(pa.array(flew), array.cast(pa.float64()), pa.scalar(None, pa.float64())).combine_chunks()
    if checked is not None and checked.numbers is not None:
        return pa.array(checked.numbers, pa.float64(), mask=~(flew & checked.given))
    cells, codes = distinct(array)
    echoed = [echo(column, cell) for cell in cells] + [None]
    codes = np.where(flew, codes, -1)
    return pa.array([echoed[code] for code in codes.tolist()], kind)

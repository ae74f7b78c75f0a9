"""A chunk of a sweep's rows checked against the request model and made into one engine batch a column at a time:
the verdicts, problem lines and flights `Flyer` gave when every row went through the request model on its own,
without a request object a valid row.

Checking. The request model (`contract.requests.ShotRequest`) stays the one contract: this reads its rules, it does
not restate them.
- A number column of Arrow numbers (a grid, a Parquet file) is checked in bulk against its own field's bounds, read
  from the pydantic field's metadata (`ge`, `le`; finite); every other column (a CSV's text, words, flags, Arrow
  types such as decimals) has its distinct cells read as `simulate` reads a cell and put through their field itself
  (a pydantic TypeAdapter of the field), each once.
- The model's cross-field rules (one form of each quantity, back and side spin within the spin range, a slope its
  surface holds, ...) read which columns a row gives and the values of VALUE_RULE_COLUMNS only
  (`tests/test_sweep_errors.py` reads the validators to hold this): the rows whose every cell passes are grouped by
  those, and one row of each group goes through the whole model, which decides for its group.
- Every other row (a cell out of range, not a number, NaN; a group the model refuses) goes through the model on its
  own (`contract.columns.check_cells`), so a refused row gets exactly the problem lines it got before.

Flying. The valid rows' launches are converted as `contract.inputs.launch_of` converts them, in arrays (back and side
spin by `spin_from_components` itself); their conditions, grounds and normalized replays come from the contract's own
functions (`air_of`, `wind_of`, `ground_of`, `reference_of`, `lands_off_the_flat`) on one validated request part for
each distinct combination of those columns' cells. The batch (the rows, their normalized replays, then their flat
flights) is a `contract.flying.Batch`, made by `Batch.of` as `batch_of` makes one from requests (its one
`flight.problem.FlightProblem`), and its flights go back into columns through the same `contract.flying.columns_of`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache
from typing import Annotated, get_args

import annotated_types
import numpy as np
from golfflight.contract.columns import (
    AIR_COLUMNS,
    GROUND_COLUMNS,
    REQUEST_COLUMNS,
    SECTION_COLUMNS,
    WIND_COLUMNS,
    cell_value,
    check_cells,
    request_of_cells,
)
from golfflight.contract.flying import Batch, ShotColumns, columns_of
from golfflight.contract.inputs import (
    air_of,
    ground_of,
    lands_off_the_flat,
    reference_of,
    spin_from_components,
    wind_of,
)
from golfflight.contract.requests import ShotRequest
from golfflight.flight.conditions import STANDARD, Conditions
from golfflight.flight.constants import MPH_TO_MPS
from golfflight.flight.per_shot import PerShot
from golfflight.flight.wind import CALM
from pydantic import BaseModel, ConfigDict, TypeAdapter, ValidationError
from pydantic.fields import FieldInfo

VALUE_RULE_COLUMNS = frozenset({"back_spin_rpm", "side_spin_rpm", "ground_surface", "stimp_ft", "slope_deg"})
"""The columns whose values (not only whether they are given) the request models' cross-field validators read: the
spin total of back and side spin, a green's reading, the slope a surface holds."""

BOUNDS = {
    annotated_types.Ge: np.greater_equal,
    annotated_types.Gt: np.greater,
    annotated_types.Le: np.less_equal,
    annotated_types.Lt: np.less,
}
"""The pydantic field constraints a number column is checked against in bulk, and how."""


def section_model(section: str) -> type[BaseModel]:
    """The request model of one of the request's condition objects (air, wind, ground)."""
    annotation = ShotRequest.model_fields[section].annotation
    return next(a for a in get_args(annotation) if isinstance(a, type) and issubclass(a, BaseModel))


def field_of(column: str) -> tuple[type[BaseModel], str]:
    """The request model and field a column's cells go to (`contract.columns.request_of_cells`)."""
    for section, columns in SECTION_COLUMNS.items():
        if column in columns:
            return section_model(section), columns[column]
    return ShotRequest, column


def _info(column: str) -> tuple[type[BaseModel], FieldInfo]:
    model, name = field_of(column)
    return model, model.model_fields[name]


def is_number_column(column: str) -> bool:
    """Whether the column's field is a float (or an optional one): checked in bulk against its bounds."""
    return _info(column)[1].annotation in (float, float | None)


@cache
def number_bounds(column: str) -> tuple[tuple, bool]:
    """A number column's bounds as (numpy comparison, bound) pairs from its field's metadata, and whether the model
    takes non-finite numbers; TypeError for a constraint this module does not read (the bulk check would miss it)."""
    model, info = _info(column)
    bounds = []
    for constraint in info.metadata:
        kind = type(constraint)
        if kind not in BOUNDS:
            raise TypeError(f"{column}: the bulk check does not read the constraint {constraint!r}")
        bounds.append((BOUNDS[kind], getattr(constraint, kind.__name__.lower())))
    return tuple(bounds), model.model_config.get("allow_inf_nan", True)


@cache
def field_adapter(column: str) -> TypeAdapter:
    """The column's field as a validator of one value, with its model's strictness."""
    model, info = _info(column)
    config = {key: model.model_config[key] for key in ("strict", "allow_inf_nan") if key in model.model_config}
    return TypeAdapter(Annotated[info.annotation, info], config=ConfigDict(**config))


def request_value(column: str, cell):
    """The value a cell (as `cell_value` reads it, not None) takes in the request (`request_of_cells`)."""
    request = request_of_cells({column: cell})
    for section, columns in SECTION_COLUMNS.items():
        if column in columns:
            return request[section][columns[column]]
    return request[column]


@dataclass(frozen=True)
class Column:
    """One input column of a chunk: whether each row gives a value, whether its field takes it, and the value as a
    key (rows with equal keys give equal request values: a float's bits, or the index of a distinct value) and, for
    a number column, as a float."""

    given: np.ndarray
    ok: np.ndarray
    key: np.ndarray
    numbers: np.ndarray | None = None


def distinct(array) -> tuple[list, np.ndarray]:
    """An Arrow array's distinct cells as Python values and each row's index into them, -1 where null."""
    import pyarrow as pa
    import pyarrow.compute as pc

    if isinstance(array, pa.ChunkedArray):
        array = array.combine_chunks()
    try:
        encoded = pc.dictionary_encode(array)
    except pa.ArrowNotImplementedError:  # a type Arrow cannot hash: cell by cell
        seen: dict = {}
        cells = array.to_pylist()
        codes = [-1 if cell is None else seen.setdefault(cell, len(seen)) for cell in cells]
        return list(seen), np.array(codes, dtype=np.int64)
    codes = encoded.indices.fill_null(-1).to_numpy(zero_copy_only=False).astype(np.int64)
    return encoded.dictionary.to_pylist(), codes


def _in_bounds(column: str, numbers: np.ndarray) -> np.ndarray:
    """Where floats are what the column's field takes: finite (unless its model takes non-finite numbers) and within
    the bounds of its metadata."""
    bounds, non_finite = number_bounds(column)
    with np.errstate(invalid="ignore"):
        ok = np.ones(len(numbers), dtype=bool) if non_finite else np.isfinite(numbers)
        for compare, bound in bounds:
            ok &= compare(numbers, bound)
    return ok


def _number_column(column: str, array) -> Column:
    """A number column of Arrow numbers (a grid, a Parquet file), in bulk (the strict model takes integers as
    floats)."""
    import pyarrow as pa

    numbers = array.cast(pa.float64(), safe=False).to_numpy(zero_copy_only=False)
    given = ~array.is_null().to_numpy(zero_copy_only=False)
    return Column(given, _in_bounds(column, numbers) | ~given, numbers.view(np.int64), numbers)


def _number_cells(column: str, array) -> Column:
    """A number column of other cells (a CSV's text, decimals, booleans, ...): each distinct cell read as `simulate`
    reads it (`cell_value`); a float is checked in bulk as above, anything else through the field's own validator."""
    cells, codes = distinct(array)
    value, bulk, taken, given = [], [], [], []
    for cell in cells:
        read = cell_value(cell)
        validated, ok = math.nan, read is not None
        if read is not None and type(read) is not float:
            try:
                validated = float(field_adapter(column).validate_python(read))
            except ValidationError:
                ok = False
        value.append(read if type(read) is float else validated)
        bulk.append(type(read) is float)
        taken.append(ok)
        given.append(read is not None)
    numbers = np.array([*value, math.nan])[codes]
    given_rows = np.array([*given, False])[codes]
    ok = np.where(np.array([*bulk, False])[codes], _in_bounds(column, numbers), np.array([*taken, False])[codes])
    return Column(given_rows, ok | ~given_rows, numbers.view(np.int64), numbers)


def _value_cells(column: str, array) -> Column:
    """A text or flag column: each distinct cell read as `simulate` reads it (`cell_value`, `request_of_cells`) and
    put through the field's own validator; the key is the validated value's index."""
    cells, codes = distinct(array)
    known: dict = {}
    key, taken, given = [], [], []
    for cell in cells:
        read = cell_value(cell)
        index, ok = -1, True
        if read is not None:
            try:
                validated = field_adapter(column).validate_python(request_value(column, read))
                index = known.setdefault((type(validated), validated), len(known))
            except ValidationError:
                ok = False
        key.append(index)
        taken.append(ok)
        given.append(read is not None)
    return Column(np.array([*given, False])[codes], np.array([*taken, True])[codes], np.array([*key, -1])[codes])


def read_column(column: str, array) -> Column:
    """One request column of a chunk (an Arrow array), checked against its field (module docstring)."""
    import pyarrow as pa

    if not is_number_column(column):
        return _value_cells(column, array)
    if pa.types.is_floating(array.type) or pa.types.is_integer(array.type):
        return _number_column(column, array)
    return _number_cells(column, array)


MIX = np.uint64(0x9E3779B97F4A7C15)
"""Odd 64-bit multiplier (2^64 / golden ratio) that mixes the group-key parts into one hash."""


def _groups(parts: list[np.ndarray], rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows (indices) grouped by equal values across `parts` (int64 arrays over every row): each group's first row,
    and each row's group. The parts are hashed into one 64-bit number a row and grouped by one sort of those; every
    group is then checked to hold one value of each part, and where two keys shared a hash the rows are grouped by
    the keys themselves (exact either way; the hash about 3x faster than sorting the keys as bytes)."""
    if not parts or not len(rows):
        return rows[:1], np.zeros(len(rows), dtype=np.intp)
    columns = [np.ascontiguousarray(part[rows], dtype=np.int64) for part in parts]
    mixed = np.zeros(len(rows), dtype=np.uint64)
    for column in columns:
        mixed = (mixed ^ column.view(np.uint64)) * MIX
        mixed ^= mixed >> np.uint64(29)
    _, first, inverse = np.unique(mixed, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    if all(np.array_equal(column, column[first][inverse]) for column in columns):
        return rows[first], inverse
    keys = np.stack(columns, axis=1)
    _, first, inverse = np.unique(keys.view(np.dtype((np.void, 8 * len(columns)))).ravel(), return_index=True,
                                  return_inverse=True)
    return rows[first], inverse.reshape(-1)


def _key(columns: dict[str, Column], names) -> list[np.ndarray]:
    """Group-key parts of `names` (those present): whether given, and the value where given."""
    parts = []
    for name in names:
        if name in columns:
            column = columns[name]
            parts += [column.given.astype(np.int64), np.where(column.given, column.key, 0)]
    return parts


@dataclass(frozen=True)
class Checked:
    """A chunk's rows checked: its request columns as read, the rows that fly (`valid`), each refused row's problem
    lines by row, and the chunk itself (for the cells of the few rows read one by one)."""

    columns: dict[str, Column]
    valid: np.ndarray
    problems: dict[int, list[str]]
    table: object


def cells_of(table, rows, names) -> dict[int, dict]:
    """The cells of `rows` (indices) in the columns `names` (those the table has) of an Arrow table, as `cell_value`
    reads them: a dict by column for each row."""
    rows = np.unique(np.asarray(rows, dtype=np.int64))
    table = table.select([name for name in table.column_names if name in names])
    if not table.num_columns:
        return {i: {} for i in rows.tolist()}
    taken = table.take(rows).to_pylist()
    return {i: {name: cell_value(value) for name, value in row.items()} for i, row in zip(rows.tolist(), taken)}


def check_rows(table) -> Checked:
    """Every row of `table` (an Arrow table of a sweep's columns) checked as `check_cells(cells)` checks one row
    (module docstring); `check_cells` runs on the groups' representatives and on each row not shown valid in bulk."""
    n = table.num_rows
    columns = {name: read_column(name, table[name]) for name in table.column_names if name in REQUEST_COLUMNS}
    fields_ok = np.ones(n, dtype=bool)
    for column in columns.values():
        fields_ok &= column.ok
    candidates = np.flatnonzero(fields_ok)
    presence = [column.given.astype(np.int64) for column in columns.values()]
    firsts, group = _groups(presence + _key(columns, sorted(VALUE_RULE_COLUMNS)), candidates)
    firsts_cells = cells_of(table, firsts, REQUEST_COLUMNS)
    group_valid = np.array([not isinstance(check_cells(firsts_cells[i]), list) for i in firsts.tolist()], dtype=bool)
    valid = np.zeros(n, dtype=bool)
    valid[candidates] = group_valid[group] if len(candidates) else False
    problems = {}
    for i, cells in cells_of(table, np.flatnonzero(~valid), REQUEST_COLUMNS).items():
        checked = check_cells(cells)
        if isinstance(checked, list):
            problems[i] = checked
        else:  # shown valid on its own: in a group whose representative the model refused for a rule of its own
            valid[i] = True
    return Checked(columns, valid, problems, table)


def _launches(columns: dict[str, Column], rows: np.ndarray) -> np.ndarray:
    """The rows' launches [N, 5] (speed m/s, angle, direction, spin rpm, axis deg) as `launch_of` makes them."""

    def number(name: str, default: float = math.nan) -> np.ndarray:
        if name not in columns:
            return np.full(len(rows), default)
        column = columns[name]
        return np.where(column.given[rows], column.numbers[rows], default)

    def given(name: str) -> np.ndarray:
        return columns[name].given[rows] if name in columns else np.zeros(len(rows), dtype=bool)

    speed = np.where(given("ball_speed_mps"), number("ball_speed_mps"), number("ball_speed_mph") * MPH_TO_MPS)
    direction = number("launch_direction_deg", ShotRequest.model_fields["launch_direction_deg"].default)
    axis = number("spin_axis_deg", 0.0)
    axis = np.where(axis == 0.0, 0.0, axis)  # launch_of's `spin_axis_deg or 0.0`: a -0.0 axis is 0.0
    spin = number("spin_rpm")
    components = np.flatnonzero(~given("spin_rpm"))
    if len(components):
        back, side = number("back_spin_rpm")[components], number("side_spin_rpm", 0.0)[components]
        total = [spin_from_components(b, s or 0.0) for b, s in zip(back.tolist(), side.tolist(), strict=True)]
        spin[components], axis[components] = np.array(total, dtype=float).reshape(-1, 2).T
    return np.stack([speed, number("launch_angle_deg"), direction, spin, axis], axis=1)


def _section(request: dict, section: str):
    """The validated condition object (air, wind, ground) of a request dict, or None where it gives none."""
    part = request.get(section)
    return None if part is None else section_model(section).model_validate(part)


def _made(checked: Checked, rows: np.ndarray, names, make) -> PerShot:
    """One object for each distinct combination of the rows' cells in the columns `names`, made by `make` from the
    request dict of its first row, and each row's."""
    firsts, group = _groups(_key(checked.columns, names), rows)
    cells = cells_of(checked.table, firsts, names)
    return PerShot([make(request_of_cells(cells[i])) for i in firsts.tolist()], group)


def fly_checked(engine, checked: Checked) -> ShotColumns:
    """The valid rows of `checked` flown in the batch `contract.flying.batch_of` makes of their requests (module
    docstring), as `contract.flying.columns_of`'s columns over those rows."""
    rows = np.flatnonzero(checked.valid)
    n = len(rows)
    airs = _made(checked, rows, AIR_COLUMNS, lambda request: _section(request, "air"))
    winds = _made(checked, rows, WIND_COLUMNS, lambda request: _section(request, "wind"))
    grounds = _made(checked, rows, GROUND_COLUMNS, lambda request: _section(request, "ground"))
    references = _made(
        checked, rows, ["normalized"], lambda request: reference_of(ShotRequest.model_construct(**request))
    )
    air_of_group = [air_of(air) for air in airs.objects]
    wind_of_group = [wind_of(wind) for wind in winds.objects]
    pairs, pair = _groups([airs.index.astype(np.int64), winds.index.astype(np.int64)], np.arange(n))
    conditions = PerShot(
        [  # conditions_from(air, wind), each distinct air and wind made once
            STANDARD
            if airs.objects[a] is None and winds.objects[w] is None
            else Conditions(air_of_group[a], wind_of_group[w])
            for a, w in zip(airs.index[pairs].tolist(), winds.index[pairs].tolist(), strict=True)
        ],
        pair,
    )
    off_flat = np.array(
        [lands_off_the_flat(ShotRequest.model_construct(ground=g)) for g in grounds.objects], dtype=bool
    )
    replays = PerShot([None if r is None else Conditions(air_of(r), CALM) for r in references.objects],
                      references.index)
    own_grounds = PerShot([ground_of(g) for g in grounds.objects], grounds.index)
    batch = Batch.of(_launches(checked.columns, rows), conditions, own_grounds, replays,
                     np.flatnonzero(off_flat[grounds.index]))
    return columns_of(engine.fly_batch(batch.problem), batch)

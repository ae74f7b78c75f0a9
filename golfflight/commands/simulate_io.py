"""`golfflight simulate`'s files: its input read and checked (CSV or JSON), what matches each result to its
input, and the flat CSV written; its shots flown in order (putts rolled as the bay rolls them). Imported when the
command runs: the shot contract and the engine are not needed to show its help."""

from __future__ import annotations

import csv
import json
import sys
from dataclasses import dataclass, field
from pathlib import Path

from golfflight.contract.columns import (
    AIR_COLUMNS,
    AIR_DENSITY,
    GROUND_COLUMNS,
    IDENTITY_COLUMNS,
    LAUNCH_COLUMNS,
    PUTT,
    WIND_COLUMNS,
    cell_value,
    check,
    columns_message,
    condition_cells,
    flat_row,
    is_flag_set,
    request_of_cells,
)
from golfflight.contract.inputs import conditions_of
from golfflight.contract.requests import ShotRequest
from golfflight.errors import InputError
from golfflight.shots.records import CSV_ENCODING, reading

ECHOED_CONDITIONS = (*WIND_COLUMNS, *GROUND_COLUMNS)
"""The condition columns echoed as read (the air's come with `flown_air`)."""


@dataclass
class Input:
    """The shots of an input as read, before validation: request dicts, each with its input row number (from 0), its
    place in messages ("FILE line N", "FILE shot N"), its shot id (CSV only: None where the file has none), the
    cells it echoes (CSV only: identity columns and `putt`, as read) and whether it is a putt, and the problems found
    while reading (extra cells, repeated shot ids) of `rows_read` rows in all."""

    shots: list = field(default_factory=list)
    rows: list[int] = field(default_factory=list)
    places: list[str] = field(default_factory=list)
    ids: list[str | None] = field(default_factory=list)
    echoed: list[dict] = field(default_factory=list)
    putts: list[bool] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)
    rows_read: int = 0


def shots_from_csv(path: Path) -> Input:
    """The shots of a launches CSV, its header checked first (`columns_message`): a missing launch column refuses
    the file in one line instead of one "Field required" a row."""
    read = Input()
    with reading(path), open(path, newline="", encoding=CSV_ENCODING) as handle:
        reader = csv.DictReader(handle)
        refused = columns_message(str(path), list(reader.fieldnames or []), also=frozenset({PUTT}))
        if refused:
            raise InputError(refused)
        seen: dict[str, int] = {}
        for row, cells in enumerate(reader):
            line, read.rows_read = row + 2, row + 1
            place = f"{path} line {line}"
            if None in cells:
                read.problems.append(f"{place}: {len(cells[None])} cells beyond the header")
                continue
            shot_id = cells.get("shot_id")
            if shot_id and shot_id in seen:
                read.problems.append(
                    f"{place} column 'shot_id': {shot_id!r} duplicates the shot_id of line {seen[shot_id]}"
                )
                continue
            if shot_id:
                seen[shot_id] = line
            read.shots.append(request_of_cells({k: cell_value(v) for k, v in cells.items()}))
            read.rows.append(row)
            read.places.append(place)
            read.ids.append(shot_id)
            echoed = {c: cells[c] for c in (*IDENTITY_COLUMNS, PUTT) if cells.get(c) is not None}
            conditions = {c: cell_value(cells.get(c)) for c in ECHOED_CONDITIONS}
            read.echoed.append({**echoed, **{c: v for c, v in conditions.items() if v is not None}})
            read.putts.append(is_flag_set((cells.get(PUTT) or "").strip()))
    return read


def validate(raw: list, places: list[str], csv_columns: bool) -> tuple[list, list[int], list[str]]:
    """(valid ShotRequests, their indices in `raw`, one problem line per invalid value naming where and which field)."""
    shots, kept, problems = [], [], []
    for index, (item, place) in enumerate(zip(raw, places, strict=True)):
        checked = check(item, csv_columns)
        if isinstance(checked, list):
            problems += [f"{place} {problem}" for problem in checked]
        else:
            shots.append(checked)
            kept.append(index)
    return shots, kept, problems


def shots_from_json(text: str, source: str) -> Input:
    """The shots of a JSON input (one shot, a list of shots, or {"shots": [...]}), each placed by its index."""
    try:
        data = json.loads(text)
    except json.JSONDecodeError as error:
        raise InputError(f"{source}: not valid JSON ({error})") from None
    if isinstance(data, dict) and "shots" in data:
        data = data["shots"]
    shots = data if isinstance(data, list) else [data]
    rows = list(range(len(shots)))
    return Input(shots, rows, [f"{source} shot {i}" for i in rows], rows_read=len(shots))


def read_input(name: str) -> tuple[Input, bool]:
    """The shots of the command's input (`-`: JSON on standard input) and whether it is a CSV."""
    if name == "-":
        return shots_from_json(sys.stdin.read(), "standard input"), False
    path = Path(name)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    if path.suffix.lower() == ".csv":
        return shots_from_csv(path), True
    with reading(path):
        return shots_from_json(path.read_text(encoding=CSV_ENCODING), str(path)), False


def refuse_or_skip(name: str, problems: list[str], flyable: int, rows_read: int, skip_bad_rows: bool) -> None:
    """Refuse the input listing its problems, unless `skip_bad_rows` and some shot is left to fly (each problem is
    then listed as skipped); with none left it is refused either way, rather than answered with no results."""
    if not problems:
        return
    if flyable and skip_bad_rows:
        for problem in problems:
            print(f"golfflight simulate: skipped: {problem}", file=sys.stderr)
        return
    why = "--skip-bad-rows flies the rest" if flyable else f"none of its {rows_read} shots is valid; nothing written"
    shown = "\n  ".join(problems[:20]) + (f"\n  ... and {len(problems) - 20} more" if len(problems) > 20 else "")
    raise InputError(f"{name}: {len(problems)} invalid values ({why}):\n  {shown}")


def flown_air(shot: ShotRequest) -> dict:
    """The air a shot was flown in: its air columns as given, then the density the engine flew it in (`AIR_DENSITY`),
    so that a result says which air made its numbers."""
    given = {} if shot.air is None else shot.air.model_dump(exclude_none=True)
    return {**given, AIR_DENSITY: float(conditions_of(shot).air.density_kg_m3)}


def matching(read: Input, kept: list[int], shots: list[ShotRequest]) -> list[dict]:
    """What matches each flown shot (`shots`, validated from the inputs `kept`) to its input, in front of its result:
    `row`, its shot_id and identity cells (where it has them), its launch columns as read, `putt` as read, its wind and
    ground columns as read (a JSON shot's: as given), and the air it was flown in (`flown_air`)."""
    fronts = []
    for i, shot in zip(kept, shots, strict=True):
        given = {c: v for c, v in condition_cells(shot, given_only=True).items() if c in ECHOED_CONDITIONS}
        echoed = read.echoed[i] if read.echoed else given
        fronts.append({
            "row": read.rows[i],
            **({"shot_id": read.ids[i]} if read.ids and read.ids[i] is not None else {}),
            **{c: v for c, v in echoed.items() if c not in ECHOED_CONDITIONS},
            **{c: read.shots[i][c] for c in LAUNCH_COLUMNS if read.shots[i].get(c) is not None},
            **{c: v for c, v in echoed.items() if c in ECHOED_CONDITIONS},
            **flown_air(shot),
        })
    return fronts


FRONT_COLUMNS = ("row", "shot_id", *IDENTITY_COLUMNS, *LAUNCH_COLUMNS, PUTT, *WIND_COLUMNS, *GROUND_COLUMNS,
                 *AIR_COLUMNS, AIR_DENSITY)
"""The order of a result row's `matching` columns (those that some row has)."""


def write_csv(out: str, fronts: list[dict], results: list[dict]) -> None:
    """The results as a flat CSV: each row's `matching` columns first, then its result's (`flat_row`)."""
    flats = [flat_row(r) for r in results]
    front = [c for c in FRONT_COLUMNS if any(c in f for f in fronts)]
    columns = [*front, *dict.fromkeys(key for flat in flats for key in flat)]
    with open(out, "w", newline="") as handle:
        writer = csv.DictWriter(handle, columns)
        writer.writeheader()
        writer.writerows({**f, **flat} for f, flat in zip(fronts, flats, strict=True))


def fly_all(engine, shots: list[ShotRequest], putts: list[bool]) -> list[dict]:
    """Each shot's result as a dict, in order: the putts rolled one by one as the bay rolls them
    (`fly_request(..., putt=True)`), the rest in engine batches (`fly_requests`)."""
    from golfflight.contract.flying import fly_request, fly_requests
    from golfflight.contract.results import ShotFailure
    from golfflight.errors import FlightError

    results: list = [None] * len(shots)
    full = [i for i, putt in enumerate(putts) if not putt]
    for i, result in zip(full, fly_requests(engine, [shots[i] for i in full])[0], strict=True):
        results[i] = result
    for i in (i for i, putt in enumerate(putts) if putt):
        try:
            results[i] = fly_request(engine, shots[i], putt=True)[0]
        except FlightError as error:
            results[i] = ShotFailure(error=str(error))
    return [r.model_dump(exclude_none=True) for r in results]

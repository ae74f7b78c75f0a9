"""Loader for TrackMan CSV exports (header row, then a units row such as [mph],[deg],[rpm],[ft],[yds],[s]).

Each column's unit is read from the units row and converted to SI here, at the file edge. Real exports are messy
(indoor shots whose flight is TrackMan's model, range balls, blank launch values), so rows are filtered and every
dropped row is counted under its reason in a `ConversionReport`; nothing is dropped silently. A malformed cell (not a
number, out of its physical range, a side carry longer than the carry) refuses the file with its line and column,
unless `skip_bad_rows` is given: then the row is left out and listed one by one in the report.

"Carry Flat - Length" is the straight-line horizontal distance from the tee to the landing point, not the
distance along the target line: in the shared driver export, TrackMan's own "Curve" column equals
Side cos(φ) − sqrt(Length² − Side²) sin(φ) (φ = launch direction) to 1e-7 yd on every shot, while reading Length
as the along-line distance misses by up to 7 yd. So carry_x_m = Side and carry_y_m = sqrt(Length² − Side²).
"""

from __future__ import annotations

import csv
import math
import os
from collections.abc import Collection
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from golfflight.flight.constants import FOOT_M, MPH_TO_MPS, YARD_M
from golfflight.shots.cells import BadRow, MalformedCell, finite_number, when
from golfflight.shots.records import RANGES, RecordError, ShotRecord, reading

SPEED = {"mph": MPH_TO_MPS, "m/s": 1.0, "km/h": 1.0 / 3.6}
ANGLE = {"deg": 1.0}
SPIN = {"rpm": 1.0}
LENGTH = {"yds": YARD_M, "yd": YARD_M, "ft": FOOT_M, "m": 1.0}
TIME = {"s": 1.0}

LAUNCH = {
    "Ball Speed": ("ball_speed_mps", SPEED),
    "Launch Angle": ("launch_angle_deg", ANGLE),
    "Launch Direction": ("launch_direction_deg", ANGLE),
    "Spin Rate": ("spin_rpm", SPIN),
    "Spin Axis": ("spin_axis_deg", ANGLE),
}
"""Required export columns -> (canonical column, accepted units and their factor to SI)."""

OUTCOME = {
    "Max Height - Height": ("apex_m", LENGTH),
    "Carry Flat - Time": ("flight_time_s", TIME),
    "Carry Flat - Land. Angle": ("landing_angle_deg", ANGLE),
}
"""Optional export columns copied one-to-one into canonical outcome columns."""

CARRY_LENGTH, CARRY_SIDE = "Carry Flat - Length", "Carry Flat - Side"
LAST_POINT_TIME, CARRY_TIME = "Last data Point - Time", "Carry Flat - Time"


@dataclass
class ConversionReport:
    """What a loader did with each source row: how many came in, were kept, and were dropped for which reason."""

    source: str
    rows_in: int = 0
    kept: int = 0
    dropped: dict[str, list[int]] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    bad_rows: list[str] = field(default_factory=list)

    def drop(self, reason: str, line: int) -> None:
        self.dropped.setdefault(reason, []).append(line)

    def bad_row(self, problem: str, reason: str, line: int, skip: bool) -> None:
        """A malformed row: listed in full (`problem` names line, column and value), counted under `reason`; without
        `skip` it is kept for `refuse_bad_rows`."""
        self.bad_rows.append(problem)
        if skip:
            self.drop(f"bad row: {reason}", line)

    def refuse_bad_rows(self, skip: bool) -> None:
        """RecordError listing every malformed row, unless they were skipped."""
        if self.bad_rows and not skip:
            shown = "\n  ".join(self.bad_rows[:50])
            more = f"\n  ... and {len(self.bad_rows) - 50} more" if len(self.bad_rows) > 50 else ""
            raise RecordError(
                f"{self.source}: {len(self.bad_rows)} malformed rows (--skip-bad-rows leaves them out and lists "
                f"them):\n  {shown}{more}"
            )

    @property
    def n_dropped(self) -> int:
        return sum(len(lines) for lines in self.dropped.values())

    def count(self, reason_start: str) -> int:
        """Rows dropped for every reason that starts with `reason_start`."""
        return sum(len(lines) for reason, lines in self.dropped.items() if reason.startswith(reason_start))

    def summary(self, examples: int = 5) -> str:
        lines = [f"{self.source}: {self.rows_in} in, {self.kept} kept, {self.n_dropped} dropped"]
        for reason, where in sorted(self.dropped.items(), key=lambda item: -len(item[1])):
            shown = ", ".join(str(n) for n in where[:examples]) + (", ..." if len(where) > examples else "")
            lines.append(f"  dropped {len(where)}: {reason} (lines {shown})")
        lines.extend(f"  skipped bad row: {problem}" for problem in self.bad_rows)
        lines.extend(f"  note: {note}" for note in self.notes)
        return "\n".join(lines)


@dataclass
class Conversion:
    """Canonical records converted from an export, the filter report, and (where the source has them) flights."""

    records: list[ShotRecord]
    report: ConversionReport
    trajectories: dict[str, np.ndarray] = field(default_factory=dict)


def read_table(path: Path) -> tuple[list[str], list[str], list[tuple[int, list[str]]]]:
    """Header, units row and (line number, cells) of each data row; an optional 'sep=,' first line is skipped."""
    with reading(path), path.open(newline="", encoding="utf-8-sig") as handle:
        lines = list(enumerate(csv.reader(handle), start=1))
    if lines and lines[0][1][:1] == ["sep="]:
        lines = lines[1:]
    if len(lines) < 2:
        raise RecordError(f"{path}: a TrackMan export needs a header row and a units row; it has {len(lines)} rows")
    (_, header), (units_line, units) = lines[0], lines[1]
    header = [name.strip() for name in header]
    cells = [u.strip() for u in units]
    if not any(cells) or not all(u == "" or (u.startswith("[") and u.endswith("]")) for u in cells):
        raise RecordError(f"{path} line {units_line}: expected the units row ([mph],[deg],[rpm],...) under the header, "
                          f"got {units[:6]}")
    cells += [""] * (len(header) - len(cells))
    return header, [u.strip("[]") for u in cells], lines[2:]


def _column_factors(path: Path, header: list[str], units: list[str], wanted: dict[str, dict[str, float]],
                    required: Collection[str]) -> dict[str, tuple[int, float]]:
    """Column index and SI factor of each wanted column present; refuse a missing required column or an unknown unit."""
    found = {}
    for name, accepted in wanted.items():
        if name not in header:
            if name in required:
                raise RecordError(f"{path}: required column '{name}' is missing (columns: {header})")
            continue
        index = header.index(name)
        unit = units[index]
        if unit not in accepted:
            raise RecordError(f"{path} units row, column '{name}': unit [{unit}] not accepted; "
                              f"expected one of {['[' + u + ']' for u in accepted]}")
        found[name] = (index, accepted[unit])
    return found


def _number(cells: list[str], column: str, spec: tuple[int, float]) -> float | None:
    index, factor = spec
    value = finite_number(cells[index] if index < len(cells) else "", column)
    return None if value is None else value * factor


def _in_range(column: str, canonical: str, value: float | None) -> float | None:
    allowed = RANGES[canonical]
    if value is not None and not allowed.low <= value <= allowed.high:
        reason = f"'{column}' ({canonical}) outside the allowed range {allowed.describe()}"
        raise MalformedCell(reason, column, f"{canonical} = {value:g}")
    return value


def _carry(length: float | None, side: float | None) -> tuple[float | None, float | None]:
    """(carry_x_m, carry_y_m) from Carry Flat Length (straight-line distance) and Side; see the module docstring."""
    if length is None or side is None:
        return None, None
    if abs(side) > length:
        raise MalformedCell(
            f"'{CARRY_SIDE}' larger than '{CARRY_LENGTH}' (Length is the straight-line distance)",
            CARRY_SIDE,
            f"{side:g} m against a length of {length:g} m",
        )
    return side, math.sqrt(length * length - side * side)


def _outcome(cells: list[str], specs: dict[str, tuple[int, float]]) -> dict[str, float | None]:
    """Canonical outcome columns of a row whose flight was recorded."""
    values = {canonical: _in_range(name, canonical, _number(cells, name, specs[name]))
              for name, (canonical, _) in OUTCOME.items() if name in specs}
    carry_x, carry_y = _carry(*(_number(cells, name, specs[name]) if name in specs else None
                                for name in (CARRY_LENGTH, CARRY_SIDE)))
    values["carry_x_m"] = _in_range(CARRY_SIDE, "carry_x_m", carry_x)
    values["carry_y_m"] = _in_range(CARRY_LENGTH, "carry_y_m", carry_y)
    return values


def load_trackman(path: str | os.PathLike, *, min_tracked_fraction: float | None = 0.9,
                  balls: Collection[str] | None = None, session: str | None = None,
                  lines: tuple[int, int] | None = None, skip_bad_rows: bool = False) -> Conversion:
    """Convert a TrackMan CSV export to canonical records.

    min_tracked_fraction: keep a shot only if the radar tracked it for at least this fraction of its flight
    ("Last data Point - Time" >= fraction x "Carry Flat - Time"): the rest were indoor shots whose outcome is
    TrackMan's model. None keeps every flight. balls: keep only these "Ball" types (None keeps all).
    session: the session id when the file has no "Date" column (default: the file name without extension).
    lines: (first, last) file lines to convert, inclusive and 1-based (the header is line 1); the rest are not read
    as shots at all (e.g. the held-out half of a file, `shots.heldout`).
    skip_bad_rows: leave malformed rows out (each listed in the report) instead of refusing the file.
    shot_id is the line number of the shot in the export. A shot whose "Carry Flat - Time" is blank or 0 has no
    recorded flight: its outcome columns stay blank (and the tracked-fraction filter drops it).
    """
    path = Path(path)
    header, units, rows = read_table(path)
    wanted = {name: accepted for name, (_, accepted) in {**LAUNCH, **OUTCOME}.items()}
    wanted.update({CARRY_LENGTH: LENGTH, CARRY_SIDE: LENGTH, LAST_POINT_TIME: TIME})
    required = set(LAUNCH) | ({LAST_POINT_TIME, CARRY_TIME} if min_tracked_fraction is not None else set())
    specs = _column_factors(path, header, units, wanted, required)
    if balls is not None and "Ball" not in header:
        raise RecordError(f"{path}: column 'Ball' is missing, so the ball-type filter {sorted(balls)} cannot apply")
    keep_balls = None if balls is None else {b.strip().lower() for b in balls}
    text = {name: header.index(name) for name in ("Club", "Ball", "Date") if name in header}

    def cell(cells: list[str], name: str) -> str:
        return cells[text[name]].strip() if name in text and text[name] < len(cells) else ""

    if lines is not None:
        rows = [(line, cells) for line, cells in rows if lines[0] <= line <= lines[1]]
    report = ConversionReport(str(path), rows_in=len(rows))
    records = []
    for line, cells in rows:
        ball = cell(cells, "Ball")
        if keep_balls is not None and ball.lower() not in keep_balls:
            report.drop(f"ball type {ball or '(blank)'!r} not in {sorted(balls)}", line)
            continue
        try:
            flight = _number(cells, CARRY_TIME, specs[CARRY_TIME]) if CARRY_TIME in specs else None
            if min_tracked_fraction is not None:
                tracked = _number(cells, LAST_POINT_TIME, specs[LAST_POINT_TIME])
                if tracked is None or not flight:
                    report.drop(f"no flight recorded: '{LAST_POINT_TIME}' or '{CARRY_TIME}' blank or 0", line)
                    continue
                if tracked < min_tracked_fraction * flight:
                    report.drop(f"not a measured flight: '{LAST_POINT_TIME}' < {min_tracked_fraction:g} x "
                                f"'{CARRY_TIME}' (indoor, outcome modelled by TrackMan)", line)
                    continue
            values = {}
            for name, (canonical, _) in LAUNCH.items():
                value = _number(cells, name, specs[name])
                if value is None:
                    raise BadRow(f"'{name}' is blank")
                values[canonical] = _in_range(name, canonical, value)
            if flight:
                values.update(_outcome(cells, specs))
        except MalformedCell as bad:
            report.bad_row(f"{path} line {line} {bad.cell}: {bad}", str(bad), line, skip_bad_rows)
            continue
        except BadRow as bad:
            report.drop(str(bad), line)
            continue
        timestamp, day = when(cell(cells, "Date")) if cell(cells, "Date") else (None, None)
        records.append(ShotRecord(shot_id=str(line), session=day or session or path.stem, timestamp=timestamp,
                                  club=cell(cells, "Club") or None, ball=ball or None, **values))
    report.refuse_bad_rows(skip_bad_rows)
    report.kept = len(records)
    if keep_balls is None and "Ball" in text:
        kinds = sorted({cell(c, "Ball") for _, c in rows} - {""})
        report.notes.append(f"no ball-type filter; ball types in the file: {kinds}")
    if min_tracked_fraction is None:
        report.notes.append("all flights kept, including indoor shots whose outcome is TrackMan's model")
    return Conversion(records, report)

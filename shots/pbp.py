"""Loader for PGA TOUR play-by-play files (pbp_*.csv): one canonical record per radar-measured tee shot.

A pbp file has one row per stroke; the rows TrackMan measured carry radarData.* cells (NA elsewhere):
  ballSpeed mph, launchSpin rpm (0 = missing), verticalLaunchAngle and horizontalLaunchAngle deg (+ right: the same
  sign as the launch direction of the event's TOURCAST polynomials, checked on the 2022 Sentry), apexHeight,
  apexRange and apexSide ft, actualFlightTime ms (the radar-tracked time, not the landing time: left out).
No spin axis is recorded (spin_axis_deg = 0). ShotLink adds where each stroke came to rest: tee `from_x, from_y,
from_z` and rest `x, y, z` in feet on the course's own grid, `distance` (horizontal, "306 yds") and the lie `to`.
Ids follow `shots.tourcast.shot_id`; a key that holds several radar rows (a provisional ball) numbers them -f1,
-f2, ... in file order, as the TOURCAST loader numbers the flights of a re-teed shot. No column names a hole's par:
`hole_pars` reads it from each player's strokes and score on the hole.
"""

from __future__ import annotations

import csv
import os
import re
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from golfflight.errors import InputError
from golfflight.flight.constants import FOOT_M, MPH_TO_MPS, YARD_M
from golfflight.shots.cells import BadRow, MalformedCell, finite_number
from golfflight.shots.heldout import held_out_rounds, held_out_set
from golfflight.shots.records import RANGES, RecordError, ShotRecord, reading
from golfflight.shots.tourcast import shot_id, shot_key
from golfflight.shots.trackman import Conversion, ConversionReport

KEY_COLUMNS = ("tournamentNumber", "seasonYear", "roundNumber", "holeNumber", "playerId", "shotNumber")
RADAR_FLAG = "radarData.ballSpeed"
"""A row is radar-measured when this cell holds a value (NA on every other row)."""

LAUNCH = {
    "radarData.ballSpeed": ("ball_speed_mps", MPH_TO_MPS),
    "radarData.verticalLaunchAngle": ("launch_angle_deg", 1.0),
    "radarData.horizontalLaunchAngle": ("launch_direction_deg", 1.0),
    "radarData.launchSpin": ("spin_rpm", 1.0),
}
"""pbp column -> (canonical column, factor to SI)."""
SPIN = "radarData.launchSpin"
APEX_HEIGHT, APEX_RANGE, APEX_SIDE = "radarData.apexHeight", "radarData.apexRange", "radarData.apexSide"
TEE, REST = ("from_x", "from_y", "from_z"), ("x", "y", "z")
MISSING = ("", "NA")

APEX_NOT_AN_APEX = {
    ("2020", "011"): "THE PLAYERS 2020's apexHeight is not the apex (it hardly grows with spin) and its apexRange "
                     "matches the carry (docs/real_data.md)",
}
"""(seasonYear, tournamentNumber) of events whose apex fields are not TrackMan's apex: apex_m stays blank."""

SCORE_TO_PAR = {"Eagle": -2, "Birdie": -1, "Par": 0, "Bogey": 1, "Double Bogey": 2}
"""ShotLink's `textScore` (a player's score on the hole, on each row of it) -> strokes over par; 'Double Bogey+' and
a blank name no exact number."""
PAR_COLUMNS = ("roundNumber", "holeNumber", "playerId", "shotNumber", "textScore")
DISTANCE = re.compile(r"(?:(?P<yds>\d+(?:\.\d+)?) yds|(?:(?P<ft>\d+) ft)? ?(?:(?P<inch>\d+(?:\.\d+)?) in\.)?)")
"""ShotLink's `distance` text: '306 yds', '23 ft 3 in.', '9 in.', '12 ft'."""


@dataclass(frozen=True)
class RadarRow:
    """One radar-measured row: its line, ids and cells."""

    line: int
    shot_id: str
    session: str
    group: str
    cells: dict[str, str]


@dataclass(frozen=True)
class RecordedApex:
    """The apex fields as the file records them, in metres: apexHeight, apexRange, apexSide (+ right); not an apex
    for the events of APEX_NOT_AN_APEX."""

    height_m: float | None
    range_m: float | None
    side_m: float | None


@dataclass(frozen=True)
class RestPosition:
    """Where ShotLink says a radar-measured shot came to rest, relative to its tee, in metres on the course's own
    grid (dx, dy: not the target line; dz up); `distance_m` is ShotLink's horizontal distance (carry plus roll) and
    `lie` its code for where the ball stopped (ELF/ERF fairway, ELR/ERR rough, EG* green, ...)."""

    shot_id: str
    dx_m: float | None
    dy_m: float | None
    dz_m: float | None
    distance_m: float | None
    lie: str


def _number(cells: dict[str, str], column: str) -> float | None:
    """A cell as a float; None where NA or blank, MalformedCell where it is not a finite number."""
    return finite_number(cells.get(column) or "", column, MISSING)


def _event(path: Path, rows: list[dict[str, str]]) -> tuple[str, str]:
    """(seasonYear, tournamentNumber) of the file; several events in one file refuse it."""
    events = {(row["seasonYear"].strip(), row["tournamentNumber"].strip()) for row in rows}
    if len(events) > 1:
        raise RecordError(f"{path}: columns 'seasonYear', 'tournamentNumber' hold several events {sorted(events)}; "
                          "expected one")
    return events.pop() if events else ("", "")


def read_rows(path: str | os.PathLike, report: ConversionReport, skip_bad_rows: bool = False,
              columns: tuple[str, ...] = (*LAUNCH, APEX_HEIGHT)) -> tuple[tuple[str, str], list[RadarRow]]:
    """The file's event (seasonYear, tournamentNumber) and its radar rows with their ids; `columns` (beside the
    key) are required. Every row is counted in `report`; rows without radar data are dropped there. A malformed key
    cell is a bad row (see `load_pbp`)."""
    path = Path(path)
    with reading(path), path.open(newline="", encoding="utf-8-sig") as handle:
        reader = csv.DictReader(handle)
        missing = [c for c in (*KEY_COLUMNS, RADAR_FLAG, *columns) if c not in (reader.fieldnames or [])]
        if missing:
            raise RecordError(f"{path}: required columns {missing} are missing (columns: {reader.fieldnames})")
        rows = list(enumerate(reader, start=2))
    season, tournament = _event(path, [row for _, row in rows])
    report.rows_in += len(rows)
    keyed = []
    for line, row in rows:
        if (row[RADAR_FLAG] or "").strip() in MISSING:
            report.drop(f"no radar data ('{RADAR_FLAG}' is NA: not a radar-measured tee shot)", line)
            continue
        try:
            keyed.append((line, shot_key(path, line, row), row))
        except RecordError as error:
            report.bad_row(str(error), "a shot key cell is not a number", line, skip_bad_rows)
    return (season, tournament), _identified(tournament, keyed)


def _identified(tournament: str, keyed: list[tuple[int, tuple, dict[str, str]]]) -> list[RadarRow]:
    """RadarRows with ids; the radar rows of a key that holds several are numbered -f1, -f2, ... in file order."""
    counts: dict[tuple, int] = {}
    for _, key, _ in keyed:
        counts[key] = counts.get(key, 0) + 1
    seen: dict[tuple, int] = {}
    radar = []
    for line, key, row in keyed:
        seen[key] = seen.get(key, 0) + 1
        flight = seen[key] if counts[key] > 1 else None
        session = f"{tournament}-R{key[0]}"
        radar.append(RadarRow(line, shot_id(tournament, key, flight), session, f"{session}-H{key[1]}", row))
    return radar


def _in_range(column: str, canonical: str, value: float) -> float:
    allowed = RANGES[canonical]
    if not allowed.low <= value <= allowed.high:
        raise BadRow(f"'{column}' ({canonical}) outside the allowed range {allowed.describe()}")
    return value


def _record(row: RadarRow, apex: bool) -> ShotRecord:
    """Every cell read first (a malformed one outranks a drop reason), then NA, spin 0 and ranges checked."""
    columns = {**LAUNCH, **({APEX_HEIGHT: ("apex_m", FOOT_M)} if apex else {})}
    numbers = {column: _number(row.cells, column) for column in columns}
    values = {}
    for column, (canonical, factor) in columns.items():
        value = numbers[column]
        if value is None and column in LAUNCH:
            raise BadRow(f"'{column}' is NA")
        if column == SPIN and value == 0:
            raise BadRow(f"no spin: '{SPIN}' is 0 (missing)")
        if value is not None:
            values[canonical] = _in_range(column, canonical, value * factor)
    return ShotRecord(shot_id=row.shot_id, session=row.session, group=row.group, spin_axis_deg=0.0, **values)


def load_pbp(path: str | os.PathLike, *, apex: bool = True, skip_bad_rows: bool = False) -> Conversion:
    """Convert a pbp file's radar-measured shots to canonical records (launch, spin, and with `apex` the apex).

    Rows without radar data, with spin 0 (missing) or a value outside its physical range are dropped, each counted
    under its reason. A malformed cell (not a number) refuses the file naming line and column, or with
    `skip_bad_rows` is left out and listed. The apex of an event in `APEX_NOT_AN_APEX` stays blank (see its note).
    """
    report = ConversionReport(str(path))
    (season, tournament), rows = read_rows(path, report, skip_bad_rows)
    reason = APEX_NOT_AN_APEX.get((season, tournament)) if apex else None
    records = []
    for row in rows:
        try:
            records.append(_record(row, apex and reason is None))
        except MalformedCell as bad:
            report.bad_row(f"{path} line {row.line} {bad.cell}: {bad}", str(bad), row.line, skip_bad_rows)
        except BadRow as bad:
            report.drop(str(bad), row.line)
    report.refuse_bad_rows(skip_bad_rows)
    report.kept = len(records)
    _notes(report, path, rows, apex, reason)
    return Conversion(records, report)


def _notes(report: ConversionReport, path: str | os.PathLike, rows: list[RadarRow], apex: bool,
           reason: str | None) -> None:
    report.notes.append("spin_axis_deg is 0 for every shot: the pbp file records no spin axis")
    report.notes.append("flight_time_s left blank: radarData.actualFlightTime is the radar-tracked time, not the "
                        "landing time; club left blank: the file does not name it")
    if reason:
        report.notes.append(f"apex_m left blank: {reason}")
    elif not apex:
        report.notes.append("apex_m left blank (apex not requested)")
    several = sorted({row.shot_id.rsplit("-f", 1)[0] for row in rows if "-f" in row.shot_id})
    if several:
        report.notes.append(f"{len(several)} shot keys hold several radar rows (a provisional ball): ids end -f1, "
                            f"-f2, ... in file order: {several[:5]}")
    held = held_out_set(path)
    if held:
        report.notes.append(f"{held.rows()} held out ({held.name}): for evaluation only, never for training "
                            "(shots.heldout)")


def _cells(path: str | os.PathLike, columns: tuple[str, ...]) -> list[RadarRow]:
    """The radar rows of a file that must have `columns`; a malformed key cell refuses it."""
    report = ConversionReport(str(path))
    _, rows = read_rows(path, report, columns=columns)
    report.refuse_bad_rows(skip=False)
    return rows


def _value(path: str | os.PathLike, row: RadarRow, column: str, factor: float) -> float | None:
    """A cell in SI; None where NA; a RecordError naming line and column where it is not a number."""
    try:
        value = _number(row.cells, column)
    except MalformedCell as bad:
        raise RecordError(f"{path} line {row.line} {bad.cell}: {bad}") from None
    return None if value is None else value * factor


def recorded_apex(path: str | os.PathLike) -> dict[str, RecordedApex]:
    """The apex fields exactly as recorded (feet turned into metres), per radar-measured shot: for checking them
    (scripts/check_pbp_apex.py); `load_pbp` decides whether apexHeight is used."""
    return {row.shot_id: RecordedApex(*(_value(path, row, c, FOOT_M) for c in (APEX_HEIGHT, APEX_RANGE, APEX_SIDE)))
            for row in _cells(path, (APEX_HEIGHT, APEX_RANGE, APEX_SIDE))}


def distance_m(text: str) -> float | None:
    """ShotLink's `distance` text in metres; None where NA or blank; InputError where it has another form."""
    text = text.strip()
    if text in MISSING:
        return None
    match = DISTANCE.fullmatch(text)
    if not match or not any(match.groupdict().values()):
        raise InputError(f"{text!r} is not a distance such as '306 yds' or '23 ft 3 in.'")
    parts = {unit: float(amount) for unit, amount in match.groupdict().items() if amount}
    return parts.get("yds", 0.0) * YARD_M + parts.get("ft", 0.0) * FOOT_M + parts.get("inch", 0.0) * FOOT_M / 12


def rest_positions(path: str | os.PathLike) -> dict[str, RestPosition]:
    """ShotLink's rest position relative to the tee of every radar-measured shot (ids as in `load_pbp`); a cell
    that is NA is None, one that is not a number refuses the file naming line and column."""
    positions = {}
    for row in _cells(path, (*TEE, *REST, "distance", "to")):
        tee = [_value(path, row, c, FOOT_M) for c in TEE]
        rest = [_value(path, row, c, FOOT_M) for c in REST]
        dx, dy, dz = (None if a is None or b is None else b - a for a, b in zip(tee, rest))
        try:
            distance = distance_m(row.cells["distance"] or "")
        except ValueError as error:
            raise RecordError(f"{path} line {row.line} column 'distance': {error}") from None
        positions[row.shot_id] = RestPosition(row.shot_id, dx, dy, dz, distance, (row.cells["to"] or "").strip())
    return positions


def _holes_played(path: Path) -> dict[tuple[int, int, str], tuple[int, set[str]]]:
    """Per player's hole in a round not held out (`shots.heldout`), keyed (round, hole, player): the strokes played
    (its last `shotNumber`) and the `textScore` cells of its rows."""
    held_out = held_out_rounds(path)
    played: dict[tuple[int, int, str], tuple[int, set[str]]] = {}
    with reading(path), path.open(newline="", encoding="utf-8-sig") as handle:
        reader = csv.DictReader(handle)
        missing = [c for c in PAR_COLUMNS if c not in (reader.fieldnames or [])]
        if missing:
            raise RecordError(f"{path}: required columns {missing} are missing (columns: {reader.fieldnames})")
        for line, row in enumerate(reader, start=2):
            try:
                round_number, hole, stroke = (int(row[c]) for c in ("roundNumber", "holeNumber", "shotNumber"))
            except ValueError as error:
                message = f"{path} line {line}: a round, hole or stroke number is not a number ({error})"
                raise RecordError(message) from None
            if round_number in held_out:
                continue
            key = (round_number, hole, row["playerId"].strip())
            strokes, scores = played.get(key, (0, set()))
            played[key] = (max(strokes, stroke), scores | {row["textScore"].strip()})
    return played


def hole_pars(path: str | os.PathLike) -> dict[int, int]:
    """The par of each hole of a pbp file's course, which the file does not name: for each player's hole in each
    round, the strokes played less the strokes over par its `textScore` names; the most common answer per hole, so a
    hole with a stroke missing from the file cannot move it. Held-out rounds are not read: a hole's par is the same
    in every round, so nothing built on it depends on them."""
    answers: dict[int, Counter[int]] = {}
    for (_, hole, _), (strokes, scores) in _holes_played(Path(path)).items():
        if len(scores) == 1 and (score := next(iter(scores))) in SCORE_TO_PAR:
            answers.setdefault(hole, Counter())[strokes - SCORE_TO_PAR[score]] += 1
    return {hole: counts.most_common(1)[0][0] for hole, counts in sorted(answers.items())}

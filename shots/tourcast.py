"""Loader for PGA TOUR TOURCAST TrackMan trajectories (shot_trajectory_*.csv, optionally joined to a pbp_*.csv).

Each shot is a polynomial of position (m) against time (s): one file row per coefficient (row 1..max_row,
ascending powers) in TrackMan axes (x downrange, y up, z right), turned here into our axes
(X right, Y down the line, Z up) = (zFit, xFit, yFit). From it:
  launch      ball speed, launch angle and direction from the velocity at t = 0 (c1);
  landing     the descending root of height − start height near the interval end (timeInterval = landing time);
              carry is the horizontal point there relative to the start point, with flight time and landing angle;
  apex        the maximum height above the start over [0, landing];
  trajectory  positions relative to the start point, sampled from 0 to landing;
  spin        radarData.launchSpin of the pbp file (0 = missing), joined on round/hole/player/shot;
  spin axis   NOT in the data: DERIVED from the initial lift direction (see `spin_axis_deg`).
Only the row with row == max_row holds the true interval ends: the scraper wrote end * row / max_row in the others
(so a block of rows ending at row r gives end = value * max_row / r). A key whose max_row is a multiple of the
file's coefficient count holds several flights (a re-teed shot); they are split and paired with the key's pbp rows
in file order. Truncated files (fewer than 7 coefficients, e.g. events 047 and 054) only give c0..c2 and the
interval ends: their shots get launch values and flight time, and no carry, apex, landing angle or trajectory.
"""

from __future__ import annotations

import csv
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from golfflight.errors import InputError
from golfflight.flight.constants import BALL_AREA_M2, BALL_MASS_KG, BALL_RADIUS_M, GRAVITY_MPS2, RPM_TO_RADPS
from golfflight.shots.records import RANGES, RecordError, ShotRecord, reading
from golfflight.shots.trackman import Conversion, ConversionReport
from numpy.polynomial import Polynomial
from pydantic import ValidationError

FULL_COEFFICIENTS = 7
"""Coefficients of a complete TOURCAST polynomial (degree 6); fewer means the scraper truncated it."""

LANDING_TOLERANCE_S = 0.5
"""How far the ground crossing may lie from the recorded landing time (in the shared files it is within 0.01 s)."""

FERGUSON_CL = (0.0504, 1.2031, -1.1490)
"""Ferguson, McNally & McPhee 2022: C_L(S) = 0.0504 + 1.2031 S - 1.1490 S^2 (ascending powers of S)."""

ESTIMATE_AIR_DENSITY = 1.19
"""Air density (kg/m^3) assumed when spin is estimated from the lift."""

TRAJECTORY_COLUMNS = ("row", "max_row", "tournamentNumber", "roundNumber", "holeNumber", "playerId", "shotNumber",
                      "timeInterval", "measuredTimeInterval", "xFit", "yFit", "zFit")
PBP_COLUMNS = ("tournamentNumber", "roundNumber", "holeNumber", "playerId", "shotNumber", "radarData.launchSpin")
NO_SPIN_HINT = "spin is required; --estimate-spin estimates it from the lift"


@dataclass(frozen=True)
class TrackedFlight:
    """One trajectory polynomial: coefficients [n, 3] in our axes (X right, Y down the line, Z up), ascending powers."""

    shot_id: str
    tournament: str
    session: str
    key: tuple[str, str, str, str]
    line: int
    coefficients: np.ndarray
    landing_time_s: float
    measured_time_s: float

    @property
    def complete(self) -> bool:
        return len(self.coefficients) >= FULL_COEFFICIENTS


class _BadFlight(InputError):
    """A flight that cannot become a canonical record; the message is the drop reason."""


def launch(coefficients: np.ndarray) -> tuple[float, float, float]:
    """(ball speed m/s, launch angle deg, launch direction deg, + right) from the velocity at t = 0."""
    vx, vy, vz = coefficients[1]
    return (math.sqrt(vx * vx + vy * vy + vz * vz), math.degrees(math.atan2(vz, math.hypot(vx, vy))),
            math.degrees(math.atan2(vx, vy)))


def lift_acceleration(coefficients: np.ndarray) -> np.ndarray:
    """Initial aerodynamic acceleration (2 c2 minus gravity) less its component along the velocity (the drag)."""
    aero = 2.0 * coefficients[2] + np.array([0.0, 0.0, GRAVITY_MPS2])
    along = coefficients[1] / np.linalg.norm(coefficients[1])
    return aero - np.dot(aero, along) * along


def spin_axis_deg(coefficients: np.ndarray) -> float:
    """Spin axis DERIVED from the initial lift L: with ω = |ω|(cos ψ, 0, −sin ψ), ω × v has X = |ω| sin ψ v_Y and
    Z = |ω| cos ψ v_Y, so tan ψ = L_X / L_Z; a lift to the right gives a positive axis (the ball curves right)."""
    lift = lift_acceleration(coefficients)
    return math.degrees(math.atan2(lift[0], lift[2]))


def estimate_spin_rpm(coefficients: np.ndarray, air_density: float = ESTIMATE_AIR_DENSITY) -> float:
    """An ESTIMATE of |ω|: the lift coefficient of the initial lift, C_L = 2 m |L| / (ρ A v²), inverted through
    Ferguson 2022's C_L(S) on its rising branch, and S = R |ω| / v."""
    speed = float(np.linalg.norm(coefficients[1]))
    lift_mps2 = float(np.linalg.norm(lift_acceleration(coefficients)))
    lift = 2.0 * BALL_MASS_KG * lift_mps2 / (air_density * BALL_AREA_M2 * speed**2)
    c0, c1, c2 = FERGUSON_CL
    top = c0 - c1 * c1 / (4.0 * c2)
    if not c0 <= lift <= top:
        raise InputError(f"lift coefficient outside Ferguson's C_L(S) range {c0:g} to {top:.4f}")
    ratio = (-c1 + math.sqrt(c1 * c1 - 4.0 * c2 * (c0 - lift))) / (2.0 * c2)
    return ratio * speed / BALL_RADIUS_M / RPM_TO_RADPS


def _height(coefficients: np.ndarray) -> Polynomial:
    return Polynomial(coefficients[:, 2]) - coefficients[0, 2]


def landing_time_s(coefficients: np.ndarray, time_end_s: float, tolerance_s: float = LANDING_TOLERANCE_S) -> float:
    """The descending crossing of the start height nearest the recorded landing time."""
    height = _height(coefficients)
    rising = height.deriv()
    crossings = [r.real for r in height.roots() if abs(r.imag) < 1e-9 and r.real > 0 and rising(r.real) < 0]
    if not crossings or min(abs(t - time_end_s) for t in crossings) > tolerance_s:
        raise InputError(f"no descending crossing of the start height within {tolerance_s:g} s of timeInterval end")
    return min(crossings, key=lambda t: abs(t - time_end_s))


def apex_m(coefficients: np.ndarray, landing_s: float) -> float:
    """Maximum height above the start point over [0, landing]."""
    height = _height(coefficients)
    times = [0.0, landing_s] + [r.real for r in height.deriv().roots() if abs(r.imag) < 1e-9 and 0 < r.real < landing_s]
    return float(max(height(t) for t in times))


def positions(coefficients: np.ndarray, times: np.ndarray) -> np.ndarray:
    """Positions [T, 3] relative to the start point at the given times."""
    return np.stack([Polynomial(coefficients[:, axis])(times) - coefficients[0, axis] for axis in range(3)], axis=1)


def landing(coefficients: np.ndarray, landing_s: float) -> tuple[float, float, float]:
    """(carry_x_m, carry_y_m, landing angle deg, descent positive) at the landing time."""
    x, y, _ = positions(coefficients, np.array([landing_s]))[0]
    vx, vy, vz = (Polynomial(coefficients[:, axis]).deriv()(landing_s) for axis in range(3))
    return float(x), float(y), math.degrees(math.atan2(-vz, math.hypot(vx, vy)))


def sample(coefficients: np.ndarray, landing_s: float, interval_s: float) -> np.ndarray:
    """[T, 4] of t, x, y, z from 0 to landing (the landing itself is the last sample)."""
    times = np.append(np.arange(0.0, landing_s - 1e-9, interval_s), landing_s)
    return np.column_stack([times, positions(coefficients, times)])


def _require(path: Path, header: list[str] | None, columns: tuple[str, ...]) -> None:
    missing = [c for c in columns if c not in (header or [])]
    if missing:
        raise RecordError(f"{path}: required columns {missing} are missing (columns: {header})")


def shot_key(path: Path, line: int, row: dict[str, str]) -> tuple[str, str, str, str]:
    """(round, hole, player, shot): the join key shared by trajectory and pbp files."""
    key = []
    for column in ("roundNumber", "holeNumber", "playerId", "shotNumber"):
        text = (row[column] or "").strip()
        if column != "playerId":
            try:
                text = str(int(float(text)))
            except ValueError:
                raise RecordError(f"{path} line {line} column '{column}': {text!r} is not a number") from None
        key.append(text)
    return tuple(key)


def shot_id(tournament: str, key: tuple[str, str, str, str], flight: int | None = None) -> str:
    """The id of a tour shot, shared by the TOURCAST and pbp loaders; `flight` numbers the flights (from 1) of a key
    that holds several (a re-teed shot)."""
    base = f"{tournament}-R{key[0]}-H{key[1]}-P{key[2]}-S{key[3]}"
    return base if flight is None else f"{base}-f{flight}"


def _groups(path: Path) -> tuple[str, list[tuple[int, tuple, list[dict[str, str]]]]]:
    """Tournament number and the file's rows grouped per shot key, in file order: (first line, key, rows)."""
    with reading(path), path.open(newline="", encoding="utf-8-sig") as handle:
        reader = csv.DictReader(handle)
        _require(path, reader.fieldnames, TRAJECTORY_COLUMNS)
        groups: list[tuple[int, tuple, list[dict[str, str]]]] = []
        for line, row in enumerate(reader, start=2):
            key = shot_key(path, line, row)
            if groups and groups[-1][1] == key and row["row"].strip() != "1":
                groups[-1][2].append(row)
            else:
                groups.append((line, key, [row]))
    tournaments = {rows[0]["tournamentNumber"].strip() for _, _, rows in groups}
    if len(tournaments) > 1:
        raise RecordError(f"{path}: column 'tournamentNumber' holds several events {sorted(tournaments)}; expected one")
    return (tournaments.pop() if tournaments else ""), groups


class _Malformed(_BadFlight):
    """A shot whose rows are not what the format holds: refuses the file unless bad rows are skipped."""

    def __init__(self, reason: str, line: int, where: str):
        super().__init__(reason)
        self.line, self.where = line, where


def _number(row: dict[str, str], column: str, line: int) -> float:
    text = row[column]
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise _Malformed(f"'{column}' is not a number", line, f"column '{column}': {text!r}") from None
    if not math.isfinite(value):
        raise _Malformed(f"'{column}' is not a number", line, f"column '{column}': {text!r}")
    return value


def _flights(line: int, key: tuple, rows: list[dict[str, str]], n: int, tournament: str) -> list[TrackedFlight]:
    """Split one key's rows (consecutive lines from `line`) into flights of n coefficients each."""
    max_row = int(_number(rows[0], "max_row", line))
    numbers = [int(_number(r, "row", line + i)) for i, r in enumerate(rows)]
    if numbers != list(range(1, max_row + 1)) or max_row % n:
        raise _Malformed(
            f"rows 'row' = 1..'max_row' incomplete or not a multiple of the {n} coefficients",
            line,
            f"column 'row': {numbers} with max_row {max_row}",
        )
    count = max_row // n
    flights = []
    for block in range(count):
        part = rows[block * n:(block + 1) * n]
        first = line + block * n
        coefficients = np.array(
            [[_number(r, axis, first + j) for axis in ("zFit", "xFit", "yFit")] for j, r in enumerate(part)]
        )
        scale = max_row / ((block + 1) * n)
        flights.append(TrackedFlight(shot_id(tournament, key, block + 1 if count > 1 else None), tournament,
                              f"{tournament}-R{key[0]}", key, line + block * n, coefficients,
                              _number(part[-1], "timeInterval", first + n - 1) * scale,
                              _number(part[-1], "measuredTimeInterval", first + n - 1) * scale))
    return flights


def read_flights(path: str | os.PathLike, report: ConversionReport, skip_bad_rows: bool = False) -> list[TrackedFlight]:
    """Every flight of a trajectory file. A malformed shot refuses the file (RecordError naming line and column), or
    with `skip_bad_rows` is counted in `report` as one row in, dropped and listed."""
    path = Path(path)
    tournament, groups = _groups(path)
    n = min((int(rows[0]["max_row"]) for _, _, rows in groups if rows[0]["max_row"].strip().isdigit()), default=0)
    if groups and not 3 <= n <= FULL_COEFFICIENTS:
        raise RecordError(f"{path}: column 'max_row': shots have {n} coefficients; expected 3 to {FULL_COEFFICIENTS}")
    flights = []
    for line, key, rows in groups:
        try:
            found = _flights(line, key, rows, n, tournament)
        except _Malformed as bad:
            report.rows_in += 1
            report.bad_row(f"{path} line {bad.line} {bad.where}: {bad}", str(bad), line, skip_bad_rows)
            continue
        report.rows_in += len(found)
        flights.extend(found)
    report.refuse_bad_rows(skip_bad_rows)
    return flights


def read_pbp_spin(path: str | os.PathLike, tournament: str) -> dict[tuple[str, str, str, str], list[float | None]]:
    """radarData.launchSpin (rpm; None where 0 = missing) of each radar-measured pbp row, per shot key in file order."""
    path = Path(path)
    spins: dict[tuple[str, str, str, str], list[float | None]] = {}
    with reading(path), path.open(newline="", encoding="utf-8-sig") as handle:
        reader = csv.DictReader(handle)
        _require(path, reader.fieldnames, PBP_COLUMNS)
        for line, row in enumerate(reader, start=2):
            if row["tournamentNumber"].strip() != tournament:
                raise RecordError(f"{path} line {line} column 'tournamentNumber': {row['tournamentNumber']!r} is not "
                                  f"the trajectories' event {tournament!r}")
            text = row["radarData.launchSpin"].strip()
            if text in ("", "NA"):
                continue
            try:
                spin = float(text)
            except ValueError:
                raise RecordError(f"{path} line {line} column 'radarData.launchSpin': {text!r} is not a number"
                                  ) from None
            limit = RANGES["spin_rpm"]
            if not (spin == 0 or limit.low <= spin <= limit.high):
                raise RecordError(f"{path} line {line} column 'radarData.launchSpin': {spin:g} outside the allowed "
                                  f"range {limit.describe()} (0 = missing)")
            spins.setdefault(shot_key(path, line, row), []).append(spin or None)
    return spins


def _spin_sources(flights: list[TrackedFlight], spins: dict | None) -> dict[str, float | str]:
    """Per shot id the pbp spin (rpm) or, where there is none, the reason why."""
    by_key: dict[tuple, list[TrackedFlight]] = {}
    for flight in flights:
        by_key.setdefault(flight.key, []).append(flight)
    found: dict[str, float | str] = {}
    for key, group in by_key.items():
        rows = None if spins is None else spins.get(key, [])
        for index, flight in enumerate(group):
            if rows is None:
                found[flight.shot_id] = "no spin: no pbp file given"
            elif not rows:
                found[flight.shot_id] = "no spin: no radar-measured pbp row for this shot"
            elif len(rows) != len(group):
                found[flight.shot_id] = f"no spin: pbp has {len(rows)} radar rows for {len(group)} flights of this shot"
            elif rows[index] is None:
                found[flight.shot_id] = "no spin: pbp launchSpin is 0 (missing)"
            else:
                found[flight.shot_id] = rows[index]
    return found


def _record(flight: TrackedFlight, spin: float) -> ShotRecord:
    coefficients = flight.coefficients
    speed, angle, direction = launch(coefficients)
    axis = spin_axis_deg(coefficients)
    if abs(axis) > 90:
        raise _BadFlight("derived spin axis beyond -90 to 90 deg: the initial lift (2 c2 + g, less drag) points down")
    values = dict(ball_speed_mps=speed, launch_angle_deg=angle, launch_direction_deg=direction, spin_rpm=spin,
                  spin_axis_deg=axis, flight_time_s=flight.landing_time_s)
    if flight.complete:
        try:
            landing_s = landing_time_s(coefficients, flight.landing_time_s)
        except ValueError as error:
            raise _BadFlight(str(error)) from None
        carry_x, carry_y, angle_down = landing(coefficients, landing_s)
        values.update(flight_time_s=landing_s, carry_x_m=carry_x, carry_y_m=carry_y, landing_angle_deg=angle_down,
                      apex_m=apex_m(coefficients, landing_s))
    try:
        return ShotRecord(shot_id=flight.shot_id, session=flight.session, **values)
    except ValidationError as error:
        column = str(error.errors()[0]["loc"][0])
        raise _BadFlight(f"{column} outside the allowed range {RANGES[column].describe()}") from None


def load_tourcast(trajectory_path: str | os.PathLike, pbp_path: str | os.PathLike | None = None, *,
                  estimate_spin: bool = False, sample_interval_s: float = 0.01,
                  skip_bad_rows: bool = False) -> Conversion:
    """Convert a TOURCAST trajectory file (plus its pbp file for spin) to canonical records and sampled flights.

    Shots without a measured spin are dropped with the reason, or with `estimate_spin` get `estimate_spin_rpm`.
    A malformed shot (a cell that is not a number, missing coefficient rows) refuses the file, or with
    `skip_bad_rows` is left out and listed in the report.
    """
    report = ConversionReport(str(trajectory_path))
    flights = read_flights(trajectory_path, report, skip_bad_rows)
    tournament = flights[0].tournament if flights else ""
    spins = _spin_sources(flights, None if pbp_path is None else read_pbp_spin(pbp_path, tournament))
    records, trajectories, estimated = [], {}, 0
    for flight in flights:
        spin = spins[flight.shot_id]
        try:
            if isinstance(spin, str):
                if not estimate_spin:
                    raise _BadFlight(f"{spin} ({NO_SPIN_HINT})")
                try:
                    spin = estimate_spin_rpm(flight.coefficients)
                except ValueError as error:
                    raise _BadFlight(f"spin estimate impossible: {error}") from None
                estimated += 1
            record = _record(flight, spin)
        except _BadFlight as bad:
            report.drop(str(bad), flight.line)
            continue
        records.append(record)
        if flight.complete:
            trajectories[flight.shot_id] = sample(flight.coefficients, record.flight_time_s, sample_interval_s)
    report.kept = len(records)
    _notes(report, flights, records, estimated)
    return Conversion(records, report, trajectories)


def _notes(report: ConversionReport, flights: list[TrackedFlight], records: list[ShotRecord], estimated: int) -> None:
    split = sorted({f.shot_id.rsplit("-f", 1)[0] for f in flights if "-f" in f.shot_id})
    if split:
        report.notes.append(f"{len(split)} shot keys hold several flights (re-teed shots): ids end -f1, -f2, ... "
                            f"(in file order, as are the key's pbp rows): {split[:5]}")
    truncated = sum(not f.complete for f in flights)
    if truncated:
        report.notes.append(f"{truncated} flights have fewer than {FULL_COEFFICIENTS} coefficients (truncated): launch "
                            "from c0..c2 and flight time only; carry, apex, landing angle and trajectory left blank")
    if records:
        report.notes.append(f"spin_axis_deg of all {len(records)} kept shots is DERIVED from the initial lift "
                            "direction (the data have no spin axis)")
    if estimated:
        report.notes.append(f"spin_rpm of {estimated} kept shots is an ESTIMATE from the initial lift (Ferguson 2022 "
                            f"C_L(S), rho = {ESTIMATE_AIR_DENSITY} kg/m^3)")

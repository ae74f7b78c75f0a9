"""The canonical shot-record CSV (one row per shot) that training, evaluation and diagnosis all read.

Columns, SI units:
  identity (optional)  shot_id, session, club, timestamp, split (train/val), source (the data set a merged file
                       took the row from), group (shots that shared one unrecorded wind and air: a tour hole in one
                       round, a block of a range session), ball (the ball type as the export names it)
  launch (required)    ball_speed_mps, launch_angle_deg, launch_direction_deg (+ right), spin_rpm,
                       spin_axis_deg (+ tilted right: the ball curves right)
  outcome (optional)   carry_x_m (+ right), carry_y_m (down the line), apex_m, flight_time_s,
                       landing_angle_deg (descent, positive); all at the launch elevation
  conditions (opt.)    temperature_c, altitude_m, pressure_hpa, humidity_pct, wind_speed_mps, wind_from_deg
A blank cell means "not recorded". An optional companion `NAME.trajectories.csv` holds
shot_id,t_s,x_m,y_m,z_m samples of the flight.
"""

from __future__ import annotations

import csv
import math
import os
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Iterable, Iterator, Literal

import numpy as np
from golfflight.errors import InputError
from golfflight.flight import limits
from golfflight.flight.air import Air, pressure_at_altitude
from golfflight.flight.limits import Range
from golfflight.shots.files import write_atomic
from pydantic import BaseModel, ConfigDict, Field, ValidationError

RANGES: dict[str, Range] = {
    "ball_speed_mps": limits.BALL_SPEED_MPS,
    "launch_angle_deg": limits.LAUNCH_ANGLE_DEG,
    "launch_direction_deg": limits.LAUNCH_DIRECTION_DEG,
    "spin_rpm": limits.SPIN_RPM,
    "spin_axis_deg": limits.SPIN_AXIS_DEG,
    "carry_x_m": limits.CARRY_X_M,
    "carry_y_m": limits.CARRY_Y_M,
    "apex_m": limits.APEX_M,
    "flight_time_s": limits.FLIGHT_TIME_S,
    "landing_angle_deg": limits.LANDING_ANGLE_DEG,
    "temperature_c": limits.TEMPERATURE_C,
    "altitude_m": limits.ALTITUDE_M,
    "pressure_hpa": limits.PRESSURE_HPA,
    "humidity_pct": limits.HUMIDITY_PCT,
    "wind_speed_mps": limits.WIND_SPEED_MPS,
    "wind_from_deg": limits.WIND_FROM_DEG,
}
"""Allowed physical range of every numeric column."""


def _bounded(r: Range):
    return Annotated[float, Field(ge=r.low, le=r.high, allow_inf_nan=False, json_schema_extra={"unit": r.unit})]


def _optional(r: Range):
    return Annotated[float | None, Field(default=None, ge=r.low, le=r.high, allow_inf_nan=False, json_schema_extra={"unit": r.unit})]


class ShotRecord(BaseModel):
    """One row of the canonical CSV."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    shot_id: str | None = None
    session: str | None = None
    club: str | None = None
    timestamp: str | None = None
    split: Literal["train", "val"] | None = None
    source: str | None = None
    group: str | None = None
    ball: str | None = None

    ball_speed_mps: _bounded(limits.BALL_SPEED_MPS)
    launch_angle_deg: _bounded(limits.LAUNCH_ANGLE_DEG)
    launch_direction_deg: _bounded(limits.LAUNCH_DIRECTION_DEG)
    spin_rpm: _bounded(limits.SPIN_RPM)
    spin_axis_deg: _bounded(limits.SPIN_AXIS_DEG)

    carry_x_m: _optional(limits.CARRY_X_M)
    carry_y_m: _optional(limits.CARRY_Y_M)
    apex_m: _optional(limits.APEX_M)
    flight_time_s: _optional(limits.FLIGHT_TIME_S)
    landing_angle_deg: _optional(limits.LANDING_ANGLE_DEG)

    temperature_c: _optional(limits.TEMPERATURE_C)
    altitude_m: _optional(limits.ALTITUDE_M)
    pressure_hpa: _optional(limits.PRESSURE_HPA)
    humidity_pct: _optional(limits.HUMIDITY_PCT)
    wind_speed_mps: _optional(limits.WIND_SPEED_MPS)
    wind_from_deg: _optional(limits.WIND_FROM_DEG)


COLUMNS: tuple[str, ...] = tuple(ShotRecord.model_fields)
REQUIRED_COLUMNS: tuple[str, ...] = tuple(name for name, f in ShotRecord.model_fields.items() if f.is_required())
NUMERIC_COLUMNS: tuple[str, ...] = tuple(RANGES)
LAUNCH_COLUMNS: tuple[str, ...] = REQUIRED_COLUMNS
CSV_ENCODING = "utf-8-sig"
"""How every CSV golfflight reads is decoded: UTF-8, a byte-order mark at the start passed over (a spreadsheet's
"CSV UTF-8" writes one; read as plain UTF-8 it glues itself to the first column's name)."""

OUTCOME_COLUMNS = ("carry_x_m", "carry_y_m", "apex_m", "flight_time_s", "landing_angle_deg")
AIR_COLUMNS = ("temperature_c", "altitude_m", "pressure_hpa", "humidity_pct")
TRAJECTORY_COLUMNS = ("shot_id", "t_s", "x_m", "y_m", "z_m")


class RecordError(InputError):
    """A file that does not follow the canonical format; the message names file, line and column of each problem."""


@dataclass(frozen=True)
class RowProblem:
    """Why one row of a file was refused."""

    file: str
    line: int
    column: str
    value: str
    reason: str

    def __str__(self) -> str:
        return f"{self.file} line {self.line} column '{self.column}': {self.value!r} {self.reason}"


def _row_problems(error: ValidationError, file: str, line: int, row: dict[str, str]) -> list[RowProblem]:
    problems = []
    for item in error.errors():
        column = str(item["loc"][0]) if item["loc"] else "?"
        reason = item["msg"]
        if column in RANGES:
            reason = f"is not accepted ({item['msg']}); allowed range {RANGES[column].describe()}"
        problems.append(RowProblem(file, line, column, row.get(column, ""), reason))
    return problems


def _parse_cell(column: str, text: str) -> float | str | None:
    text = text.strip()
    if text == "":
        return None
    if column in NUMERIC_COLUMNS:
        return float(text)
    return text


@dataclass
class ShotSet:
    """Shots read from (or to be written to) a canonical file, with NumPy columns for batch work."""

    records: list[ShotRecord]
    skipped: list[RowProblem] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.records)

    def column(self, name: str) -> np.ndarray:
        """A numeric column as a float array (NaN where not recorded) or a text column as an object array."""
        values = [getattr(r, name) for r in self.records]
        if name in NUMERIC_COLUMNS:
            return np.array([np.nan if v is None else v for v in values], dtype=float)
        return np.array(values, dtype=object)

    def launch(self) -> dict[str, np.ndarray]:
        """The five launch columns, ready for `flight.physics.initial_state(**shots.launch())`."""
        return {name: self.column(name) for name in LAUNCH_COLUMNS}

    def air(self) -> Air:
        """Air (density, kinematic viscosity) per shot from its recorded conditions. What was not recorded takes the
        ICAO standard value (15 degC, sea-level pressure, dry), so a shot without conditions flies in standard air."""
        altitude = np.nan_to_num(self.column("altitude_m"))
        pressure_hpa = self.column("pressure_hpa")
        temperature = self.column("temperature_c")
        return Air.from_conditions(
            np.where(np.isnan(temperature), 15.0, temperature),
            humidity_pct=np.nan_to_num(self.column("humidity_pct")),
            pressure_pa=np.where(np.isnan(pressure_hpa), pressure_at_altitude(altitude), pressure_hpa * 100.0),
        )

    def air_recorded(self) -> bool:
        """Whether any shot records any air condition."""
        return bool(np.isfinite(np.stack([self.column(name) for name in AIR_COLUMNS])).any())

    def subset(self, mask: np.ndarray) -> "ShotSet":
        return ShotSet([r for r, keep in zip(self.records, mask) if keep])


@contextmanager
def reading(path: str | os.PathLike) -> Iterator[None]:
    """Turns a file that is not UTF-8 text, or not CSV at all, into a RecordError naming it (never a traceback)."""
    try:
        yield
    except UnicodeDecodeError as error:
        raise RecordError(f"{path}: not UTF-8 text (byte {error.start}: {error.reason})") from None
    except csv.Error as error:
        raise RecordError(f"{path}: not a CSV file ({error})") from None


def read_shots(path: str | os.PathLike, skip_bad_rows: bool = False) -> ShotSet:
    """Read and validate a canonical CSV. Bad rows (a cell that is not a number or out of its range, an extra cell,
    a shot_id seen before) raise `RecordError` listing every problem with file, line and column, or with
    `skip_bad_rows` are left out and reported in `ShotSet.skipped`. A missing or unknown column refuses the file."""
    with reading(path):
        return _read_shots(Path(path), skip_bad_rows)


def _read_shots(path: Path, skip_bad_rows: bool) -> ShotSet:
    with path.open(newline="", encoding=CSV_ENCODING) as handle:
        reader = csv.DictReader(handle)
        header = reader.fieldnames or []
        missing = [c for c in REQUIRED_COLUMNS if c not in header]
        unknown = [c for c in header if c not in COLUMNS]
        if missing or unknown:
            parts = []
            if missing:
                parts.append(f"missing required columns {missing}")
            if unknown:
                parts.append(f"unknown columns {unknown} (allowed: {list(COLUMNS)})")
            raise RecordError(f"{path} line 1 (header): " + "; ".join(parts))
        records, problems, first_line = [], [], {}
        for line, row in enumerate(reader, start=2):
            row_problems = []
            values = {}
            for column, text in row.items():
                if column is None:
                    row_problems.append(RowProblem(str(path), line, "?", ",".join(text), "is an extra cell beyond the header"))
                    continue
                try:
                    values[column] = _parse_cell(column, text or "")
                except ValueError:
                    row_problems.append(RowProblem(str(path), line, column, text, "is not a number"))
            if not row_problems:
                try:
                    record = ShotRecord(**values)
                except ValidationError as error:
                    row_problems = _row_problems(error, str(path), line, row)
                else:
                    if record.shot_id is not None and record.shot_id in first_line:
                        reason = f"duplicates the shot_id of line {first_line[record.shot_id]}"
                        row_problems = [RowProblem(str(path), line, "shot_id", record.shot_id, reason)]
                    else:
                        records.append(record)
                        if record.shot_id is not None:
                            first_line[record.shot_id] = line
            problems.extend(row_problems)
    if problems and not skip_bad_rows:
        shown = "\n  ".join(str(p) for p in problems[:50])
        more = f"\n  ... and {len(problems) - 50} more" if len(problems) > 50 else ""
        raise RecordError(f"{path}: {len(problems)} bad cells:\n  {shown}{more}")
    return ShotSet(records, problems)


def _format(value: object) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return "" if math.isnan(value) else f"{value:.6g}"
    return str(value)


def write_csv_atomic(path: Path, header: Iterable[str], rows: Iterable[Iterable[object]]) -> None:
    """Write a CSV atomically (`shots.files.write_atomic`): readers never see half a file."""

    def write(tmp: str) -> None:
        with open(tmp, "w", newline="") as handle:
            writer = csv.writer(handle)
            writer.writerow(header)
            for row in rows:
                writer.writerow([_format(v) for v in row])

    write_atomic(path, write)


def write_shots(path: str | os.PathLike, records: Iterable[ShotRecord]) -> None:
    """Write canonical shot records (all columns, blanks for what was not recorded)."""
    write_csv_atomic(Path(path), COLUMNS, ([getattr(r, c) for c in COLUMNS] for r in records))


def trajectories_path(path: str | os.PathLike) -> Path:
    """The companion trajectories file of a canonical CSV: NAME.csv -> NAME.trajectories.csv."""
    path = Path(path)
    return path.with_name(path.stem + ".trajectories.csv")


def write_trajectories(path: str | os.PathLike, trajectories: dict[str, np.ndarray]) -> None:
    """Write {shot_id: array [T,4] of t_s, x_m, y_m, z_m} as the companion file."""
    rows = ([shot_id, *sample] for shot_id, samples in trajectories.items() for sample in np.asarray(samples, dtype=float))
    write_csv_atomic(Path(path), TRAJECTORY_COLUMNS, rows)


def read_trajectories(path: str | os.PathLike) -> dict[str, np.ndarray]:
    """Read a companion file into {shot_id: array [T,4] of t_s, x_m, y_m, z_m}, samples in time order."""
    with reading(path):
        return _read_trajectories(Path(path))


def _read_trajectories(path: Path) -> dict[str, np.ndarray]:
    grouped: dict[str, list[list[float]]] = {}
    with path.open(newline="", encoding=CSV_ENCODING) as handle:
        reader = csv.DictReader(handle)
        if list(reader.fieldnames or []) != list(TRAJECTORY_COLUMNS):
            raise RecordError(f"{path} line 1 (header): expected columns {list(TRAJECTORY_COLUMNS)}, got {reader.fieldnames}")
        for line, row in enumerate(reader, start=2):
            try:
                sample = [float(row[c]) for c in TRAJECTORY_COLUMNS[1:]]
            except (TypeError, ValueError):
                raise RecordError(f"{path} line {line}: t_s, x_m, y_m, z_m must all be numbers, got {row}") from None
            if not all(math.isfinite(v) for v in sample):
                raise RecordError(f"{path} line {line}: non-finite sample {sample}")
            grouped.setdefault(row["shot_id"], []).append(sample)
    return {shot_id: np.array(sorted(samples)) for shot_id, samples in grouped.items()}

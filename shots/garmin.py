"""Loader for the Garmin Golf app's shot export (Approach R10, R50): one canonical record per shot with a flight.

The export has one header row whose names carry their units ("Ball Speed (mph)", "Apex Height (ft)", "Carry Distance
(yards)", "Temperature (F)", "Air Pressure (kPA)"); every value is converted to SI here, at the file edge. Read:

- launch: Ball Speed, Launch Angle, Launch Direction (+ right, golfflight's sign).
- spin: Spin Rate is the total spin; Spin Axis has golfflight's sign (+ tilted right: the ball curves right). Where a
  row lacks either, it follows from Backspin and Sidespin, whose sign is the opposite of golfflight's (Garmin's
  + sidespin curves the ball left): total hypot(backspin, sidespin), axis atan2(-sidespin, backspin).
- carry: Carry Distance is the straight-line horizontal distance from the tee to the landing point, Carry Deviation
  Angle the direction of that point off the target line and Carry Deviation Distance its distance from the line,
  both + right as golfflight's x. So carry_y_m (down the line) = carry cos(angle) and carry_x_m (+ right) = the
  deviation distance; the two are one landing point (carry_x² + carry_y² = carry²) when the deviation distance is
  carry sin(angle), and rows where they differ by more than GEOMETRY_TOLERANCE_YD are noted in the report.
- apex: Apex Height, feet -> apex_m.
- air: the canonical record holds the weather, not a density (temperature_c, altitude_m, pressure_hpa,
  humidity_pct), so each row keeps its Temperature (F -> temperature_c) and Air Pressure (station pressure,
  kPa -> pressure_hpa) and flies in the density they make (dry: the export names no humidity). The recorded Air
  Density (g/L, the same number in kg/m³) is not kept: rows where it differs from that density by more than
  DENSITY_TOLERANCE are noted in the report. `air=False` (--no-air) leaves the air blank: ICAO standard air.
- wind: every row records a calm wind (wind_speed_mps 0). The export's carry and apex are the monitor's own flight
  model's, computed from the launch it measured in still air: a consumer radar tracks the ball for 8 to 30 feet and a
  camera unit sees only the impact (https://halfwayhouse.golf/articles/how-a-launch-monitor-actually-works). So no
  wind reaches them, and `golfflight diagnose` looks for none (a wind would otherwise stand in for the monitor's
  model).
- identity: shot_id is the row's line number; Date gives timestamp and session (its day); Club, else Club Type, the
  club, as written. Other columns (the club's delivery, smash factor, totals) are passed over.

A row without a launch angle, or whose carry is blank or 0 (no flight), is listed in the report and skipped. Any
other malformed cell (not a number; blank where the launch needs it; outside its physical range in `flight.limits`,
quoted as recorded and in SI with the allowed range) refuses the file naming line and column, unless `skip_bad_rows`:
then the row is left out and listed.
"""

from __future__ import annotations

import csv
import math
import os
from collections.abc import Callable
from pathlib import Path

from golfflight.flight.air import air_density
from golfflight.flight.constants import FOOT_M, MPH_TO_MPS, YARD_M
from golfflight.shots.cells import BadRow, MalformedCell, finite_number, when
from golfflight.shots.records import RANGES, RecordError, ShotRecord, reading
from golfflight.shots.trackman import Conversion, ConversionReport

BALL_SPEED, LAUNCH_ANGLE, LAUNCH_DIRECTION = "Ball Speed (mph)", "Launch Angle (deg)", "Launch Direction (deg)"
SPIN_RATE, SPIN_AXIS, BACKSPIN, SIDESPIN = "Spin Rate (rpm)", "Spin Axis (deg)", "Backspin (rpm)", "Sidespin (rpm)"
SPIN_TYPE = "Spin Rate Type"
CARRY, DEVIATION_ANGLE = "Carry Distance (yards)", "Carry Deviation Angle (deg)"
DEVIATION = "Carry Deviation Distance (yards)"
APEX = "Apex Height (ft)"
TEMPERATURE, PRESSURE, DENSITY = "Temperature (F)", "Air Pressure (kPA)", "Air Density (g/L)"

CONVERTED: dict[str, tuple[str, Callable[[float], float]]] = {
    BALL_SPEED: ("ball_speed_mps", lambda mph: mph * MPH_TO_MPS),
    LAUNCH_ANGLE: ("launch_angle_deg", float),
    LAUNCH_DIRECTION: ("launch_direction_deg", float),
    APEX: ("apex_m", lambda ft: ft * FOOT_M),
}
"""Export columns copied one-to-one: canonical column and the conversion to SI."""
AIR: dict[str, tuple[str, Callable[[float], float]]] = {
    TEMPERATURE: ("temperature_c", lambda f: (f - 32.0) * 5.0 / 9.0),
    PRESSURE: ("pressure_hpa", lambda kpa: kpa * 10.0),
}
"""The recorded air kept in each row (station pressure: the export's Air Pressure is not reduced to sea level)."""
FLIGHT_NUMBERS = (*CONVERTED, SPIN_RATE, SPIN_AXIS, BACKSPIN, SIDESPIN, CARRY, DEVIATION_ANGLE, DEVIATION)
"""The numeric columns of the shot, always read."""
AIR_NUMBERS = (*AIR, DENSITY)
"""The numeric columns of the air, read unless the air is left blank."""
REQUIRED = (BALL_SPEED, LAUNCH_ANGLE, LAUNCH_DIRECTION, CARRY)
SPIN_FORMS = ((SPIN_RATE, SPIN_AXIS), (BACKSPIN, SIDESPIN))
"""A file needs one of these pairs of columns (a row may mix them: the pair it lacks gives what the other lacks)."""

STILL_AIR = {"wind_speed_mps": 0.0, "wind_from_deg": 0.0}
"""The wind every row records: the carry is the monitor's computation, which no wind reaches (module docstring)."""

GEOMETRY_TOLERANCE_YD = 1.0
"""Most a row's Carry Deviation Distance may differ from carry sin(deviation angle) before the report notes it (the
export's rounding to 0.1 deg and 0.1 yd stays well below it)."""
DENSITY_TOLERANCE = 0.01
"""Most a recorded Air Density may differ (relatively) from the density of the row's temperature and pressure before
the report notes it."""


def _header(path: Path) -> tuple[list[str], list[tuple[int, list[str]]]]:
    """Header names and (line number, cells) of each data row; a file missing a needed column is refused."""
    with reading(path), path.open(newline="", encoding="utf-8-sig") as handle:
        lines = list(enumerate(csv.reader(handle), start=1))
    if not lines:
        raise RecordError(f"{path}: empty; a Garmin Golf export starts with its header row ({BALL_SPEED}, ...)")
    header = [name.strip() for name in lines[0][1]]
    missing = [name for name in REQUIRED if name not in header]
    if not any(all(name in header for name in form) for form in SPIN_FORMS):
        missing.append(" and ".join(SPIN_FORMS[0]) + ", or " + " and ".join(SPIN_FORMS[1]))
    if missing:
        raise RecordError(f"{path} line 1 (header): a Garmin Golf export needs the columns {missing} "
                          f"(columns: {header})")
    return header, lines[1:]


def _checked(column: str, canonical: str, recorded: float, value: float) -> float:
    """`value` (the column's `recorded` number in SI), or MalformedCell naming the column and the allowed range and
    quoting the number as recorded and in SI."""
    allowed = RANGES[canonical]
    if not allowed.low <= value <= allowed.high:
        reason = f"'{column}' ({canonical}) outside the allowed range {allowed.describe()}"
        raise MalformedCell(reason, column, f"{recorded:g} = {value:.6g} {allowed.unit}")
    return value


def _launch_value(numbers: dict[str, float | None], column: str) -> float:
    """A launch column's value in SI, range-checked; a blank cell is malformed (the launch needs it)."""
    recorded = numbers[column]
    if recorded is None:
        raise MalformedCell(f"'{column}' is blank", column, "")
    canonical, to_si = CONVERTED[column]
    return _checked(column, canonical, recorded, to_si(recorded))


def _spin(numbers: dict[str, float | None]) -> dict[str, float]:
    """spin_rpm and spin_axis_deg: Spin Rate and Spin Axis, each where recorded, else from Backspin and Sidespin
    (Garmin's sidespin + curves left, golfflight's axis + curves right: the sign flips)."""
    total, axis, back, side = (numbers[c] for c in (SPIN_RATE, SPIN_AXIS, BACKSPIN, SIDESPIN))
    derived = back is not None and side is not None
    if total is None and not derived:
        raise MalformedCell(f"'{SPIN_RATE}' is blank and '{BACKSPIN}', '{SIDESPIN}' do not give it", SPIN_RATE, "")
    if axis is None and not derived:
        raise MalformedCell(f"'{SPIN_AXIS}' is blank and '{BACKSPIN}', '{SIDESPIN}' do not give it", SPIN_AXIS, "")
    if total is None:
        total = _checked(BACKSPIN, "spin_rpm", back, math.hypot(back, side))
    else:
        total = _checked(SPIN_RATE, "spin_rpm", total, total)
    if axis is None:
        axis = _checked(SIDESPIN, "spin_axis_deg", side, math.degrees(math.atan2(-side, back)))
    else:
        axis = _checked(SPIN_AXIS, "spin_axis_deg", axis, axis)
    return {"spin_rpm": total, "spin_axis_deg": axis}


def _carry(numbers: dict[str, float | None]) -> dict[str, float]:
    """carry_x_m (the deviation distance, + right) and carry_y_m (carry cos(angle)); none where the deviation is
    blank. The carry is neither blank nor 0 here (`_values` skips those rows); a negative one is malformed."""
    carry, angle, deviation = numbers[CARRY], numbers[DEVIATION_ANGLE], numbers[DEVIATION]
    if carry < 0:
        raise MalformedCell(f"'{CARRY}' is negative (a straight-line distance)", CARRY, f"{carry:g}")
    if angle is None or deviation is None:
        return {}
    along = carry * math.cos(math.radians(angle)) * YARD_M
    return {"carry_x_m": _checked(DEVIATION, "carry_x_m", deviation, deviation * YARD_M),
            "carry_y_m": _checked(CARRY, "carry_y_m", carry, along)}


def _air(numbers: dict[str, float | None]) -> dict[str, float]:
    """The recorded temperature and station pressure in SI, range-checked; blanks left out."""
    return {canonical: _checked(column, canonical, numbers[column], to_si(numbers[column]))
            for column, (canonical, to_si) in AIR.items() if numbers[column] is not None}


def _values(numbers: dict[str, float | None], air: bool) -> dict[str, float]:
    """A row's canonical numbers; BadRow (a skip) without a launch angle or a carry, MalformedCell for a bad cell."""
    if numbers[LAUNCH_ANGLE] is None:
        raise BadRow(f"no launch angle: '{LAUNCH_ANGLE}' is blank")
    if not numbers[CARRY]:
        raise BadRow(f"no flight recorded: '{CARRY}' blank or 0")
    values = {CONVERTED[c][0]: _launch_value(numbers, c) for c in (BALL_SPEED, LAUNCH_ANGLE, LAUNCH_DIRECTION)}
    values |= _spin(numbers) | _carry(numbers)
    if numbers[APEX] is not None:
        values["apex_m"] = _checked(APEX, "apex_m", numbers[APEX], numbers[APEX] * FOOT_M)
    values |= STILL_AIR
    return (values | _air(numbers)) if air else values


def _geometry_gap_yd(numbers: dict[str, float | None]) -> float:
    """How far the recorded deviation distance is from carry sin(angle), yards (0 where either is blank)."""
    carry, angle, deviation = numbers[CARRY], numbers[DEVIATION_ANGLE], numbers[DEVIATION]
    if angle is None or deviation is None:
        return 0.0
    return abs(deviation - carry * math.sin(math.radians(angle)))


def _density_gap(values: dict[str, float], recorded: float | None) -> float:
    """Relative difference of the recorded density from the (dry) density of the row's temperature and pressure;
    0 where any of the three is not recorded."""
    if recorded is None or "temperature_c" not in values or "pressure_hpa" not in values:
        return 0.0
    computed = float(air_density(values["temperature_c"], values["pressure_hpa"] * 100.0))
    return abs(recorded - computed) / computed


def _lines(lines: list[int], examples: int = 5) -> str:
    """The first few line numbers, as the report lists them."""
    return ", ".join(str(n) for n in lines[:examples]) + (", ..." if len(lines) > examples else "")


def _notes(report: ConversionReport, air: bool, density: dict[int, float], geometry: dict[int, float],
           estimated: list[int]) -> None:
    """What the report says besides the drops: the air kept, and the rows whose recorded numbers disagree."""
    if not air:
        report.notes.append("air left blank (--no-air): the shots fly in ICAO standard air")
    if density:
        worst = max(density, key=density.__getitem__)
        report.notes.append(
            f"{len(density)} rows' '{DENSITY}' differs from the density of their temperature and pressure by more than "
            f"{DENSITY_TOLERANCE:.0%} (largest {density[worst]:.1%}, line {worst}; lines {_lines(list(density))}): "
            "the canonical file keeps the temperature and pressure, so they fly in the computed density")
    if geometry:
        worst = max(geometry, key=geometry.__getitem__)
        report.notes.append(
            f"{len(geometry)} rows' '{DEVIATION}' differs from carry x sin('{DEVIATION_ANGLE}') by more than "
            f"{GEOMETRY_TOLERANCE_YD:g} yd (largest {geometry[worst]:.1f} yd, line {worst}; lines "
            f"{_lines(list(geometry))}): their carry_x_m and carry_y_m are not one landing point at the carry")
    if estimated:
        report.notes.append(f"{len(estimated)} rows' spin is Garmin's estimate ('{SPIN_TYPE}' Estimated), not "
                            f"measured (lines {_lines(estimated)})")


def load_garmin(path: str | os.PathLike, *, air: bool = True, session: str | None = None,
                skip_bad_rows: bool = False) -> Conversion:
    """Convert a Garmin Golf app shot export to canonical records (see the module docstring for every column).

    air: keep each row's recorded temperature and station pressure (False: leave the air blank, ICAO standard).
    session: the session id when the file has no "Date" column (default: the file name without extension).
    skip_bad_rows: leave malformed rows out (each listed in the report) instead of refusing the file.
    """
    path = Path(path)
    header, rows = _header(path)
    index = {name: i for i, name in enumerate(header)}

    def cell(cells: list[str], name: str) -> str:
        return cells[index[name]].strip() if name in index and index[name] < len(cells) else ""

    report = ConversionReport(str(path), rows_in=len(rows))
    read = FLIGHT_NUMBERS + AIR_NUMBERS if air else FLIGHT_NUMBERS
    records, density, geometry, estimated = [], {}, {}, []
    for line, cells in rows:
        try:
            numbers = {name: finite_number(cell(cells, name), name) for name in read}
            values = _values(numbers, air)
        except MalformedCell as bad:
            report.bad_row(f"{path} line {line} {bad.cell}: {bad}", str(bad), line, skip_bad_rows)
            continue
        except BadRow as bad:
            report.drop(str(bad), line)
            continue
        if air and (gap := _density_gap(values, numbers[DENSITY])) > DENSITY_TOLERANCE:
            density[line] = gap
        if (gap := _geometry_gap_yd(numbers)) > GEOMETRY_TOLERANCE_YD:
            geometry[line] = gap
        if cell(cells, SPIN_TYPE).lower() == "estimated":
            estimated.append(line)
        timestamp, day = when(cell(cells, "Date")) if cell(cells, "Date") else (None, None)
        club = cell(cells, "Club") or cell(cells, "Club Type") or None
        records.append(ShotRecord(shot_id=str(line), session=day or session or path.stem, timestamp=timestamp,
                                  club=club, **values))
    report.refuse_bad_rows(skip_bad_rows)
    report.kept = len(records)
    _notes(report, air, density, geometry, estimated)
    return Conversion(records, report)

"""`golfflight physics-check`: a model bundle's aerodynamics along real flights, held against the literature.

Torch-free (NumPy and ONNX Runtime only), so it runs in the serving install. Each club of `shots.clubs.CLUBS` is
flown through the runtime path (`evaluation.accuracy_flyers.model_flyer`: the bundle's ONNX graph in
`flight.flyer.Flyer.flight`, forward Euler at the card's step) in ICAO standard air, calm. At every step above the
ground it records the Reynolds number Re = |v_rel| d / nu and spin ratio S = R |omega| / |v_rel| the ball meets, and
the coefficients the graph gives there, converted to the literature's convention (below). Two checks:

1. C_D and C_L against the band the MEASURED literature points (`shared/data/literature/
   aero_coefficients_curated.csv`; fitted laws left out) span near that (Re, S): `measured_band`.
2. The spin the graph's C_M takes away after 1, 3 and 5 s of a driver, 5-iron and 8-iron flight against TrackMan's
   radar measurements (`spin_decay_and_torque.csv`): `spin_lost`.

The convention: the literature's coefficients multiply 1/2 rho |v|^2; a bundle's multiply q = C_Q rho |v_rel|^2
(`flight.physics.accelerations`, the card's `physics.equations`). The force is the same when C_D,lit = 2 C_Q C_D,
C_L,lit = 2 C_Q C_L and C_M,lit = 2 C_Q C_M: `effective_coefficients`. Only these products are physical; a network
may trade its C_Q head against its C_D and C_L heads freely.

The literature data is read by path from the shared data folder (`shots.paths.shared_data_dir`), never copied.
"""

from __future__ import annotations

import csv
import math
import os
import re
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from golfflight.contract.problems import launch_problem
from golfflight.errors import InputError
from golfflight.evaluation.accuracy_flyers import model_flyer
from golfflight.flight.air import Air
from golfflight.flight.constants import BALL_RADIUS_M
from golfflight.flight.flyer import Flyer
from golfflight.flight.physics import spin_ratio
from golfflight.shots.clubs import CLUBS, ClubLaunch, straight_launches
from golfflight.shots.markdown import table
from golfflight.shots.records import CSV_ENCODING

COMMAND = "physics-check"
LITERATURE_DIR = Path("literature")
AERO_FILE = LITERATURE_DIR / "aero_coefficients_curated.csv"
SPIN_FILE = LITERATURE_DIR / "spin_decay_and_torque.csv"
"""The literature tables, relative to the shared data folder."""

COEFFICIENTS = ("C_D", "C_L")
"""The coefficients checked against the measured band, in the literature's 1/2 rho v^2 convention."""


@dataclass(frozen=True)
class Neighbourhood:
    """What "near" a flight point (Re, S) means: the measured points inside the ellipse

        (ln Re_j - ln Re)^2 / ln(re_factor)^2 + (S_j - S)^2 / s_half_width^2 <= 1,

    and the point counts as covered by the measurements only where at least `min_points` of them, from at least
    `min_publications` publications, lie inside. The band is then [min - margin, max + margin] of their values.

    Why these numbers. Re in ratio (ln Re): the drag crisis and the lift reversal below Re ~ 7.5e4 act over ratios of
    Re, and the measured series are spaced in steps of 10-25 % (Acushnet's indoor range 10-25 %, Polara's radar
    regression 12-17 %, Lyu 2020 20-25 %), so +-25 % reaches a neighbour on each side in every series. S +-0.04:
    C_L rises about 1 per unit S at these S (Polara's tunnel and radar series), so the window adds at most ~0.04 of
    trend to the band, no more than the ball-to-ball spread the sources show at one (Re, S) (Acushnet's two balls
    and two orientations 0.01-0.04, Lyu's three balls 0.03-0.07); a wider window would widen the band with trend, a
    narrower one would leave the measured series' own gaps (S steps of 0.02-0.07) uncovered. Two publications at
    least, because one source's points share its ball, rig and convention: its spread is not the literature's. The
    band is not a fit through the points: within these windows the sources disagree by as much as any smooth trend,
    and their envelope is the claim the literature supports.

    The margins are one measurement standard deviation (Lyu et al. 2020 report 0.02 for C_D and 0.01 for C_L; the
    other sources give none; digitising adds 0.002-0.005), so a model on a band's edge is not called outside
    because the edge point itself was measured low or high."""

    re_factor: float = 1.25
    s_half_width: float = 0.04
    min_points: int = 3
    min_publications: int = 2
    margin: tuple[tuple[str, float], ...] = (("C_D", 0.02), ("C_L", 0.01))

    def margin_of(self, coefficient: str) -> float:
        return dict(self.margin)[coefficient]


NEAR = Neighbourhood()

INSIDE_REQUIRED = 0.9
"""A club passes a coefficient's band check when at least this share of its covered flight points are inside the
band: measured bands have holes (one odd point narrows or shifts a window), so one step out of ten may leave it."""

SPIN_TOLERANCE_PCT = 3.0
"""Spin-loss check at 5 s: the model within +-3 percentage points of TrackMan's measured loss. TrackMan's three clubs
lose 12.8, 15.5 and 13.3 % at 5 s, a spread of 2.7 points with no order in club speed or spin, which is the
shot-to-shot and reading scatter one curve per club carries (the 5-iron's curve ends near 4 s, so its 5 s value is
already an extrapolation; the mean decay rates derived from the curves are quoted +-15 %, i.e. +-1.9 to 2.3 points
at 5 s). The loss of a C_M = p_M S model depends on the flight's speed only, so a model cannot match the clubs more
closely than their own scatter: 3 points, the spread rounded up."""

SPIN_CHECK_TIME_S = 5.0


# --- the literature ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class LiteraturePoint:
    """One row of the curated coefficient table: Re, S and C_D, C_L in the 1/2 rho v^2 convention (NaN where the
    source gives none), and whether the row is a fitted law evaluated at chosen S rather than a measurement."""

    source: str
    reynolds: float
    spin_ratio: float
    c_d: float
    c_l: float
    fit: bool

    @property
    def publication(self) -> str:
        """The publication a row comes from (its source's first two words: author-year or patent, and venue or
        number), to count independent sources."""
        return " ".join(self.source.split()[:2])

    def value(self, coefficient: str) -> float:
        return {"C_D": self.c_d, "C_L": self.c_l}[coefficient]


def _number(text: str) -> float:
    return float(text) if text.strip() else math.nan


def is_fit(source: str, method: str) -> bool:
    """A row is a fitted law (Naruo 2004's tunnel fits, Ferguson 2022's S-only laws) when its source or method says
    "fit": the table's own flag. Those rows sit at an Re the fit did not resolve (Naruo: "Re-independent"; Ferguson:
    none), so they are left out of the measured band."""
    return "fit" in source.lower() or "fit" in method.lower()


def _rows(path: str | os.PathLike, columns: tuple[str, ...]) -> list[dict[str, str]]:
    """The rows of a CSV table that must have these columns (InputError naming the file and the missing ones)."""
    with Path(path).open(newline="", encoding=CSV_ENCODING) as handle:
        reader = csv.DictReader(handle)
        missing = [c for c in columns if c not in (reader.fieldnames or [])]
        if missing:
            raise InputError(f"{path}: columns {missing} missing")
        return list(reader)


def read_aero_literature(path: str | os.PathLike) -> list[LiteraturePoint]:
    """The curated C_D/C_L table (columns source, Re, S, CD, CL, method), one point per row."""
    rows = _rows(path, ("source", "Re", "S", "CD", "CL", "method"))
    return [
        LiteraturePoint(row["source"], _number(row["Re"]), _number(row["S"]), _number(row["CD"]), _number(row["CL"]),
                        is_fit(row["source"], row["method"]))
        for row in rows
    ]


@dataclass(frozen=True)
class MeasuredSet:
    """The measured points of one coefficient that have Re, S and a value: arrays [M] and each one's publication."""

    coefficient: str
    reynolds: np.ndarray
    spin_ratio: np.ndarray
    value: np.ndarray
    publication: np.ndarray


def measured_set(points: list[LiteraturePoint], coefficient: str) -> MeasuredSet:
    """The points of `coefficient` that are measurements (not fits) placed in (Re, S): a row without Re or S (such as
    TrackMan's output along a flight, which gives Re only) cannot be compared at a flight's (Re, S)."""
    kept = [p for p in points
            if not p.fit and all(math.isfinite(x) for x in (p.reynolds, p.spin_ratio, p.value(coefficient)))]
    return MeasuredSet(
        coefficient,
        np.array([p.reynolds for p in kept]),
        np.array([p.spin_ratio for p in kept]),
        np.array([p.value(coefficient) for p in kept]),
        np.array([p.publication for p in kept], dtype=object),
    )


@dataclass(frozen=True)
class Band:
    """The measured band at each of N flight points: low and high (NaN where not covered), whether the point is
    covered, and for an uncovered point why (`OUTSIDE_REASONS`)."""

    low: np.ndarray
    high: np.ndarray
    covered: np.ndarray
    reason: np.ndarray


OUTSIDE_REASONS = {
    "low Re": "Re below every measurement",
    "high Re": "Re above every measurement",
    "high S": "S above the measurements at that Re",
    "low S": "S below the measurements at that Re",
    "sparse": "between measurements: too few points or one publication near it",
}


def _outside_reason(ln_re: float, s: float, measured: MeasuredSet, near: Neighbourhood) -> str:
    """Why a flight point has no band: no measurement within the Re window at all (low or high Re), the point's S
    beyond every measurement in that window by more than the S half-width (high or low S), or else too sparse."""
    measured_ln_re = np.log(measured.reynolds)
    in_re = np.abs(measured_ln_re - ln_re) <= math.log(near.re_factor)
    if not in_re.any():
        return "low Re" if ln_re < measured_ln_re.min() else "high Re"
    if s > measured.spin_ratio[in_re].max() + near.s_half_width:
        return "high S"
    if s < measured.spin_ratio[in_re].min() - near.s_half_width:
        return "low S"
    return "sparse"


def measured_band(reynolds: np.ndarray, s: np.ndarray, measured: MeasuredSet, near: Neighbourhood = NEAR) -> Band:
    """The band `measured` spans near each flight point (Re [N], S [N]), as `Neighbourhood` defines it."""
    ln_re = np.log(np.asarray(reynolds, dtype=float))[:, None]
    s = np.asarray(s, dtype=float)
    distance_sq = ((np.log(measured.reynolds)[None] - ln_re) / math.log(near.re_factor)) ** 2 + (
        (measured.spin_ratio[None] - s[:, None]) / near.s_half_width
    ) ** 2
    inside = distance_sq <= 1.0
    publications = np.array([len(set(measured.publication[row])) for row in inside])
    covered = (inside.sum(axis=1) >= near.min_points) & (publications >= near.min_publications)
    margin = near.margin_of(measured.coefficient)
    near_values = np.where(inside[covered], measured.value[None], np.nan)
    low, high = np.full(len(s), np.nan), np.full(len(s), np.nan)
    low[covered] = np.nanmin(near_values, axis=1, initial=np.inf) - margin
    high[covered] = np.nanmax(near_values, axis=1, initial=-np.inf) + margin
    reason = np.array(["" if ok else _outside_reason(float(lr), float(si), measured, near)
                       for ok, lr, si in zip(covered, ln_re[:, 0], s)], dtype=object)
    return Band(low, high, covered, reason)


def excess(value: np.ndarray, band: Band) -> np.ndarray:
    """How far each value lies outside its band: positive above the top, negative below the bottom, 0 inside, NaN
    where the band is not covered."""
    above, below = value - band.high, value - band.low
    return np.where(above > 0, above, np.where(below < 0, below, np.where(band.covered, 0.0, np.nan)))


@dataclass(frozen=True)
class SpinDecayMeasurement:
    """TrackMan's measured spin loss of one club's shot: its launch spin, and the share lost at each time."""

    club: str
    launch_spin_rpm: float
    times_s: tuple[float, ...]
    lost_pct: tuple[float, ...]


_SPIN_CLUB = re.compile(r"^(?P<club>\S+) \(launch ~(?P<rpm>\d+) rpm\)")
_SPIN_TIMES = re.compile(r"spin lost at (?P<times>[\d/]+) s")


def read_spin_decay(path: str | os.PathLike) -> list[SpinDecayMeasurement]:
    """The rows of the spin table that give the share of spin lost at times (e.g. club_or_S "driver (launch ~3400
    rpm)", quantity "spin lost at 1/3/5 s (% of launch)", value "3.1/8.8/12.8"); the table's other rows (torque fits,
    mean rates) are not measurements at given times."""
    found = []
    for row in _rows(path, ("club_or_S", "quantity", "value")):
        club, times = _SPIN_CLUB.match(row["club_or_S"]), _SPIN_TIMES.search(row["quantity"])
        if club and times:
            found.append(SpinDecayMeasurement(
                club["club"], float(club["rpm"]), tuple(float(t) for t in times["times"].split("/")),
                tuple(float(v) for v in row["value"].split("/")),
            ))
    return found


# --- the model along its flights ----------------------------------------------------------------------------------


def reynolds_number(v_rel: np.ndarray, kinematic_viscosity_m2_s: float) -> np.ndarray:
    """Re = |v_rel| d / nu [N] of balls with air-relative velocity [N,3] (d = 2R): the literature's Re."""
    return np.linalg.norm(v_rel, axis=-1) * 2.0 * BALL_RADIUS_M / kinematic_viscosity_m2_s


def effective_coefficients(coefficients: np.ndarray) -> dict[str, np.ndarray]:
    """C_L, C_D, C_M [N] in the literature's 1/2 rho v^2 convention from a model's (C_L, C_D, C_M, C_Q) [N,4]: the
    model's force C q A with q = C_Q rho v^2 is (2 C_Q C) (1/2 rho v^2) A."""
    c_l, c_d, c_m, c_q = coefficients.T
    return {"C_L": 2.0 * c_q * c_l, "C_D": 2.0 * c_q * c_d, "C_M": 2.0 * c_q * c_m}


@dataclass(frozen=True)
class FlightPoints:
    """The states one flight passes through at each Euler step from launch to its last step above the ground: time,
    Re, S and the model's effective coefficients there (`effective_coefficients`), arrays [K]."""

    club: str
    time_s: np.ndarray
    reynolds: np.ndarray
    spin_ratio: np.ndarray
    coefficients: dict[str, np.ndarray]


def flight_points(flyer: Flyer, clubs: list[ClubLaunch], air: Air) -> list[FlightPoints]:
    """Fly the clubs through `flyer` in `air` (calm) and read back what each flight meets at each step above the
    ground. The coefficients are the model's at those states, the very values the integrator stepped with."""
    flight = flyer.flight(launch_problem(straight_launches(clubs), air, keep_states=True))
    model = flyer.in_air(air.kinematic_viscosity_m2_s)
    result = []
    for i, club in enumerate(clubs):
        last = int(flight.last_step[i]) if flight.landed[i] else len(flight.states) - 1
        v_rel = np.stack([state.velocity[i] for state in flight.states[: last + 1]])
        omega = np.stack([state.spin[i] for state in flight.states[: last + 1]])
        result.append(FlightPoints(
            club.name, flight.times_s[: last + 1], reynolds_number(v_rel, float(air.kinematic_viscosity_m2_s)),
            spin_ratio(v_rel, omega), effective_coefficients(model(v_rel, omega)),
        ))
    return result


def spin_lost(flyer: Flyer, clubs: list[ClubLaunch], air: Air, times_s: tuple[float, ...]) -> np.ndarray:
    """Share (0-1) of its launch spin each club's ball has lost at each time [clubs, times], flown through `flyer`
    in `air` (the spin magnitude interpolated linearly between steps). A ball is followed past its landing (the
    measurement is of the decay law, not of a flight's length), so the flight is run for the longest time asked."""
    longest = max(flyer.max_flight_time_s, max(times_s))
    problem = launch_problem(straight_launches(clubs), air, keep_states=True, max_time_s=longest, ground_height_m=-1e9)
    flight = flyer.flight(problem)
    spin = np.stack([np.linalg.norm(state.spin, axis=-1) for state in flight.states])
    return np.stack([1.0 - np.interp(times_s, flight.times_s, spin[:, i]) / spin[0, i] for i in range(len(clubs))])


# --- the checks and their report ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class CoefficientCheck:
    """One coefficient of one flight against its measured band: the band at every flight point and the excess."""

    band: Band
    excess: np.ndarray

    @property
    def covered_share(self) -> float:
        return float(self.band.covered.mean())

    @property
    def inside_share(self) -> float:
        """Share of the covered points inside the band (NaN where none is covered)."""
        covered = self.band.covered
        return float(np.mean(self.excess[covered] == 0.0)) if covered.any() else math.nan

    @property
    def largest_excess_index(self) -> int | None:
        """The covered point furthest outside its band (None where none is covered or all are inside)."""
        magnitude = np.where(self.band.covered, np.abs(np.nan_to_num(self.excess)), 0.0)
        return int(np.argmax(magnitude)) if magnitude.max(initial=0.0) > 0.0 else None

    @property
    def passed(self) -> bool | None:
        """At least INSIDE_REQUIRED of the covered points inside; None where none is covered."""
        share = self.inside_share
        return None if math.isnan(share) else share >= INSIDE_REQUIRED


@dataclass(frozen=True)
class ClubCheck:
    """A club's flight and each coefficient's check along it."""

    points: FlightPoints
    checks: dict[str, CoefficientCheck]


def check_flight(points: FlightPoints, measured: dict[str, MeasuredSet], near: Neighbourhood = NEAR) -> ClubCheck:
    """Each coefficient of a flight against the band of its measured literature points."""
    checks = {}
    for name in COEFFICIENTS:
        band = measured_band(points.reynolds, points.spin_ratio, measured[name], near)
        checks[name] = CoefficientCheck(band, excess(points.coefficients[name], band))
    return ClubCheck(points, checks)


@dataclass(frozen=True)
class SpinCheck:
    """TrackMan's measured spin loss of a club and the model's on the same club's launch with TrackMan's spin."""

    measurement: SpinDecayMeasurement
    launch: ClubLaunch
    model_lost_pct: np.ndarray

    @property
    def difference_at_check_pct(self) -> float:
        """Model minus TrackMan at SPIN_CHECK_TIME_S, percentage points."""
        k = self.measurement.times_s.index(SPIN_CHECK_TIME_S)
        return float(self.model_lost_pct[k] - self.measurement.lost_pct[k])

    @property
    def passed(self) -> bool:
        return abs(self.difference_at_check_pct) <= SPIN_TOLERANCE_PCT


def club_launch(name: str, spin_rpm: float | None = None) -> ClubLaunch:
    """The launch of CLUBS's club of this name (case-insensitive), with its spin replaced where one is given."""
    match = next((c for c in CLUBS if c.name.lower() == name.lower()), None)
    if match is None:
        raise InputError(f"no club {name!r} in shots.clubs.CLUBS")
    return match if spin_rpm is None else match._replace(spin_rpm=spin_rpm)


def check_spin(flyer: Flyer, measurements: list[SpinDecayMeasurement], air: Air) -> list[SpinCheck]:
    """Each TrackMan club flown with its tour-average speed and launch angle and TrackMan's launch spin: for a
    C_M = p_M S model the share lost depends on the speed history alone, and the launch spin changes that history
    only through the flight's lift."""
    checks = []
    for measurement in measurements:
        club = club_launch(measurement.club, measurement.launch_spin_rpm)
        checks.append(SpinCheck(measurement, club, 100.0 * spin_lost(flyer, [club], air, measurement.times_s)[0]))
    return checks


@dataclass(frozen=True)
class PhysicsReport:
    """Everything `golfflight physics-check` found about one bundle."""

    flyer: Flyer
    air: Air
    literature: list[LiteraturePoint]
    measured: dict[str, MeasuredSet]
    clubs: list[ClubCheck]
    spin: list[SpinCheck]


def run_physics_checks(model_dir: str | os.PathLike | None, data_dir: str | os.PathLike) -> PhysicsReport:
    """Both checks of a bundle against the literature in `data_dir` (the shared data folder)."""
    aero, spin = Path(data_dir) / AERO_FILE, Path(data_dir) / SPIN_FILE
    for path in (aero, spin):
        if not path.is_file():
            raise FileNotFoundError(f"{path} not found (set GOLFFLIGHT_SHARED_DATA or put the shared data beside the "
                                    "repository)")
    flyer, air = model_flyer(model_dir), Air.standard()
    literature = read_aero_literature(aero)
    measured = {name: measured_set(literature, name) for name in COEFFICIENTS}
    if not all(len(m.value) for m in measured.values()):
        raise InputError(f"{aero}: no measured point with Re and S for {', '.join(COEFFICIENTS)}")
    decay = read_spin_decay(spin)
    if not decay or any(SPIN_CHECK_TIME_S not in m.times_s for m in decay):
        raise InputError(f"{spin}: no spin-loss rows, or one without a value at {SPIN_CHECK_TIME_S:g} s")
    clubs = [check_flight(points, measured) for points in flight_points(flyer, list(CLUBS), air)]
    return PhysicsReport(flyer, air, literature, measured, clubs, check_spin(flyer, decay, air))


def _re(value: float) -> str:
    """A Reynolds number in short scientific form: 77000 -> 7.7e4."""
    exponent = math.floor(math.log10(value))
    return f"{value / 10**exponent:.1f}e{exponent}"


def _share(value: float) -> str:
    return "–" if math.isnan(value) else f"{100.0 * value:.0f} %"


def _excess_cell(check: CoefficientCheck, points: FlightPoints) -> str:
    k = check.largest_excess_index
    if k is None:
        return "0" if check.band.covered.any() else "–"
    return f"{check.excess[k]:+.3f} (Re {_re(points.reynolds[k])}, S {points.spin_ratio[k]:.2f})"


def _reasons_cell(check: CoefficientCheck) -> str:
    """The share of the flight's points left uncovered for each reason, most frequent first."""
    counts = Counter(check.band.reason[~check.band.covered])
    n = len(check.band.reason)
    return ", ".join(f"{reason} {100 * c / n:.0f} %" for reason, c in counts.most_common()) or "–"


def _model_lines(report: PhysicsReport) -> list[str]:
    card, air = report.flyer.card, report.air
    return [
        (f"Model: {report.flyer.label}, {card.variant}, ONNX {card.onnx.sha256[:12]}, p_M {card.architecture.p_m:.5g}. "
        f"Each club of `shots.clubs.CLUBS` flown straight and calm through `flight.flyer.Flyer.flight` (forward "
        f"Euler, dt {card.physics.dt_s:g} s) in ICAO standard air (rho {float(air.density_kg_m3):.4f} kg/m^3, nu "
        f"{float(air.kinematic_viscosity_m2_s):.4g} m^2/s); every step from launch to the last one above the ground "
        "is a flight point, at Re = |v_rel| d / nu and S = R |omega| / |v_rel|. Coefficients in the literature's "
        "1/2 rho v^2 convention: 2 C_Q C_D, 2 C_Q C_L, 2 C_Q C_M (the bundle's q is C_Q rho v^2)."),
    ]


def _literature_lines(report: PhysicsReport) -> list[str]:
    fits = sorted({p.publication for p in report.literature if p.fit})
    unplaced = sorted({p.publication for p in report.literature
                       if not p.fit and not (math.isfinite(p.reynolds) and math.isfinite(p.spin_ratio))})
    counts = "; ".join(
        f"{name} {len(m.value)} points from {len(set(m.publication))} publications (Re {_re(m.reynolds.min())}-"
        f"{_re(m.reynolds.max())}, S {m.spin_ratio.min():.2f}-{m.spin_ratio.max():.2f})"
        for name, m in report.measured.items()
    )
    near = NEAR
    return [
        (f"Literature: `{AERO_FILE}` of the shared data, {len(report.literature)} rows. Measured points placed in "
        f"(Re, S): {counts}. Left out: fitted laws ({', '.join(fits)}) and rows without S ({', '.join(unplaced)})."),
        "",
        f"Band at a flight point: the measured points within +-{100 * (near.re_factor - 1):.0f} % in Re and "
        f"+-{near.s_half_width:g} in S (an ellipse in ln Re and S); covered where at least {near.min_points} points "
        f"from at least {near.min_publications} publications lie inside; the band is their min to max widened by "
        + " and ".join(f"{m:g} ({name})" for name, m in near.margin)
        + ", one measurement standard deviation (`evaluation.physics_checks.Neighbourhood` says why).",
    ]


def _club_table(report: PhysicsReport) -> list[str]:
    header = ["club", "Re", "S", "points"]
    for name in COEFFICIENTS:
        header += [name, "covered", "inside", "largest excess"]
    rows = []
    for club in report.clubs:
        p = club.points
        cells = [p.club, f"{_re(p.reynolds.min())}-{_re(p.reynolds.max())}",
                 f"{p.spin_ratio.min():.2f}-{p.spin_ratio.max():.2f}", len(p.time_s)]
        for name in COEFFICIENTS:
            check = club.checks[name]
            values = p.coefficients[name]
            cells += [f"{values.min():.3f}-{values.max():.3f}", _share(check.covered_share),
                      _share(check.inside_share), _excess_cell(check, p)]
        rows.append(cells)
    return table(header, rows)


def _coverage_lines(report: PhysicsReport) -> list[str]:
    """Where and why the flights leave the measured region: the reasons per club, then the general cause."""
    rows = [(c.points.club, *(_reasons_cell(c.checks[name]) for name in COEFFICIENTS)) for c in report.clubs]
    never = [c for c in report.clubs if not any(check.band.covered.any() for check in c.checks.values())]
    lines = [
        "Where the flights leave the measured region (share of each flight's points, by reason: "
        + "; ".join(f"{key}: {text}" for key, text in OUTSIDE_REASONS.items()) + "):",
        "",
        *table(("club", *(f"{name} not covered" for name in COEFFICIENTS)), rows, align="lll"),
    ]
    if never:
        launch_s = [c.points.spin_ratio[0] for c in never]
        top_s = [c.points.spin_ratio.max() for c in never]
        slowest = [int(np.argmin(c.points.reynolds)) for c in never]
        speed = [c.points.reynolds[k] / c.points.reynolds[0] for c, k in zip(never, slowest)]
        spin = [c.points.spin_ratio[k] * c.points.reynolds[k] / (c.points.spin_ratio[0] * c.points.reynolds[0])
                for c, k in zip(never, slowest)]
        c_d, c_l = report.measured["C_D"], report.measured["C_L"]
        high_lift = sorted(set(c_l.publication[c_l.spin_ratio > c_d.spin_ratio.max()]))
        lowest = min(never, key=lambda c: c.points.reynolds.min())
        lowest_measured = int(np.argmin(c_l.reynolds))
        lines += [
            "",
            (f"Never covered: {', '.join(c.points.club for c in never)}. They launch at S {min(launch_s):.2f}-"
            f"{max(launch_s):.2f} and reach S {min(top_s):.2f}-{max(top_s):.2f}: at its slowest the ball flies at "
            f"{100 * min(speed):.0f}-{100 * max(speed):.0f} % of its launch speed with {100 * min(spin):.0f}-"
            f"{100 * max(spin):.0f} % of its spin (S = R |omega| / |v| rises as it slows), while the measurements stop "
            f"at S {c_d.spin_ratio.max():.2f} for C_D and {c_l.spin_ratio.max():.2f} for C_L (above S "
            f"{c_d.spin_ratio.max():.2f} only {', '.join(high_lift)}). Their lowest Re, "
            f"{_re(lowest.points.reynolds.min())} ({lowest.points.club} near its apex), is "
            f"{'below' if lowest.points.reynolds.min() < c_l.reynolds[lowest_measured] else 'above'} the lowest "
            f"measured, {_re(c_l.reynolds[lowest_measured])} ({c_l.publication[lowest_measured]})."),
        ]
    return lines


def _verdict(name: str, clubs: list[ClubCheck]) -> str:
    covered = [c for c in clubs if c.checks[name].passed is not None]
    failed = [c.points.club for c in covered if not c.checks[name].passed]
    line = (f"**{name}: {'inside' if not failed else 'outside'} the measured band** on {len(covered) - len(failed)} "
            f"of the {len(covered)} flights it covers (pass: at least {100 * INSIDE_REQUIRED:.0f} % of the covered "
            "points inside)")
    return line + (f"; outside on {', '.join(failed)}." if failed else ".")


def _spin_lines(report: PhysicsReport) -> list[str]:
    rows = []
    for check in report.spin:
        m, launch = check.measurement, check.launch
        rows.append((
            launch.name, f"{launch.ball_speed_mps:g} m/s, {launch.launch_angle_deg:g} deg, {m.launch_spin_rpm:g} rpm",
            " / ".join(f"{v:.1f}" for v in m.lost_pct), " / ".join(f"{v:.1f}" for v in check.model_lost_pct),
            f"{check.difference_at_check_pct:+.1f}", "yes" if check.passed else "**no**",
        ))
    times = "/".join(f"{t:g}" for t in report.spin[0].measurement.times_s)
    failed = [c.launch.name for c in report.spin if not c.passed]
    slopes = [float(np.median(c.points.coefficients["C_M"] / c.points.spin_ratio)) for c in report.clubs]
    return [
        ("Spin lost to the model's C_M (the graph's C_M column, p_M S per the card) against TrackMan's radar "
        "(Acushnet US 8,016,695 Table 6B, Pro V1x): each club at its tour-average speed and launch angle "
        "(`shots.clubs.CLUBS`) with TrackMan's launch spin, followed past landing when it lands earlier."),
        "",
        *table(("club", "launch", f"TrackMan lost at {times} s (%)", f"model lost at {times} s (%)",
                f"model - TrackMan at {SPIN_CHECK_TIME_S:g} s (points)", f"within +-{SPIN_TOLERANCE_PCT:g}"), rows),
        "",
        f"- **Spin decay: {'within' if not failed else 'outside'} TrackMan's +-{SPIN_TOLERANCE_PCT:g} points at "
        f"{SPIN_CHECK_TIME_S:g} s** on {len(report.spin) - len(failed)} of {len(report.spin)} clubs"
        + (f"; outside on {', '.join(failed)}." if failed else ".")
        + " The tolerance is TrackMan's own club-to-club spread at 5 s (12.8-15.5 %) rounded up "
        "(`SPIN_TOLERANCE_PCT` says why).",
        "",
        (f"Effective C_M / S = 2 C_Q p_M along the flights (median per club): {min(slopes):.4f}-{max(slopes):.4f}; the "
        "literature's torque fits: 0.010-0.012 (Smits; Tavares 1999; Ferguson 2022 at its lower bound 0.010)."),
    ]


def markdown(report: PhysicsReport) -> str:
    """The report, the generated section of docs/physics_checks.md."""
    lines = [
        "## Lift and drag along each club's flight",
        "",
        *_model_lines(report),
        "",
        *_literature_lines(report),
        "",
        *_club_table(report),
        "",
        ("Per coefficient: its range along the flight; covered: the share of the flight's points with a measured band; "
        "inside: the share of the covered points inside it; largest excess: the covered point furthest outside its "
        "band (+ above, - below) and where."),
        "",
        *(f"- {_verdict(name, report.clubs)}" for name in COEFFICIENTS),
        "",
        *_coverage_lines(report),
        "",
        "## Spin decay",
        "",
        *_spin_lines(report),
    ]
    return "\n".join(lines) + "\n"

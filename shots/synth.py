"""Synthetic launch-monitor sessions flown through the reference world.

A session is one player (or robot) on one day: a few clubs, launches scattered around each club's mean,
and its own air and wind that are NOT written to the shot records (as in the paper's TrackMan data).
Recorded launches and outcomes carry launch-monitor measurement noise (`MeasurementNoise`). The hidden
truth of each session goes to a separate `NAME.sessions.csv` for analysis, never into the records.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass, field, fields
from datetime import datetime, timedelta
from pathlib import Path

import numpy as np
from golfflight.flight.air import Air
from golfflight.flight.constants import YARD_M
from golfflight.flight.outcomes import Flight
from golfflight.flight.physics import initial_state
from golfflight.flight.reference_aero import CALIBRATED, ReferenceParameters
from golfflight.flight.wind import Wind
from golfflight.shots.clubs import CLUBS, club_weights
from golfflight.shots.progress import progress_bar, progress_step
from golfflight.shots.records import LAUNCH_COLUMNS, RANGES, ShotRecord, write_csv_atomic, write_shots
from golfflight.shots.reference_world import fly_reference

MIN_APEX_M = 8 * YARD_M
"""The paper drops shots that peak under 8 yd (tops and duffs)."""

ALTITUDE_BANDS_M = ((0.0, 100.0), (100.0, 500.0), (500.0, 1500.0))
ALTITUDE_BAND_SHARES = (0.85, 0.12, 0.03)
"""Hidden session weather: altitude bands and their shares, with temperature N(10, 7) degC and humidity 30-95 %.
Chosen so the shot-weighted mean density is ICAO standard (1.225 kg/m^3, within 1 %): training flies shots without
recorded air at standard density, so hidden air centred elsewhere would bias every learned coefficient (a mean of
1.139 kg/m^3 once made the model fly 7 % thin air as if it were standard)."""

BATCH = 8192
START = datetime(2025, 3, 1, 8, 0, 0)


@dataclass(frozen=True)
class MeasurementNoise:
    """1-sigma launch-monitor noise. Our assumption for a radar unit outdoors: a few tenths of a m/s and of a
    degree on launch, ~2 % on spin, about half a metre on carry and side, a few decimetres on apex."""

    ball_speed_mps: float = 0.25
    launch_angle_deg: float = 0.2
    launch_direction_deg: float = 0.3
    spin_rpm_fraction: float = 0.02
    spin_rpm_floor: float = 30.0
    spin_axis_deg: float = 1.5
    carry_m: float = 0.4
    carry_fraction: float = 0.004
    apex_m: float = 0.3
    flight_time_s: float = 0.05
    landing_angle_deg: float = 0.4


@dataclass(frozen=True)
class SyntheticSession:
    """One session's hidden truth: who hit, with which clubs, in which air and wind."""

    session: str
    kind: str
    n_shots: int
    clubs: tuple[str, ...]
    speed_factor: float
    launch_offset_deg: float
    spin_factor: float
    spin_axis_bias_deg: float
    direction_bias_deg: float
    temperature_c: float
    altitude_m: float
    humidity_pct: float
    wind_speed_mps: float
    wind_from_deg: float


@dataclass(frozen=True)
class SynthConfig:
    """What `generate` draws; the defaults make realistic outdoor robot and player testing."""

    n_shots: int = 1000
    seed: int = 0
    robot_share: float = 0.3
    val_fraction: float = 0.1
    noise: MeasurementNoise = field(default_factory=MeasurementNoise)
    wind_profile: str = "log"
    calm: bool = False
    world: ReferenceParameters = CALIBRATED


@dataclass
class LaunchTable:
    """True launch values of every shot, the session index and club of each."""

    ball_speed_mps: np.ndarray
    launch_angle_deg: np.ndarray
    launch_direction_deg: np.ndarray
    spin_rpm: np.ndarray
    spin_axis_deg: np.ndarray
    session_index: np.ndarray
    club: np.ndarray

    def launch(self) -> dict[str, np.ndarray]:
        return {k: getattr(self, k) for k in ("ball_speed_mps", "launch_angle_deg", "launch_direction_deg", "spin_rpm", "spin_axis_deg")}


@dataclass
class SyntheticSet:
    """Generated records plus the hidden truth and what was dropped (and why)."""

    records: list[ShotRecord]
    sessions: list[SyntheticSession]
    dropped: dict[str, int]
    seconds: float


def draw_sessions(rng: np.random.Generator, n_shots: int, config: SynthConfig) -> list[SyntheticSession]:
    """Sessions in time order until they hold `n_shots` shots, each with its own (hidden) air and wind."""
    sessions, total = [], 0
    weights = club_weights()
    names = [c.name for c in CLUBS]
    while total < n_shots:
        robot = rng.random() < config.robot_share
        n = int(rng.integers(60, 200) if robot else rng.integers(30, 130))
        n = min(n, n_shots - total)
        n_clubs = int(rng.integers(1, 3) if robot else rng.integers(3, 9))
        clubs = tuple(rng.choice(names, size=min(n_clubs, len(names)), replace=False, p=weights))
        altitude_band = rng.choice(3, p=list(ALTITUDE_BAND_SHARES))
        wind = 0.0 if config.calm else float(min(rng.weibull(2.0) * 3.5, 12.0))
        sessions.append(SyntheticSession(
            session=f"S{len(sessions):05d}",
            kind="robot" if robot else "player",
            n_shots=n,
            clubs=clubs,
            speed_factor=float(rng.uniform(0.85, 1.02) if robot else rng.uniform(0.72, 1.03)),
            launch_offset_deg=float(rng.normal(0, 0.8 if robot else 1.5)),
            spin_factor=float(np.exp(rng.normal(0, 0.05 if robot else 0.08))),
            spin_axis_bias_deg=float(rng.normal(0, 2.0 if robot else 4.0)),
            direction_bias_deg=float(rng.normal(0, 0.5 if robot else 2.0)),
            temperature_c=float(np.clip(rng.normal(10, 7), -5, 35)),
            altitude_m=float(rng.uniform(*ALTITUDE_BANDS_M[altitude_band])),
            humidity_pct=float(rng.uniform(30, 95)),
            wind_speed_mps=wind,
            wind_from_deg=float(rng.uniform(0, 360)),
        ))
        total += n
    return sessions


def draw_launches(rng: np.random.Generator, sessions: list[SyntheticSession]) -> LaunchTable:
    """True launches: the club mean scaled by the session's player, plus shot-to-shot scatter."""
    by_name = {c.name: c for c in CLUBS}
    rows = []
    for index, s in enumerate(sessions):
        robot = s.kind == "robot"
        club_names = rng.choice(s.clubs, size=s.n_shots)
        for name in club_names:
            c = by_name[name]
            rows.append((
                c.ball_speed_mps * s.speed_factor * rng.normal(1, 0.006 if robot else 0.025),
                c.launch_angle_deg + s.launch_offset_deg + rng.normal(0, 0.35 if robot else 1.3),
                s.direction_bias_deg + rng.normal(0, 0.6 if robot else 2.5),
                c.spin_rpm * s.spin_factor * np.exp(rng.normal(0, 0.03 if robot else 0.07)),
                s.spin_axis_bias_deg + rng.normal(0, 1.5 if robot else 5.0),
                index,
                name,
            ))
    columns = list(zip(*rows))
    table = LaunchTable(*(np.array(col, dtype=float) for col in columns[:5]), np.array(columns[5], dtype=int),
                        np.array(columns[6], dtype=object))
    for name in LAUNCH_COLUMNS:
        np.clip(getattr(table, name), RANGES[name].low, RANGES[name].high, out=getattr(table, name))
    return table


def fly_sessions(
    table: LaunchTable, sessions: list[SyntheticSession], config: SynthConfig, rng: np.random.Generator, progress: bool = False
) -> Flight:
    """Fly the true launches in each session's air and (gusting, log-profile) wind through the reference world, BATCH
    shots at a time (with a bar over the shots when `progress`: the reference world's RK4 takes most of a run)."""
    per_shot = {f.name: np.array([getattr(sessions[i], f.name) for i in table.session_index]) for f in fields(SyntheticSession)
                if f.name in ("temperature_c", "altitude_m", "humidity_pct", "wind_speed_mps", "wind_from_deg")}
    gust = np.exp(rng.normal(0, 0.15, size=len(table.session_index)))
    launch = table.launch()
    parts, n = [], len(table.session_index)
    with progress_bar(desc="flying", total=n, unit="shot", shown=progress) as flown:
        for start in range(0, n, BATCH):
            chunk = slice(start, start + BATCH)
            air = Air.from_conditions(per_shot["temperature_c"][chunk], per_shot["altitude_m"][chunk], per_shot["humidity_pct"][chunk])
            wind = Wind(per_shot["wind_speed_mps"][chunk] * gust[chunk], per_shot["wind_from_deg"][chunk], profile=config.wind_profile)
            state = initial_state(**{k: v[chunk] for k, v in launch.items()})
            parts.append(fly_reference(state, air, wind, params=config.world))
            flown.update(len(state.position))
    return Flight(*(np.concatenate([getattr(p, name) for p in parts]) for name in
                    ("landed", "landing_position", "landing_velocity", "landing_spin", "flight_time_s", "apex_m", "apex_time_s")))


def _noisy(rng: np.random.Generator, value: np.ndarray, sigma: np.ndarray | float) -> np.ndarray:
    return value + rng.normal(size=value.shape) * sigma


def measure(rng: np.random.Generator, table: LaunchTable, flight: Flight, noise: MeasurementNoise) -> dict[str, np.ndarray]:
    """What a launch monitor would record: the true launch and outcome plus measurement noise."""
    carry_sigma = noise.carry_m + noise.carry_fraction * np.nan_to_num(flight.carry_m)
    spin_sigma = np.hypot(noise.spin_rpm_fraction * table.spin_rpm, noise.spin_rpm_floor)
    return {
        "ball_speed_mps": _noisy(rng, table.ball_speed_mps, noise.ball_speed_mps),
        "launch_angle_deg": _noisy(rng, table.launch_angle_deg, noise.launch_angle_deg),
        "launch_direction_deg": _noisy(rng, table.launch_direction_deg, noise.launch_direction_deg),
        "spin_rpm": np.maximum(_noisy(rng, table.spin_rpm, spin_sigma), 0.0),
        "spin_axis_deg": _noisy(rng, table.spin_axis_deg, noise.spin_axis_deg),
        "carry_x_m": _noisy(rng, flight.landing_position[:, 0], carry_sigma),
        "carry_y_m": _noisy(rng, flight.landing_position[:, 1], carry_sigma),
        "apex_m": _noisy(rng, flight.apex_m, noise.apex_m),
        "flight_time_s": _noisy(rng, flight.flight_time_s, noise.flight_time_s),
        "landing_angle_deg": _noisy(rng, flight.landing_angle_deg, noise.landing_angle_deg),
    }


def validation_sessions(sessions: list[SyntheticSession], fraction: float) -> set[str]:
    """The most recent sessions holding at least `fraction` of all shots (the paper's time-ordered split)."""
    total = sum(s.n_shots for s in sessions)
    chosen, count = set(), 0
    for s in reversed(sessions):
        if count >= fraction * total:
            break
        chosen.add(s.session)
        count += s.n_shots
    return chosen


def generate(config: SynthConfig, progress: bool = True) -> SyntheticSet:
    """Draw sessions and launches, fly them through the reference world, record them with noise; with `progress`,
    what it is doing goes to standard error (`shots.progress`)."""
    started = time.perf_counter()
    rng = np.random.default_rng(config.seed)
    progress_step(f"drawing {config.n_shots:,} launches...", progress)
    sessions = draw_sessions(rng, config.n_shots, config)
    table = draw_launches(rng, sessions)
    flight = fly_sessions(table, sessions, config, rng, progress)
    progress_step(f"recording {len(table.session_index):,} shots with launch-monitor noise...", progress)
    recorded = measure(rng, table, flight, config.noise)
    val = validation_sessions(sessions, config.val_fraction)

    not_landed = ~flight.landed
    too_low = flight.landed & (flight.apex_m < MIN_APEX_M)
    out_of_range = np.zeros_like(not_landed)
    for name, values in recorded.items():
        out_of_range |= flight.landed & ((values < RANGES[name].low) | (values > RANGES[name].high))
    out_of_range &= ~too_low
    keep = ~(not_landed | too_low | out_of_range)
    records, shot_in_session = [], np.zeros(len(sessions), dtype=int)
    for i in np.flatnonzero(keep):
        s = sessions[table.session_index[i]]
        order = shot_in_session[table.session_index[i]]
        shot_in_session[table.session_index[i]] += 1
        stamp = START + timedelta(days=int(table.session_index[i]) // 3, hours=3 * (int(table.session_index[i]) % 3),
                                  seconds=40 * int(order))
        records.append(ShotRecord(
            shot_id=f"{s.session}-{order:04d}", session=s.session, club=table.club[i], timestamp=stamp.isoformat(),
            split="val" if s.session in val else "train", **{k: float(v[i]) for k, v in recorded.items()}))
    dropped = {
        "did not land within the time cap": int(not_landed.sum()),
        "max height under 8 yd (paper's filter)": int(too_low.sum()),
        "a recorded value outside the canonical range": int(out_of_range.sum()),
    }
    return SyntheticSet(records, sessions, dropped, time.perf_counter() - started)


def sessions_path(path: str | Path) -> Path:
    """The hidden-truth companion of a synthetic file: NAME.csv -> NAME.sessions.csv."""
    path = Path(path)
    return path.with_name(path.stem + ".sessions.csv")


def write_synthetic(path: str | Path, synthetic: SyntheticSet) -> None:
    """Write the canonical records and, beside them, the hidden per-session truth."""
    write_shots(path, synthetic.records)
    header = [f.name for f in fields(SyntheticSession)]
    rows = ([*(("|".join(v) if isinstance(v, tuple) else v) for v in asdict(s).values())] for s in synthetic.sessions)
    write_csv_atomic(sessions_path(path), header, rows)

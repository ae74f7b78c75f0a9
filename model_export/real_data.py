"""The real-flight training set: every usable source of ../shared/data converted by the loaders, tagged with its
source, its conditions group and its split, merged into one canonical CSV (+ trajectories) that training reads.

Sources (`SOURCES`), each with a weight per shot in the loss:
  trackman-outdoor  TrackMan driver shots the radar tracked for >= 90 % of the flight, lines 3-2942 only (the rest
                    of the file is held out, `shots.heldout`); landing point, apex, flight time, landing angle.
  sentry-2022       PGA TOUR TrackMan trajectories of the 2022 Sentry joined with the pbp spin: the landing and
                    apex of the polynomial plus positions along the radar-tracked part of the path.
  players-2020      THE PLAYERS 2020 (round 1) pbp radar tee shots: launch and spin, and the carry, which this event
                    records in its apexRange field (its apexHeight is not an apex and is left out, docs/real_data.md);
                    no spin axis is recorded, so the side is not trained on.
  trackman-model    the indoor rows of the driver file (lines 3-2942): TrackMan's own model of the flight in its
                    normalisation air, not a measurement; labelled "modelled" and reported on its own.
  tour-championship-2020  rounds 1-2 of the TOUR Championship 2020 (rounds 3-4 are held out): radar tee shots with
                    launch, spin and the radar apex; tour irons on the par 3s.
  pga-2023-table    TrackMan's PGA TOUR 2023 averages: each club's average launch and its average carry, max height and
                    land angle, in the table's air (about 0.99 of ICAO standard, `shots.source_air`).
  synthetic         calm reference-world flights of the other clubs and slower players, clean, where real data is
                    missing; shots inside the measured drivers' launch range are left out, so real data decides there.
Every source with known air carries it in its records' condition columns (`shots.source_air`): the tour events their
course's elevation and season, TrackMan's modelled rows its normalisation air, the table its 0.99; the range sessions
recorded none and are trained in an air fitted to them.
Groups (the `group` column) are the shots that shared one unrecorded wind and air: a tour hole in one round; for the
driver file, which has no date or session column, a run of consecutive measured rows of one ball type (a new group
where more than `GAP_LINES` lines separate two measured shots, or after `BLOCK_SHOTS` shots).
Validation is by group, never a random shuffle: every `VAL_EVERY`-th driver group in file order, the last round of
the Sentry, every `VAL_EVERY`-th hole of THE PLAYERS (one round was played) and of the TOUR Championship's rounds 1-2,
every `TABLE_VAL_EVERY`-th club of the table, the synthetic generator's last sessions.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from golfflight.flight.air import Air
from golfflight.flight.constants import YARD_M
from golfflight.flight.physics import initial_state
from golfflight.model_export.real_sources import DEFAULT_SOURCES, SOURCES
from golfflight.shots.heldout import check_training_rows, shot_round
from golfflight.shots.pbp import load_pbp, recorded_apex
from golfflight.shots.range_blocks import driver_groups
from golfflight.shots.records import ShotRecord, trajectories_path, write_shots, write_trajectories
from golfflight.shots.reference_world import TOUR_AVERAGES_FILE, ClubAverage, fly_reference, read_tour_averages
from golfflight.shots.source_air import KNOWN_AIR
from golfflight.shots.synth import MIN_APEX_M, SynthConfig, draw_launches, draw_sessions
from golfflight.shots.tourcast import load_tourcast, read_flights
from golfflight.shots.trackman import ConversionReport, load_trackman
from golfflight.weights_schema.bundle import sha256_of

DRIVER_FILE = Path("real/trackman_driver_sessions/data.csv")
DRIVER_TRAIN_LINES = (3, 2942)
"""Lines of the driver file that may be trained on; `shots.heldout` refuses any other."""
SENTRY_TRAJECTORIES = Path("real/pga_tourcast_trackman/shot_trajectory/shot_trajectory_2021_016_656.csv")
SENTRY_PBP = Path("real/pga_tourcast_trackman/pbp/pbp_2021_016_656.csv")
PLAYERS_PBP = Path("real/pga_tourcast_trackman/pbp/pbp_2020_011_011.csv")
TOUR_CHAMPIONSHIP_PBP = Path("real/pga_tourcast_trackman/pbp/pbp_2020_060_688.csv")
TOUR_CHAMPIONSHIP_TRAIN_ROUNDS = (1, 2)
"""Rounds of the TOUR Championship 2020 that may be trained on; `shots.heldout` refuses 3 and 4."""
TABLE_VAL_EVERY = 3
"""Every third club of the tour-averages table (3-wood, 3-iron, 6-iron, 9-iron) is validation."""

VAL_EVERY = 4
PATH_INTERVAL_S = 0.5
"""Spacing of the trajectory samples trained on, up to the radar's last measured time."""

SYNTHETIC_SHOTS = 3000
SYNTHETIC_SEED = 11
DRIVER_LIKE = {"max_launch_angle_deg": 20.0, "min_ball_speed_mps": 50.0}
"""Synthetic shots at least this fast and at most this steep sit where the measured drivers are: left out."""


@dataclass
class SourceData:
    """One source converted: its records (source, group and split set), sampled paths, files and what was dropped."""

    name: str
    kind: str
    records: list[ShotRecord]
    files: dict[str, str]
    report: str
    trajectories: dict[str, np.ndarray] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


def _tag(records: list[ShotRecord], source: str, groups: list[str], val: set[str]) -> list[ShotRecord]:
    """Source, group, split and prefixed id on every record, and the source's air where it is known."""
    air = KNOWN_AIR.get(source)
    conditions = {} if air is None else air.record_conditions()
    return [
        r.model_copy(update={"source": source, "group": g, "split": "val" if g in val else "train",
                             "shot_id": f"{source}:{r.shot_id}", **conditions})
        for r, g in zip(records, groups, strict=True)
    ]


def _every_nth_val(groups: list[str]) -> set[str]:
    ordered = list(dict.fromkeys(groups))
    return {g for i, g in enumerate(ordered) if i % VAL_EVERY == VAL_EVERY - 1}


def trackman_outdoor(root: Path) -> SourceData:
    """Measured driver flights of the training lines."""
    path = root / DRIVER_FILE
    conversion = load_trackman(path, lines=DRIVER_TRAIN_LINES, skip_bad_rows=True)
    check_training_rows(path, (int(r.shot_id) for r in conversion.records))
    groups = driver_groups(conversion.records)
    records = _tag(conversion.records, "trackman-outdoor", [f"tm-{g}" for g in groups],
                   {f"tm-{g}" for g in _every_nth_val(groups)})
    return SourceData("trackman-outdoor", "measured", records, {str(DRIVER_FILE): sha256_of(path)},
                      conversion.report.summary())


def trackman_model(root: Path) -> SourceData:
    """The driver file's indoor rows (training lines only): outcomes from TrackMan's model, one air for them all."""
    path = root / DRIVER_FILE
    everything = load_trackman(path, lines=DRIVER_TRAIN_LINES, min_tracked_fraction=None, skip_bad_rows=True)
    measured = {r.shot_id for r in load_trackman(path, lines=DRIVER_TRAIN_LINES, skip_bad_rows=True).records}
    kept = [r for r in everything.records if r.shot_id not in measured and r.carry_y_m is not None]
    check_training_rows(path, (int(r.shot_id) for r in kept))
    groups = [f"tmm-{'val' if i % 10 == 9 else 'train'}" for i in range(len(kept))]
    records = _tag(kept, "trackman-model", groups, {"tmm-val"})
    note = (f"{len(kept)} indoor rows (radar tracked < 90 % of the flight): carry, apex, landing angle and flight time "
            "are TrackMan's model, not a measurement")
    return SourceData("trackman-model", "modelled", records, {str(DRIVER_FILE): sha256_of(path)}, note)


def _tour_group(shot_id: str) -> str:
    """'016-R2-H15-P29725-S1' -> '016-R2-H15' (tournament, round, hole)."""
    return "-".join(shot_id.split("-")[:3])


def _measured_paths(conversion_paths: dict[str, np.ndarray], measured_s: dict[str, float]) -> dict[str, np.ndarray]:
    """Samples every PATH_INTERVAL_S from PATH_INTERVAL_S up to the radar's last measured time."""
    out = {}
    for shot_id, path in conversion_paths.items():
        end = min(measured_s[shot_id], path[-1, 0])
        times = np.arange(PATH_INTERVAL_S, end + 1e-9, PATH_INTERVAL_S)
        out[shot_id] = np.column_stack([times, *(np.interp(times, path[:, 0], path[:, k]) for k in (1, 2, 3))])
    return out


def sentry(root: Path) -> SourceData:
    """2022 Sentry trajectories with pbp spin; validation = the last round."""
    trajectories, pbp = root / SENTRY_TRAJECTORIES, root / SENTRY_PBP
    conversion = load_tourcast(trajectories, pbp, skip_bad_rows=True)
    measured = {f.shot_id: f.measured_time_s for f in read_flights(trajectories, ConversionReport(str(trajectories)),
                                                                   skip_bad_rows=True)}
    check_training_rows(trajectories, [])
    check_training_rows(pbp, [])
    groups = [_tour_group(r.shot_id) for r in conversion.records]
    last_round = max(g.split("-")[1] for g in groups)
    val = {g for g in groups if g.split("-")[1] == last_round}
    records = _tag(conversion.records, "sentry-2022", groups, val)
    paths = _measured_paths(conversion.trajectories, measured)
    return SourceData("sentry-2022", "measured", records,
                      {str(SENTRY_TRAJECTORIES): sha256_of(trajectories), str(SENTRY_PBP): sha256_of(pbp)},
                      conversion.report.summary(), {f"sentry-2022:{k}": v for k, v in paths.items()})


def players(root: Path) -> SourceData:
    """THE PLAYERS 2020 radar tee shots: recorded launch and spin (spin axis 0) and the forward carry from the
    apexRange and apexSide fields, which this event fills with the landing point (docs/real_data.md). The side
    is left out of the loss (no spin axis is recorded, so no model can predict it). Validation: every
    `VAL_EVERY`-th hole."""
    path = root / PLAYERS_PBP
    check_training_rows(path, [])
    conversion = load_pbp(path, skip_bad_rows=True)
    fields = recorded_apex(path)
    records, no_carry = [], 0
    for record in conversion.records:
        recorded = fields[record.shot_id]
        if recorded.range_m is None:
            no_carry += 1
            continue
        side = recorded.side_m or 0.0
        records.append(record.model_copy(update={"carry_y_m": math.sqrt(max(recorded.range_m**2 - side**2, 0.0))}))
    groups = [r.group for r in records]
    val = {g for g in groups if int(g.rsplit("-H", 1)[1]) % VAL_EVERY == 0}
    report = (f"{conversion.report.summary()}\n  carry = sqrt(apexRange^2 - apexSide^2) of {len(records)} shots"
              f"{f'; {no_carry} without apexRange left out' if no_carry else ''}")
    return SourceData("players-2020", "measured", _tag(records, "players-2020", groups, val),
                      {str(PLAYERS_PBP): sha256_of(path)}, report)


def tour_championship(root: Path) -> SourceData:
    """Rounds 1-2 of the TOUR Championship 2020 (East Lake): radar launch, spin and apex of every tee shot, no spin
    axis, so no side; the par 3s are the only tour irons with a radar apex we may train on. Validation: every
    `VAL_EVERY`-th hole."""
    path = root / TOUR_CHAMPIONSHIP_PBP
    conversion = load_pbp(path, skip_bad_rows=True)
    kept = [r for r in conversion.records if shot_round(r.shot_id) in TOUR_CHAMPIONSHIP_TRAIN_ROUNDS and r.apex_m]
    check_training_rows(path, shot_ids=[r.shot_id for r in kept])
    groups = [_tour_group(r.shot_id) for r in kept]
    val = {g for g in groups if int(g.rsplit("-H", 1)[1]) % VAL_EVERY == 0}
    report = (f"{conversion.report.summary()}\n  rounds {TOUR_CHAMPIONSHIP_TRAIN_ROUNDS} only (3-4 held out): "
              f"{len(kept)} tee shots with a radar apex")
    return SourceData("tour-championship-2020", "measured", _tag(kept, "tour-championship-2020", groups, val),
                      {str(TOUR_CHAMPIONSHIP_PBP): sha256_of(path)}, report)


def _club_record(club: ClubAverage) -> ShotRecord:
    return ShotRecord(shot_id=club.club, club=club.club, ball_speed_mps=club.ball_speed_mps,
                      launch_angle_deg=club.launch_angle_deg, launch_direction_deg=0.0, spin_rpm=club.spin_rpm,
                      spin_axis_deg=0.0, carry_y_m=club.carry_yd * YARD_M, apex_m=club.max_height_yd * YARD_M,
                      landing_angle_deg=club.land_angle_deg)


def pga_table(root: Path) -> SourceData:
    """TrackMan's PGA TOUR 2023 averages as one shot per club (its average launch, straight, no spin axis) with the
    average carry, max height and land angle; validation: every `TABLE_VAL_EVERY`-th club from the second on."""
    path = root / TOUR_AVERAGES_FILE
    check_training_rows(path, [])
    clubs = read_tour_averages(path)
    groups = [f"pga-{c.club}" for c in clubs]
    val = {g for i, g in enumerate(groups) if i % TABLE_VAL_EVERY == 1}
    records = _tag([_club_record(c) for c in clubs], "pga-2023-table", groups, val)
    note = (f"{len(clubs)} clubs, one average shot each; air: {KNOWN_AIR['pga-2023-table'].basis}; validation "
            f"clubs: {', '.join(r.club for r in records if r.split == 'val')}")
    return SourceData("pga-2023-table", "measured", records, {str(TOUR_AVERAGES_FILE): sha256_of(path)}, note)


def driver_like(launch: dict[str, np.ndarray]) -> np.ndarray:
    """Launches where the measured drivers decide (fast and flat)."""
    return (launch["ball_speed_mps"] >= DRIVER_LIKE["min_ball_speed_mps"]) & (
        launch["launch_angle_deg"] <= DRIVER_LIKE["max_launch_angle_deg"]
    )


def synthetic(n_shots: int = SYNTHETIC_SHOTS, seed: int = SYNTHETIC_SEED) -> SourceData:
    """Clean calm flights of the reference world in standard air, launches drawn like the synthetic sessions'
    (every club, players from 72 % to 103 % of tour speed), less the driver-like ones."""
    rng = np.random.default_rng(seed)
    sessions = draw_sessions(rng, n_shots, SynthConfig(n_shots=n_shots, seed=seed, calm=True))
    table = draw_launches(rng, sessions)
    launch = table.launch()
    keep_launch = ~driver_like(launch)
    flight = fly_reference(initial_state(**launch), Air.standard())
    keep = keep_launch & flight.landed & (flight.apex_m >= MIN_APEX_M)
    records, groups = [], []
    for i in np.flatnonzero(keep):
        session = sessions[table.session_index[i]].session
        records.append(ShotRecord(
            shot_id=f"{session}-{i:05d}", session=session, club=str(table.club[i]),
            **{k: float(v[i]) for k, v in launch.items()},
            carry_x_m=float(flight.landing_position[i, 0]), carry_y_m=float(flight.landing_position[i, 1]),
            apex_m=float(flight.apex_m[i]), flight_time_s=float(flight.flight_time_s[i]),
            landing_angle_deg=float(flight.landing_angle_deg[i]),
        ))
        groups.append(f"syn-{session}")
    ordered = list(dict.fromkeys(groups))
    val = set(ordered[-max(1, len(ordered) // 10):])
    report = (f"synthetic: {len(table.club)} launches drawn, {int((~keep_launch).sum())} driver-like left out, "
              f"{int((keep_launch & ~keep).sum())} not landed or under 8 yd apex, {len(records)} kept")
    return SourceData("synthetic", "synthetic", _tag(records, "synthetic", groups, val), {}, report)


BUILDERS: dict[str, Callable[[Path], SourceData]] = dict(zip(SOURCES, (
    trackman_outdoor, sentry, players, trackman_model, tour_championship, pga_table, lambda root: synthetic(),
), strict=True))
"""Every source, by name (`real_sources.SOURCES`), in the order the merged file lists them."""



def build(root: str | os.PathLike, out: str | os.PathLike, names: tuple[str, ...] = tuple(BUILDERS)) -> list[SourceData]:
    """Convert the named sources from the shared data folder `root` and write the merged canonical CSV `out` (and
    its trajectories companion); returns each source's data (files with their SHA-256, report)."""
    root = Path(root)
    built = [BUILDERS[name](root) for name in names]
    write_shots(out, [r for data in built for r in data.records])
    write_trajectories(trajectories_path(out), {k: v for data in built for k, v in data.trajectories.items()})
    return built

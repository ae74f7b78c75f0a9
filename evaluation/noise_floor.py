"""The noise floor: the error the reference world itself makes when fed the recorded (noisy) launches.

In nominal conditions (calm, one air) it is the best a model trained without conditions can hope for; for a
synthetic file, whose hidden per-session air and wind are in NAME.sessions.csv, the true-conditions floor leaves
only the measurement noise (and the per-shot gusts, which are not recorded anywhere).
"""

from __future__ import annotations

import csv
import os
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from golfflight.errors import InputError
from golfflight.evaluation.validation import Errors, Prediction, ValidationShots, errors_of
from golfflight.flight.air import Air
from golfflight.flight.physics import initial_state
from golfflight.flight.wind import CALM, Wind
from golfflight.shots.records import CSV_ENCODING, ShotSet
from golfflight.shots.reference_world import fly_reference
from golfflight.shots.synth import MeasurementNoise, sessions_path


class SessionTruth(NamedTuple):
    """A synthetic session's hidden conditions (from NAME.sessions.csv)."""

    temperature_c: float
    altitude_m: float
    humidity_pct: float
    wind_speed_mps: float
    wind_from_deg: float


def read_session_truth(path: str | os.PathLike) -> dict[str, SessionTruth]:
    """The hidden air and wind of every session of a synthetic file's companion NAME.sessions.csv."""
    with open(path, newline="", encoding=CSV_ENCODING) as handle:
        return {
            row["session"]: SessionTruth(*(float(row[f]) for f in SessionTruth._fields))
            for row in csv.DictReader(handle)
        }


def _truth_columns(sessions: np.ndarray, truth: dict[str, SessionTruth]) -> dict[str, np.ndarray]:
    unknown = sorted({s for s in sessions if s not in truth})
    if unknown:
        raise InputError(f"shots of sessions {unknown[:5]} have no hidden truth in the sessions file")
    return {field: np.array([getattr(truth[s], field) for s in sessions]) for field in SessionTruth._fields}


def population_air(shots: ShotSet, truth: dict[str, SessionTruth]) -> Air:
    """The mean air (density and kinematic viscosity averaged over shots) of the training shots' sessions: the
    single air a model trained on them without conditions could at best have learnt."""
    train = shots.subset(shots.column("split") == "train")
    columns = _truth_columns(train.column("session"), truth)
    air = Air.from_conditions(columns["temperature_c"], columns["altitude_m"], columns["humidity_pct"])
    return Air(float(np.mean(air.density_kg_m3)), float(np.mean(air.kinematic_viscosity_m2_s)))


def session_conditions(shots: ShotSet, truth: dict[str, SessionTruth]) -> tuple[Air, Wind]:
    """Each shot's true session air and mean wind (log profile, as `golfflight synth` flies; the per-shot gusts
    are not in the sessions file)."""
    columns = _truth_columns(shots.column("session"), truth)
    air = Air.from_conditions(columns["temperature_c"], columns["altitude_m"], columns["humidity_pct"])
    return air, Wind(columns["wind_speed_mps"], columns["wind_from_deg"], profile="log")


def reference_prediction(shots: ShotSet, air: Air, wind: Wind = CALM) -> Prediction:
    """The reference world's landing points and max heights for the shots' recorded launches."""
    flight = fly_reference(initial_state(**shots.launch()), air, wind)
    return Prediction(flight.landing_position[:, :2], flight.apex_m)


DEFAULT_NOISE = MeasurementNoise()
"""The measurement noise `golfflight synth` records with."""


def expected_outcome_noise(val: ValidationShots, noise: MeasurementNoise = DEFAULT_NOISE) -> tuple[float, float]:
    """Mean landing and max-height error that the recorded outcomes' own noise alone gives (the generator's default
    `MeasurementNoise`): E|2-D normal| = sigma sqrt(pi/2) with sigma = carry_m + carry_fraction x carry, and
    E|normal| = sigma sqrt(2/pi)."""
    carry = np.hypot(*val.landing_m.T)
    sigma = noise.carry_m + noise.carry_fraction * carry
    return float(np.nanmean(sigma) * np.sqrt(np.pi / 2)), noise.apex_m * float(np.sqrt(2 / np.pi))


@dataclass
class Floor:
    """The reference world's own error from the recorded launches, in stated conditions."""

    name: str
    description: str
    landing_m: float
    max_height_m: float | None
    errors: Errors | None = None
    prediction: Prediction | None = None


def hidden_truth(val: ValidationShots) -> dict[str, SessionTruth] | None:
    """The per-session hidden conditions of a synthetic file (NAME.sessions.csv beside it), None for other data."""
    truth_file = sessions_path(val.path)
    return read_session_truth(truth_file) if truth_file.is_file() else None


def nominal_conditions(val: ValidationShots) -> tuple[Air, str]:
    """The air of the nominal floor and its description: the training sessions' mean air where the hidden truth
    is known (the best single air a model trained without conditions can learn), else ICAO standard air."""
    truth = hidden_truth(val)
    air, described = (
        (population_air(val.all_shots, truth), "calm, the training sessions' mean air")
        if truth
        else (Air.standard(), "calm, ICAO standard air")
    )
    return air, f"{described} (rho {float(air.density_kg_m3):.3f} kg/m^3)"


def noise_floors(val: ValidationShots, nominal_air: Air, described: str) -> list[Floor]:
    """The nominal floor (calm, `nominal_air`) and, with a synthetic file's hidden truth, the true-conditions floor
    and the expected outcome-noise part of it."""
    truth = hidden_truth(val)
    world = reference_prediction(val.shots, nominal_air)
    nominal = errors_of(world, val)
    floors = [Floor("nominal", described, nominal.mean_landing_m, nominal.mean_abs_apex_m, nominal, world)]
    if truth:
        air, wind = session_conditions(val.shots, truth)
        true = errors_of(reference_prediction(val.shots, air, wind), val)
        floors.append(
            Floor(
                "true conditions",
                "each session's hidden air and mean wind (no gusts)",
                true.mean_landing_m,
                true.mean_abs_apex_m,
                true,
            )
        )
        landing, apex = expected_outcome_noise(val)
        floors.append(Floor("outcome noise", "expected from the recorded carry/apex noise alone", landing, apex))
    return floors

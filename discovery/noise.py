"""What mismatch to expect without any left-out physics: the model's own error plus the launch monitor's noise.

Per shot and observable, sigma^2 = model error^2 + outcome noise^2 + sum over launch values of
(d outcome / d launch value x launch noise)^2; the launch-noise terms are propagated through the model itself.
Real recordings are often far noisier than a radar (gusts, players, mixed balls): their own shot-to-shot scatter is
measured, and where it is larger than assumed beyond doubt it replaces the assumption (`recording_scatter`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from golfflight.discovery.fit import cluster_bootstrap
from golfflight.discovery.model import FlightModel, reference
from golfflight.discovery.recordings import OBSERVABLES, Recordings
from golfflight.discovery.simulator import Setup, concatenate
from golfflight.shots.records import LAUNCH_COLUMNS
from golfflight.shots.synth import MeasurementNoise
from scipy.spatial import cKDTree

RADAR_NOISE = MeasurementNoise()
"""The launch-monitor noise assumed unless told otherwise (the synthetic generator's)."""

FLOOR = {"carry_y_m": 0.3, "carry_x_m": 0.3, "apex_m": 0.2, "flight_time_s": 0.03, "landing_angle_deg": 0.3}
"""Smallest sigma allowed per observable, so no shot gets an absurd weight."""


@dataclass
class ExpectedError:
    """Per-shot 1-sigma scales [N, 5] and their parts (RMS over shots per observable) for the report."""

    sigma: np.ndarray
    noise_sigma: np.ndarray
    """The part of sigma [N, 5] that measurement noise alone makes (no model error): the floor that no correction
    of the physics can go below on held-out shots."""
    model: dict[str, float]
    model_source: dict[str, str]
    outcome_noise: dict[str, float]
    launch_noise: dict[str, float]
    dilution: dict[str, np.ndarray]
    """Per launch value [N, 5]: the residual's expected change per unit of that recorded launch value under the
    null, divided by the value's spread about its mean (`dilution_slopes`)."""


def base_conditions(recordings: Recordings, model: FlightModel) -> Setup:
    """The conditions the model assumes for the recordings: recorded air (its density and kinematic viscosity, as the
    service flies it) and wind where present, else its own air."""
    n = len(recordings)
    density = recordings.density_kg_m3
    if density is None:
        density = np.full(n, model.flyer.density_kg_m3)
    viscosity = recordings.kinematic_viscosity_m2_s
    if viscosity is None:
        viscosity = np.full(n, model.flyer.kinematic_viscosity_m2_s)
    wind = recordings.wind_xy_mps if recordings.wind_xy_mps is not None else np.zeros((n, 2))
    return Setup(
        {k: v.copy() for k, v in recordings.launch.items()},
        np.ones(n),
        np.asarray(density, dtype=float),
        np.asarray(wind, dtype=float),
        np.zeros(n),
        np.ones((n, 3)),
        kinematic_viscosity_m2_s=np.asarray(viscosity, dtype=float),
    )


def launch_noise_steps(launch: dict[str, np.ndarray], noise: MeasurementNoise) -> dict[str, np.ndarray]:
    """1-sigma recording noise of each launch value [N] (the synthetic generator's radar assumption)."""
    n = len(launch["ball_speed_mps"])
    return {
        "ball_speed_mps": np.full(n, noise.ball_speed_mps),
        "launch_angle_deg": np.full(n, noise.launch_angle_deg),
        "launch_direction_deg": np.full(n, noise.launch_direction_deg),
        "spin_rpm": np.hypot(noise.spin_rpm_fraction * launch["spin_rpm"], noise.spin_rpm_floor),
        "spin_axis_deg": np.full(n, noise.spin_axis_deg),
    }


def _rms(values: np.ndarray) -> dict[str, float]:
    return {name: float(np.sqrt(np.nanmean(values[:, j] ** 2))) for j, name in enumerate(OBSERVABLES)}


def expected_error(
    model: FlightModel,
    recordings: Recordings,
    base: Setup,
    predicted: np.ndarray,
    noise: MeasurementNoise = RADAR_NOISE,
) -> ExpectedError:
    """Expected 1-sigma mismatch of every shot and observable under the null hypothesis (nothing left out)."""
    n = len(recordings)
    steps = launch_noise_steps(base.launch, noise)
    responses = launch_responses(model, base, predicted, steps)
    launch_var = np.nansum(np.stack(list(responses.values())) ** 2, axis=0)

    carry = np.hypot(predicted[:, 0], predicted[:, 1])
    carry_noise = noise.carry_m + noise.carry_fraction * np.nan_to_num(carry)
    outcome = np.stack(
        [
            carry_noise,
            carry_noise,
            np.full(n, noise.apex_m),
            np.full(n, noise.flight_time_s),
            np.full(n, noise.landing_angle_deg),
        ],
        axis=1,
    )

    model_sigma = dict(model.model_error)
    source = dict(model.error_source)
    missing = [name for name in OBSERVABLES if name not in model_sigma]
    if missing:
        truth = reference().simulate(base).outcomes()
        for j, name in enumerate(OBSERVABLES):
            if name in missing:
                model_sigma[name] = float(np.sqrt(np.nanmean((predicted[:, j] - truth[:, j]) ** 2)))
                source[name] = "estimated: RMS of the model against the reference world on these launches"
    model_part = np.array([model_sigma[name] for name in OBSERVABLES])
    floor = np.array([FLOOR[name] for name in OBSERVABLES])
    sigma = np.sqrt(model_part[None] ** 2 + outcome**2 + launch_var)
    sigma = np.maximum(np.where(np.isfinite(sigma), sigma, np.nanmax(sigma, axis=0)), floor)
    noise_sigma = np.minimum(np.nan_to_num(np.sqrt(outcome**2 + launch_var), nan=np.inf), sigma)
    return ExpectedError(
        sigma,
        noise_sigma,
        model_sigma,
        source,
        _rms(outcome),
        _rms(np.sqrt(launch_var)),
        dilution_slopes(base, responses, steps),
    )


RESPONSE_SHOTS = 5_000
"""The launch-noise responses are flown for at most this many shots of a session (a random share); every other shot
takes its nearest flown neighbours' (`launch_responses`): at 100,000 shots, five more flights of each were ~25 % of
a diagnosis against a baseline."""
RESPONSE_NEIGHBOURS = 4
"""How many flown shots an unflown shot's response per unit of launch noise is averaged from (inverse distance)."""


def launch_responses(
    model: FlightModel, base: Setup, predicted: np.ndarray, steps: dict[str, np.ndarray]
) -> dict[str, np.ndarray]:
    """Each launch value's response [N,5]: the outcomes' change when it moves by its 1-sigma noise `steps`. In a
    session of more than RESPONSE_SHOTS shots only that many are flown (`flown_responses`); the rest take the response
    per unit step of their nearest flown shots in the launch values and the air they fly in (standardized), times
    their own step: the response changes smoothly with both."""
    n = len(base)
    if n <= RESPONSE_SHOTS:
        return flown_responses(model, base, predicted, steps)
    flown = np.sort(np.random.default_rng(0).permutation(n)[:RESPONSE_SHOTS])
    some = flown_responses(model, base.take(flown), predicted[flown], {k: v[flown] for k, v in steps.items()})
    where = np.column_stack([*(base.launch[name] for name in LAUNCH_COLUMNS), base.density_kg_m3, base.wind_xy_mps])
    where = (where - where.mean(axis=0)) / np.where(where.std(axis=0) > 0, where.std(axis=0), 1.0)
    distance, nearest = cKDTree(where[flown]).query(where, RESPONSE_NEIGHBOURS)
    weight = 1.0 / np.maximum(distance, 1e-9)
    responses = {}
    for name, step in steps.items():
        neighbours = (some[name] / step[flown, None])[nearest]
        w = weight * np.isfinite(neighbours).all(axis=2)  # a neighbour the model does not land tells nothing
        with np.errstate(invalid="ignore", divide="ignore"):
            responses[name] = np.einsum("nk,nkj->nj", w, np.nan_to_num(neighbours)) / w.sum(axis=1)[:, None]
        responses[name] *= step[:, None]
        responses[name][flown] = some[name]
    return responses


def flown_responses(
    model: FlightModel, base: Setup, predicted: np.ndarray, steps: dict[str, np.ndarray]
) -> dict[str, np.ndarray]:
    """Each launch value's response [N,5], every shot flown again with that value moved by its step."""
    shifted = []
    for name, step in steps.items():
        moved = base.copy()
        moved.launch[name] = moved.launch[name] + step
        shifted.append(moved)
    outcomes = model.simulate(concatenate(shifted)).outcomes().reshape(len(steps), len(base), len(OBSERVABLES))
    return {name: outcomes[k] - predicted for k, name in enumerate(steps)}


def dilution_slopes(
    base: Setup, responses: dict[str, np.ndarray], steps: dict[str, np.ndarray]
) -> dict[str, np.ndarray]:
    """Under the null, a recorded launch value x = true + e predicts with e in it, so the residual carries
    -(response to a 1-sigma step) e / sigma, which correlates with x: E[residual | x] = -response sigma (x - mean)
    / var(x) per shot (errors in variables). Per launch value, response x sigma / var(x) [N, 5]: the trend the
    systematic test must not mistake for left-out physics (a noisy spin axis alone gave t = 6 on clean sets)."""
    out = {}
    for name, response in responses.items():
        spread = float(np.var(base.launch[name]))
        out[name] = np.nan_to_num(response * steps[name][:, None] / max(spread, 1e-12))
    return out


SCATTER_MATERIAL = 1.5
"""The recordings' own scatter replaces the assumed noise only when it is at least this many times larger..."""

SCATTER_LEVEL = 0.975
"""...and larger than assumed beyond doubt (the lower end of this one-sided session-bootstrap bound is above 1)."""

MIN_GROUP_SHOTS = 12
"""Session-club groups smaller than this are left out of the scatter estimate (too few shots for the trend)."""


@dataclass
class Scatter:
    """Shot-to-shot scatter of the residuals, in units of the expected sigma, per observable (1 = as noisy as
    assumed) with the lower end of its bootstrap interval. `applied` observables have their expected sigma scaled by
    it."""

    ratio: dict[str, float]
    low: dict[str, float]
    applied: dict[str, float]


def recording_scatter(recordings: Recordings, z: np.ndarray, rng: np.random.Generator, draws: int = 1000) -> Scatter:
    """How noisy the recordings are, from themselves: within each session and club, the standardized residuals
    z [N, 5] are fitted linearly on the five launch values, and the scatter about that fit (with its degrees of
    freedom) is the noise, whatever its source (monitor, gusts, the player). A left-out effect changes smoothly with
    the launch, so within one club and session the linear trend takes it out."""
    values = np.stack([recordings.launch[name] for name in LAUNCH_COLUMNS], axis=1)
    keys = [f"{s}\x00{c}" for s, c in zip(recordings.session, recordings.club)]
    groups = np.unique(keys, return_inverse=True)[1]
    squares = np.zeros(z.shape)
    dof = np.zeros(z.shape)  # per shot: its share of its group's degrees of freedom
    for g in range(groups.max() + 1):
        members = np.flatnonzero(groups == g)
        x = values[members]
        x = (x - x.mean(axis=0)) / np.maximum(x.std(axis=0), 1e-9)
        design = np.column_stack([np.ones(members.size), x])
        for j in range(z.shape[1]):
            used = np.isfinite(z[members, j])
            if used.sum() < MIN_GROUP_SHOTS:
                continue
            rows = members[used]
            fitted = design[used] @ np.linalg.lstsq(design[used], z[rows, j], rcond=None)[0]
            squares[rows, j] = (z[rows, j] - fitted) ** 2
            dof[rows, j] = 1.0 - np.linalg.matrix_rank(design[used]) / used.sum()
    ratio, low, applied = {}, {}, {}
    for j, name in enumerate(OBSERVABLES):
        if dof[:, j].sum() < 10:
            continue
        ratio[name] = float(np.sqrt(squares[:, j].sum() / dof[:, j].sum()))
        bootstrap = cluster_bootstrap(squares[:, j], dof[:, j], recordings.session, rng, draws)
        low[name] = float(np.sqrt(np.quantile(bootstrap, 1.0 - SCATTER_LEVEL)))
        if low[name] > 1.0 and ratio[name] >= SCATTER_MATERIAL:
            applied[name] = ratio[name]
    return Scatter(ratio, low, applied)


def with_scatter(expected: ExpectedError, scatter: Scatter) -> ExpectedError:
    """The expected error with each `applied` observable's sigma scaled by the recordings' own scatter."""
    scale = np.array([scatter.applied.get(name, 1.0) for name in OBSERVABLES])
    return replace(expected, sigma=expected.sigma * scale[None], noise_sigma=expected.noise_sigma * scale[None])


def with_discrepancy(expected: ExpectedError, sd: np.ndarray) -> ExpectedError:
    """The expected error with a baseline's discrepancy SD [N,5] (`discovery.discrepancy`) added to each shot's
    model error: small near the baseline's launches, the whole discrepancy far from them."""
    sd = np.nan_to_num(sd)
    model = {
        name: float(np.sqrt(expected.model[name] ** 2 + np.mean(sd[:, j] ** 2))) for j, name in enumerate(OBSERVABLES)
    }
    source = {name: "the baseline session: its discrepancy at these launches (RMS)" for name in OBSERVABLES}
    return replace(expected, sigma=np.sqrt(expected.sigma**2 + sd**2), model=model, model_source=source)

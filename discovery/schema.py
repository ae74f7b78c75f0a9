"""report.json as pydantic models: what `golfflight diagnose` writes (its JSON Schema is generated from these)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

SCHEMA_VERSION = "1.2"
"""1.1: the held-out noise floor and absorbs_noise; the systematic test decides (structure_found). 1.2: the headline,
the baseline session (`baseline`) and another ball (effect kind "ball")."""
SCHEMA_PATH = Path(__file__).with_name("report.schema.json")


class _ReportModel(BaseModel):
    model_config = ConfigDict(extra="forbid")


class ObservableStat(_ReportModel):
    """Mismatch of one observable before any correction: residual = recorded - model."""

    name: str
    n: int
    bias: float = Field(description="mean residual, in the observable's unit")
    bias_se: float = Field(description="standard error of the bias (clustered by session where there are 5+)")
    bias_p: float
    spread: float = Field(description="standard deviation of the residuals")
    rms: float
    expected: float = Field(description="RMS of the expected 1-sigma mismatch (model error + launch-monitor noise)")
    rms_ratio: float = Field(description="sqrt(mean (residual / expected sigma)^2): 1 = as the model's error predicts")
    excess_p: float = Field(description="p-value of 'the mismatch is no larger than expected'")
    significant: bool = Field(description="bias or excess significant at the family-wise level (Holm)")


class CovariateStat(_ReportModel):
    """How an observable's residual changes with a launch value or the shot order."""

    observable: str
    covariate: str
    slope_per_sd: float = Field(description="residual change per standard deviation of the covariate")
    t: float
    p: float
    significant: bool


class GroupStat(_ReportModel):
    """Whether residuals differ between clubs or between sessions (one-way ANOVA on standardized residuals)."""

    observable: str
    grouping: Literal["club", "session"]
    n_groups: int
    f: float
    p: float
    significant: bool
    extremes: dict[str, float] = Field(description="mean residual of the groups furthest from the overall mean")


class TrajectoryStat(_ReportModel):
    """Mean position residual (recorded - model) of trajectory samples in one flight phase and height band."""

    phase: Literal["ascent", "descent"]
    height_band: str
    n_samples: int
    n_shots: int
    across_m: float
    along_m: float
    height_m: float
    rms_m: float


class Located(_ReportModel):
    """Where the mismatch is: per observable, against covariates, between groups, along the flight."""

    observables: list[ObservableStat]
    covariates: list[CovariateStat]
    groups: list[GroupStat]
    trajectory: list[TrajectoryStat]
    outliers: dict[str, int] = Field(description="shots left out of the fits per observable (wild readings)")
    alpha: float = Field(description="family-wise significance level of the 'significant' flags (Holm)")
    summary: list[str]


class EffectResult(_ReportModel):
    """A named effect with its fitted parameters and their 1-sigma uncertainties."""

    name: str
    kind: Literal["venue", "monitor", "ball", "form"] = Field(
        "form",
        description="a condition of the venue (air, wind, ground), a bias of the launch monitor, another ball than a "
        "baseline session's, or the model's form (coefficient scales or a learned correction: the recordings' physics "
        "differs from the model's in form)",
    )
    parameters: dict[str, float]
    uncertainty: dict[str, float] = Field(
        description="1 standard deviation of each parameter, from the fit's Jacobian; against a baseline session it "
        "counts the model's error shared between shots once, and for the chosen explanation also the error of the "
        "form the baseline taught (held while fitting) and, in another air than the baseline's, half the move to the "
        "form's other reading (docs/discovery.md, 'The ± counts what the baseline leaves unsure')"
    )


class Candidate(_ReportModel):
    """One effect (or combination) fitted through the simulator and scored on held-out sessions."""

    name: str
    effects: list[EffectResult]
    n_parameters: int
    heldout_error: float = Field(description="mean squared standardized held-out residual (1 = noise level)")
    penalty: float = Field(description="held-out error x k ln(n) / n (BIC-like, k parameters, n shots)")
    score: float = Field(description="heldout_error + penalty: lower is better")


class Heldout(_ReportModel):
    """Held-out error before (model as is) and after (with the chosen correction), folds grouped by session."""

    grouping: str
    n_folds: int
    before: dict[str, float] = Field(description="held-out RMS residual per observable, in its unit")
    after: dict[str, float]
    expected: dict[str, float] = Field(description="RMS expected sigma per observable")
    before_error: float = Field(description="mean squared standardized residual, all observables")
    after_error: float
    improvement: float = Field(description="before_error - after_error")
    improvement_ci: tuple[float, float] = Field(description="95 % session-bootstrap interval of the improvement")
    improvement_by_observable: dict[str, tuple[float, float, float]] = Field(
        description="per observable: improvement of the mean squared standardized residual and its 95 % interval"
    )
    noise_floor: float = Field(
        description="held-out error that measurement noise alone leaves (no model error): what a perfect "
        "explanation reaches"
    )
    explained_fraction: float | None = Field(
        description="share of the excess error (above the noise floor) removed on held-out shots"
    )
    explained_fraction_ci: tuple[float, float] | None
    absorbs_noise: bool = Field(
        description="the explained share is above 100 % beyond doubt and the fit goes more than a quarter below what "
        "measurement noise alone leaves (further than noise scatters by chance): part of what it removes is noise"
    )


class Ambiguity(_ReportModel):
    """Two explanations the data cannot tell apart, and what would."""

    effects: tuple[str, str]
    score_difference: float
    difference_ci: tuple[float, float]
    separating_measurement: str
    note: str


class AirRival(_ReportModel):
    """Air density set against the chosen explanation of recordings that carry no air (`discovery.venue_air`)."""

    explanation: str = Field(
        description="the candidate with air density: the chosen one, or it with air density in place of its main "
        "library effect (air alone for a single effect)"
    )
    named: bool = Field(description="air density is part of the chosen explanation")
    ratio: float = Field(description="fitted density / the density the model assumed")
    ratio_sd: float
    equivalent_altitude_m: float = Field(description="standard-atmosphere height of that density in dry air at 15 degC")
    heldout_error: float
    difference_ci: tuple[float, float] = Field(
        description="95 % session-bootstrap interval of its held-out error minus the chosen one's"
    )
    separable: bool = Field(
        description="worse than the chosen explanation beyond doubt (the interval above zero) and apart from it by "
        "more than the model's own error in some recorded observable"
    )
    separating_measurement: str | None = Field(
        description="the observable where the two differ most, unrecorded first (None where air is named)"
    )
    note: str


class Unlisted(_ReportModel):
    """A learned extra acceleration, summarised as a readable expression, when no library effect explains enough."""

    expression: str
    terms: dict[str, float] = Field(description="coefficient of each kept term, SI units")
    uncertainty: dict[str, float]
    meaning: dict[str, str]
    heldout_error: float
    library_heldout_error: float = Field(description="held-out error of the best library explanation alone")


class WindSetting(_ReportModel):
    speed_mps: float
    from_deg: float
    profile: Literal["uniform", "log"] = "uniform"
    reference_height_m: float | None = Field(default=None, description="height the speed is stated at (log profile)")


class AirDensity(_ReportModel):
    density_kg_m3: float


class AirAltitude(_ReportModel):
    altitude_m: float
    temperature_c: float


class CorrectionSettings(_ReportModel):
    """The correction in the service's request options where it has one; launch-monitor corrections otherwise."""

    wind: WindSetting | None = None
    wind_at_station: WindSetting | None = Field(
        default=None,
        description="the same wind as a weather station's 10 m reading with the log profile (the uniform speed over "
        "the profile's mean speed factor along the corrected flights of these shots)",
    )
    air: AirDensity | None = None
    air_as_altitude: AirAltitude | None = Field(default=None, description="the same air as altitude + temperature")
    ground_height_m: float | None = Field(default=None, description="landing ground relative to the tee")
    launch_corrections: dict[str, float] = Field(
        default_factory=dict, description="apply to recorded launches before simulating"
    )
    coefficient_scales: dict[str, float] = Field(
        default_factory=dict, description="model changes (no service option): retrain or rescale"
    )


class ScatterStat(_ReportModel):
    """The recordings' own shot-to-shot scatter of one observable, in units of the expected error."""

    ratio: float = Field(
        description="RMS of the standardized residuals about a linear trend in the launch within each session and "
        "club (1 = as noisy as assumed)"
    )
    low: float = Field(description="lower end of its one-sided 97.5 % session-bootstrap bound")
    applied: bool = Field(description="the expected error of this observable was scaled by `ratio`")


class ModelInfo(_ReportModel):
    name: str
    dt_s: float
    integrator: str
    density_kg_m3: float
    model_error: dict[str, float]
    model_error_source: dict[str, str]
    outcome_noise: dict[str, float]
    launch_noise: dict[str, float]
    scatter: dict[str, ScatterStat] = Field(
        default_factory=dict,
        description="the recordings' own scatter per observable; where it is larger than assumed beyond doubt (and "
        "by half again or more) it replaces the assumed noise",
    )
    control: str | None = Field(
        None, description="the physics the model imitates; its difference from the model is taken out first"
    )
    known_model_error: dict[str, float] | None = Field(
        None, description="mean model - control per observable on the recorded launches (taken out before fitting)"
    )


class BaselineInfo(_ReportModel):
    """The baseline session a diagnosis was made against (`golfflight diagnose NEW --baseline BASELINE`): what it
    taught about the model's form, and where the new session's launches lie outside it."""

    source: str
    n_shots: int
    heldout_error_before: float = Field(
        description="the baseline against the model as is: mean squared standardized residual (1 = noise alone)"
    )
    heldout_error_after: float = Field(
        description="the same on held-out baseline shots, with the form and discrepancy learned without their fold"
    )
    form: dict[str, float] = Field(
        description="the learned form's weights (`discovery.form_terms`): log-multipliers of C_L, C_D and C_M over "
        "the spin ratio and the Reynolds number"
    )
    discrepancy_sd: dict[str, float] = Field(
        description="per observable, the discrepancy's amplitude (its unit): what a shot far outside the baseline's "
        "launches is expected to miss by beyond noise"
    )
    baseline_density_kg_m3: list[float] = Field(description="the lowest and highest air density the baseline flew in")
    new_density_kg_m3: list[float] = Field(description="the lowest and highest air density assumed for the new shots")
    baseline_launch: dict[str, list[float]] = Field(
        description="per launch value, the baseline's 1st and 99th percentiles"
    )
    outside_shots: int = Field(description="new shots outside the baseline's launches (the learned form extrapolated)")
    outside_launch: dict[str, list[float]] = Field(
        description="per launch value, the lowest and highest among the new shots outside the baseline's launches"
    )
    outside_clubs: list[str] = Field(description="the clubs of the new shots outside the baseline's launches")
    needed: str = Field(description="the baseline shots that would cover the new session, in words; empty if none")
    cannot_inform: list[str] = Field(description="what the baseline cannot teach about these new shots, in words")


class Report(_ReportModel):
    """report.json of `golfflight diagnose`."""

    schema_version: Literal["1.2"] = SCHEMA_VERSION
    recordings: str
    n_shots: int
    n_sessions: int
    fit_shots: int = Field(
        description="shots the candidates' least-squares fits used (a subsample spread over sessions above 600)"
    )
    scored_shots: int = Field(
        description="shots the candidates were scored on (their residuals, Jacobian, the quoted ± and the held-out "
        "comparisons): every shot up to 5,000, above that a subsample stratified by session and club; the systematic "
        "test and the chosen explanation's held-out errors use every shot"
    )
    observables: list[str]
    trajectories: int = Field(description="shots with a recorded trajectory")
    model: ModelInfo
    systematic: bool
    systematic_test: dict[str, float | bool | str]
    located: Located
    effects: list[EffectResult]
    unlisted: Unlisted | None
    candidates: list[Candidate]
    ambiguities: list[Ambiguity]
    air_rival: AirRival | None = Field(
        default=None, description="air density against the chosen explanation, where the recordings carry no air"
    )
    heldout: Heldout
    baseline: BaselineInfo | None = Field(
        default=None, description="the baseline session the new shots were diagnosed against; null without one"
    )
    statement: str
    headline: list[str] = Field(
        default_factory=list,
        description="the verdict read in ten seconds (`discovery.headline`): at most three sentences of at most 35 "
        "words, what differs (carry, apex, side with their sizes and directions), the most likely cause with its "
        "value, the runner-up",
    )
    service_settings: CorrectionSettings
    seconds: float


def schema_text() -> str:
    """The JSON Schema of report.json."""
    return json.dumps(Report.model_json_schema(), indent=2, sort_keys=True) + "\n"


if __name__ == "__main__":
    SCHEMA_PATH.write_text(schema_text())
    print(f"wrote {SCHEMA_PATH}")

"""model_card.json: everything a third party needs to re-run a shipped model without reading our code.

The JSON Schema beside this file (model_card.schema.json) is generated from these models by
`python -m golfflight.weights_schema`; a test fails when the committed copy is stale.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field

SCHEMA_VERSION = "1.3"
SUPPORTED_SCHEMA_VERSIONS = ("1.1", "1.2", "1.3")
"""1.1 added physics.kinematic_viscosity_m2_s (the Reynolds scale of the graph's inputs); 1.0 cards lack it.
1.2 added the real-data sections (training_data.sources, training.latent_conditions, held_out), all optional.
1.3 added own_error (the model's own error per observable where the truth is known), optional."""
SCHEMA_PATH = Path(__file__).with_name("model_card.schema.json")

ExportableVariant = Literal["phys-nn", "phys-nn-pm", "phys-nn-pm-cq", "phys-nn+", "phys-q"]
Sha256 = Annotated[str, Field(pattern=r"^[0-9a-f]{64}$", description="SHA-256, lower-case hex")]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class TensorSpec(_Strict):
    """One input or output of the ONNX graph."""

    name: str
    dtype: Literal["float32"]
    shape: list[int | Literal["N"]] = Field(description="'N' is the dynamic batch dimension")
    unit: str
    description: str


class OnnxGraph(_Strict):
    """The coefficient model as an ONNX graph: (v_rel, omega) -> (C_L, C_D, C_M, C_Q) for a batch of balls."""

    file: str
    sha256: Sha256
    opset: int = Field(ge=7)
    inputs: list[TensorSpec] = Field(min_length=2, max_length=2)
    outputs: list[TensorSpec] = Field(min_length=1, max_length=1)
    output_columns: list[str]
    contents: str = Field(description="what the graph computes, so nothing outside it is needed")


class Architecture(_Strict):
    """How the coefficients are computed inside the graph."""

    kind: Literal["mlp", "quadratic-in-spin-ratio"]
    input_normalisation: str | None
    hidden_units: list[int]
    activation: Literal["relu"] | None
    heads: list[str] = Field(description="raw network outputs in order, before their output transforms")
    coefficient_equations: list[str]
    p_m: Positive | None = Field(description="learned C_M = p_M S factor (pM variants)")
    quadratic_params: list[float] | None = Field(description="Phys-Q p0..p6 as in the equations")


class Physics(_Strict):
    """Constants, conventions and equations of the simulation the model was trained inside."""

    ball_mass_kg: Positive
    ball_radius_m: Positive
    ball_area_m2: Positive
    ball_inertia_kg_m2: Positive
    gravity_mps2: Positive
    tee_height_m: NonNegative
    air_density_kg_m3: Positive = Field(description="reference air density the model was trained at")
    kinematic_viscosity_m2_s: Positive = Field(
        description="kinematic viscosity nu_0 of that air; in air of viscosity nu the graph is fed v_rel * nu_0/nu "
        "and omega * nu_0/nu (the same spin ratio at the actual Reynolds number)"
    )
    density_note: str
    integrator: Literal["forward-euler"]
    dt_s: Positive
    t_sim_s: Positive
    landing_search_start_s: NonNegative = Field(
        description="where the soft-argmax landing of training's L_p loss starts its search (s); the reported landing "
        "is the first downward crossing of r_z = 0, in training as at runtime"
    )
    axes: str
    launch_state: str
    equations: list[str]
    landing: str


class SourceFile(_Strict):
    """One file a training source was converted from."""

    path: str = Field(description="relative to the shared data folder")
    sha256: Sha256


class TrainingSource(_Strict):
    """One source of a merged training file, with what it contributed and how much a shot of it weighs."""

    name: str
    kind: Literal["measured", "modelled", "synthetic"] = Field(
        description="measured flights; a launch monitor's own model of the flight; our reference world"
    )
    files: list[SourceFile]
    n_rows: int = Field(ge=0)
    n_train: int = Field(ge=0)
    n_val: int = Field(ge=0)
    weight: NonNegative = Field(description="weight of one shot of this source in the loss")
    observables: list[str] = Field(description="what its shots were trained on")
    note: str


class TrainingData(_Strict):
    """The data the model was trained and validated on."""

    file: str
    sha256: Sha256
    n_rows: int = Field(ge=0)
    n_train: int = Field(ge=1)
    n_val: int = Field(ge=1)
    n_landing_targets: int = Field(ge=0)
    n_apex_targets: int = Field(ge=0)
    density_min_kg_m3: Positive
    density_max_kg_m3: Positive
    n_with_wind: int = Field(ge=0, description="shots with recorded wind, trained as calm air")
    min_apex_m: NonNegative
    filters: dict[str, int] = Field(description="shots left out, by reason, in the order applied")
    split: str
    sources: list[TrainingSource] | None = Field(default=None, description="the sources merged into `file`")


class TrainingSettings(_Strict):
    """How the model was trained."""

    optimizer: Literal["adam"]
    learning_rate: Positive
    batch_size: int = Field(ge=1)
    epochs: int = Field(ge=1)
    best_epoch: int = Field(ge=1)
    loss: Literal["lp", "lp+lh", "observables"]
    loss_description: str
    seed: int
    grad_clip_norm: Positive
    soft_argmax_temperature_m: Positive
    limit: int | None
    latent_conditions: str | None = Field(
        default=None, description="the unrecorded conditions fitted beside the network, and their priors"
    )


class Validation(_Strict):
    """Validation metrics of the exported checkpoint (mean over the val split, inference landing)."""

    n_shots: int = Field(ge=1)
    landing_error_m: NonNegative
    landing_error_yd: NonNegative
    max_height_error_m: NonNegative | None
    max_height_error_yd: NonNegative | None


class HeldOutResult(_Strict):
    """The exported model's error on one held-out set (never trained on, never used to select the model), flown
    through the runtime path, calm, in the set's own air where it is known (the note says which), else the card's."""

    name: str
    path: str = Field(description="relative to the shared data folder")
    sha256: Sha256
    rows: str = Field(description="which rows of the file: all, a line range or rounds")
    n_shots: int = Field(ge=1)
    errors: dict[str, NonNegative] = Field(description="mean absolute error per observable (SI units in the key)")
    note: str


class OwnError(_Strict):
    """The model's own 1-sigma error per observable, measured where the truth is known (against its teacher on
    clean launches, or on held-out real data with the measurement noise taken out): what `golfflight diagnose`
    expects of the model itself, beside the launch monitor's noise. Not the validation error, which also holds its
    data's noise and unrecorded weather."""

    sigma: dict[str, NonNegative] = Field(
        description="RMS error per observable: carry_y_m, carry_x_m, apex_m, flight_time_s, landing_angle_deg"
    )
    measured_against: str = Field(description="the truth it was measured against, and how")
    n_shots: int = Field(ge=1)


class ExportCheck(_Strict):
    """ONNX Runtime against the training framework on a probe batch, checked at export."""

    probe_points: int = Field(ge=1)
    max_abs_coefficient_difference: NonNegative


class Producer(_Strict):
    """Software that produced the bundle."""

    golfflight: str
    python: str
    torch: str
    onnx: str
    onnxruntime: str
    numpy: str
    created_utc: str


class ModelCard(_Strict):
    """model_card.json of a model bundle."""

    schema_version: Literal["1.1", "1.2", "1.3"]
    variant: ExportableVariant
    architecture: Architecture
    onnx: OnnxGraph
    physics: Physics
    training_data: TrainingData
    training: TrainingSettings
    validation: Validation
    export_check: ExportCheck
    producer: Producer
    held_out: list[HeldOutResult] | None = Field(default=None, description="error on each held-out real set")
    own_error: OwnError | None = Field(default=None, description="the model's own error where the truth is known")


def schema_text() -> str:
    """The JSON Schema of `ModelCard`, formatted as committed."""
    return json.dumps(ModelCard.model_json_schema(), indent=2, sort_keys=True) + "\n"


def write_schema(path: Path = SCHEMA_PATH) -> Path:
    """Regenerate the committed JSON Schema file."""
    path.write_text(schema_text())
    return path

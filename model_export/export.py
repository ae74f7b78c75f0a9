"""Export a trained physics variant as a model bundle: model.onnx (the coefficient model only) + model_card.json.

The graph takes the air-relative velocity and spin [N,3] float32 and returns [N,4] float32 = C_L, C_D, C_M, C_Q,
with the input normalisation, sigmoid heads and p_M S inside, so a consumer needs the card's equations and
nothing else. Written with the TorchScript exporter (the MLP exports in well under a second) at a pinned opset.
"""

from __future__ import annotations

import copy
import importlib.metadata
import json
import os
import platform
import warnings
from collections.abc import Callable
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
import onnx
import onnxruntime as ort
import torch
from golfflight.errors import InputError
from golfflight.flight.air import Air
from golfflight.flight.bundle_check import OUTPUT_COLUMNS
from golfflight.flight.coefficients import BASE_DYNAMIC_PRESSURE
from golfflight.flight.constants import (
    BALL_AREA_M2,
    BALL_INERTIA_KG_M2,
    BALL_MASS_KG,
    BALL_RADIUS_M,
    GRAVITY_MPS2,
    TEE_HEIGHT_M,
)
from golfflight.flight.physics import TINY
from golfflight.flight.rollout import LANDING_SEARCH_START_S
from golfflight.model_export import PHYSICS_VARIANTS
from golfflight.model_export.training import TrainConfig, load_checkpoint, model_from_checkpoint
from golfflight.model_export.variants import SPIN_SCALE_RADPS, VELOCITY_SCALE_MPS, PhysNN, PhysQ
from golfflight.shots.files import write_atomic
from golfflight.weights_schema.bundle import CARD_FILE, sha256_of
from golfflight.weights_schema.model_card import SCHEMA_VERSION, Architecture, ModelCard, TensorSpec
from torch import nn

OPSET = 17
ONNX_FILE = "model.onnx"
VELOCITY_INPUT, SPIN_INPUT, OUTPUT = "v_rel", "omega", "coefficients"
PARITY_TOLERANCE = 1e-5
"""Largest |ONNX Runtime - torch| coefficient difference an export may have."""

AXES = (
    "Right-handed, metres and seconds. x: to the right of the target line seen from behind the golfer; "
    "y: along the target line towards the target; z: up. The ball starts at r0 = (0, 0, tee_height_m); "
    "the ground is the plane z = 0."
)
LAUNCH_STATE = (
    "v0 = |v0| (cos(gamma) sin(phi), cos(gamma) cos(phi), sin(gamma)) with gamma the vertical launch angle and phi "
    "the launch direction (positive = right). omega0 = |omega| (cos(psi), 0, -sin(psi)) rad/s with |omega| = "
    "rpm * 2 pi / 60 and psi the spin axis (positive = tilted right: the ball curves right); rifle spin is zero."
)
EQUATIONS = [
    "v_rel = v - v_wind (v_wind = 0 in training)",
    (
        "(C_L, C_D, C_M, C_Q) = graph(k v_rel, k omega), evaluated once per step, k = nu_0 / nu with nu the kinematic "
        "viscosity of the air (dynamic viscosity / density) and nu_0 = physics.kinematic_viscosity_m2_s: the same spin "
        "ratio at the Reynolds number of the actual air (k = 1 in the card's air)"
    ),
    "q = C_Q * rho * |v_rel|^2 (C_Q = 0.5 is the usual dynamic pressure 1/2 rho |v|^2)",
    "F_drag = -C_D * q * A * v_rel / |v_rel|, A = pi R^2",
    (
        "F_lift = C_L * q * A * (omega x v_rel) / |omega x v_rel| (Magnus force along omega x v: "
        "back spin lifts the ball, a positive spin axis curves it right; the paper's eq. 4 has the opposite order, "
        "an erratum)"
    ),
    "T = -C_M * q * d * A * omega / |omega|, d = 2R",
    (
        "dr/dt = v; dv/dt = (F_drag + F_lift) / m - g e_z; domega/dt = T / I with I = 2/5 m R^2 "
        "(spin magnitude only decreases; the paper's eq. 14 sign is an erratum)"
    ),
    "every |x| in a denominator is max(|x|, 1e-12)",
    "forward Euler: r, v, omega at step i+1 = value at step i + dt * derivative at step i, from t = 0 to t_sim",
]
LANDING = (
    "Landing: the first step i with r_z,i > 0 >= r_z,i+1 (z_a > 0 >= z_b); the state is interpolated linearly to r_z = "
    "0 between the two (fraction z_a / (z_a - z_b)); landing point = (x, y) there. Max height: the vertex of the "
    "parabola through the highest step k up to the landing and its two neighbours, z_k - (z_{k-1} - z_{k+1})^2 / (8 "
    "(z_{k-1} - 2 z_k + z_{k+1})) at t_k + dt (z_{k-1} - z_{k+1}) / (2 (z_{k-1} - 2 z_k + z_{k+1})) (the highest step "
    "itself where it is the first or last or the three do not bend down): about g dt^2 / 8 (1.2 cm at 0.1 s) above it "
    "at most. Training (flight.rollout) and the runtime (flight.engine, flight.integrator) measure both by one rule "
    "(flight.events). The soft-argmax landing of the L_p loss searches from landing_search_start_s on."
)


class LeanPhysNN(nn.Module):
    """A Phys-NN model's coefficient function rearranged for a small graph (the same numbers to float rounding):
    input scaling folded into the first layer, the heads padded to the four output columns, then one `tail` Gemm
    that scales the sigmoids, adds the constant C_Q and p_M S in one go. For one shot a step pays a fixed cost per
    graph node, so fewer nodes mean a faster single-shot step (benchmarks/bench_graph.py)."""

    def __init__(self, model: PhysNN):
        super().__init__()
        layers = [copy.deepcopy(layer).float() for layer in model.net]
        first, last = layers[0], layers[-1]
        with torch.no_grad():
            first.weight.mul_(torch.tensor([1 / VELOCITY_SCALE_MPS, 1 / SPIN_SCALE_RADPS]))
            padded = nn.Linear(last.in_features, len(OUTPUT_COLUMNS))
            padded.weight.zero_()
            padded.bias.zero_()
            for row, name in enumerate(model.heads):
                padded.weight[OUTPUT_COLUMNS.index(name)] = last.weight[row]
                padded.bias[OUTPUT_COLUMNS.index(name)] = last.bias[row]
        self.net = nn.Sequential(*layers[:-1], padded)
        self.learned_moment = model.learned_moment
        head_scale = {"C_L": 0.5, "C_D": 0.5, "C_M": 1 / 50, "C_Q": 1.0}
        self.tail = nn.Linear(len(OUTPUT_COLUMNS) + int(self.learned_moment), len(OUTPUT_COLUMNS))
        with torch.no_grad():
            self.tail.weight.zero_()
            for column, name in enumerate(OUTPUT_COLUMNS):
                self.tail.weight[column, column] = head_scale[name] if name in model.heads else 0.0
            if self.learned_moment:
                self.tail.weight[OUTPUT_COLUMNS.index("C_M"), -1] = BALL_RADIUS_M * float(model.p_m.detach())
            self.tail.bias.copy_(
                torch.tensor([0.0, 0.0, 0.0, 0.0 if model.learned_pressure else BASE_DYNAMIC_PRESSURE])
            )

    def forward(self, v_rel: torch.Tensor, omega: torch.Tensor) -> torch.Tensor:
        speed = torch.linalg.vector_norm(v_rel, dim=-1, keepdim=True)
        spin_rate = torch.linalg.vector_norm(omega, dim=-1, keepdim=True)
        heads = torch.sigmoid(self.net(torch.cat([speed, spin_rate], dim=-1)))
        if self.learned_moment:
            heads = torch.cat([heads, spin_rate / speed.clamp_min(TINY)], dim=-1)
        return self.tail(heads)


def export_onnx(model: nn.Module, path: str | os.PathLike) -> None:
    """Write the coefficient graph of a physics variant (float32, dynamic batch, opset OPSET)."""
    model = model.float().eval()
    if isinstance(model, PhysNN):
        model = LeanPhysNN(model).eval()
    example = (torch.zeros(2, 3), torch.zeros(2, 3))
    batch = {0: "N"}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        torch.onnx.export(
            model,
            example,
            str(path),
            dynamo=False,
            opset_version=OPSET,
            input_names=[VELOCITY_INPUT, SPIN_INPUT],
            output_names=[OUTPUT],
            dynamic_axes={VELOCITY_INPUT: batch, SPIN_INPUT: batch, OUTPUT: batch},
        )
    onnx.checker.check_model(str(path))


def probe_inputs(n: int = 4096, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Velocities (3-90 m/s, any direction with forward motion) and spins (0-1100 rad/s) covering golf flights."""
    rng = np.random.default_rng(seed)
    velocity = rng.normal(0, 1, (n, 3)) * [0.2, 1.0, 0.6]
    velocity[:, 1] = np.abs(velocity[:, 1])
    velocity *= (rng.uniform(3.0, 90.0, n) / np.linalg.norm(velocity, axis=-1))[:, None]
    spin = rng.normal(0, 1, (n, 3)) * [1.0, 0.05, 0.4]
    spin *= (rng.uniform(0.0, 1100.0, n) / np.linalg.norm(spin, axis=-1))[:, None]
    return velocity.astype(np.float32), spin.astype(np.float32)


def onnx_torch_difference(
    model: nn.Module, onnx_path: str | os.PathLike, velocity: np.ndarray, spin: np.ndarray
) -> float:
    """Largest absolute coefficient difference between ONNX Runtime and the torch model on the same float32 inputs."""
    session = ort.InferenceSession(str(onnx_path), providers=["CPUExecutionProvider"])
    got = session.run([OUTPUT], {VELOCITY_INPUT: velocity, SPIN_INPUT: spin})[0]
    with torch.no_grad():
        expected = model.float().eval()(torch.from_numpy(velocity), torch.from_numpy(spin)).numpy()
    return float(np.max(np.abs(got - expected)))


def describe_architecture(model: nn.Module) -> Architecture:
    """The card's account of what the graph computes."""
    if isinstance(model, PhysQ):
        return Architecture(
            kind="quadratic-in-spin-ratio",
            input_normalisation=None,
            hidden_units=[],
            activation=None,
            heads=[],
            coefficient_equations=[
                "S = R |omega| / |v_rel|",
                "C_L = max(0, p0 + p1 S + p2 S^2)",
                "C_D = p3 + p4 S + p5 S^2",
                "C_M = p6 S",
                "C_Q = 0.5",
            ],
            p_m=None,
            quadratic_params=[float(p) for p in model.params.detach()],
        )
    assert isinstance(model, PhysNN)
    transforms = {
        "C_L": "C_L = sigmoid(h_C_L) / 2",
        "C_D": "C_D = sigmoid(h_C_D) / 2",
        "C_M": "C_M = sigmoid(h_C_M) / 50",
        "C_Q": "C_Q = sigmoid(h_C_Q)",
    }
    equations = [transforms[head] for head in model.heads]
    if model.learned_moment:
        equations.append("C_M = p_M * S, S = R |omega| / |v_rel|")
    if not model.learned_pressure:
        equations.append("C_Q = 0.5")
    return Architecture(
        kind="mlp",
        input_normalisation=(
            f"x = [|v_rel| / {VELOCITY_SCALE_MPS}, |omega| / {SPIN_SCALE_RADPS}] (2 values: speed and spin rate)"
        ),
        hidden_units=list(model.hidden),
        activation="relu",
        heads=[f"h_{head}" for head in model.heads],
        coefficient_equations=equations,
        p_m=float(model.p_m.detach()) if model.learned_moment else None,
        quadratic_params=None,
    )


def _versions() -> dict[str, str]:
    """The versions that wrote the bundle, and when (the card's producer)."""
    return {
        "golfflight": importlib.metadata.version("golfflight"),
        "python": platform.python_version(),
        "torch": torch.__version__,
        "onnx": onnx.__version__,
        "onnxruntime": ort.__version__,
        "numpy": np.__version__,
        "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
    }


def _onnx_section(onnx_sha256: str) -> dict[str, Any]:
    """The card's account of the graph file: its hash, opset, tensors and what it computes."""
    spec = {"dtype": "float32", "shape": ["N", 3]}
    return {
        "file": ONNX_FILE,
        "sha256": onnx_sha256,
        "opset": OPSET,
        "inputs": [
            TensorSpec(
                name=VELOCITY_INPUT,
                unit="m/s",
                description="ball velocity relative to the air, per ball",
                **spec,
            ),
            TensorSpec(name=SPIN_INPUT, unit="rad/s", description="ball spin vector, per ball", **spec),
        ],
        "outputs": [
            TensorSpec(
                name=OUTPUT,
                dtype="float32",
                shape=["N", 4],
                unit="1",
                description="aerodynamic coefficients per ball",
            )
        ],
        "output_columns": list(OUTPUT_COLUMNS),
        "contents": "the whole coefficient model: input normalisation, network or polynomial, output "
        "transforms (sigmoid heads, p_M S, constant C_Q); the equations of motion are not in the graph",
    }


def _physics_section(config: TrainConfig) -> dict[str, Any]:
    """The ball, the air and the integration the graph was trained in: what a consumer must simulate."""
    return {
        "ball_mass_kg": BALL_MASS_KG,
        "ball_radius_m": BALL_RADIUS_M,
        "ball_area_m2": BALL_AREA_M2,
        "ball_inertia_kg_m2": BALL_INERTIA_KG_M2,
        "gravity_mps2": GRAVITY_MPS2,
        "tee_height_m": TEE_HEIGHT_M,
        "air_density_kg_m3": float(Air.standard().density_kg_m3),
        "kinematic_viscosity_m2_s": float(Air.standard().kinematic_viscosity_m2_s),
        "density_note": "ICAO standard air (15 degC, sea level, dry). Shots with recorded conditions were "
        "trained with their own density and viscosity (density range in training_data); simulate a shot "
        "with the density and viscosity of its air.",
        "integrator": "forward-euler",
        "dt_s": config.dt_s,
        "t_sim_s": config.t_sim_s,
        "landing_search_start_s": LANDING_SEARCH_START_S,
        "axes": AXES,
        "launch_state": LAUNCH_STATE,
        "equations": EQUATIONS,
        "landing": LANDING,
    }


def _training_data_section(payload: dict[str, Any]) -> dict[str, Any]:
    """The checkpoint's data summary and how it was split into training and validation."""
    return {
        **payload["data"],
        "split": payload.get(
            "split",
            "validation = the rows marked 'val' in the file's split column (never a random shuffle); "
            "training = the rows marked 'train'",
        ),
    }


def _training_section(config: TrainConfig, payload: dict[str, Any]) -> dict[str, Any]:
    """How the checkpoint was trained: optimiser, loss, epochs and the settings that reproduce it."""
    return {
        "optimizer": "adam",
        "learning_rate": config.lr,
        "batch_size": config.batch_size,
        "epochs": payload["epoch"],
        "best_epoch": payload["metrics"]["epoch"],
        "loss": config.loss,
        "loss_description": payload.get(
            "loss_description",
            "L_p = mean |soft-argmax landing (x, y) - target|"
            + (" + L_h = mean |parabola apex - apex|" if config.loss == "lp+lh" else "")
            + " over the shots that have each target, in metres",
        ),
        "latent_conditions": payload.get("latent_conditions"),
        "seed": config.seed,
        "grad_clip_norm": config.grad_clip_norm,
        "soft_argmax_temperature_m": config.soft_argmax_temperature_m,
        "limit": config.limit,
    }


def _validation_section(payload: dict[str, Any]) -> dict[str, Any]:
    """The best epoch's errors on the validation shots, in metres and yards."""
    metrics = payload["metrics"]
    return {
        "n_shots": payload["data"]["n_val"],
        "landing_error_m": metrics["landing_error_m"],
        "landing_error_yd": metrics["landing_error_yd"],
        "max_height_error_m": metrics.get("max_height_error_m"),
        "max_height_error_yd": metrics.get("max_height_error_yd"),
    }


def build_card(
    model: nn.Module,
    config: TrainConfig,
    payload: dict[str, Any],
    onnx_sha256: str,
    difference: float,
    probe_points: int,
) -> ModelCard:
    """Assemble and validate the model card of a checkpoint `payload` (config, data summary, metrics)."""
    return ModelCard.model_validate(
        {
            "schema_version": SCHEMA_VERSION,
            "variant": config.variant,
            "architecture": describe_architecture(model),
            "onnx": _onnx_section(onnx_sha256),
            "physics": _physics_section(config),
            "training_data": _training_data_section(payload),
            "training": _training_section(config, payload),
            "validation": _validation_section(payload),
            "export_check": {"probe_points": probe_points, "max_abs_coefficient_difference": difference},
            "producer": _versions(),
        }
    )


def _replace_atomically(directory: Path, name: str, write: Callable[[Path], object]) -> None:
    """One file of the bundle, written whole or not at all (the seam the crash test breaks)."""
    write_atomic(directory / name, lambda tmp: write(Path(tmp)))


def export_bundle(model: nn.Module, payload: dict[str, Any], out_dir: str | os.PathLike) -> ModelCard:
    """Write model.onnx and model_card.json for a trained physics model and its checkpoint `payload`, after
    checking ONNX Runtime reproduces the torch coefficients within PARITY_TOLERANCE."""
    config = TrainConfig(**payload["config"])
    if config.variant not in PHYSICS_VARIANTS:
        raise InputError(
            f"variant {config.variant!r} has no coefficient graph to export "
            "(the NN baseline is trained and evaluated in torch only)"
        )
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    velocity, spin = probe_inputs()
    card: ModelCard | None = None

    def write_onnx(tmp: Path) -> None:
        nonlocal card
        export_onnx(model, tmp)
        difference = onnx_torch_difference(model, tmp, velocity, spin)
        if not difference <= PARITY_TOLERANCE:
            raise RuntimeError(
                f"ONNX Runtime differs from torch by {difference:.3g} (> {PARITY_TOLERANCE}); bundle not written"
            )
        card = build_card(model, config, payload, sha256_of(tmp), difference, len(velocity))

    _replace_atomically(out_dir, ONNX_FILE, write_onnx)
    _replace_atomically(
        out_dir, CARD_FILE, lambda tmp: tmp.write_text(json.dumps(card.model_dump(mode="json"), indent=2) + "\n")
    )
    return card


def export_checkpoint(checkpoint: str | os.PathLike, out_dir: str | os.PathLike) -> ModelCard:
    """Export a training checkpoint (a file, or a run directory meaning its best.pt) as a bundle."""
    checkpoint = Path(checkpoint)
    if checkpoint.is_dir():
        checkpoint = checkpoint / "best.pt"
    if not checkpoint.is_file():
        raise FileNotFoundError(f"no checkpoint at {checkpoint}")
    payload = load_checkpoint(checkpoint)
    model, _ = model_from_checkpoint(payload)
    return export_bundle(model, payload, out_dir)

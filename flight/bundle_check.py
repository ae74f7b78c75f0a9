"""What `weights_schema.load_bundle` cannot check without running the graph: the ONNX file opens in ONNX Runtime,
its inputs and outputs are exactly the ones its card declares (and the ones the engine feeds), and it gives finite
coefficients over every speed and spin a flight can reach. Every failure is a `BundleError` naming the file."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import onnxruntime as ort
from golfflight.flight import limits
from golfflight.flight.constants import RPM_TO_RADPS
from golfflight.weights_schema.bundle import CARD_FILE, BundleError, load_bundle
from golfflight.weights_schema.model_card import ModelCard

INPUT_SHAPE = ["N", 3]
OUTPUT_SHAPE = ["N", 4]
OUTPUT_COLUMNS = ["C_L", "C_D", "C_M", "C_Q"]
"""What the engine feeds the graph (v_rel and omega, [N,3] each) and reads back ([N,4], these columns)."""

PROBE_SPEEDS_MPS = (0.0, 0.01, 0.5, 5.0, 20.0, 45.0, 70.0, limits.BALL_SPEED_MPS.high, 130.0)
"""Air-relative speeds probed: from a ball at rest to the fastest launch into the strongest headwind."""

PROBE_SPINS_RPM = (0.0, 100.0, 1000.0, 3000.0, 7000.0, limits.SPIN_RPM.high)


def probe_set() -> tuple[np.ndarray, np.ndarray]:
    """(v_rel, omega) [M,3] float32: every probe speed in rising, falling and sideways directions against every
    probe spin about back-spin, tilted and side axes."""
    directions = np.array([[0, 1, 0], [0, 0.7, 0.7], [0, 0.7, -0.7], [0.7, 0.7, 0], [-0.6, 0.5, -0.6], [0, 0, -1]])
    axes = np.array([[1, 0, 0], [0.87, 0, -0.5], [0.87, 0, 0.5], [0, 0, 1], [0.6, 0.6, 0.5]])
    directions = directions / np.linalg.norm(directions, axis=1, keepdims=True)
    axes = axes / np.linalg.norm(axes, axis=1, keepdims=True)
    velocity = (np.array(PROBE_SPEEDS_MPS)[:, None, None] * directions[None]).reshape(-1, 3)
    spin = (np.array(PROBE_SPINS_RPM)[:, None, None] * RPM_TO_RADPS * axes[None]).reshape(-1, 3)
    rows_v = np.repeat(velocity, len(spin), axis=0)
    rows_w = np.tile(spin, (len(velocity), 1))
    return rows_v.astype(np.float32), rows_w.astype(np.float32)


def check_card_interface(card: ModelCard, card_path: Path) -> None:
    """The card declares the interface the engine uses: two float32 [N,3] inputs, one float32 [N,4] output with
    columns C_L, C_D, C_M, C_Q."""
    problems = [
        f"input {spec.name!r} has shape {spec.shape}, the engine feeds {INPUT_SHAPE}"
        for spec in card.onnx.inputs
        if spec.shape != INPUT_SHAPE
    ]
    output = card.onnx.outputs[0]
    if output.shape != OUTPUT_SHAPE:
        problems.append(f"output {output.name!r} has shape {output.shape}, the engine reads {OUTPUT_SHAPE}")
    if card.onnx.output_columns != OUTPUT_COLUMNS:
        problems.append(f"output columns {card.onnx.output_columns}, the engine reads {OUTPUT_COLUMNS}")
    if problems:
        raise BundleError(f"{card_path}: the card's ONNX interface is not the engine's: {'; '.join(problems)}")


def _described(args) -> list[tuple[str, str, list]]:
    return [(arg.name, arg.type, [d if isinstance(d, int) else "N" for d in arg.shape]) for arg in args]


def check_graph_interface(card: ModelCard, session: ort.InferenceSession, onnx_path: Path) -> None:
    """The graph's own inputs and outputs match the card's names, float32 type and shapes (any symbolic dimension
    counts as the batch dimension N)."""
    declared_in = [(spec.name, "tensor(float)", spec.shape) for spec in card.onnx.inputs]
    declared_out = [(spec.name, "tensor(float)", spec.shape) for spec in card.onnx.outputs]
    actual_in, actual_out = _described(session.get_inputs()), _described(session.get_outputs())
    if actual_in != declared_in or actual_out != declared_out:
        raise BundleError(
            f"{onnx_path}: the graph's inputs {actual_in} and outputs {actual_out} are not the card's "
            f"{declared_in} and {declared_out}"
        )


def check_coefficients(card: ModelCard, session: ort.InferenceSession, onnx_path: Path) -> None:
    """The coefficients on `probe_set()` are all finite."""
    velocity, spin = probe_set()
    names = [spec.name for spec in card.onnx.inputs]
    try:
        coefficients = session.run([card.onnx.outputs[0].name], {names[0]: velocity, names[1]: spin})[0]
    except Exception as error:  # noqa: BLE001 - ORT's own exception types; any failure here refuses the bundle
        raise BundleError(f"{onnx_path}: the graph failed on the probe set ({type(error).__name__}: {error})") from None
    bad = ~np.isfinite(coefficients).all(axis=1)
    if coefficients.shape != (len(velocity), len(OUTPUT_COLUMNS)) or bad.any():
        where = np.flatnonzero(bad)[:3]
        examples = "; ".join(
            f"v_rel {velocity[i].tolist()} omega {spin[i].tolist()} -> {coefficients[i]}" for i in where
        )
        raise BundleError(
            f"{onnx_path}: non-finite or misshapen coefficients on the probe set "
            f"(shape {coefficients.shape}, {int(bad.sum())} of {len(velocity)} rows not finite: {examples})"
        )


def session_options(threads: int) -> ort.SessionOptions:
    """ORT options for `threads` cores whose idle threads sleep rather than spin (spinning threads steal the core
    the step's NumPy physics and other workers need)."""
    options = ort.SessionOptions()
    options.intra_op_num_threads = threads
    options.inter_op_num_threads = 1
    options.execution_mode = ort.ExecutionMode.ORT_SEQUENTIAL
    options.add_session_config_entry("session.intra_op.allow_spinning", "0")
    return options


def open_session(onnx_path: Path, options: ort.SessionOptions | None = None) -> ort.InferenceSession:
    """An ORT CPU session, or a BundleError if the file is not a graph ONNX Runtime can run."""
    try:
        return ort.InferenceSession(str(onnx_path), options, providers=["CPUExecutionProvider"])
    except Exception as error:  # noqa: BLE001 - ORT raises its own types (InvalidProtobuf, Fail, ...)
        raise BundleError(f"{onnx_path}: ONNX Runtime cannot load it ({type(error).__name__}: {error})") from None


def verify_session(card: ModelCard, session: ort.InferenceSession, onnx_path: Path) -> None:
    """Every runtime check of a bundle whose card and hash `load_bundle` already accepted."""
    check_card_interface(card, onnx_path.parent / CARD_FILE)
    check_graph_interface(card, session, onnx_path)
    check_coefficients(card, session, onnx_path)


def open_verified(directory: str | os.PathLike, threads: int = 1) -> tuple[ModelCard, Path, ort.InferenceSession]:
    """Load and verify a bundle completely (card, schema version, hash, graph interface, probe): its card, its ONNX
    path and the verified session on `threads` cores."""
    card, onnx_path = load_bundle(directory)
    session = open_session(onnx_path, session_options(threads))
    verify_session(card, session, onnx_path)
    return card, onnx_path, session


def verify_bundle(directory: str | os.PathLike) -> ModelCard:
    """Load and verify a bundle completely; its card."""
    return open_verified(directory)[0]

"""A shipped bundle back into torch, for fine-tuning from a bundle and for evaluating it through the torch path.

An MLP graph's initializers are the network's layers as exported by `export.LeanPhysNN` (input scaling folded
into the first layer, the heads padded to the four output columns; the tail's scales follow from the variant).
p_M and Phys-Q's seven parameters come from the card. The rebuilt model is checked against ONNX Runtime on probe
inputs before it is returned.
"""

from __future__ import annotations

import math
import os

import onnx
import torch
from golfflight.errors import InputError
from golfflight.flight.bundle_check import OUTPUT_COLUMNS
from golfflight.model_export.export import (
    PARITY_TOLERANCE,
    onnx_torch_difference,
    probe_inputs,
)
from golfflight.model_export.training import TrainConfig
from golfflight.model_export.variants import SPIN_SCALE_RADPS, VELOCITY_SCALE_MPS, PhysNN, build_model
from golfflight.weights_schema.bundle import load_bundle
from golfflight.weights_schema.model_card import ModelCard
from onnx import numpy_helper
from torch import nn


def _mlp_state(model: PhysNN, weights: dict[str, torch.Tensor], card: ModelCard) -> dict[str, torch.Tensor]:
    """The PhysNN state dict from the graph's layer initializers (undoing the lean layout) and the card's p_M."""
    state = {name: weights[name] for name in model.state_dict() if name.startswith("net.")}
    state["net.0.weight"] = state["net.0.weight"] * torch.tensor([VELOCITY_SCALE_MPS, SPIN_SCALE_RADPS])
    rows = [OUTPUT_COLUMNS.index(head) for head in model.heads]
    last = f"net.{len(model.net) - 1}"
    state[f"{last}.weight"] = state[f"{last}.weight"][rows]
    state[f"{last}.bias"] = state[f"{last}.bias"][rows]
    if model.learned_moment:
        state["log_p_m"] = torch.tensor(math.log(card.architecture.p_m))
    return state


def model_from_bundle(bundle_dir: str | os.PathLike) -> tuple[nn.Module, ModelCard]:
    """The bundle's coefficient model as a torch module (float32, eval mode) and its card.

    Raises InputError when the graph's weights do not fit the card's architecture or the rebuilt model does not
    reproduce the graph within the export tolerance."""
    card, onnx_path = load_bundle(bundle_dir)
    model = build_model(card.variant, card.architecture.hidden_units)
    weights = {
        tensor.name: torch.from_numpy(numpy_helper.to_array(tensor).copy())
        for tensor in onnx.load(str(onnx_path)).graph.initializer
    }
    try:
        if isinstance(model, PhysNN):
            state = _mlp_state(model, weights, card)
        else:
            state = {"params": torch.tensor(card.architecture.quadratic_params)}
        model.load_state_dict(state)
    except (KeyError, RuntimeError, TypeError) as error:
        raise InputError(
            f"{onnx_path}: its weights do not fit a {card.variant} model {card.architecture.hidden_units} ({error})"
        ) from None
    model.eval()
    difference = onnx_torch_difference(model, onnx_path, *probe_inputs())
    if not difference <= PARITY_TOLERANCE:
        raise InputError(f"{onnx_path}: torch weights rebuilt from the graph differ from it by {difference:.3g}")
    return model, card


def config_from_card(card: ModelCard) -> TrainConfig:
    """The training settings a bundle's card records, as a TrainConfig (the starting point of a fine-tune); a model
    trained on every observable is fine-tuned with the landing and max-height loss (what a user's file holds)."""
    training = card.training
    return TrainConfig(
        variant=card.variant,
        hidden=tuple(card.architecture.hidden_units),
        epochs=training.epochs,
        batch_size=training.batch_size,
        lr=training.learning_rate,
        loss="lp+lh" if training.loss == "observables" else training.loss,
        seed=training.seed,
        grad_clip_norm=training.grad_clip_norm,
        soft_argmax_temperature_m=training.soft_argmax_temperature_m,
        min_apex_m=card.training_data.min_apex_m,
        dt_s=card.physics.dt_s,
        t_sim_s=card.physics.t_sim_s,
    )

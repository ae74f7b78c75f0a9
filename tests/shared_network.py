"""Tests' NumPy Flyer of the torch engine's own network, so that the NumPy integrator, the torch engine and training's
rollout fly the same coefficients and differ only in their arithmetic (and, where they differ, in their rules)."""

from __future__ import annotations

import numpy as np
import torch
from golfflight.flight.flyer import Flyer
from golfflight.flight.physics import reynolds_scale
from golfflight.flight.rollout import InAir
from golfflight.flight.torch_engine import TorchEngine


class TorchNetwork:
    """The torch engine's own network (float32, as it runs it) as a NumPy coefficient model for the Flyer."""

    def __init__(self, engine: TorchEngine, scale: float | np.ndarray = 1.0) -> None:
        self.engine, self.scale = engine, scale

    def in_air(self, kinematic_viscosity_m2_s: float | np.ndarray) -> TorchNetwork:
        scale = reynolds_scale(np.asarray(kinematic_viscosity_m2_s), self.engine.flyer.kinematic_viscosity_m2_s)
        return TorchNetwork(self.engine, scale[:, None] if scale.ndim else float(scale))

    def take(self, index: np.ndarray) -> TorchNetwork:
        return TorchNetwork(self.engine, self.scale[index] if isinstance(self.scale, np.ndarray) else self.scale)

    @torch.no_grad()
    def __call__(self, v_rel: np.ndarray, omega: np.ndarray) -> np.ndarray:
        inputs = (torch.as_tensor(a * self.scale, dtype=torch.float64) for a in (v_rel, omega))
        return InAir(self.engine.network, run_in=torch.float32)(*inputs).numpy()


def numpy_flyer_of(engine: TorchEngine) -> Flyer:
    """A NumPy Flyer of the torch engine's network, with the engine's step, maximum flight time and nominal air."""
    onnx = engine.flyer
    return Flyer(TorchNetwork(engine), onnx.dt_s, onnx.max_flight_time_s, onnx.density_kg_m3,
                 onnx.kinematic_viscosity_m2_s)

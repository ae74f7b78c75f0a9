"""Coefficient model backed by an exported bundle's ONNX graph (ONNX Runtime, no torch).

model = OnnxCoefficients(path); card = model.card
flown by a `flight.flyer.Flyer` (`flight.flyer.load_flyer` assembles one from a bundle at its card's step and air).
In other air: `model.in_air(air.kinematic_viscosity_m2_s)` (the same graph, inputs at that air's Reynolds scale) and
that air's density.
"""

from __future__ import annotations

import copy
import os

import numpy as np
from golfflight.flight import xp
from golfflight.flight.bundle_check import open_verified
from golfflight.flight.physics import reynolds_scale


class OnnxCoefficients:
    """`flight.physics.CoefficientModel` running a bundle's graph: float32 in, float64 [N,4] C_L, C_D, C_M, C_Q out.
    The bundle is verified like the engine's (`flight.bundle_check`): a bad one raises BundleError."""

    def __init__(self, bundle_dir: str | os.PathLike, intra_op_threads: int = 1):
        self.card, self.onnx_path, self.session = open_verified(bundle_dir, intra_op_threads)
        self.velocity_name, self.spin_name = (spec.name for spec in self.card.onnx.inputs)
        self.output_name = self.card.onnx.outputs[0].name
        self.input_scale: float | np.ndarray = 1.0

    def in_air(self, kinematic_viscosity_m2_s: float | np.ndarray) -> OnnxCoefficients:
        """This model (sharing its ONNX session) for air of this kinematic viscosity: a float, or one per ball in
        the order the simulator passes them."""
        nominal = self.card.physics.kinematic_viscosity_m2_s
        scale = reynolds_scale(np.asarray(kinematic_viscosity_m2_s, dtype=float), nominal)
        other = copy.copy(self)
        other.input_scale = float(scale) if scale.ndim == 0 else scale[:, None]
        return other

    def take(self, index: np.ndarray) -> OnnxCoefficients:
        """This model for some of the balls (their own air's input scale)."""
        if xp.is_number(self.input_scale):
            return self
        other = copy.copy(self)
        other.input_scale = self.input_scale[index]
        return other

    def __call__(self, v_rel: np.ndarray, omega: np.ndarray) -> np.ndarray:
        feeds = {
            self.velocity_name: np.ascontiguousarray(v_rel * self.input_scale, dtype=np.float32),
            self.spin_name: np.ascontiguousarray(omega * self.input_scale, dtype=np.float32),
        }
        return self.session.run([self.output_name], feeds)[0].astype(np.float64)

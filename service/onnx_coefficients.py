"""Coefficient model backed by an exported bundle's ONNX graph (ONNX Runtime, no torch).

card, _ = load_bundle(path); model = OnnxCoefficients(path)
simulate(state, model, density=card.physics.air_density_kg_m3, dt=card.physics.dt_s, t_max=card.physics.t_sim_s)
"""

from __future__ import annotations

import os

import numpy as np
import onnxruntime as ort

from service.bundle_check import open_session, verify_session
from weights_schema.bundle import load_bundle


class OnnxCoefficients:
    """`service.physics.CoefficientModel` running a bundle's graph: float32 in, float64 [N,4] C_L, C_D, C_M, C_Q out.
    The bundle is verified like the engine's (`service.bundle_check`): a bad one raises BundleError."""

    def __init__(self, bundle_dir: str | os.PathLike, intra_op_threads: int = 1):
        self.card, self.onnx_path = load_bundle(bundle_dir)
        options = ort.SessionOptions()
        options.intra_op_num_threads = intra_op_threads
        options.inter_op_num_threads = 1
        self.session = open_session(self.onnx_path, options)
        verify_session(self.card, self.session, self.onnx_path)
        self.velocity_name, self.spin_name = (spec.name for spec in self.card.onnx.inputs)
        self.output_name = self.card.onnx.outputs[0].name

    def __call__(self, v_rel: np.ndarray, omega: np.ndarray) -> np.ndarray:
        feeds = {
            self.velocity_name: np.ascontiguousarray(v_rel, dtype=np.float32),
            self.spin_name: np.ascontiguousarray(omega, dtype=np.float32),
        }
        return self.session.run([self.output_name], feeds)[0].astype(np.float64)

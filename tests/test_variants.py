"""Model variants: coefficient ranges, the pM and cQ heads, Phys-Q's start values, the NN baseline's shape."""

from __future__ import annotations

from typing import get_args

import numpy as np
import pytest
import torch
from golfflight.flight.coefficients import QuadraticSpinRatio
from golfflight.model_export import PHYSICS_VARIANTS, VARIANTS
from golfflight.flight.physics import spin_ratio
from golfflight.model_export.variants import P_M_INIT, LandingNN, PhysNN, PhysQ, build_model
from golfflight.weights_schema.model_card import ExportableVariant

torch.set_num_threads(1)  # tiny models: one thread is as fast, and immune to other jobs on the 2 cores


def _inputs(n: int = 512, scale: float = 1.0) -> tuple[torch.Tensor, torch.Tensor]:
    generator = torch.Generator().manual_seed(0)
    velocity = torch.randn(n, 3, generator=generator) * 30 * scale
    spin = torch.randn(n, 3, generator=generator) * 400 * scale
    return velocity, spin


@pytest.mark.parametrize("variant", PHYSICS_VARIANTS)
def test_coefficients_have_shape_and_range(variant):
    torch.manual_seed(0)
    model = build_model(variant, hidden=(16, 8))
    for scale in (1.0, 1000.0):
        c = model.coefficients(*_inputs(scale=scale))
        assert c.shape == (512, 4) and torch.isfinite(c).all()
        c_lift, c_drag, c_moment, c_q = c.unbind(-1)
        assert (c_lift >= 0).all() and (c_moment >= 0).all() and (c_q > 0).all()
        if variant != "phys-q":
            assert (c_lift <= 0.5).all() and (c_drag >= 0).all() and (c_drag <= 0.5).all() and (c_q <= 1).all()


@pytest.mark.parametrize("variant", PHYSICS_VARIANTS)
def test_coefficients_ignore_the_direction_of_flight(variant):
    """Rotating or mirroring v_rel and omega together (a hook vs the mirrored slice) leaves the coefficients alone."""
    torch.manual_seed(0)
    model = build_model(variant, hidden=(16, 8))
    velocity, spin = _inputs()
    rotation, _ = torch.linalg.qr(torch.randn(3, 3, generator=torch.Generator().manual_seed(1)))
    mirror = torch.diag(torch.tensor([-1.0, 1.0, 1.0]))
    with torch.no_grad():
        expected = model.coefficients(velocity, spin)
        for transform in (rotation, mirror):
            torch.testing.assert_close(model.coefficients(velocity @ transform.T, spin @ transform.T), expected)


def test_base_variant_has_own_moment_head_and_base_pressure():
    model = PhysNN("phys-nn", hidden=(16,))
    c = model.coefficients(*_inputs())
    assert model.heads == ("C_L", "C_D", "C_M") and not hasattr(model, "log_p_m")
    assert (c[:, 2] <= 0.02).all()
    torch.testing.assert_close(c[:, 3], torch.full((512,), 0.5))


@pytest.mark.parametrize("variant", ["phys-nn-pm", "phys-nn-pm-cq", "phys-nn+"])
def test_pm_variants_make_moment_proportional_to_spin_ratio(variant):
    model = PhysNN(variant, hidden=(16,))
    velocity, spin = _inputs()
    c = model.coefficients(velocity, spin)
    assert float(model.p_m.detach()) == pytest.approx(P_M_INIT)
    torch.testing.assert_close(c[:, 2], P_M_INIT * spin_ratio(velocity, spin))
    with torch.no_grad():
        model.log_p_m.fill_(-40.0)
    assert float(model.p_m.detach()) > 0


def test_cq_head_varies_the_pressure_and_base_pm_keeps_half():
    velocity, spin = _inputs()
    pm = PhysNN("phys-nn-pm", hidden=(16,)).coefficients(velocity, spin)
    torch.testing.assert_close(pm[:, 3], torch.full((512,), 0.5))
    torch.manual_seed(1)
    cq = PhysNN("phys-nn-pm-cq", hidden=(16,)).coefficients(velocity, spin)
    assert cq[:, 3].std() > 0 and ((cq[:, 3] > 0) & (cq[:, 3] < 1)).all()


def test_phys_q_starts_at_ferguson():
    velocity, spin = _inputs()
    got = PhysQ(dtype=torch.float64).coefficients(velocity.double(), spin.double()).detach().numpy()
    np.testing.assert_allclose(got, QuadraticSpinRatio()(velocity.double().numpy(), spin.double().numpy()), atol=1e-12)


def test_hidden_units_are_configurable_and_nn_predicts_landing():
    model = PhysNN("phys-nn+", hidden=(32, 16, 8))
    widths = [layer.out_features for layer in model.net if isinstance(layer, torch.nn.Linear)]
    assert widths == [32, 16, 8, 3]
    assert LandingNN(hidden=(8,))(*_inputs()).shape == (512, 2)


def test_variant_names_agree_with_the_card():
    assert set(get_args(ExportableVariant)) == set(PHYSICS_VARIANTS)
    assert set(VARIANTS) - set(PHYSICS_VARIANTS) == {"nn"}
    with pytest.raises(ValueError, match="unknown variant"):
        build_model("phys-xx")

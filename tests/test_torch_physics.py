"""The PyTorch physics is the NumPy core's twin: same derivatives, same Euler flights, same landing."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from conftest import random_launches
from golfflight.flight.air import Air
from golfflight.flight.coefficients import ConstantCoefficients, QuadraticSpinRatio
from golfflight.flight.physics import State, initial_state
from golfflight.flight.physics import derivatives as np_derivatives
from golfflight.flight.rollout import (
    Trajectory,
    apex,
    euler_rollout,
    hard_landing,
    positions_at,
    soft_landing,
)
from golfflight.model_export.variants import PhysQ

from flights import simulate

torch.set_num_threads(1)  # tiny models: one thread is as fast, and immune to other jobs on the 2 cores

DENSITY = float(Air.standard().density_kg_m3)


def _torch(array: np.ndarray) -> torch.Tensor:
    return torch.as_tensor(array, dtype=torch.float64)


def _constant(c_lift: float, c_drag: float, c_moment: float, c_q: float = 0.5):
    row = torch.tensor([c_lift, c_drag, c_moment, c_q], dtype=torch.float64)
    return lambda v, w: row.expand(v.shape[0], 4)


@pytest.fixture(scope="module")
def launch_state() -> State:
    return initial_state(**random_launches(64, seed=5))


MODELS = [
    ("ferguson", QuadraticSpinRatio(), lambda: PhysQ(dtype=torch.float64)),
    ("constant", ConstantCoefficients(0.2, 0.25, 0.01, 0.45), lambda: _constant(0.2, 0.25, 0.01, 0.45)),
]


@pytest.mark.parametrize("name, numpy_model, torch_model", MODELS, ids=[m[0] for m in MODELS])
@torch.no_grad()
def test_derivatives_match_numpy(launch_state, name, numpy_model, torch_model):
    rng = np.random.default_rng(0)
    state = State(launch_state.position + rng.normal(0, 5, (64, 3)), launch_state.velocity, launch_state.spin)
    expected = np_derivatives(state, numpy_model, DENSITY)
    got = np_derivatives(State(_torch(state.position), _torch(state.velocity), _torch(state.spin)), torch_model(),
                         DENSITY)
    for e, g in zip((expected.position, expected.velocity, expected.spin), (got.position, got.velocity, got.spin),
                    strict=True):
        np.testing.assert_allclose(g.numpy(), e, rtol=0, atol=1e-6)


@pytest.mark.parametrize("name, numpy_model, torch_model", MODELS, ids=[m[0] for m in MODELS])
@torch.no_grad()
def test_euler_flights_and_landing_match_numpy(launch_state, name, numpy_model, torch_model):
    flight = simulate(launch_state, numpy_model, DENSITY, dt=0.1, t_max=10.0, keep_states=True)
    trajectory = euler_rollout(
        _torch(launch_state.position), _torch(launch_state.velocity), _torch(launch_state.spin), torch_model(), DENSITY
    )
    steps = len(flight.states)
    for state_name, trajectory_name in (("position", "positions"), ("velocity", "velocities"), ("spin", "spins")):
        expected = np.stack([getattr(s, state_name) for s in flight.states])
        np.testing.assert_allclose(getattr(trajectory, trajectory_name)[:steps].numpy(), expected, rtol=0, atol=1e-6)
    landing = hard_landing(trajectory)
    assert flight.landed.all() and landing.landed.all()
    np.testing.assert_allclose(landing.position.numpy(), flight.landing_position, rtol=0, atol=1e-6)
    np.testing.assert_allclose(landing.velocity.numpy(), flight.landing_velocity, rtol=0, atol=1e-6)
    np.testing.assert_allclose(landing.spin.numpy(), flight.landing_spin, rtol=0, atol=1e-6)
    np.testing.assert_allclose(landing.time_s.numpy(), flight.flight_time_s, rtol=0, atol=1e-9)
    measured = apex(trajectory)
    np.testing.assert_allclose(measured.height_m.numpy(), flight.apex_m, rtol=0, atol=1e-6)
    np.testing.assert_allclose(measured.time_s.numpy(), flight.apex_time_s, rtol=0, atol=1e-9)
    highest_step = np.stack([s.position[:, 2] for s in flight.states]).max(axis=0)
    assert (flight.apex_m - highest_step > 1e-4).any(), "the apex lies between the steps, not on the highest one"


def _low_and_high_launches() -> State:
    """Topped shots that land within 1 s (one launched downward from the tee), a flat one and full shots."""
    return initial_state(
        np.array([30.0, 20.0, 40.0, 25.0, 70.0, 60.0]),
        np.array([-5.0, 1.0, 2.0, 0.0, 12.0, 30.0]),
        np.array([0.0, 3.0, -2.0, 0.0, 1.0, -4.0]),
        np.array([500.0, 800.0, 1500.0, 0.0, 2500.0, 6000.0]),
        np.array([0.0, 10.0, -20.0, 0.0, 5.0, 0.0]),
    )


@pytest.mark.parametrize("name, numpy_model, torch_model", MODELS, ids=[m[0] for m in MODELS])
@pytest.mark.parametrize("t_max", [10.0, 2.5])
@torch.no_grad()
def test_landing_and_apex_are_measured_as_the_runtime_measures_them(name, numpy_model, torch_model, t_max):
    """Short flights (landing within 1 s, or on the first step) and, at 2.5 s, flights still in the air at the end:
    the same landing x/y, time and apex as the flight core's batch flight (`Flyer.flight`) within 1e-6 m."""
    state = _low_and_high_launches()
    flight = simulate(state, numpy_model, DENSITY, dt=0.1, t_max=t_max)
    trajectory = euler_rollout(
        _torch(state.position), _torch(state.velocity), _torch(state.spin), torch_model(), DENSITY, t_sim=t_max
    )
    landing, measured = hard_landing(trajectory), apex(trajectory)
    np.testing.assert_array_equal(landing.landed.numpy(), flight.landed)
    assert flight.landed[:4].all() and (flight.flight_time_s[:4] < 1.0).all()
    assert t_max == 10.0 or not flight.landed.all()
    np.testing.assert_allclose(landing.position.numpy()[flight.landed], flight.landing_position[flight.landed],
                               rtol=0, atol=1e-6)
    np.testing.assert_allclose(landing.time_s.numpy()[flight.landed], flight.flight_time_s[flight.landed],
                               rtol=0, atol=1e-9)
    np.testing.assert_allclose(measured.height_m.numpy(), flight.apex_m, rtol=0, atol=1e-6)
    np.testing.assert_allclose(trajectory.apex_m.numpy(), flight.apex_m, rtol=0, atol=1e-6)
    np.testing.assert_allclose(measured.time_s.numpy(), flight.apex_time_s, rtol=0, atol=1e-9)


@torch.no_grad()
def test_back_spin_lifts_side_spin_curves_right_and_spin_decays():
    state = initial_state(
        *(
            np.array([60.0, 60.0]),
            np.array([12.0, 12.0]),
            np.zeros(2),
            np.array([3000.0, 3000.0]),
            np.array([0.0, 15.0]),
        )
    )
    trajectory = euler_rollout(
        _torch(state.position), _torch(state.velocity), _torch(state.spin), PhysQ(dtype=torch.float64), DENSITY
    )
    vacuum = euler_rollout(
        _torch(state.position), _torch(state.velocity), _torch(state.spin), _constant(0, 0, 0), DENSITY
    )
    assert trajectory.apex_m[0] > vacuum.apex_m[0]
    assert hard_landing(trajectory).position[1, 0] > 1.0
    spin = torch.linalg.vector_norm(trajectory.spins, dim=-1)
    assert (spin[1:] < spin[:-1]).all()


@torch.no_grad()
def test_soft_argmax_tends_to_the_hard_argmax(launch_state):
    trajectory = euler_rollout(
        _torch(launch_state.position),
        _torch(launch_state.velocity),
        _torch(launch_state.spin),
        PhysQ(dtype=torch.float64),
        DENSITY,
    )
    z = trajectory.positions[10:, :, 2]
    nearest = 10 + torch.argmax(-z.abs(), dim=0)
    expected = trajectory.positions[nearest, torch.arange(64), :2]
    torch.testing.assert_close(soft_landing(trajectory, temperature_m=1e-4), expected, rtol=0, atol=1e-6)
    interpolated = hard_landing(trajectory).position[:, :2]
    assert (torch.linalg.vector_norm(soft_landing(trajectory) - interpolated, dim=-1)).mean() < 1.0


def test_soft_landing_has_gradients_and_no_landing_is_flagged():
    position = torch.tensor([[0.0, 0.0, 0.01]], dtype=torch.float64)
    velocity = torch.tensor([[0.0, 50.0, 20.0]], dtype=torch.float64)
    spin = torch.tensor([[300.0, 0.0, 0.0]], dtype=torch.float64)
    drag = torch.tensor(0.25, dtype=torch.float64, requires_grad=True)

    def coefficients(v: torch.Tensor, w: torch.Tensor) -> torch.Tensor:
        fixed = torch.tensor([0.15, 0.0, 0.0, 0.5], dtype=v.dtype)
        return torch.stack([fixed[0], drag, fixed[2], fixed[3]]).expand(v.shape[0], 4)

    trajectory = euler_rollout(position, velocity, spin, coefficients, DENSITY)
    soft_landing(trajectory)[0, 1].backward(retain_graph=True)
    assert drag.grad is not None and drag.grad < 0
    for measure in (lambda: hard_landing(trajectory).position[0, 1], lambda: apex(trajectory).height_m[0]):
        drag.grad = None
        measure().backward(retain_graph=True)
        assert drag.grad is not None and torch.isfinite(drag.grad) and drag.grad < 0
    short = Trajectory(trajectory.positions[:15], trajectory.velocities[:15], trajectory.spins[:15], 0.1)
    assert not hard_landing(short).landed.any()


def test_a_rollout_stopped_once_every_shot_is_down_reads_the_same_landing_apex_path_and_gradient(launch_state):
    """`stop_after_s`: the rollout stops at the first check after that time where every shot has come down, flying
    fewer steps; the landing, apex and positions up to that time are the full rollout's, and so is the gradient of a
    loss of them. A shot started at or below the ground has not come down by being below it: the rollout runs on."""
    model = PhysQ(dtype=torch.float64)
    start = [_torch(getattr(launch_state, name)) for name in ("position", "velocity", "spin")]
    with torch.no_grad():
        down_by_7_s = hard_landing(euler_rollout(*start, model, DENSITY)).time_s < 7.0
    start = [state[down_by_7_s] for state in start]
    times = torch.linspace(0.0, 3.0, 7, dtype=torch.float64).expand(len(start[0]), 7)

    def measured(stop_after_s: float | None) -> tuple[list[torch.Tensor], list[torch.Tensor], int]:
        model.zero_grad()
        trajectory = euler_rollout(*start, model, DENSITY, stop_after_s=stop_after_s)
        landing = hard_landing(trajectory)
        figures = [landing.position, landing.velocity, landing.time_s, apex(trajectory).height_m,
                   positions_at(trajectory, times)]
        sum(figure.sum() for figure in figures).backward()
        return figures, [p.grad.clone() for p in model.parameters()], trajectory.positions.shape[0]

    full, full_gradient, full_steps = measured(None)
    stopped, stopped_gradient, stopped_steps = measured(3.0)
    assert len(times) > 32 and full_steps == 101 and stopped_steps == 71
    for want, got in zip(full + full_gradient, stopped + stopped_gradient, strict=True):
        torch.testing.assert_close(got, want, rtol=0, atol=0)
    assert euler_rollout(*start, model, DENSITY, stop_after_s=9.0).positions.shape[0] == 91  # not before 9 s
    below = start[0].clone()
    below[0, 2] = -0.01
    assert euler_rollout(below, *start[1:], model, DENSITY, stop_after_s=0.0).positions.shape[0] == 101

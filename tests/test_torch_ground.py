"""The ground phase's one driver on torch tensors (`flight.ground.phase.roll_to_rest`, the torch engine's on a GPU)
against the engine's NumPy ground phase on the same landings: the same code, so the same rests, hops and times to
rounding."""

from __future__ import annotations

import numpy as np
import pytest
from golfflight.flight.ground import SURFACES, Surface, ground_phase
from golfflight.flight.ground.phase import plane_normals, roll_to_rest

torch = pytest.importorskip("torch")

SURFACE_NAMES = ("fairway", "green", "rough", "firm_fairway", "bunker")


def landings(n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Landing states from drives to wedges: 10-35 m/s at 20-60 degrees, side spin, back spin from a driver's to a
    wedge's that spins the ball back, on grounds at three heights."""
    rng = np.random.default_rng(seed)
    speed, angle, side = rng.uniform(10, 35, n), np.radians(rng.uniform(20, 60, n)), rng.normal(0, 0.05, n)
    position = np.stack([rng.uniform(100, 250, n), rng.normal(0, 10, n), rng.choice([0.0, -3.0, 5.0], n)], -1)
    velocity = np.stack([speed * np.cos(angle) * np.cos(side), speed * np.cos(angle) * np.sin(side),
                         -speed * np.sin(angle)], -1)
    spin = np.stack([rng.normal(0, 20, n), rng.uniform(-900, -50, n), rng.normal(0, 20, n)], -1)
    return position, velocity, spin


def tensor(values: np.ndarray | float):
    return float(values) if np.ndim(values) == 0 else torch.as_tensor(values, dtype=torch.float64)


@pytest.mark.parametrize("mixed", [False, True], ids=["one surface, level", "five surfaces, a third sloped"])
def test_the_device_ground_phase_gives_numpys_rests_hops_and_times(mixed):
    n = 3000
    position, velocity, spin = landings(n)
    rng = np.random.default_rng(1)
    if mixed:
        surface = Surface.stack([SURFACES[name] for name in SURFACE_NAMES]).take(rng.integers(0, 5, n))
        slope = np.where(rng.random(n) < 0.33, rng.uniform(0.5, 2.0, n), 0.0)
        direction = rng.uniform(0, 360, n)
    else:
        surface, slope, direction = SURFACES["fairway"], np.zeros(n), np.zeros(n)
    want = ground_phase(position, velocity, spin, surface, slope, direction)
    on_device = Surface(*(tensor(getattr(surface, name)) for name in Surface.__dataclass_fields__))
    rest, hops, time_s = roll_to_rest(tensor(position), tensor(velocity), tensor(spin),
                                      tensor(plane_normals(slope, direction, n)), on_device)
    np.testing.assert_array_equal(hops.numpy(), want.bounces)
    np.testing.assert_allclose(rest.numpy(), want.rest_position, rtol=0, atol=1e-9)
    np.testing.assert_allclose(time_s.numpy(), want.time_s, rtol=0, atol=1e-9)
    assert (want.rest_position[:, 0] < position[:, 0]).any(), "no ball spun back: the case is not covered"
    assert (want.bounces > 1).any() and (slope > 0).any() == mixed
    speed = np.linalg.norm(velocity, axis=-1)
    from_normal = np.degrees(np.arctan2(np.hypot(velocity[:, 0], velocity[:, 1]), -velocity[:, 2]))
    penner = np.asarray(surface.critical_angle_deg) * speed / 18.6 * from_normal / 44.0
    assert (penner > np.asarray(surface.max_tilt_deg)).any() == mixed, "the green's tilt cap is not covered"


def test_the_namespace_functions_answer_in_the_library_of_their_arguments():
    """Plain numbers (NumPy's scalars among them) stay plain, arrays NumPy's, tensors torch's (the device's)."""
    from golfflight.flight import xp as vectors

    for name, args in (("minimum", (0.3, 0.5)), ("maximum", (0.3, 0.5)), ("atan2", (0.3, 0.5)), ("cos", (0.3,)),
                       ("sin", (0.3,)), ("log", (0.3,)), ("log1p", (0.3,)), ("expm1", (0.3,))):
        function = getattr(vectors, name)
        plain = function(*args)
        assert isinstance(plain, float), name
        assert function(*(np.float32(a) for a in args)) == pytest.approx(plain, rel=1e-6), name
        array = function(*(np.full(2, a) for a in args))
        assert isinstance(array, np.ndarray) and array.tolist() == [plain, plain], name
        tensor = function(torch.full((2,), args[0], dtype=torch.float64), *args[1:])
        assert isinstance(tensor, torch.Tensor) and tensor.tolist() == pytest.approx([plain, plain], rel=1e-15), name
    assert vectors.where(np.bool_(True), 1.0, 2.0) == 1.0
    assert vectors.where(torch.tensor([True, False]), 1.0, torch.tensor([5.0, 6.0], dtype=torch.float64)).tolist() == [
        1.0, 6.0]

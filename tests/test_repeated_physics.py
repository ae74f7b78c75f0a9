"""Issue 44's line on repeated physics, held: the functions that still do a home's work again (the single shot's float
loop, training's readers of a trajectory) come to at most 100 code lines (scripts/repeated_physics.py), and every
function its lists name is still there, so a renamed copy cannot drop out of the count unseen."""

import importlib.util
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "repeated_physics.py"
spec = importlib.util.spec_from_file_location("repeated_physics", SCRIPT)
repeated_physics = importlib.util.module_from_spec(spec)
spec.loader.exec_module(repeated_physics)


def test_the_repeated_physics_stays_within_100_lines():
    assert sum(lines for _, lines in repeated_physics.count(repeated_physics.REPEATS)) <= 100


def test_every_counted_function_is_still_there():
    for functions in (repeated_physics.REPEATS, repeated_physics.WRAPPERS):
        assert all(lines > 0 for _, lines in repeated_physics.count(functions)), functions

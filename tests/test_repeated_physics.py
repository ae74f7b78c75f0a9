"""Issues 44 and 58's line on repeated physics, held by the formulas (scripts/repeated_physics.py reads every package's
syntax tree): a force, a spin ratio, a landing, an apex or a slope hold computed outside its one home comes to at
most LINES_NOW code lines, a copy of a home pasted anywhere is found by what it computes, the copies issue 58
names (discovery's outside effects, the reference world's spin ratio, the ground's slope holds, the request's) are
gone, and no landing or apex is told outside the one rule (`flight.events`)."""

import ast
import importlib.util
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "scripts" / "repeated_physics.py"
spec = importlib.util.spec_from_file_location("repeated_physics", SCRIPT)
repeated_physics = importlib.util.module_from_spec(spec)
sys.modules["repeated_physics"] = repeated_physics  # its dataclass looks its module up there
spec.loader.exec_module(repeated_physics)

LINES_NOW = 10
"""The count today: `shots.tourcast`'s lift coefficient from an acceleration (q A / m inverted, 10). Issue 58's one
landing and apex rule (`flight.events`) took away the single shot's float loop (`FlightEngine.fly`, 68) and
training's readers of a trajectory (`flight.rollout`, 32); issue 44's goal is 100; a new copy anywhere raises the
count above this."""

GONE = (
    "discovery/outside.py", "discovery/form_terms.py", "flight/reference_aero.py", "flight/ground/", "contract/requests.py"
)
"""Where issue 58 found repeats: they call the homes now."""

COPIES = '''
import numpy as np

BALL_AREA_M2 = BALL_MASS_KG = BALL_RADIUS_M = ROLLING_GRAVITY_FRACTION = 1.0


def drag_again(v, cd, rho):
    return -cd * 0.5 * rho * np.sum(v * v, axis=1) * BALL_AREA_M2 / BALL_MASS_KG


def pressure_again(air_density, speed):
    return 0.5 * air_density * speed**2


def ratio_again(spin, speed):
    return BALL_RADIUS_M * spin / np.maximum(speed, 1e-9)


def _crossing(heights):
    return (heights[:-1] > 0.0) & (heights[1:] <= 0.0)


def first_landing(heights):
    return np.argmax(_crossing(heights))


def landing_fraction(z_old, z_new, ground):
    return (z_old - ground) / (z_old - z_new)


class Peaks:
    def highest(self, states):
        return np.argmax(states[:, :, 2], axis=0)

    def running(self, z, apex):
        return z if z > apex else apex


def steepest(resistance):
    return np.degrees(np.arctan(resistance / ROLLING_GRAVITY_FRACTION))


def no_physics(a, b):
    return (a + b) / (a - 2.0 * b)
'''
"""One copy of each piece, as a new module would write it, and one function of no physics."""


@pytest.fixture(scope="module")
def findings():
    return repeated_physics.find()


def test_the_repeated_physics_stays_within_its_lines(findings):
    assert sum(f.lines for f in findings) <= LINES_NOW, [(f.place, f.patterns, f.lines) for f in findings]


def test_the_repeats_issue_58_names_are_gone(findings):
    assert [f.place for f in findings if f.path.startswith(GONE)] == []


def test_landings_and_apexes_are_found_by_the_one_rule_alone(findings):
    """The single shot, the batch, the torch engine and training's rollout call `flight.events`: no other function
    tells a landing or an apex itself."""
    assert [(f.place, f.patterns) for f in findings if {"landing", "apex"} & set(f.patterns)] == []


def test_a_new_copy_of_each_piece_is_found_by_its_formula(tmp_path):
    (tmp_path / "package").mkdir()
    (tmp_path / "package" / "copies.py").write_text(COPIES)
    found = {f.function: f.patterns for f in repeated_physics.find(tmp_path, ("package",))}
    assert found == {
        "drag_again": ("force",),
        "pressure_again": ("force",),
        "ratio_again": ("spin ratio",),
        "_crossing": ("landing",),
        "first_landing": ("landing",),
        "landing_fraction": ("landing",),
        "Peaks.highest": ("apex",),
        "Peaks.running": ("apex",),
        "steepest": ("slope hold",),
    }


def _home_source(place: str) -> str:
    path, name = place.split(": ")
    source = (ROOT / path).read_text()
    functions = {n.name: n for n in ast.walk(ast.parse(source)) if isinstance(n, ast.FunctionDef)}
    return textwrap.dedent(ast.get_source_segment(source, functions[name.rsplit(".", 1)[-1]], padded=True))


def test_every_home_is_there_and_a_copy_of_it_elsewhere_is_found(tmp_path):
    """Each piece's home still exists (a renamed home would count itself), and pasting a home's own code into
    another module is found as that piece: the patterns match the formulas the flight core really writes."""
    (tmp_path / "package").mkdir()
    for piece, homes in repeated_physics.HOMES.items():
        assert all(repeated_physics.home_exists(home) for home in homes), homes
        copies = "\n\n".join(_home_source(home) for home in homes)
        (tmp_path / "package" / "copies.py").write_text(copies)
        found = {p for f in repeated_physics.find(tmp_path, ("package",)) for p in f.patterns}
        assert piece in found, (piece, homes)


def test_the_script_prints_each_place_its_pieces_and_the_total(findings):
    printed = subprocess.run([sys.executable, str(SCRIPT)], capture_output=True, text=True, check=True).stdout
    for finding in findings:
        assert f"| `{finding.place}` | {', '.join(finding.patterns)} | {finding.lines} |" in printed
    assert f"| total | | {sum(f.lines for f in findings)} |" in printed

"""The distribution's layout: one `golfflight.*` import namespace, so an installed wheel sits beside any other package
(one called `service` or `flight` included), and the package list in pyproject.toml covers every folder."""

from __future__ import annotations

import subprocess
import sys
import tomllib
from pathlib import Path

from built_wheel import PIP, build_wheel

ROOT = Path(__file__).resolve().parents[1]
FOLDERS = sorted(p.name for p in ROOT.iterdir() if (p / "__init__.py").is_file())
"""The repository's package folders; all but golfflight/ become golfflight.<folder> when installed."""


def _setuptools() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]


def test_every_package_folder_is_listed_under_the_one_namespace():
    found = set()
    for folder in FOLDERS:
        for init in (ROOT / folder).rglob("__init__.py"):
            dotted = ".".join(init.parent.relative_to(ROOT).parts)
            found.add(dotted if folder == "golfflight" else f"golfflight.{dotted}")
    assert set(_setuptools()["packages"]) == found
    assert _setuptools()["package-dir"] == {"golfflight": "golfflight"} | {
        f"golfflight.{folder}": folder for folder in FOLDERS if folder != "golfflight"
    }


def test_no_module_imports_a_folder_by_its_bare_name():
    """`from service.x import …` would work in a checkout and break in the wheel: every import names golfflight."""
    others = [name for name in FOLDERS if name != "golfflight"]
    bare = [f"{name} " for name in others] + [f"{name}." for name in others]
    offenders = []
    for path in [*ROOT.glob("*/**/*.py")]:
        if path.parts[len(ROOT.parts)] in {"build", ".git", "runs"}:
            continue
        for number, line in enumerate(path.read_text().splitlines(), 1):
            words = line.strip()
            if words.startswith(("from ", "import ")) and words.split(" ", 1)[1].startswith(tuple(bare)):
                offenders.append(f"{path.relative_to(ROOT)}:{number}: {words}")
    assert offenders == []


def test_the_wheel_installs_beside_a_package_called_service_and_flies_a_shot(tmp_path):
    wheel = build_wheel(tmp_path)
    target = tmp_path / "site"
    subprocess.run([*PIP, "install", "--no-deps", "--target", str(target), str(wheel)], check=True)
    assert sorted(p.name for p in target.iterdir() if (p / "__init__.py").is_file()) == ["golfflight"]

    others = tmp_path / "others"
    for name in ("service", "flight"):
        (others / name).mkdir(parents=True)
        (others / name / "__init__.py").write_text(f"WHO = 'somebody else\\'s {name}'\n")
    code = (
        "import service, flight\n"
        "from golfflight.flight.engine import FlightEngine, FlightProblem, Launch\n"
        "from golfflight.flight.bundle_location import model_dir\n"
        "assert service.WHO.endswith('service') and flight.WHO.endswith('flight')\n"
        f"engine = FlightEngine(model_dir({str(target / 'share/golfflight/models/default')!r}))\n"
        "import golfflight.flight.engine as engine_module\n"
        f"assert engine_module.__file__.startswith({str(target)!r}), engine_module.__file__\n"
        "print(engine.fly(FlightProblem.of([Launch(55.0, 16.0, 0.0, 7100.0, 0.0)]))[0].carry_m)\n"
    )
    env = {"PYTHONPATH": f"{target}:{others}", "PATH": "/usr/bin:/bin"}
    flown = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True)
    assert flown.returncode == 0, flown.stderr
    assert 140 < float(flown.stdout) < 180


def test_no_two_classes_share_a_name():
    """One name per concept: a class name means one thing across the project (tests aside)."""
    import ast
    from collections import defaultdict

    from tests.test_imports import _modules

    where = defaultdict(list)
    for path in _modules():
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.ClassDef):
                where[node.name].append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert {name: places for name, places in where.items() if len(places) > 1} == {}

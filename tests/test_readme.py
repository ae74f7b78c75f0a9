"""A newcomer's first hour (issue 31): the README's serving steps work from a fresh virtual environment, not only the
system Python; a checkout never installed imports and knows its version; `golfflight --version`; and `python3 -m
golfflight` run beside a checkout called golfflight says what to do instead of failing on an import."""

from __future__ import annotations

import json
import re
import shutil
import site
import subprocess
import sys
import time
import tomllib
from importlib.metadata import Distribution
from pathlib import Path

import httpx
import pytest
from built_wheel import PIP, ROOT, build_wheel, package_folders
from servers import free_port

from golfflight import __version__
from golfflight.cli import main

README = (ROOT / "README.md").read_text(encoding="utf-8")
PROJECT_VERSION = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["version"]


def venv_with_these_packages(prefix: Path) -> Path:
    """A fresh virtual environment at `prefix` (no pip of its own) that sees the packages this interpreter has
    installed through a .pth file in its site-packages, and so its python. Not `--system-site-packages`: a venv made
    from a venv's interpreter sees the base Python's packages, not that venv's (where pytest runs from a venv, as the
    README's commands may). The running site folders join the path as plain folders, after the new venv's own: their
    .pth files (an editable install's finder among them) are not run, so what is installed into the new venv is what
    it imports."""
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(prefix)], check=True)
    python = prefix / "bin" / "python"
    purelib = subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"],
                             check=True, capture_output=True, text=True).stdout.strip()
    folders = site.getsitepackages() + ([site.getusersitepackages()] if site.ENABLE_USER_SITE else [])
    (Path(purelib) / "_running_interpreter.pth").write_text("".join(f"{folder}\n" for folder in folders))
    return python


def test_golfflight_version_prints_the_projects_version(capsys):
    with pytest.raises(SystemExit) as done:
        main(["--version"])
    assert done.value.code == 0
    assert capsys.readouterr().out == f"golfflight {PROJECT_VERSION}\n" and __version__ == PROJECT_VERSION


CHECKOUT_IMPORT = """
import importlib.metadata, golfflight, golfflight.flight.constants
try:
    importlib.metadata.version("golfflight")
    print("metadata found: not a checkout never installed")
except importlib.metadata.PackageNotFoundError:
    print(golfflight.__version__, golfflight.flight.constants.__file__)
"""


def test_a_checkout_never_installed_imports_and_knows_its_version(tmp_path):
    """A fresh clone has no package metadata (no egg-info, nothing in site-packages): a copy of the checkout's
    pyproject.toml and package folders on PYTHONPATH, imported with -S (no site-packages, so no installed metadata)
    from another folder, imports golfflight and its subpackages from the copy and takes its version from
    pyproject.toml (it raised PackageNotFoundError before anything ran)."""
    clone = tmp_path / "clone"
    clone.mkdir()
    shutil.copy(ROOT / "pyproject.toml", clone / "pyproject.toml")
    for folder in package_folders():
        shutil.copytree(ROOT / folder, clone / folder, ignore=shutil.ignore_patterns("__pycache__"))
    run = subprocess.run([sys.executable, "-S", "-c", CHECKOUT_IMPORT], cwd=tmp_path, env={"PYTHONPATH": str(clone)},
                         capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == [PROJECT_VERSION, str(clone / "flight" / "constants.py")]


def _editable_install() -> bool:
    """Whether the golfflight this interpreter has installed is an editable install (a finder, not a package folder on
    the path); the checkout's own egg-info, on the tests' path here, is not an install."""
    installed = [folder for folder in sys.path if Path(folder or ".").resolve() != ROOT]
    found = next(iter(Distribution.discover(name="golfflight", path=installed)), None)
    direct_url = found.read_text("direct_url.json") if found else None
    return bool(direct_url and json.loads(direct_url).get("dir_info", {}).get("editable"))


def test_python_m_golfflight_beside_a_checkout_called_golfflight_says_what_to_do(tmp_path):
    """Run from the folder that holds the checkout, its folder called golfflight: with an editable install (the
    README's test command) Python takes that folder for the package, and the command says so and what to do in one
    line instead of failing to import `__version__`; a wheel's package comes first on the path and just runs."""
    parent = tmp_path / "parent"
    parent.mkdir()
    (parent / "golfflight").symlink_to(ROOT, target_is_directory=True)
    run = subprocess.run([sys.executable, "-m", "golfflight", "--version"], cwd=parent, capture_output=True, text=True,
                         check=False)
    if not _editable_install():
        assert (run.returncode, run.stdout) == (0, f"golfflight {PROJECT_VERSION}\n"), run.stderr
        return
    assert run.returncode != 0 and run.stderr.count("\n") == 1, run.stderr
    assert f"imported the folder {parent / 'golfflight'} instead of the installed golfflight" in run.stderr
    assert "from any other folder" in run.stderr and "the `golfflight` command" in run.stderr


def _readme_request() -> tuple[str, dict]:
    """The README's curl example: its route and its body."""
    curl = re.search(r"curl -s localhost:8000(/\S+) .*?-d '(\{[^']*\})'", README, flags=re.DOTALL)
    assert curl, "the README's curl example is not where this test reads it"
    return curl.group(1), json.loads(curl.group(2))


def test_the_readmes_serving_steps_work_from_a_fresh_virtual_environment(tmp_path):
    """The README's `python3 -m pip install . && python3 -m golfflight serve` in a fresh venv, not the system Python:
    the distribution's wheel (what `pip install .` builds and installs) installed with --no-deps into a new venv that
    reuses this interpreter's installed dependencies (a full install downloads and unpacks them: about 50 s with a
    warm cache, too slow for the suite), then `python -m golfflight serve` from that venv, outside the checkout, on a
    free port, finds the bundle the wheel installed under the venv's prefix and answers the README's curl request
    with a carry. Resolving the dependencies from a clean venv without torch, and the viewer, /docs and /metrics of
    that install, are left to `.ci/serving-install`."""
    assert "python3 -m pip install . && python3 -m golfflight serve" in README
    route, body = _readme_request()
    prefix = tmp_path / "venv"
    python = venv_with_these_packages(prefix)
    subprocess.run([str(python), *PIP[1:], "install", "--no-deps", str(build_wheel(tmp_path))], check=True)
    elsewhere, port = tmp_path / "elsewhere", free_port()
    elsewhere.mkdir()
    log = tmp_path / "serve.log"
    with log.open("w") as output:
        server = subprocess.Popen([str(python), "-m", "golfflight", "serve", "--port", str(port)], cwd=elsewhere,
                                  env={"PATH": "/usr/bin:/bin"}, stdout=output, stderr=subprocess.STDOUT)
    try:
        base, deadline = f"http://127.0.0.1:{port}", time.monotonic() + 60
        while True:
            assert server.poll() is None, log.read_text()
            try:
                if httpx.get(base + "/healthz").status_code == 200:
                    break
            except httpx.TransportError:
                pass
            assert time.monotonic() < deadline, "the service did not become ready"
            time.sleep(0.1)
        answer = httpx.post(base + route, json=body, timeout=30)
        assert answer.status_code == 200, answer.text
        assert answer.json()["carry_yd"] > 200  # the README's driver
    finally:
        server.terminate()
        server.wait(timeout=30)
    assert f"from {prefix / 'share' / 'golfflight' / 'models' / 'default'} on http://127.0.0.1:{port}" in log.read_text()

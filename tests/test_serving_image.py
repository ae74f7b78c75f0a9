"""The serving image (Dockerfile) installs the whole distribution: every package pyproject.toml ships is copied in,
so no command the command line registers is missing from the image."""

from __future__ import annotations

import fnmatch
import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_the_dockerfile_copies_every_package_of_the_distribution():
    folders = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-dir"].values())
    copied = set(re.findall(r"^COPY (\w+) \./\1$", (ROOT / "Dockerfile").read_text(), flags=re.MULTILINE))
    assert folders >= {"golfflight", "flight", "service", "sweep"}
    assert folders <= copied, f"not copied into the image: {sorted(folders - copied)}"


# ---- issue 56, item 9: the build context, Open Connect in a container, the bay file's owner ----------------------

DOCKERIGNORE = ROOT / ".dockerignore"


def ignored(path: str, patterns: list[str]) -> bool:
    """Whether Docker leaves `path` (a file or folder of the context) out: the last pattern matching it or a folder
    above it decides, `!` bringing back (Docker's rule; `**` any number of folders, as fnmatch's `*` also crosses)."""
    parts = path.split("/")
    left_out = False
    for pattern in patterns:
        keep = pattern.startswith("!")
        glob = pattern.removeprefix("!").rstrip("/").removeprefix("**/")
        whole = pattern.removeprefix("!").startswith("**/")
        candidates = ["/".join(parts[:n]) for n in range(1, len(parts) + 1)]
        if whole:
            candidates += ["/".join(parts[i:n]) for i in range(1, len(parts)) for n in range(i + 1, len(parts) + 1)]
        if any(fnmatch.fnmatchcase(c, glob) for c in candidates):
            left_out = not keep
    return left_out


def test_the_build_context_leaves_out_venvs_git_caches_and_data_but_keeps_what_the_image_copies():
    patterns = [line.strip() for line in DOCKERIGNORE.read_text().splitlines()
                if line.strip() and not line.startswith("#")]
    copied = re.findall(r"^COPY (.+) \./?\S*$", (ROOT / "Dockerfile").read_text(), flags=re.MULTILINE)
    sources = [source for line in copied for source in line.split()]
    assert {"pyproject.toml", "README.md", "golfflight", "models/default"} <= set(sources)
    for source in sources:
        for path in (source, f"{source}/model.onnx", f"{source}/__init__.py"):  # the folder and what is in it
            assert not ignored(path, patterns), f"{path} is copied into the image but left out of the context"
    for junk in (".venv/lib/python3.11/site-packages/torch/__init__.py", ".git/objects/pack/x.pack",
                 "flight/__pycache__/engine.cpython-311.pyc", ".pytest_cache/v/cache", "shared/data/x.csv",
                 "runs/train/model.onnx", "models/real/model.onnx", "golfflight.egg-info/PKG-INFO"):
        assert ignored(junk, patterns), f"{junk} would go into the build context"


def test_the_image_exposes_open_connect_and_the_docs_say_how_to_run_it_and_who_owns_the_bay_file():
    dockerfile = (ROOT / "Dockerfile").read_text()
    exposed = {port for line in re.findall(r"^EXPOSE (.+)$", dockerfile, flags=re.MULTILINE) for port in line.split()}
    assert {"8000", "921"} <= exposed, exposed
    (uid,) = re.findall(r"useradd .*--uid (\d+)", dockerfile)
    service = (ROOT / "docs" / "service.md").read_text()
    section = service.split("### The image on a bay", 1)[1].split("\n## ", 1)[0]
    assert "--connect-port 921 --connect-host 0.0.0.0" in section and "-p 921:921" in section
    assert f"writable by uid {uid}" in section and "--bay" in section
    readme = (ROOT / "README.md").read_text()
    assert "--connect-port 921 --connect-host 0.0.0.0" in readme and f"uid {uid}" in readme

"""Issue 56, item 8: a benchmark writes its results where `--results FILE` says, and nowhere else; without the flag it
prints its table and writes nothing, so the tracked benchmarks/results.json changes only when a run names it.

The benchmark runs for real (bench_inprocess.py, one round of 50 shots: a few seconds) from a copy of benchmarks/ in a temporary
folder, so that a script that still rewrote its own folder's results.json changes the copy, never the checkout's."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _run(scripts: Path, work: Path, *args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
    command = [sys.executable, str(scripts / "bench_inprocess.py"), "--rounds", "1", "--shots", "50", *args]
    done = subprocess.run(command, cwd=work, env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return done


def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_a_benchmark_writes_only_the_file_its_flag_names(tmp_path):
    scripts = tmp_path / "benchmarks"
    shutil.copytree(ROOT / "benchmarks", scripts, ignore=shutil.ignore_patterns("__pycache__"))
    work = tmp_path / "work"
    work.mkdir()
    before = _files(scripts)

    printed = _run(scripts, work)
    assert "single shot, 7-iron" in printed.stdout and "results not written" in printed.stdout
    assert _files(scripts) == before and _files(work) == {}, "a run without --results wrote a file"

    chosen = tmp_path / "elsewhere" / "mine.json"
    _run(scripts, work, "--results", str(chosen))
    assert _files(scripts) == before and _files(work) == {}, "a run wrote beside the one file it was given"
    section = json.loads(chosen.read_text())["in_process"]
    assert len(section["rows"]) == 4 and section["machine"]["cores"] == os.cpu_count()

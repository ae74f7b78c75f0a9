"""Issue 56, item 4: files and pipes as a person's tools make them.

A CSV saved as a spreadsheet's "CSV UTF-8" starts with a byte-order mark: every CSV reader takes it as the same file
without one (`simulate` refused it: "unknown columns ['\\ufeffball_speed_mps']"). A command whose output is piped to
a reader that stops early (`golfflight simulate s.csv | head`) ends quietly with status 0, in real processes: through
a shell pipe into `head`, and into a pipe whose reader is gone before the command writes."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from golfflight.cli import main
from golfflight.evaluation.noise_floor import SessionTruth, read_session_truth
from golfflight.evaluation.physics_checks import read_aero_literature, read_spin_decay
from golfflight.shots.paths import shared_data_dir
from golfflight.shots.records import read_shots, read_trajectories, write_trajectories
from golfflight.shots.reference_world import TOUR_AVERAGES_FILE, read_tour_averages
from golfflight.sweep.sources import CsvSource

ROOT = Path(__file__).resolve().parents[1]
BOM = "\ufeff".encode()
LAUNCHES = "ball_speed_mps,launch_angle_deg,spin_rpm,spin_axis_deg\n" + "".join(
    f"{50 + i % 25},{10 + i % 15},{2500 + 100 * (i % 40)},{i % 9 - 4}\n" for i in range(300)
)
"""300 launches: their JSON results (about 300 kB) are far more than a pipe holds, so the writer meets the closed
pipe while it writes, not only at its last flush."""


def with_bom(path: Path, folder: Path) -> Path:
    """A copy of a CSV with a UTF-8 byte-order mark in front, as a spreadsheet's "CSV UTF-8" saves it."""
    marked = folder / f"bom-{path.name}"
    marked.write_bytes(BOM + path.read_bytes())
    return marked


def test_simulate_reads_a_csv_with_a_byte_order_mark_as_the_same_file(tmp_path, capsys):
    plain = tmp_path / "launches.csv"
    plain.write_text(LAUNCHES[: LAUNCHES.index("\n", 200) + 1])
    outputs = []
    for source in (plain, with_bom(plain, tmp_path)):
        assert main(["simulate", str(source)]) == 0, capsys.readouterr().err
        outputs.append(json.loads(capsys.readouterr().out))
    assert outputs[0] == outputs[1] and len(outputs[0]["results"]) >= 5


def _session_truth(folder: Path) -> Path:
    path = folder / "synth.sessions.csv"
    fields = ("session", *SessionTruth._fields)
    path.write_text(",".join(fields) + "\n" + "s1," + ",".join(str(20.0 + i) for i in range(len(fields) - 1)) + "\n")
    return path


def _trajectories(folder: Path) -> Path:
    path = folder / "shots.trajectories.csv"
    write_trajectories(path, {"a": np.array([[0.0, 0.0, 0.0, 0.0], [0.5, 20.0, 0.1, 8.0]])})
    return path


READERS = {
    "read_shots (canonical shots)": (lambda folder, shots: shots, lambda path: read_shots(path).records),
    "read_trajectories": (lambda folder, shots: _trajectories(folder),
                          lambda path: {k: v.tolist() for k, v in read_trajectories(path).items()}),
    "read_tour_averages": (lambda folder, shots: shared_data_dir() / TOUR_AVERAGES_FILE, read_tour_averages),
    "read_aero_literature": (lambda folder, shots: shared_data_dir() / "literature" / "aero_coefficients_curated.csv",
                             read_aero_literature),
    "read_spin_decay": (lambda folder, shots: shared_data_dir() / "literature" / "spin_decay_and_torque.csv",
                        read_spin_decay),
    "read_session_truth": (lambda folder, shots: _session_truth(folder), read_session_truth),
    "sweep's CSV header": (lambda folder, shots: _launches(folder), lambda path: CsvSource.open(path, 64).columns),
}
"""Every CSV reader of the project but the launch monitors' (convert: they read a mark already): where its file
comes from, and what it read."""


def _launches(folder: Path) -> Path:
    path = folder / "launches.csv"
    path.write_text(LAUNCHES)
    return path


@pytest.mark.parametrize("reader", READERS)
def test_every_csv_reader_reads_a_byte_order_mark_as_the_same_file(reader, tmp_path, tiny_shots):
    source, read = READERS[reader]
    plain = Path(source(tmp_path, tiny_shots))
    assert not plain.read_bytes().startswith(BOM)
    assert read(with_bom(plain, tmp_path)) == read(plain)


def _golfflight(*argv: str) -> list[str]:
    return [sys.executable, "-m", "golfflight", *argv]


def _env() -> dict:
    return {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}


def test_simulate_piped_into_head_ends_quietly_with_status_0(tmp_path):
    source = _launches(tmp_path)
    line = f"{' '.join(_golfflight('simulate', str(source)))} | head -n 3; echo \"status ${{PIPESTATUS[0]}}\" >&2"
    done = subprocess.run(["bash", "-c", line], cwd=tmp_path, env=_env(), capture_output=True, text=True, timeout=120)
    assert done.stdout.splitlines() == ["{", '  "results": [', "    {"]
    assert done.stderr == "status 0\n", done.stderr


@pytest.mark.parametrize("argv", [("fly", "--club", "7i"), ("fly", "--club", "7i", "--json"), ("simulate", "{launches}")])
def test_a_command_writing_into_a_pipe_whose_reader_is_gone_ends_quietly(argv, tmp_path):
    """The pipe's reader closes before the command starts: its first write fails (a line of text, a JSON object,
    300 kB of results)."""
    argv = [a.format(launches=_launches(tmp_path)) for a in argv]
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        done = subprocess.run(_golfflight(*argv), stdout=write_end, stderr=subprocess.PIPE, cwd=tmp_path, env=_env(),
                              text=True, timeout=120)
    finally:
        os.close(write_end)
    assert (done.returncode, done.stderr) == (0, "")

"""Long commands are never silent (issue 31): progress reaches standard error before the first slow step, `--quiet`
silences it, and what a command prints to standard output and the files it writes are the same either way."""

from __future__ import annotations

import re
import sys
import tomllib
from pathlib import Path

import pytest
from golfflight.shots import progress, synth
from golfflight.shots.progress import print_line, progress_bar, progress_step

from golfflight.cli import main

ROOT = Path(__file__).resolve().parents[1]


def _timeless(text: str) -> str:
    """A command's output without its run time and the paths that differ between two runs."""
    return re.sub(r"\d+\.\d s\b", "T s", text).replace("quiet", "loud")


class ErrAtFirstCall:
    """Wraps a function so that its first call records what standard error held by then (the work before it)."""

    def __init__(self, capsys: pytest.CaptureFixture, function):
        self.capsys, self.function = capsys, function
        self.err_before: str | None = None
        self.out_before = ""

    def __call__(self, *args, **kwargs):
        if self.err_before is None:
            captured = self.capsys.readouterr()
            self.err_before, self.out_before = captured.err, captured.out
        return self.function(*args, **kwargs)


def test_a_bar_and_a_step_go_to_stderr_and_nothing_when_not_shown(capsys):
    assert list(progress_bar(range(3), "counting", unit="n")) == [0, 1, 2]
    progress_step("a slow step...")
    captured = capsys.readouterr()
    assert captured.out == ""
    assert "counting" in captured.err and "3/3" in captured.err and "a slow step...\n" in captured.err
    assert list(progress_bar(range(3), "counting", shown=False)) == [0, 1, 2]
    progress_step("a slow step...", shown=False)
    assert capsys.readouterr() == ("", "")


@pytest.mark.parametrize("terminal", [False, True])
def test_a_line_beside_a_bar_is_printed_to_stdout_as_print_would(terminal, capsys, monkeypatch):
    monkeypatch.setattr(sys.stderr, "isatty", lambda: terminal)
    with progress_bar(range(2), "runs"):
        print_line("one run done")
    assert capsys.readouterr().out == "one run done\n"


def test_off_a_terminal_the_bar_redraws_seldom(capsys):
    assert progress._interval() == progress.LOG_INTERVAL_S  # captured stderr is not a terminal


def test_tqdm_is_a_dependency_of_the_serving_install():
    """The library loops import the helper, so `pip install .` (no extras) must bring tqdm."""
    dependencies = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    assert any(re.match(r"tqdm\b", d) for d in dependencies)


def test_synth_shows_progress_before_flying_and_writes_the_same(tmp_path, capsys, monkeypatch):
    first_flight = ErrAtFirstCall(capsys, synth.fly_reference)
    monkeypatch.setattr(synth, "fly_reference", first_flight)
    assert main(["synth", "--shots", "120", "--seed", "3", "--out", str(tmp_path / "loud.csv")]) == 0
    loud = capsys.readouterr()
    assert "drawing 120 launches..." in first_flight.err_before and "0/120" in first_flight.err_before
    assert first_flight.out_before == ""  # nothing on stdout before the work is done
    assert "120/120" in loud.err and "writing" in loud.err

    assert main(["synth", "--shots", "120", "--seed", "3", "--out", str(tmp_path / "quiet.csv"), "--quiet"]) == 0
    quiet = capsys.readouterr()
    assert quiet.err == ""
    assert _timeless(quiet.out) == _timeless(first_flight.out_before + loud.out)
    for name in ("{}.csv", "{}.sessions.csv"):
        assert (tmp_path / name.format("loud")).read_bytes() == (tmp_path / name.format("quiet")).read_bytes()


def test_diagnose_names_its_steps_before_flying_and_writes_the_same(tmp_path, capsys, monkeypatch):
    from golfflight.discovery import diagnose

    shots = tmp_path / "shots.csv"
    assert main(["synth", "--shots", "150", "--seed", "5", "--calm", "--out", str(shots), "--quiet"]) == 0
    capsys.readouterr()
    first_flight = ErrAtFirstCall(capsys, diagnose.as_is)
    monkeypatch.setattr(diagnose, "as_is", first_flight)
    argv = ["diagnose", str(shots), "--model", "reference"]
    assert main([*argv, "--out", str(tmp_path / "loud")]) == 0
    loud = capsys.readouterr()
    assert first_flight.err_before.startswith("flying 150 recorded shots")
    assert "effects" in loud.err and "writing the report" in loud.err

    assert main([*argv, "--out", str(tmp_path / "quiet"), "--quiet"]) == 0
    quiet = capsys.readouterr()
    assert quiet.err == ""
    assert _timeless(quiet.out) == _timeless(loud.out)
    settings = "service_settings.json"
    assert (tmp_path / "loud" / settings).read_text() == (tmp_path / "quiet" / settings).read_text()


def test_train_draws_its_epoch_bar_before_the_first_batch_and_quiet_draws_nothing(tiny_shots, tmp_path, capsys,
                                                                                 monkeypatch):
    from golfflight.model_export import training

    first_batch = ErrAtFirstCall(capsys, training.errors)
    monkeypatch.setattr(training, "errors", first_batch)
    argv = ["train", "--data", str(tiny_shots), "--epochs", "1", "--variant", "phys-q", "--limit", "40",
            "--threads", "1"]
    assert main([*argv, "--out", str(tmp_path / "loud")]) == 0
    assert "epoch 1/1" in first_batch.err_before
    loud = capsys.readouterr()
    assert "epoch 1: train Lp" in loud.out  # the line per epoch stays on stdout

    assert main([*argv, "--out", str(tmp_path / "quiet"), "--quiet"]) == 0
    quiet = capsys.readouterr()
    assert quiet.err == ""
    assert "epoch 1: train Lp" not in quiet.out and "best epoch 1" in quiet.out

"""A training run killed mid-way leaves only complete checkpoints and resumes from the last one; a crash while a
checkpoint or a bundle is being written leaves the previous file intact."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import golfflight.model_export.export as export
import golfflight.model_export.training as training
import pytest
import torch
from golfflight.flight.engine import FlightEngine
from golfflight.model_export.export import export_checkpoint
from golfflight.model_export.training import TrainConfig, load_checkpoint, train

TINY = ["--variant", "phys-nn-pm", "--hidden", "16,8", "--batch-size", "32", "--threads", "1", "--limit", "64"]


def _train_command(data, out, epochs: int, *extra: str) -> list[str]:
    return [sys.executable, "-m", "golfflight", "train", "--data", str(data), "--out", str(out),
            "--epochs", str(epochs), *TINY, *extra]


def test_a_killed_run_resumes_from_its_last_complete_checkpoint(tiny_shots, tmp_path):
    out = tmp_path / "run"
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    run = subprocess.Popen(_train_command(tiny_shots, out, 30), env=env, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120
        while not (out / "last.pt").exists():
            assert run.poll() is None, "training ended before its first checkpoint"
            assert time.monotonic() < deadline, "no checkpoint within 120 s"
            time.sleep(0.05)
        time.sleep(0.3)  # somewhere in the next epoch, possibly mid-save
    finally:
        run.send_signal(signal.SIGKILL)
        run.wait(timeout=30)
    assert run.returncode == -signal.SIGKILL
    killed_at = load_checkpoint(out / "last.pt")["epoch"]  # complete, whatever the moment of the kill
    assert 1 <= killed_at < 30
    epochs = killed_at + 2
    resumed = subprocess.run(_train_command(tiny_shots, out, epochs, "--resume"), env=env, capture_output=True,
                             text=True, timeout=300)
    assert resumed.returncode == 0, resumed.stderr
    payload = load_checkpoint(out / "last.pt")
    assert payload["epoch"] == epochs
    assert [row["epoch"] for row in payload["history"]] == list(range(1, epochs + 1))


def test_a_crash_while_saving_keeps_the_previous_checkpoint(tiny_shots, tmp_path, monkeypatch):
    config = TrainConfig(variant="phys-nn-pm", hidden=(16, 8), batch_size=32, epochs=1, limit=64)
    train(tiny_shots, tmp_path, config, progress=False)
    before = (tmp_path / "last.pt").read_bytes()
    real_save = torch.save

    def crash_half_way(payload, path):
        real_save(payload, path)
        with open(path, "r+b") as handle:
            handle.truncate(os.path.getsize(path) // 2)
        raise OSError("disk full (simulated)")

    monkeypatch.setattr(training.torch, "save", crash_half_way)
    with pytest.raises(OSError, match="simulated"):
        train(tiny_shots, tmp_path, TrainConfig(**{**config.__dict__, "epochs": 2}), resume=True, progress=False)
    assert (tmp_path / "last.pt").read_bytes() == before
    assert load_checkpoint(tmp_path / "last.pt")["epoch"] == 1
    assert not list(tmp_path.glob(".*.tmp"))


def test_a_crash_while_exporting_never_leaves_a_bundle_that_loads_wrongly(tiny_shots, tmp_path, monkeypatch):
    run, bundle = tmp_path / "run", tmp_path / "bundle"
    train(tiny_shots, run, TrainConfig(variant="phys-nn-pm", hidden=(16, 8), batch_size=32, epochs=1, limit=64),
          progress=False)
    export_checkpoint(run, bundle)
    card_before = (bundle / "model_card.json").read_bytes()
    graph_before = (bundle / "model.onnx").read_bytes()

    def crash():
        raise OSError("killed while writing the card (simulated)")

    original = export._replace_atomically
    calls = []

    def replace_then_crash(directory, name, write):
        calls.append(name)
        if name == "model_card.json":
            crash()
        original(directory, name, write)

    monkeypatch.setattr(export, "_replace_atomically", replace_then_crash)
    with pytest.raises(OSError, match="simulated"):
        export_checkpoint(run, bundle)
    assert calls == ["model.onnx", "model_card.json"]
    assert (bundle / "model_card.json").read_bytes() == card_before
    assert not list(bundle.glob(".*.tmp"))
    # the new graph beside the old card: export is deterministic, so it is the same graph and the bundle loads (a
    # different graph would be refused by the card's hash: tests/test_bundle_faults.py)
    assert (bundle / "model.onnx").read_bytes() == graph_before
    assert FlightEngine(bundle).variant == "phys-nn-pm"

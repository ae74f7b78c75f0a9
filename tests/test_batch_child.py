"""Issue 42: the batch process of a real `golfflight serve` ends with its server however that dies (kill -9
included; it ignores SIGTERM and lived on, with the resource tracker, 165 MB in all), and one that dies under a
running server is replaced at once, GET /healthz saying "degraded" until the new one has loaded the model."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import httpx
import psutil
import pytest
from golfflight.service.settings import API_KEY_ENV
from servers import free_port

SEVEN_IRON = {"ball_speed_mps": 55.0, "launch_angle_deg": 16.0, "spin_rpm": 7100.0}
BATCH = {"shots": [SEVEN_IRON] * 3}


@contextmanager
def served(tmp_path: Path, workers: int = 1) -> Iterator[tuple[psutil.Process, httpx.Client]]:
    """(server process, client) of a `golfflight serve` with `workers` workers, once /healthz is ready; whatever of
    it is still running at the end is killed."""
    port = free_port()
    env = {key: value for key, value in os.environ.items() if key != API_KEY_ENV}
    log = tmp_path / "serve.log"
    command = [sys.executable, "-m", "golfflight", "serve", "--port", str(port), "--workers", str(workers)]
    with open(log, "w") as output:
        popen = subprocess.Popen(command, env=env, stdout=output, stderr=subprocess.STDOUT)
    server = psutil.Process(popen.pid)
    started: list[psutil.Process] = []
    try:
        with httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=60) as http:
            deadline = time.monotonic() + 90
            while not _answers_ready(http):
                assert time.monotonic() < deadline and popen.poll() is None, log.read_text()
                time.sleep(0.05)
            started = _descendants(server)
            yield server, http
    finally:
        started += _descendants(server)
        popen.kill()
        popen.wait(30)
        for process in _alive(started):
            process.kill()


def _answers_ready(http: httpx.Client) -> bool:
    try:
        return http.get("/healthz").status_code == 200
    except httpx.TransportError:
        return False


def _descendants(server: psutil.Process) -> list[psutil.Process]:
    try:
        return server.children(recursive=True)
    except psutil.NoSuchProcess:
        return []


def _commands(processes: list[psutil.Process]) -> list[str]:
    commands = []
    for process in processes:
        try:
            commands.append(" ".join(process.cmdline()))
        except psutil.NoSuchProcess:
            pass
    return commands


def _alive(processes: list[psutil.Process]) -> list[psutil.Process]:
    """Those still running (a zombie waiting for whoever adopted it to collect it has ended)."""
    living = []
    for process in processes:
        try:
            if process.status() != psutil.STATUS_ZOMBIE:
                living.append(process)
        except psutil.NoSuchProcess:
            pass
    return living


def _batch_process(server: psutil.Process) -> psutil.Process:
    children = [child for child in server.children() if "spawn_main" in " ".join(child.cmdline())]
    assert len(children) == 1, children
    return children[0]


def _healthz_until_ready_after_degraded(http: httpx.Client, timeout_s: float) -> list[dict]:
    """The /healthz answers, polled until one says "ready" after one said "degraded" (the first polls may still
    say "ready": the server has not noticed yet)."""
    answers, deadline = [], time.monotonic() + timeout_s
    while True:
        answers.append(http.get("/healthz").json())
        statuses = [answer["status"] for answer in answers]
        if "degraded" in statuses and statuses[-1] == "ready":
            return answers
        assert time.monotonic() < deadline, answers[-3:]
        time.sleep(0.02)


@pytest.mark.parametrize("workers", [1, 2])
def test_a_server_killed_with_sigkill_leaves_no_process_behind(tmp_path, workers):
    with served(tmp_path, workers) as (server, http):
        assert http.post("/v1/shots/batch", json=BATCH).status_code == 200
        spawned = workers * 2 if workers > 1 else 1  # each worker and its batch process, or the batch process
        deadline = time.monotonic() + 60
        while sum("spawn_main" in c for c in _commands(_descendants(server))) < spawned:  # every worker loaded
            assert time.monotonic() < deadline, _commands(_descendants(server))
            time.sleep(0.1)
        left = _descendants(server)
        assert any("resource_tracker" in c for c in _commands(left)), _commands(left)
        server.kill()
        deadline = time.monotonic() + 5
        while _alive(left) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not _alive(left), [" ".join(process.cmdline()) for process in _alive(left)]


def test_a_batch_process_killed_under_a_running_server_is_replaced_at_once(tmp_path):
    """Killed between batches, the child is restarted without waiting for a batch: /healthz says "degraded" with
    why until the new child has loaded the model, then ready again, and the next batch is flown by that child."""
    with served(tmp_path) as (server, http):
        expected = http.post("/v1/shots/batch", json=BATCH).json()
        assert http.get("/healthz").json()["batch_process"] == {"restarts": 0}
        killed = _batch_process(server)
        killed.kill()
        answers = _healthz_until_ready_after_degraded(http, timeout_s=60)
        degraded = [answer["problems"] for answer in answers if answer["status"] == "degraded"]
        assert degraded[0] == {"batch": "the batch process died (exit code -9) and is restarting"}
        assert answers[-1]["batch_process"] == {"restarts": 1}
        fresh = _batch_process(server)
        again = http.post("/v1/shots/batch", json=BATCH)
        assert again.status_code == 200 and again.json() == expected
        assert fresh.pid != killed.pid and _batch_process(server).pid == fresh.pid, "flown by the child made ready"

"""Issue 55, item 4, on a real `golfflight serve` and its batch process: the trajectory points one request may get
back are bounded (MAX_TRAJECTORY_SAMPLES), a request over it is refused with a 422 naming trajectory.rate_hz and the
allowed size, and memory stays bounded by it (100 shots at 1 kHz, a 14 KB request, took the server and its batch
process to 964 MiB against the pod's 768 MiB)."""

from __future__ import annotations

import threading

import psutil
import pytest
from golfflight.contract.trajectory_size import MAX_TRAJECTORY_SAMPLES
from test_batch_child import served

DRIVER = {"ball_speed_mph": 171.0, "launch_angle_deg": 10.4, "back_spin_rpm": 2545.0, "side_spin_rpm": -300.0}
PEAK_MIB = 600.0
"""Loose bound on the server and its batch process together while refusing 100 shots at 1 kHz: about 330 MiB
refusing it; 964 MiB flying it."""


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    with served(tmp_path_factory.mktemp("serve")) as (process, http):
        yield process, http


class Peak(threading.Thread):
    """The highest RSS of a process and its children together, sampled every 20 ms until stopped."""

    def __init__(self, process: psutil.Process):
        super().__init__(daemon=True)
        self.process, self.stopped, self.mib = process, threading.Event(), 0.0

    def run(self) -> None:
        while not self.stopped.wait(0.02):
            try:
                total = sum(p.memory_info().rss for p in [self.process, *self.process.children()])
            except psutil.NoSuchProcess:
                continue
            self.mib = max(self.mib, total / 2**20)


def test_a_batch_asking_for_too_many_points_is_refused_within_the_memory_bound(server):
    process, http = server
    peak = Peak(process)
    peak.start()
    refused = http.post("/v1/shots/batch", json={"shots": [DRIVER | {"trajectory": {"rate_hz": 1000}}] * 100})
    peak.stopped.set()
    peak.join()
    assert refused.status_code == 422, refused.status_code
    [detail] = refused.json()["detail"]
    assert detail["field"] == "trajectory.rate_hz" and detail["type"] == "too_many_points"
    assert detail["value"] > MAX_TRAJECTORY_SAMPLES
    assert f"at most {MAX_TRAJECTORY_SAMPLES:,} trajectory points per request" in detail["message"]
    assert peak.mib < PEAK_MIB, peak.mib


def test_a_single_shot_counts_its_normalized_replay_and_the_bound_leaves_renderers_room(server):
    _, http = server
    one = http.post("/v1/shots", json=DRIVER | {"trajectory": {"rate_hz": 1000}, "normalized": True})
    assert one.status_code == 200
    points = len(one.json()["trajectory"]) + len(one.json()["normalized"]["trajectory"])
    assert 10_000 < points <= MAX_TRAJECTORY_SAMPLES  # about 9.3 s each at 1 kHz
    at_60_hz = http.post("/v1/shots/batch", json={"shots": [DRIVER | {"trajectory": {"rate_hz": 60}}] * 100})
    assert at_60_hz.status_code == 200
    assert all(len(result["trajectory"]) > 60 for result in at_60_hz.json()["results"])

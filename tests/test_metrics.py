"""GET /metrics through real uvicorn servers on loopback, parsed as Prometheus parses it: counters and histograms move
by exactly what was sent, refusals are counted, the key is required, the model's info labels are the card's, and
under `golfflight serve --workers 2` every scrape sums both workers."""

from __future__ import annotations

import os
import signal
import struct
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from importlib.metadata import version
from pathlib import Path

import httpx
import pytest
from golfflight.flight.bundle_location import model_dir
from golfflight.service.settings import ServiceSettings, API_KEY_ENV
from golfflight.service.app import create_app
from golfflight.service.runtime.metrics import (
    MULTIPROC_ENV,
    StartedWorkersCollector,
    shared_across_workers,
    started,
)
from golfflight.weights_schema.bundle import load_bundle
from prometheus_client import CollectorRegistry, generate_latest
from prometheus_client.multiprocess import MultiProcessCollector
from prometheus_client.parser import text_string_to_metric_families
from servers import free_port, running, shot

KEY = "metrics-test-key-5b1e0c7a"
KEYED = {"x-api-key": KEY}
SEVEN_IRON = {"ball_speed_mps": 55.0, "launch_angle_deg": 16.0, "spin_rpm": 7100.0}
GSPRO_SHOT = {"ShotNumber": 1, "BallData": {"Speed": 150.0, "VLA": 12.0, "TotalSpin": 3000.0, "SpinAxis": 0.0}}

Samples = dict[tuple[str, frozenset], float]


def samples(text: str) -> Samples:
    """Every sample of an exposition, keyed by (sample name, its labels)."""
    return {
        (sample.name, frozenset(sample.labels.items())): sample.value
        for family in text_string_to_metric_families(text)
        for sample in family.samples
    }


def scrape(http: httpx.Client, headers: dict | None = None) -> Samples:
    answer = http.get("/metrics", headers=headers)
    assert answer.status_code == 200, answer.text
    assert answer.headers["content-type"].startswith("text/plain; version=")
    return samples(answer.text)


def value(found: Samples, name: str, **labels) -> float:
    return found.get((name, frozenset(labels.items())), 0.0)


def requests(found: Samples, route: str, status: int, method: str = "POST") -> float:
    return value(found, "golfflight_http_requests_total", route=route, method=method, status=str(status))


@pytest.fixture(scope="module")
def keyed():
    with running(create_app(ServiceSettings(api_key=KEY)), ready_path="/healthz") as http:
        http.headers.update(KEYED)
        yield http


def test_shots_batches_and_errors_move_the_metrics_by_exactly_what_was_sent(keyed):
    before = scrape(keyed)
    for _ in range(3):
        shot(keyed, **SEVEN_IRON)
    batch = keyed.post("/v1/shots/batch", json={"shots": [SEVEN_IRON] * 4})
    assert batch.status_code == 200
    bad = keyed.post("/v1/shots", json=SEVEN_IRON | {"spin_rpm": 99_999.0})
    assert bad.status_code == 422 and "spin_rpm" in bad.text
    assert keyed.post("/v1/gspro", json=GSPRO_SHOT).status_code == 200
    after = scrape(keyed)

    def moved(name: str, **labels) -> float:
        return value(after, name, **labels) - value(before, name, **labels)

    def requests_moved(route: str, status: int, method: str = "POST") -> float:
        return requests(after, route, status, method) - requests(before, route, status, method)

    assert requests_moved("/v1/shots", 200) == 3
    assert requests_moved("/v1/shots", 422) == 1
    assert requests_moved("/v1/shots/batch", 200) == 1
    assert requests_moved("/v1/gspro", 200) == 1
    assert requests_moved("/metrics", 200, "GET") == 1  # the first scrape; a scrape is counted once it is answered
    request_count = "golfflight_http_request_duration_seconds_count"
    assert moved(request_count, route="/v1/shots", method="POST") == 4
    assert moved(request_count, route="/v1/shots/batch", method="POST") == 1

    simulation = "golfflight_simulation_duration_seconds"
    assert moved(simulation + "_count", kind="shot") == 4  # three over /v1/shots, one over /v1/gspro; the 422 never flew
    assert moved(simulation + "_count", kind="batch") == 1
    request_sum = "golfflight_http_request_duration_seconds_sum"
    single_requests = moved(request_sum, route="/v1/shots", method="POST") + moved(
        request_sum, route="/v1/gspro", method="POST"
    )
    assert 0 < moved(simulation + "_sum", kind="shot") < single_requests
    assert 0 < moved(simulation + "_sum", kind="batch") < moved(request_sum, route="/v1/shots/batch", method="POST")

    assert moved("golfflight_batch_shots_count") == 1 and moved("golfflight_batch_shots_sum") == 4
    assert moved("golfflight_batch_shots_bucket", le="2.0") == 0 and moved("golfflight_batch_shots_bucket", le="5.0") == 1


def test_latency_and_metrics_come_from_the_same_measurements(keyed):
    """Single shots and batches apart in both (issue 56: a 10,000-shot batch read as every shot's p99)."""
    shot(keyed, **SEVEN_IRON)
    figures = keyed.get("/v1/latency").json()
    found = scrape(keyed)
    for window, kind in ((figures, "shot"), (figures["batch"], "batch")):
        assert window["simulation"]["count"] == value(found, "golfflight_simulation_duration_seconds_count", kind=kind)
    for window, routes in ((figures, ("/v1/shots", "/v1/gspro")), (figures["batch"], ("/v1/shots/batch",))):
        timed = sum(
            count
            for (name, labels), count in found.items()
            if name == "golfflight_http_request_duration_seconds_count" and dict(labels)["route"] in routes
        )
        assert window["request"]["count"] == timed


def test_metrics_need_the_key_and_refusals_are_counted_with_bounded_labels(keyed):
    before = scrape(keyed)
    with httpx.Client(base_url=keyed.base_url) as anonymous:
        refused = anonymous.get("/metrics")
        assert refused.status_code == 401 and "API key" in refused.json()["detail"] and KEY not in refused.text
        assert anonymous.get("/metrics", headers={"x-api-key": KEY + "x"}).status_code == 401
        assert anonymous.post("/v1/shots/batch", json={"shots": [SEVEN_IRON]}).status_code == 401
        assert anonymous.get("/metrics", headers={"authorization": f"Bearer {KEY}"}).status_code == 200
    assert keyed.get("/no/such/route/4711").status_code == 404
    assert keyed.request("PROPFIND", "/metrics").status_code == 405  # a method outside the standard labels
    # httptools (golfflight serve's parser) refuses a method HTTP has not registered before the app sees it
    assert keyed.request("BREW", "/metrics").status_code == 400
    after = scrape(keyed)
    assert requests(after, "/metrics", 401, "GET") - requests(before, "/metrics", 401, "GET") == 2
    assert requests(after, "/v1/shots/batch", 401) - requests(before, "/v1/shots/batch", 401) == 1
    assert requests(after, "/metrics", 200, "GET") - requests(before, "/metrics", 200, "GET") == 2  # scrape + Bearer
    assert requests(after, "<unmatched>", 404, "GET") - requests(before, "<unmatched>", 404, "GET") == 1
    assert requests(after, "/metrics", 405, "other") - requests(before, "/metrics", 405, "other") == 1
    label_values = {v for _, labels in after for _, v in labels}
    assert not any("4711" in v or "BREW" in v or "PROPFIND" in v for v in label_values)


def test_the_info_metric_names_the_loaded_model(keyed):
    card, _ = load_bundle(model_dir())
    text = keyed.get("/metrics").text
    (family,) = [f for f in text_string_to_metric_families(text) if f.name == "golfflight_model_info"]
    assert family.type == "gauge"  # the text format has no info type: an info metric is a gauge of 1 with labels
    (sample,) = family.samples
    assert sample.name == "golfflight_model_info" and sample.value == 1
    assert sample.labels == {"variant": card.variant, "sha256": card.onnx.sha256, "version": version("golfflight")}


def _per_worker_shots(directory: Path) -> dict[str, float]:
    """/v1/shots answered 200 by each worker process, read from its own counter file."""
    counts = {}
    for path in filter(started, directory.glob("counter_*.db")):  # a worker's file is empty for an instant
        for metric in MultiProcessCollector.merge([str(path)]):
            for sample in metric.samples:
                if sample.name == "golfflight_http_requests_total" and sample.labels == {
                    "route": "/v1/shots",
                    "method": "POST",
                    "status": "200",
                }:
                    counts[path.stem] = sample.value
    return counts


def test_several_workers_report_the_whole_server_whichever_takes_the_scrape(tmp_path):
    directory = tmp_path / "prometheus"
    directory.mkdir()
    stale = directory / "counter_1.db"
    stale.write_bytes(b"left by an earlier run")
    port = free_port()
    env = {key: v for key, v in os.environ.items() if key != API_KEY_ENV} | {MULTIPROC_ENV: str(directory)}
    log = tmp_path / "serve.log"
    base = f"http://127.0.0.1:{port}"
    with open(log, "w") as output:
        server = subprocess.Popen(
            [sys.executable, "-m", "golfflight", "serve", "--port", str(port), "--workers", "2"],
            env=env,
            stdout=output,
            stderr=subprocess.STDOUT,
        )
        try:
            flown, deadline = 0, time.monotonic() + 90
            while stale.exists():  # removed before the workers start
                assert time.monotonic() < deadline and server.poll() is None, log.read_text()
                time.sleep(0.05)
            with ThreadPoolExecutor(4) as pool:  # a fresh connection each: the workers take turns accepting
                while len([c for c in _per_worker_shots(directory).values() if c > 0]) < 2:
                    assert time.monotonic() < deadline and server.poll() is None, log.read_text()
                    answers = list(pool.map(lambda _: _post_shot(base), range(8)))
                    flown += answers.count(200)
                    assert set(answers) <= {NOT_LISTENING, 200, 503}, answers  # 503: a worker still loads its model
            while sum(_per_worker_shots(directory).values()) < flown:  # counted once the response has gone out
                assert time.monotonic() < deadline, (_per_worker_shots(directory), flown)
                time.sleep(0.05)
            assert sum(_per_worker_shots(directory).values()) == flown
            for _ in range(6):
                with httpx.Client(base_url=base) as http:
                    found = scrape(http)
                assert requests(found, "/v1/shots", 200) == flown
                assert value(found, "golfflight_simulation_duration_seconds_count", kind="shot") == flown
                assert any(name == "golfflight_model_info" for name, _ in found)
        finally:
            server.send_signal(signal.SIGTERM)
            server.wait(timeout=60)
    assert server.returncode == 0, log.read_text()


NOT_LISTENING = 0


def _post_shot(base: str) -> int:
    """The status of one shot on a connection of its own (NOT_LISTENING before the server listens)."""
    try:
        return httpx.post(base + "/v1/shots", json=SEVEN_IRON, timeout=30).status_code
    except httpx.ConnectError:
        return NOT_LISTENING


def test_workers_share_a_temporary_directory_unless_one_is_given(monkeypatch, tmp_path):
    monkeypatch.delenv(MULTIPROC_ENV, raising=False)
    with shared_across_workers(1) as directory:
        assert directory is None and MULTIPROC_ENV not in os.environ
    with shared_across_workers(3) as directory:
        assert directory.is_dir() and os.environ[MULTIPROC_ENV] == str(directory)
    assert not directory.exists() and MULTIPROC_ENV not in os.environ
    monkeypatch.setenv(MULTIPROC_ENV, str(tmp_path / "missing"))
    with pytest.raises(ValueError, match="no such directory"), shared_across_workers(2):
        pass


def test_a_scrape_as_a_worker_starts_leaves_out_its_empty_sample_file(tmp_path):
    """prometheus-client creates a worker's file empty and sizes it an instant later; read then, the library's own
    collector raises (a scrape answered 500), ours leaves the file out."""
    (tmp_path / "counter_7.db").write_bytes(b"")
    with pytest.raises(struct.error):
        list(MultiProcessCollector(None, str(tmp_path)).collect())
    registry = CollectorRegistry()
    StartedWorkersCollector(registry, tmp_path)
    assert generate_latest(registry) == b""

"""Memory and CPU of one `golfflight serve` worker, for sizing the Kubernetes Deployment (deploy/kubernetes/).

Starts `golfflight serve --workers 1` on a free loopback port, as the container does, and measures with psutil the
server process and its batch child (which flies batches at a lower priority): resident memory (RSS) after startup,
after a warm-up of single shots and batches and a burst of the largest batches, and the peak sampled every 20 ms
throughout; CPU seconds per single shot and per batched shot, each over its own phase. Then the worst request the API
accepts, for memory (`worst_batch`: 10,000 shots, each with its own air and wind, a normalized replay and a flat
flight, the last 100 with trajectories that come to just under MAX_TRAJECTORY_SAMPLES points, shown on the viewer),
BURST of them at once beside single shots at 1 kHz, with its own peak (issue 55, item 4). Prints JSON
(docs/service.md, "On Kubernetes", and docs/reliability.md quote it). Run it with the Python of a runtime-only
install (`pip install .` and psutil in a fresh virtual environment) from outside the checkout, so that what is
measured is what the serving image runs.

    python3 scripts/serving_footprint.py [--shots 500] [--batches 10] [--batch-size 1000]
"""

from __future__ import annotations

import argparse
import json
import os
import socket
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import httpx
import psutil
from golfflight.contract.requests import MAX_BATCH_SHOTS, MAX_BATCH_TRAJECTORIES
from golfflight.contract.trajectory_size import MAX_TRAJECTORY_SAMPLES

SHOT = {"ball_speed_mph": 171.0, "launch_angle_deg": 10.4, "back_spin_rpm": 2545.0, "side_spin_rpm": -300.0}
LARGEST_BATCH = 10_000
"""The largest batch the service takes."""

BURST = 4
"""Largest batches sent at once at the end (the server validates and holds each while the batch child flies them one
at a time), then the most trajectories a batch may ask for: together they set the peak."""


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def tree(server: psutil.Process) -> dict[str, psutil.Process]:
    """The server and its batch child by role (multiprocessing's resource tracker, a few MiB, is left out)."""
    children = [c for c in server.children() if "resource_tracker" not in " ".join(c.cmdline())]
    assert len(children) == 1, [c.cmdline() for c in children]
    return {"server": server, "batch_child": children[0]}


def rss_mib(processes: dict[str, psutil.Process]) -> dict[str, float]:
    return {role: round(p.memory_info().rss / 2**20, 1) for role, p in processes.items()}


def cpu_s(processes: dict[str, psutil.Process]) -> dict[str, float]:
    return {role: p.cpu_times().user + p.cpu_times().system for role, p in processes.items()}


class PeakSampler(threading.Thread):
    """The highest RSS of each process, and of both together, sampled every 20 ms until stopped."""

    def __init__(self, processes: dict[str, psutil.Process]):
        super().__init__(daemon=True)
        self.processes, self.stopped = processes, threading.Event()
        self.peak = {role: 0.0 for role in [*processes, "total"]}

    def run(self) -> None:
        while not self.stopped.wait(0.02):
            now = rss_mib(self.processes)
            now["total"] = sum(now.values())
            self.peak = {role: max(self.peak[role], now[role]) for role in self.peak}


FULL_SHOT = SHOT | {
    "normalized": True,
    "air": {"temperature_c": 31.5, "altitude_m": 1600.0, "humidity_pct": 40.0},
    "wind": {"speed_mps": 6.5, "from_deg": 210.0, "profile": "log"},
    "ground": {"surface": "fairway", "elevation_m": -4.5, "slope_deg": 2.0, "slope_dir_deg": 45.0},
}
"""A shot that asks for everything a flight can cost: its own air and wind, a normalized replay, a flat flight."""


def worst_batch(http: httpx.Client) -> dict:
    """The batch the API accepts that costs the most memory: MAX_BATCH_SHOTS FULL_SHOTs, the last
    MAX_BATCH_TRAJECTORIES with a trajectory at the highest rate whose points (both flights of each) stay within
    MAX_TRAJECTORY_SAMPLES, found from the points those shots get at 1 Hz (about one a second of flight and roll)."""
    traced = [FULL_SHOT | {"trajectory": {"rate_hz": 1}}] * MAX_BATCH_TRAJECTORIES
    answer = http.post("/v1/shots/batch", json={"shots": traced})
    answer.raise_for_status()
    flights = [r for result in answer.json()["results"] for r in (result, result["normalized"])]
    seconds = sum(flight["trajectory"][-1]["t_s"] for flight in flights)
    rate = min(1000, int((MAX_TRAJECTORY_SAMPLES - 3 * len(flights)) / seconds))
    plain = [FULL_SHOT] * (MAX_BATCH_SHOTS - MAX_BATCH_TRAJECTORIES)
    return {"shots": plain + [FULL_SHOT | {"trajectory": {"rate_hz": rate}}] * MAX_BATCH_TRAJECTORIES}


def worst_burst(http: httpx.Client, processes: dict[str, psutil.Process]) -> dict:
    """BURST worst batches at once (shown on the viewer) beside BURST single shots at 1 kHz with a normalized
    replay: the peak RSS while they are answered, and what was sent."""
    batch = worst_batch(http)
    body = json.dumps(batch).encode()  # under the 8 MiB body limit: a 413 otherwise, and the run stops
    single = FULL_SHOT | {"trajectory": {"rate_hz": 1000}}
    sampler = PeakSampler(processes)
    sampler.start()
    url = http.base_url.join("/v1/shots/batch?viewer=true")
    headers = {"content-type": "application/json"}
    with ThreadPoolExecutor(2 * BURST) as pool:
        batches = [pool.submit(httpx.post, url, content=body, headers=headers, timeout=600) for _ in range(BURST)]
        singles = [pool.submit(http.post, "/v1/shots", json=single) for _ in range(BURST)]
        answers = [future.result() for future in batches + singles]
    sampler.stopped.set()
    sampler.join()
    assert all(answer.status_code == 200 for answer in answers), [a.text[:200] for a in answers if a.is_error]
    points = sum(len(r["trajectory"]) + len(r["normalized"]["trajectory"])
                 for r in answers[0].json()["results"] if "trajectory" in r)
    return {"batch": {"shots": len(batch["shots"]), "body_bytes": len(body),
                      "trajectory_rate_hz": batch["shots"][-1]["trajectory"]["rate_hz"], "trajectory_points": points,
                      "answer_bytes": len(answers[0].content)},
            "at_once": f"{BURST} such batches and {BURST} single shots at 1 kHz with a normalized replay",
            "peak_rss_mib": sampler.peak}


def wait_ready(http: httpx.Client, server: subprocess.Popen) -> None:
    """Return once the server answers GET /healthz with 200 (two minutes at most)."""
    deadline = time.monotonic() + 120
    while True:
        try:
            if http.get("/healthz").status_code == 200:
                return
        except httpx.TransportError:
            pass
        assert time.monotonic() < deadline and server.poll() is None, "the server did not become ready"
        time.sleep(0.1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--shots", type=int, default=500, help="single shots in the warm-up")
    parser.add_argument("--batches", type=int, default=10)
    parser.add_argument("--batch-size", type=int, default=1000)
    args = parser.parse_args()
    load_before = os.getloadavg()
    port = free_port()
    env = {k: v for k, v in os.environ.items() if k not in ("GOLFFLIGHT_API_KEY", "PROMETHEUS_MULTIPROC_DIR")}
    command = [sys.executable, "-m", "golfflight", "serve", "--port", str(port), "--workers", "1"]
    server = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        with httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=120) as http:
            wait_ready(http, server)
            processes = tree(psutil.Process(server.pid))
            started = rss_mib(processes)
            sampler = PeakSampler(processes)
            sampler.start()

            cpu_before, wall = cpu_s(processes), time.perf_counter()
            for _ in range(args.shots):
                http.post("/v1/shots", json=SHOT).raise_for_status()
            single_wall = time.perf_counter() - wall
            cpu_single = {role: t - cpu_before[role] for role, t in cpu_s(processes).items()}

            cpu_before, wall = cpu_s(processes), time.perf_counter()
            for _ in range(args.batches):
                http.post("/v1/shots/batch", json={"shots": [SHOT] * args.batch_size}).raise_for_status()
            batch_wall = time.perf_counter() - wall
            cpu_batch = {role: t - cpu_before[role] for role, t in cpu_s(processes).items()}

            largest = {"shots": [SHOT] * LARGEST_BATCH}
            with ThreadPoolExecutor(BURST) as pool:
                answers = pool.map(
                    lambda _: httpx.post(http.base_url.join("/v1/shots/batch"), json=largest, timeout=300), range(BURST)
                )
                assert all(answer.status_code == 200 for answer in answers)
            traced = {"shots": [SHOT | {"trajectory": {"rate_hz": 60}}] * MAX_BATCH_TRAJECTORIES}
            http.post("/v1/shots/batch", json=traced).raise_for_status()
            warm = rss_mib(processes)
            sampler.stopped.set()
            sampler.join()
            worst = worst_burst(http, processes)
    finally:
        server.terminate()
        server.wait(timeout=60)
    batched = args.batches * args.batch_size
    print(
        json.dumps(
            {
                "command": " ".join(command[1:]),
                "cpus": os.cpu_count(),
                "load_average_before": [round(x, 2) for x in load_before],
                "rss_mib": {"after_startup": started, "after_warm_up": warm, "peak": sampler.peak},
                "worst_request": worst,
                "single_shots": {
                    "shots": args.shots,
                    "shots_per_s": round(args.shots / single_wall, 1),
                    "server_cpu_ms_per_shot": round(cpu_single["server"] / args.shots * 1e3, 3),
                    "server_cores_busy": round(cpu_single["server"] / single_wall, 2),
                },
                "batches": {
                    "shots": batched,
                    "batch_size": args.batch_size,
                    "shots_per_s": round(batched / batch_wall, 1),
                    "cpu_us_per_shot": {r: round(t / batched * 1e6, 1) for r, t in cpu_batch.items()},
                    "batch_child_cores_busy": round(cpu_batch["batch_child"] / batch_wall, 2),
                },
            },
            indent=2,
        )
    )


if __name__ == "__main__":
    main()

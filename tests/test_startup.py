"""Issue 23: the service loads its model before its ports accept, so the very first request is served (it answered
503 for about 2 s after start while the model loaded in a background thread), and the degree signs in what the
service says stay attached to their numbers."""

from __future__ import annotations

import json
import re
import socket
import threading
import time
from pathlib import Path

import httpx
import uvicorn
from golfflight.service.app import create_app
from golfflight.service.settings import ServiceSettings
from servers import free_port

SEVEN_IRON = {"ball_speed_mps": 55.0, "launch_angle_deg": 16.0, "spin_rpm": 7100.0}
SHOT = {
    "DeviceID": "startup test",
    "Units": "Yards",
    "ShotNumber": 1,
    "APIversion": "1",
    "BallData": {"Speed": 123.0, "SpinAxis": 0.0, "TotalSpin": 7100.0, "HLA": 0.0, "VLA": 16.0},
}
ROOT = Path(__file__).resolve().parents[1]


def _connect_once_accepting(port: int, deadline: float) -> socket.socket:
    """A connection to the port as soon as it accepts one (polling the port, not the service)."""
    while True:
        try:
            return socket.create_connection(("127.0.0.1", port), timeout=5)
        except ConnectionRefusedError:
            assert time.monotonic() < deadline, f"port {port} never accepted"
            time.sleep(0.005)


def test_the_first_request_once_the_ports_accept_is_served():
    http_port, tcp_port = free_port(), free_port()
    app = create_app(ServiceSettings(connect_port=tcp_port))
    server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=http_port, log_level="warning"))
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    try:
        deadline = time.monotonic() + 60
        connector = _connect_once_accepting(tcp_port, deadline)  # Open Connect accepts only once the model is in
        with connector:
            connector.sendall(json.dumps(SHOT).encode())
            reply, _ = json.JSONDecoder().raw_decode(connector.recv(8192).decode())
        assert reply["Code"] == 200, reply
        _connect_once_accepting(http_port, deadline).close()
        first = httpx.post(f"http://127.0.0.1:{http_port}/v1/shots", json=SEVEN_IRON, timeout=30)
        assert first.status_code == 200, first.text
        assert httpx.get(f"http://127.0.0.1:{http_port}/healthz").json()["status"] == "ready"
    finally:
        server.should_exit = True
        thread.join(timeout=10)


def test_the_first_request_over_http_alone_is_served():
    port = free_port()
    server = uvicorn.Server(uvicorn.Config(create_app(), host="127.0.0.1", port=port, log_level="warning"))
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    try:
        _connect_once_accepting(port, time.monotonic() + 60).close()
        first = httpx.post(f"http://127.0.0.1:{port}/v1/shots", json=SEVEN_IRON, timeout=30)
        assert first.status_code == 200, first.text
    finally:
        server.should_exit = True
        thread.join(timeout=10)


def test_no_degree_sign_detached_from_its_number_in_what_the_service_says():
    """'16.1°', never '16.1 °' (the viewer's own text is checked with the viewer)."""
    sources = [*(ROOT / "service").rglob("*.py"), *(ROOT / "golfflight" / "commands").glob("*.py")]
    sources = [path for path in sources if "viewer" not in path.relative_to(ROOT).parts]
    detached = [
        f"{path.relative_to(ROOT)}:{number}: {line.strip()}"
        for path in sources
        for number, line in enumerate(path.read_text().splitlines(), 1)
        if re.search(r"[\d}]\s+°", line)
    ]
    assert len(sources) > 20 and not detached, detached

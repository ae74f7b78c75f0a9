"""Exposure: loopback by default, the optional API key on every route but /healthz, CORS off unless configured,
no client-chosen paths, and the key never in the logs."""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import time

import httpx
import pytest
from golfflight.service.settings import ServiceSettings, API_KEY_ENV
from golfflight.service.app import create_app
from servers import free_port, running

from golfflight.commands import serve

KEY = "test-key-0d5f8c1e9a7b4c2d"
SHOT = {"ball_speed_mps": 55.0, "launch_angle_deg": 16.0, "spin_rpm": 7100.0}
GET_ROUTES = ("/v1/model", "/v1/latency", "/openapi.json", "/docs")


def test_serve_binds_loopback_unless_told_otherwise():
    parser = argparse.ArgumentParser()
    serve.register(parser.add_subparsers())
    args = parser.parse_args(["serve"])
    assert args.host == "127.0.0.1" and args.cors_origin is None


def test_the_api_key_is_required_everywhere_but_healthz():
    with running(create_app(ServiceSettings(api_key=KEY))) as http:
        assert http.get("/healthz").status_code == 200
        for path in GET_ROUTES:
            refused = http.get(path)
            assert refused.status_code == 401 and "API key" in refused.json()["detail"], path
            assert KEY not in refused.text
            assert http.get(path, headers={"x-api-key": KEY}).status_code == 200, path
        for path, body in (("/v1/shots", SHOT), ("/v1/shots/batch", {"shots": [SHOT]}), ("/v1/gspro", {})):
            assert http.post(path, json=body).status_code == 401, path
            assert http.post(path, json=body, headers={"x-api-key": KEY + "x"}).status_code == 401, path
            assert http.post(path, json=body, headers={"authorization": "Basic " + KEY}).status_code == 401, path
        assert http.post("/v1/shots", json=SHOT, headers={"x-api-key": KEY}).status_code == 200
        assert http.post("/v1/shots", json=SHOT, headers={"authorization": f"Bearer {KEY}"}).status_code == 200


def test_without_a_key_nothing_is_asked():
    with running(create_app(ServiceSettings())) as http:
        assert http.post("/v1/shots", json=SHOT).status_code == 200


def test_cors_is_off_unless_origins_are_configured():
    preflight = {"origin": "https://sim.example", "access-control-request-method": "POST"}
    with running(create_app(ServiceSettings())) as http:
        answer = http.post("/v1/shots", json=SHOT, headers={"origin": "https://sim.example"})
        assert answer.status_code == 200 and "access-control-allow-origin" not in answer.headers
        assert "access-control-allow-origin" not in http.options("/v1/shots", headers=preflight).headers
    with running(create_app(ServiceSettings(api_key=KEY, cors_origins=["https://sim.example"]))) as http:
        allowed = http.options("/v1/shots", headers={**preflight, "access-control-request-headers": "x-api-key"})
        assert allowed.status_code == 200 and allowed.headers["access-control-allow-origin"] == "https://sim.example"
        other = http.options("/v1/shots", headers={**preflight, "origin": "https://evil.example"})
        assert other.headers.get("access-control-allow-origin") != "https://evil.example"
        keyed = http.post("/v1/shots", json=SHOT, headers={"origin": "https://sim.example", "x-api-key": KEY})
        assert keyed.status_code == 200 and keyed.headers["access-control-allow-origin"] == "https://sim.example"


def test_no_route_takes_a_path_from_the_client():
    schema = create_app(ServiceSettings()).openapi()
    assert not any("{" in path for path in schema["paths"]), "path parameters"
    for path, operations in schema["paths"].items():
        for operation in operations.values():
            for parameter in operation.get("parameters", []):  # a yes/no switch (?viewer=true) or a number
                kinds = parameter["schema"].get("anyOf", [parameter["schema"]])  # (?session=3) names nothing
                types = {kind.get("type") for kind in kinds} - {"null"}
                assert types <= {"boolean", "integer"}, (path, "a query or header parameter", parameter)

    components = schema["components"]["schemas"]

    def names(node, seen: set):
        """Every property name reachable from a schema node, following $refs."""
        if isinstance(node, dict):
            ref = node.get("$ref")
            if ref and ref not in seen:
                seen.add(ref)
                yield from names(components[ref.rsplit("/", 1)[1]], seen)
            for key, value in node.items():
                if key == "properties":
                    yield from value
                yield from names(value, seen)
        elif isinstance(node, list):
            for item in node:
                yield from names(item, seen)

    bodies = [op["requestBody"] for ops in schema["paths"].values() for op in ops.values() if "requestBody" in op]
    fields = set(names(bodies, set()))
    assert {"ball_speed_mps", "temperature_c", "BallData"} <= fields
    words = {"path", "file", "filename", "dir", "directory", "folder", "url", "uri", "model"}
    angles = {name for name in fields if name.endswith("_deg")}  # a number: slope_dir_deg is a direction, not a dir
    assert not {name for name in fields - angles if words & set(name.lower().split("_"))}


def test_the_api_key_never_reaches_the_logs(tmp_path):
    port = free_port()
    env = {**os.environ, API_KEY_ENV: KEY}
    log = tmp_path / "serve.log"
    with open(log, "w") as output:
        server = subprocess.Popen(
            [sys.executable, "-m", "golfflight", "serve", "--port", str(port)],
            env=env,
            stdout=output,
            stderr=subprocess.STDOUT,
        )
        try:
            base = f"http://127.0.0.1:{port}"
            deadline = time.monotonic() + 30
            while True:
                try:
                    if httpx.get(base + "/healthz").status_code == 200:
                        break
                except httpx.TransportError:
                    pass
                assert time.monotonic() < deadline and server.poll() is None, log.read_text()
                time.sleep(0.1)
            with httpx.Client(base_url=base) as http:
                assert http.post("/v1/shots", json=SHOT, headers={"x-api-key": KEY}).status_code == 200
                assert http.post("/v1/shots", json=SHOT, headers={"x-api-key": KEY[:-1]}).status_code == 401
                bearer = {"authorization": f"Bearer {KEY}"}
                assert http.post("/v1/shots", json={"bad": 1}, headers=bearer).status_code == 422
        finally:
            server.send_signal(signal.SIGTERM)
            server.wait(timeout=30)
    text = log.read_text()
    assert "API key required" in text
    assert KEY not in text and KEY[:-1] not in text


@pytest.mark.parametrize("host", ["127.0.0.1", "localhost", "::1"])
def test_loopback_hosts_are_recognised(host):
    assert serve._loopback(host) and not serve._loopback("0.0.0.0")

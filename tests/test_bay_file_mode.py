"""A bay file whose mode changes under a running service (issue 55): `chmod 000` left /healthz "ready" and the
bay file unread, and `chmod 644` back did not heal a bay already degraded, because the change check read the
content's time, the size and the inode, not the inode's change time. `golfflight serve --bay FILE` in a process of
its own, without the capabilities that let root read a file whatever its mode where the test runs as root
(`setpriv`, util-linux)."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time

import httpx
import pytest

from tests.servers import free_port

AS_ROOT = os.geteuid() == 0
WITHOUT_OVERRIDE = ["setpriv", "--bounding-set=-dac_override,-dac_read_search", "--"] if AS_ROOT else []
"""What starts the service so that a file's mode holds for it: root bypasses modes by these two capabilities."""


def healthz(base: str) -> dict | None:
    try:
        return httpx.get(base + "/healthz", timeout=5).json()
    except (httpx.TransportError, ValueError):
        return None


def until(base: str, status: str, server: subprocess.Popen, timeout_s: float = 10.0) -> dict:
    """/healthz once its status is `status`."""
    deadline = time.monotonic() + timeout_s
    while True:
        health = healthz(base)
        if health is not None and health.get("status") == status:
            return health
        assert time.monotonic() < deadline and server.poll() is None, health
        time.sleep(0.1)


@pytest.mark.skipif(AS_ROOT and shutil.which("setpriv") is None, reason="root reads any file; no setpriv to stop it")
def test_a_bay_file_made_unreadable_degrades_the_service_and_readable_again_heals_it(tmp_path):
    bay = tmp_path / "bay.json"
    bay.write_text('{"air": {"altitude_m": 1600.0}}\n')
    port = free_port()
    command = [*WITHOUT_OVERRIDE, sys.executable, "-m", "golfflight", "serve", "--port", str(port), "--bay", str(bay)]
    env = {key: value for key, value in os.environ.items() if key != "GOLFFLIGHT_API_KEY"}
    server = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    base = f"http://127.0.0.1:{port}"
    try:
        until(base, "ready", server, timeout_s=90)
        bay.chmod(0)
        degraded = until(base, "degraded", server)
        assert "cannot be read" in degraded["problems"]["bay"], degraded
        bay.chmod(0o644)
        until(base, "ready", server)
        assert httpx.get(base + "/v1/bay", timeout=5).json()["air"]["altitude_m"] == 1600.0
    finally:
        server.send_signal(signal.SIGTERM)
        server.wait(60)

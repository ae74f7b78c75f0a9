"""`golfflight serve` in a subprocess on a free 127.0.0.1 port for the reliability scripts: start, wait for /healthz,
measure its memory (the supervisor and every worker), stop it with SIGTERM and report how it ended; and a raw
keep-alive HTTP client for the wire's benchmarks."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import httpx
import psutil
from common import REPO

HOST = "127.0.0.1"
"""All load and fuzz traffic stays on the loopback interface."""


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind((HOST, 0))
        return probe.getsockname()[1]


class RawHttp:
    """One keep-alive HTTP/1.1 connection with no client library: the request's bytes built once, the answer framed
    by its Content-Length and parsed by the C JSON parser. What a simulator's client in C++ or C# pays for the
    wire is about this (nearly nothing), so the server's and the loopback's share of a request shows without
    httpx's own CPU (pure Python, a fifth of a request in `profile_wire.py`)."""

    def __init__(self, port: int, path: str, body: bytes):
        self.sock = socket.create_connection((HOST, port), timeout=30)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.request = (f"POST {path} HTTP/1.1\r\nhost: 127.0.0.1\r\ncontent-type: application/json\r\n"
                        f"content-length: {len(body)}\r\n\r\n").encode() + body

    def post(self) -> dict:
        self.sock.sendall(self.request)
        data = b""
        while True:
            data += self.sock.recv(65536)
            head, blank, rest = data.partition(b"\r\n\r\n")
            if not blank:
                continue
            length = next(int(line.split(b":")[1]) for line in head.split(b"\r\n")
                          if line.lower().startswith(b"content-length:"))
            if len(rest) >= length:
                assert head.startswith(b"HTTP/1.1 200"), head
                return json.loads(rest[:length])

    def close(self) -> None:
        self.sock.close()


@dataclass
class Server:
    """A running `golfflight serve` and where to reach it."""

    process: subprocess.Popen
    base_url: str
    port: int

    def rss_mib(self) -> dict[str, float]:
        """Resident memory (MiB) of the supervisor and each worker process, and their total."""
        root = psutil.Process(self.process.pid)
        processes = [root, *root.children(recursive=True)]
        sizes = {}
        for process in processes:
            try:
                sizes[f"pid {process.pid}"] = process.memory_info().rss / 2**20
            except psutil.NoSuchProcess:
                continue
        return {**sizes, "total": sum(sizes.values())}

    def worker_pids(self) -> list[int]:
        return [p.pid for p in psutil.Process(self.process.pid).children(recursive=True)]

    def stop(self, timeout_s: float = 60.0) -> tuple[int | None, float]:
        """SIGTERM, then wait: (exit code, seconds it took); SIGKILL and None if it did not end in time."""
        started = time.monotonic()
        self.process.send_signal(signal.SIGTERM)
        try:
            code = self.process.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
            code = None
        return code, time.monotonic() - started


def start(
    workers: int = 1, model: str | None = None, env: dict[str, str] | None = None, tree: Path = REPO,
    args: list[str] = (),
) -> Server:
    """Start `golfflight serve` of the checkout `tree` (default this one; another for an A/B run) on a free loopback
    port, with `args` added to its command line; returns once every worker answers /healthz."""
    port = free_port()
    command = [sys.executable, "-m", "golfflight", "serve", "--host", HOST, "--port", str(port)]
    command += ["--workers", str(workers)] + (["--model", model] if model else []) + list(args)
    process = subprocess.Popen(command, cwd=tree, env={**os.environ, **(env or {})}, stdout=subprocess.DEVNULL)
    server = Server(process, f"http://{HOST}:{port}", port)
    deadline = time.monotonic() + 60
    ready = 0
    while time.monotonic() < deadline and process.poll() is None:
        try:
            ready = ready + 1 if httpx.get(server.base_url + "/healthz", timeout=2).status_code == 200 else 0
        except httpx.TransportError:
            ready = 0
        if ready >= 4 * workers and len(server.worker_pids()) >= (workers if workers > 1 else 0):
            return server
        time.sleep(0.05)
    process.kill()
    raise RuntimeError("golfflight serve did not become ready within 60 s")

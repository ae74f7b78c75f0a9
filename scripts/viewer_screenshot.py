"""docs/viewer.png and docs/viewer-summary.png: the live viewer in headless Chromium during a short range session,
and how long a shot takes to reach the page.

Starts `golfflight serve` with an API key and GSPro Open Connect on free loopback ports, opens /viewer#key=KEY,
sets a pin at 150 yd in the page's header, then hits wedges, 7-irons and drivers (seeded scatter) over Open Connect
TCP, POST /v1/gspro and POST /v1/shots?viewer=true, picking the club in the page before each group, and screenshots
the page once the last drive has played and the session's summary shows all three clubs; then the shot list with the
summary table beside the dispersion view with its ellipses (--summary-out). Prints the time from sending each shot
to its row appearing in the page (timed in the page by a MutationObserver).

    python3 scripts/viewer_screenshot.py [--out docs/viewer.png] [--summary-out docs/viewer-summary.png]
"""

from __future__ import annotations

import argparse
import json
import os
import random
import socket
import statistics
import subprocess
import sys
import time
from pathlib import Path

import httpx

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from browser import headless_page, missing
from servers import free_port

KEY = "screenshot-key"
PIN_YD = 150
"""The pin the page is given, yards down the target line: between the 7-irons and the drivers."""
SESSION = [  # club in the page, how it is sent, launch (mph, deg, rpm), shots
    ("PW", "tcp", (102.0, 24.0, 8800.0), 4),
    ("7-iron", "gspro-http", (120.0, 16.3, 7000.0), 4),
    ("Driver", "http", (167.0, 10.9, 2686.0), 5),
]

WATCH_ROWS = """() => {
  const body = document.querySelector('#shots tbody');
  window.rowSeen = [];
  new MutationObserver(() => {
    while (window.rowSeen.length < body.rows.length) window.rowSeen.push(Date.now() / 1000);
  }).observe(body, {childList: true});
}"""
"""Records in the page when each new row of the shot table appears (the clock is this machine's, as Python's)."""


SUMMARY_SHOWN = """(shots) => {
  const rows = [...document.querySelectorAll('#summary tbody tr')];
  return rows.reduce((n, r) => n + Number(r.cells[1].textContent), 0) === shots
    && document.querySelectorAll('#dispersion polygon.ellipse').length === rows.length;
}"""
"""The session's summary counts every shot sent, and each club has its ellipse."""


def summary_clip(page) -> dict:
    """The part of the page with the shot list, the session's summary and the dispersion view with its ellipses."""
    boxes = [page.locator(selector).bounding_box() for selector in (".shots", ".dispersion", "#summary")]
    left, top = min(b["x"] for b in boxes), min(b["y"] for b in boxes)
    right, bottom = max(b["x"] + b["width"] for b in boxes), max(b["y"] + b["height"] for b in boxes[1:])
    return {"x": left - 4, "y": top - 4, "width": right - left + 8, "height": bottom - top + 12}


def send(
    how: str,
    http: httpx.Client,
    tcp: socket.socket,
    number: int,
    launch: tuple[float, float, float],
    rng: random.Random,
) -> None:
    speed, angle, spin = launch
    speed, angle, spin = speed * rng.gauss(1, 0.02), angle + rng.gauss(0, 1.2), spin * rng.gauss(1, 0.06)
    direction, side_spin = rng.gauss(0, 2.0), rng.gauss(0, 350.0)
    if how == "http":
        shot = {
            "ball_speed_mph": speed,
            "launch_angle_deg": angle,
            "launch_direction_deg": direction,
            "back_spin_rpm": spin,
            "side_spin_rpm": side_spin,
        }
        http.post("/v1/shots?viewer=true", json=shot).raise_for_status()  # shown on the bay's screen
        return
    message = {
        "DeviceID": "screenshot",
        "ShotNumber": number,
        "APIversion": "1",
        "BallData": {"Speed": speed, "VLA": angle, "HLA": direction, "BackSpin": spin, "SideSpin": side_spin},
    }
    if how == "gspro-http":
        http.post("/v1/gspro", json=message).raise_for_status()
    else:
        tcp.sendall(json.dumps(message).encode())
        tcp.recv(65536)


def wait_ready(http: httpx.Client, server: subprocess.Popen) -> None:
    for _ in range(600):
        assert server.poll() is None, "golfflight serve stopped"
        try:
            if http.get("/healthz").status_code == 200:
                return
        except httpx.TransportError:
            pass
        time.sleep(0.1)
    raise SystemExit("golfflight serve never became ready")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("docs/viewer.png"))
    parser.add_argument("--summary-out", type=Path, default=Path("docs/viewer-summary.png"))
    args = parser.parse_args()
    if missing():
        raise SystemExit(f"cannot take the screenshot: {missing()}")
    port, connect_port = free_port(), free_port()
    command = [sys.executable, "-m", "golfflight", "serve", "--port", str(port), "--connect-port", str(connect_port)]
    server = subprocess.Popen(command, env={**os.environ, "GOLFFLIGHT_API_KEY": KEY})
    seen_ms: list[float] = []
    try:
        with httpx.Client(base_url=f"http://127.0.0.1:{port}", headers={"x-api-key": KEY}, timeout=30) as http:
            wait_ready(http, server)
            with headless_page(1400, 1000) as page, socket.create_connection(("127.0.0.1", connect_port)) as tcp:
                page.goto(f"http://127.0.0.1:{port}/viewer#key={KEY}")
                page.wait_for_selector("#status[data-state=live]", timeout=10_000)
                page.fill("#pin", str(PIN_YD))  # the pin, as a golfer sets it in the header (kept in localStorage)
                page.press("#pin", "Enter")
                page.evaluate(WATCH_ROWS)
                rng, number = random.Random(13), 0
                for club, how, launch, shots in SESSION:
                    page.select_option("#club", club)
                    page.wait_for_function(  # the bay's player is saved (PATCH answered) before the club's shots
                        "() => { const c = document.querySelector('#club'); return c.dataset.saved === c.value; }",
                        timeout=10_000,
                    )
                    for _ in range(shots):
                        number += 1
                        sent = time.time()
                        send(how, http, tcp, number, launch, rng)
                        page.wait_for_function("n => window.rowSeen.length >= n", arg=number, timeout=10_000)
                        seen_ms.append((page.evaluate("n => window.rowSeen[n - 1]", number) - sent) * 1e3)
                page.wait_for_selector("#side polyline.latest[data-done]", timeout=10_000)
                page.wait_for_function(SUMMARY_SHOWN, arg=sum(group[3] for group in SESSION), timeout=10_000)
                args.out.parent.mkdir(parents=True, exist_ok=True)
                page.screenshot(path=str(args.out), full_page=True)
                page.screenshot(path=str(args.summary_out), full_page=True, clip=summary_clip(page))
    finally:
        server.terminate()
        server.wait(timeout=60)
    print(
        f"wrote {args.out} and {args.summary_out}; shot sent to its row in the page: p50 {statistics.median(seen_ms):.0f} ms, "
        f"max {max(seen_ms):.0f} ms over {len(seen_ms)} shots"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())

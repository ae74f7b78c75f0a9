"""`golfflight simulate` (JSON or CSV in, JSON or CSV out) and `golfflight serve`'s refusals of a bad bundle and a
busy port."""

from __future__ import annotations

import csv
import json
import socket

from golfflight.cli import main

SHOTS = {
    "shots": [
        {"ball_speed_mph": 171, "launch_angle_deg": 10.4, "back_spin_rpm": 2545},
        {"ball_speed_mps": 55, "launch_angle_deg": 16, "spin_rpm": 7100, "normalized": True},
    ]
}


def test_simulate_json_flies_both_unit_forms_and_the_normalized_replay(tmp_path, capsys):
    path = tmp_path / "shots.json"
    path.write_text(json.dumps(SHOTS))
    assert main(["simulate", str(path)]) == 0
    results = json.loads(capsys.readouterr().out)["results"]
    assert len(results) == 2 and results[0]["carry_yd"] > 200 and "normalized" in results[1]


def test_simulate_csv_of_launches_with_conditions_to_csv(tmp_path):
    source, out = tmp_path / "launches.csv", tmp_path / "results.csv"
    rows = [
        {"shot_id": "a", "ball_speed_mps": 55, "launch_angle_deg": 16, "spin_rpm": 7100, "wind_speed_mps": ""},
        {"shot_id": "b", "ball_speed_mps": 55, "launch_angle_deg": 16, "spin_rpm": 7100, "wind_speed_mps": 6},
    ]
    with open(source, "w", newline="") as handle:
        writer = csv.DictWriter(handle, rows[0].keys())
        writer.writeheader()
        writer.writerows(rows)
    assert main(["simulate", str(source), "--out", str(out)]) == 0
    with open(out) as handle:
        results = list(csv.DictReader(handle))
    assert [r["shot_id"] for r in results] == ["a", "b"]
    assert float(results[1]["carry_m"]) < float(results[0]["carry_m"])  # 6 m/s of headwind


def test_simulate_names_bad_values_and_unknown_columns(tmp_path, capsys):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps([{"ball_speed_mps": 500, "launch_angle_deg": 10, "spin_rpm": 3000}]))
    assert main(["simulate", str(path)]) == 2
    assert "ball_speed_mps" in capsys.readouterr().err
    columns = tmp_path / "bad.csv"
    columns.write_text("ball_speed_mps,launch_angle_deg,spin_rpm,club_head_mph\n55,16,7100,90\n")
    assert main(["simulate", str(columns)]) == 2
    assert "club_head_mph" in capsys.readouterr().err


def test_serve_refuses_a_directory_without_a_bundle(tmp_path, capsys):
    assert main(["serve", "--model", str(tmp_path)]) == 2
    assert "not a model bundle" in capsys.readouterr().err


def test_serve_refuses_a_busy_http_port_in_one_line_before_saying_it_serves(capsys):
    """A port another program listens on is refused with what to do (--port), exit 2, and nothing printed about
    serving there (it printed "... on http://127.0.0.1:PORT ...", then uvicorn's [Errno 98] and exit 3)."""
    with socket.create_server(("127.0.0.1", 0)) as busy:
        port = busy.getsockname()[1]
        assert main(["serve", "--port", str(port)]) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err.count("\n") == 1 and f"--port: 127.0.0.1:{port} is in use" in err and "another port with --port" in err


def test_serve_names_uvloop_where_it_imports_and_httptools_with_request_deadlines(monkeypatch):
    from golfflight.commands import serve
    from golfflight.service.api.http_protocol import DeadlineHttpProtocol

    # runtime dependencies of the serving install; httptools with deadlines for a request's head and body
    assert serve.fast_io() == {"loop": "uvloop", "http": DeadlineHttpProtocol}
    real = serve.importlib.import_module

    def without_uvloop(name: str):
        if name == "uvloop":
            raise ImportError("no uvloop here (as on Windows)")
        return real(name)

    monkeypatch.setattr(serve.importlib, "import_module", without_uvloop)
    assert serve.fast_io() == {"loop": "asyncio", "http": DeadlineHttpProtocol}

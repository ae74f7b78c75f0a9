"""A sweep that does not reach its end (issue 42): stopped by a signal it removes its temporary file, stops its workers
and says so; killed outright, its workers, fork server and resource tracker still go, and the next sweep to the same
file removes the temporary file it left (and leaves one a running sweep owns); a write that fails names the file.
Real processes throughout: `python3 -m golfflight sweep` run and signalled, its descendants read from /proc."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from golfflight.cli import main

pa = pytest.importorskip("pyarrow")
pq = pytest.importorskip("pyarrow.parquet")

ROOT = Path(__file__).resolve().parents[1]
LONG = ["--grid", "ball_speed_mps=30:80:400", "launch_angle_deg=6:24:400", "spin_rpm=2000:4000:10", "--chunk-rows",
        "500"]
"""1,600,000 shots in pieces of 500, signalled once the first pieces are written: over a minute of flying at 23,000
shots/s on two workers."""
SHORT = ["--grid", "ball_speed_mps=50", "launch_angle_deg=12", "spin_rpm=3000"]
GONE_WITHIN_S = 5.0
"""How long after the signal nothing of the sweep may be left."""


def sweep_command(out: Path, *axes: str) -> list[str]:
    return [sys.executable, "-m", "golfflight", "sweep", *axes, "--out", str(out), "--workers", "2", "--no-progress"]


def process_table() -> dict[int, tuple[int, str, str]]:
    """pid -> (parent pid, state, start time) of every process, from /proc/PID/stat."""
    table = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rpartition(")")[2].split()
        except OSError:  # gone meanwhile
            continue
        table[int(stat.parent.name)] = (int(fields[1]), fields[0], fields[19])
    return table


def descendants(pid: int) -> dict[int, str]:
    """pid -> start time of every process below `pid` (the start time tells a reused pid from the same process)."""
    table, found, below = process_table(), {}, [pid]
    while below:
        parent = below.pop()
        for child, (ppid, _, started) in table.items():
            if ppid == parent and child not in found:
                found[child] = started
                below.append(child)
    return found


def running(recorded: dict[int, str]) -> list[int]:
    """The processes of `recorded` still running (a zombie, dead but not yet reaped, is not)."""
    table = process_table()
    return [pid for pid, started in recorded.items()
            if pid in table and table[pid][2] == started and table[pid][1] not in ("Z", "X")]


def temporaries(folder: Path) -> list[Path]:
    return sorted(folder.glob(".out.parquet.*.tmp"))


def until(condition, deadline: float) -> bool:
    """Whether `condition()` holds by `deadline` (time.monotonic), asked every 50 ms."""
    while not condition() and time.monotonic() < deadline:
        time.sleep(0.05)
    return condition()


def wait_mid_way(run: subprocess.Popen, folder: Path) -> None:
    """Until the running sweep `run` has written its first pieces to its temporary file in `folder`."""
    deadline = time.monotonic() + 180  # start-up and a first piece on a slow, busy machine
    while not [t for t in temporaries(folder) if t.stat().st_size > 4096]:
        assert run.poll() is None, (folder / "err").read_text()
        assert time.monotonic() < deadline, "no row written within 180 s"
        time.sleep(0.05)


def as_from_a_terminal() -> None:
    """Run in the child before the sweep starts: SIGINT, SIGHUP and SIGTERM back to their defaults, as a terminal's
    shell starts a command. A test run under nohup or as a background job inherits them ignored, and so would the
    sweep: it then flew on to its end and exited 0 (as a sweep started with nohup should)."""
    for signum in (signal.SIGINT, signal.SIGHUP, signal.SIGTERM):
        signal.signal(signum, signal.SIG_DFL)


def started(folder: Path) -> tuple[subprocess.Popen, dict[int, str]]:
    """A long sweep into `folder`, mid-way, in a session of its own (so that a signal to its process group reaches
    no test), and its processes below it then: the resource tracker, the fork server and the workers."""
    with open(folder / "err", "w") as err:
        run = subprocess.Popen(sweep_command(folder / "out.parquet", *LONG), cwd=ROOT, stdout=subprocess.DEVNULL,
                               stderr=err, start_new_session=True, preexec_fn=as_from_a_terminal)
    try:
        wait_mid_way(run, folder)
        recorded = descendants(run.pid)
        assert len(recorded) >= 3, recorded
    except BaseException:
        kill_all(run, descendants(run.pid))
        raise
    return run, recorded


def kill_all(run: subprocess.Popen, recorded: dict[int, str]) -> None:
    """Whatever a failed test left running (`running` checks each start time: no reused pid is killed)."""
    if run.poll() is None:
        run.kill()
    for pid in running(recorded):
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    run.wait(timeout=60)


@pytest.mark.parametrize(
    ("signum", "to_group"),
    [(signal.SIGTERM, False), (signal.SIGINT, True), (signal.SIGHUP, True)],
    ids=["SIGTERM to the sweep", "Ctrl-C to its process group", "SIGHUP to its process group"],
)
def test_a_signal_stops_the_sweep_its_workers_and_its_temporary_file(tmp_path, signum, to_group):
    """It used to leave a hidden temporary file and four processes blocked on a pipe for good."""
    run, recorded = started(tmp_path)
    try:
        (os.killpg if to_group else os.kill)(run.pid, signum)
        signalled = time.monotonic()
        assert run.wait(timeout=60) == 128 + signum
        left = until(lambda: not running(recorded) and not temporaries(tmp_path), signalled + GONE_WITHIN_S)
        assert left, (running(recorded), temporaries(tmp_path))
    finally:
        kill_all(run, recorded)
    err = (tmp_path / "err").read_text()
    name = signal.Signals(signum).name
    assert err.splitlines() == [
        f"golfflight sweep: stopped by {name}: nothing written to {tmp_path / 'out.parquet'}, no temporary file or "
        "worker left"
    ], err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["err"]


def test_a_killed_sweep_leaves_no_process_and_the_next_run_removes_its_temporary_file(tmp_path):
    run, recorded = started(tmp_path)
    temporary = temporaries(tmp_path)[0]
    try:
        run.kill()
        killed = time.monotonic()
        run.wait(timeout=60)
        assert until(lambda: not running(recorded), killed + GONE_WITHIN_S), running(recorded)
    finally:
        kill_all(run, recorded)
    assert temporaries(tmp_path) == [temporary] and f".{run.pid}." in temporary.name  # SIGKILL is not caught
    out = tmp_path / "out.parquet"
    rerun = subprocess.run(sweep_command(out, *SHORT), cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert rerun.returncode == 0, rerun.stderr
    assert rerun.stderr.splitlines() == [
        f"golfflight sweep: removed {temporary}, the temporary file of an interrupted sweep (its process is gone); "
        "this sweep flies every row again"
    ]
    assert temporaries(tmp_path) == [] and pq.read_table(out).num_rows == 1


def test_the_next_run_leaves_a_temporary_file_it_cannot_tell_is_stale(tmp_path, capsys):
    """A file whose sweep still runs (this process stands for it), or that names no process of this host, stays."""
    ended = subprocess.Popen([sys.executable, "-c", ""])
    ended.wait()
    host = socket.gethostname()
    stale = tmp_path / f".out.parquet.{host}.{ended.pid}.k2j4h5g6.tmp"
    owned = tmp_path / f".out.parquet.{host}.{os.getpid()}.a1b2c3d4.tmp"
    other = tmp_path / ".out.parquet.another-host.4242.a1b2c3d4.tmp"
    older = tmp_path / ".out.parquet.k2j4h5g6.tmp"
    for temporary in (stale, owned, other, older):
        temporary.write_bytes(b"PAR1")
    out = tmp_path / "out.parquet"
    assert main(["sweep", *SHORT, "--out", str(out), "--workers", "1", "--no-progress"]) == 0
    err = capsys.readouterr().err
    assert temporaries(tmp_path) == sorted([owned, other, older]) and out.exists()
    assert f"golfflight sweep: removed {stale}, the temporary file of an interrupted sweep" in err
    assert f"golfflight sweep: left {owned}: another sweep to {out} is running" in err
    for temporary in (other, older):
        assert f"golfflight sweep: left {temporary}: a temporary file of a sweep on another host or of an older " in err


def test_a_write_that_fails_names_the_file_and_leaves_nothing(tmp_path):
    """A real failing write without filling a disk: the sweep runs under a file size limit (`ulimit -f`, 64 KiB),
    past which the system refuses its writes (EFBIG, "File too large"; Python ignores SIGXFSZ). It used to say
    `[Errno 27] Error writing bytes to file` and name no file."""
    out = tmp_path / "out.parquet"
    axes = ["--grid", "ball_speed_mps=30:80:50", "launch_angle_deg=6:24:50", "spin_rpm=3000", "--chunk-rows", "500"]
    limited = ["bash", "-c", 'ulimit -f 64 && exec "$@"', "bash", *sweep_command(out, *axes)]
    done = subprocess.run(limited, cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 1  # a failure of ours, not an input error (golfflight.errors)
    assert done.stderr.splitlines() == [f"golfflight sweep: error: cannot write {out}: {os.strerror(27)} (errno 27)"]
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="no /dev/full")
def test_a_full_disk_is_said_in_words_naming_the_file(tmp_path):
    """ENOSPC for real: every write to /dev/full fails so. Parquet is written there as the sweep writes its file, with
    pyarrow's writer, and the error told as the sweep tells it."""
    from golfflight.sweep.output import writing

    out = tmp_path / "out.parquet"
    table = pa.table({"carry_m": np.arange(100_000.0)})
    with pytest.raises(OSError) as raised, writing(out), pq.ParquetWriter("/dev/full", table.schema) as writer:
        writer.write_table(table)
    assert str(raised.value) == f"cannot write {out}: No space left on device (errno 28)"

"""Measure, by tracing real code, how one ball speed travels between the repository's package folders: one HTTP shot
and one sweep row, each counted as moves between folders and climbs back up the floors of tests/test_imports.py.

Why: the issue "Following one HTTP shot's ball speed through the code: 10 moves between folders, 5 climbs back up;
one sweep row: 17 moves, 8 climbs" asks for fewer hops (at most 4 moves and 1 climb for the HTTP shot, 6 and 2 for a
sweep row). This script gives those counts a stated rule and a reproducible measurement, before and after a change.

    python3 scripts/trace_path.py [--journey http|sweep|both] [--mph 150.123] [--calls] [--out FILE.json]

The rule ("the ball speed's path"):

- The journeys. HTTP: the service's app as `service.app.create_app` assembles it, its lifespan run in process (the
  model loaded) and one warm-up shot at another speed flown, then one POST /v1/shots of `ball_speed_mph` through
  httpx's ASGI transport on this thread's event loop. Sweep: a one-row Parquet file of launches (`--sweep-input csv`
  for a CSV one) and the engine loaded first, then `sweep.sources.open_source` and `sweep.run.run_sweep` on the
  sweep's in-process lane (`in_process`, the lane `--engine torch` takes) with the ONNX `FlightEngine` as its engine:
  the driver, `sweep.flyer.SweepWorker` and the Parquet writer in this process (the local pool runs the same
  worker in processes a tracer here cannot see). Tracing starts right before the request (the row) and stops right
  after its result returns: neither loading nor startup is traced.
- The calls. `sys.setprofile` (and `threading.setprofile`, for the threads started in the window: the sweep's piece
  threads) sees every Python call; a call is kept when its code's file lies in a package folder (flight, shots,
  contract, service, sweep, discovery, evaluation, model_export, weights_schema, golfflight: the file's top
  folder). A generator's or coroutine's resumption is not a new call.
- Carrying the speed. A kept call counts when one of its arguments (the frame's locals named in
  co_varnames[:co_argcount + co_kwonlyargcount], `self` included, and the contents of *args and **kwargs) holds
  the ball speed: a float or NumPy floating equal, to a relative 1e-6 (which float32 rounding stays within), to the
  mph or the m/s value (mph x 0.44704); a NumPy array with such an element (np.isclose, rtol 1e-6); a float
  column of a pyarrow Array, ChunkedArray, Table or RecordBatch (the sweep's rows travel as Arrow); or a tuple,
  list, set, dict, NamedTuple, dataclass, pydantic model or other object whose `__dict__` or `__slots__` holds one,
  up to 3 levels below the argument. Text (a JSON body, a CSV cell, an Arrow IPC buffer) does not count. Guards:
  arrays of more than 1e6 elements and containers of more than 1000 items are skipped, and at most 4000 values are
  looked at per argument.
- The counts. Moves: consecutive counted calls in different folders. Climbs back: moves to a higher floor than the
  one moved from (weights_schema 0, flight 1, shots and contract 2, service, sweep, discovery and evaluation 3,
  model_export 4, golfflight 5) after which the speed goes down a floor again: a detour up and back down, as when
  a layer above translates the request piece by piece between calls below it. The answer's way back up to the
  caller is not a climb back; every move up, that way included, is printed beside it ("ups"). A move between two
  folders of one floor is a move, not a climb.
"""

from __future__ import annotations

import argparse
import asyncio
import dataclasses
import importlib.util
import itertools
import json
import sys
import tempfile
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from types import FrameType
from typing import Any, Self

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
def _import_rules():
    """tests/test_imports.py, where the package folders' floors are set and held."""
    spec = importlib.util.spec_from_file_location("test_imports", ROOT / "tests" / "test_imports.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


FLOORS: dict[str, int] = _import_rules().FLOORS
"""Each package folder's floor, the import rules' own."""

MPH_TO_MPS = 0.44704
BALL_SPEED_MPH = 150.123
"""The distinctive ball speed the journeys carry (no other number of a shot comes near it)."""

RTOL = 1e-6
MAX_DEPTH = 3
MAX_ARRAY = 1_000_000
MAX_ITEMS = 1000
MAX_NODES = 4000

_RESUMABLE = 0x20 | 0x80 | 0x100 | 0x200
"""CO_GENERATOR, CO_COROUTINE, CO_ITERABLE_COROUTINE and CO_ASYNC_GENERATOR: code whose 'call' events include every
resumption."""
_VARARGS, _VARKEYWORDS = 0x04, 0x08
_OPAQUE = (str, bytes, bytearray, memoryview, type, type(sys), type(len), type(lambda: 0), type(ROOT.is_file))


def folder_of(filename: str) -> str | None:
    """The package folder a code file lies in, or None outside them (tests, scripts, libraries)."""
    try:
        parts = Path(filename).resolve().relative_to(ROOT).parts
    except ValueError:
        return None
    return parts[0] if len(parts) > 1 and parts[0] in FLOORS else None


class SpeedMatcher:
    """Whether a value holds the ball speed (module docstring), and where: a path such as `.launch['ball_speed']`."""

    def __init__(self, mph: float):
        self.targets = (float(mph), float(mph) * MPH_TO_MPS)

    def _near(self, number: float) -> bool:
        return any(abs(number - target) <= RTOL * abs(target) for target in self.targets)

    def _in_array(self, array: np.ndarray) -> bool:
        if array.dtype.kind not in "f" or array.size > MAX_ARRAY:
            return False
        return any(bool(np.isclose(array, target, rtol=RTOL, atol=0.0).any()) for target in self.targets)

    def find(self, value: Any) -> str | None:
        """The path to the speed inside `value` ('' for the value itself), or None."""
        budget = [MAX_NODES]
        return self._find(value, 0, set(), budget)

    def _find(self, value: Any, depth: int, seen: set[int], budget: list[int]) -> str | None:
        budget[0] -= 1
        if budget[0] < 0 or value is None or isinstance(value, (bool, int, _OPAQUE)):
            return None
        if isinstance(value, (float, np.floating)):
            return "" if self._near(float(value)) else None
        if isinstance(value, np.ndarray):
            return "" if self._in_array(value) else None
        arrow = _arrow_columns(value)
        if arrow is not None:
            for name, array in arrow:
                if self._in_array(array):
                    return name
            return None
        if depth >= MAX_DEPTH or id(value) in seen:
            return None
        seen.add(id(value))
        for key, member in _members(value):
            found = self._find(member, depth + 1, seen, budget)
            if found is not None:
                return key + found
        return None


def _arrow_columns(value: Any) -> list[tuple[str, np.ndarray]] | None:
    """A pyarrow value's float columns as NumPy arrays (name, array), or None for anything else."""
    module = type(value).__module__
    if not module.startswith("pyarrow"):
        return None
    import pyarrow as pa

    if isinstance(value, (pa.Table, pa.RecordBatch)):
        pairs = [(f"[{name!r}]", value.column(name)) for name in value.column_names]
    elif isinstance(value, (pa.Array, pa.ChunkedArray)):
        pairs = [("", value)]
    else:
        return []
    return [(name, column.to_numpy(zero_copy_only=False)) for name, column in pairs
            if pa.types.is_floating(column.type) and len(column) <= MAX_ARRAY]


def _members(value: Any) -> Iterator[tuple[str, Any]]:
    """(path step, member) of a container or an object's attributes; nothing for a container too big to look at."""
    if isinstance(value, dict):
        if len(value) <= MAX_ITEMS:
            yield from ((f"[{key!r}]", member) for key, member in list(value.items()))
        return
    if isinstance(value, (list, tuple, set, frozenset)):
        if len(value) <= MAX_ITEMS:
            fields = getattr(value, "_fields", None)  # a NamedTuple's names
            names = fields if fields and len(fields) == len(value) else range(len(value))
            yield from ((f".{n}" if fields else f"[{n}]", member) for n, member in zip(names, list(value)))
        return
    if isinstance(value, np.ndarray):  # an array of objects
        if value.dtype.kind == "O" and value.size <= MAX_ITEMS:
            yield from ((f"[{i}]", member) for i, member in enumerate(value.ravel().tolist()))
        return
    yield from _attributes(value)


def _attributes(value: Any) -> Iterator[tuple[str, Any]]:
    """An object's `__dict__` entries and `__slots__` (a dataclass's or a pydantic model's fields among them)."""
    try:
        attributes = object.__getattribute__(value, "__dict__")
    except (AttributeError, TypeError):
        attributes = {}
    if isinstance(attributes, dict) and len(attributes) <= MAX_ITEMS:
        yield from ((f".{key}", member) for key, member in list(attributes.items()))
    for cls in type(value).__mro__:
        slots = cls.__dict__.get("__slots__", ())
        for slot in (slots,) if isinstance(slots, str) else slots:
            if slot not in ("__dict__", "__weakref__"):
                try:
                    yield f".{slot}", object.__getattribute__(value, slot)
                except AttributeError:
                    continue


@dataclasses.dataclass(frozen=True)
class Call:
    """One counted call: its folder, function and file, its depth and the argument that held the speed."""

    folder: str
    function: str
    file: str
    line: int
    depth: int
    argument: str
    thread: str


def arguments(frame: FrameType) -> Iterator[tuple[str, Any]]:
    """(name, value) of a frame's arguments: the named ones, then each of *args and **kwargs."""
    code, local = frame.f_code, frame.f_locals
    count = code.co_argcount + code.co_kwonlyargcount
    names = list(code.co_varnames[:count])
    for name in names:
        if name in local:
            yield name, local[name]
    if code.co_flags & _VARARGS:
        star = code.co_varnames[count]
        for i, value in enumerate(local.get(star, ())):
            yield f"{star}[{i}]", value
        count += 1
    if code.co_flags & _VARKEYWORDS:
        stars = code.co_varnames[count]
        for key, value in dict(local.get(stars, {})).items():
            yield f"{stars}[{key!r}]", value


def _depth(frame: FrameType | None) -> int:
    depth = 0
    while frame is not None:
        depth, frame = depth + 1, frame.f_back
    return depth


class Tracer:
    """Records the counted calls (module docstring) made between entering and leaving the `with` block."""

    def __init__(self, mph: float = BALL_SPEED_MPH):
        self.matcher = SpeedMatcher(mph)
        self.calls: list[Call] = []
        self.folders: dict[str, str | None] = {}
        self.started: dict[int, FrameType] = {}  # generator and coroutine frames already entered (held: ids stay apart)
        self.base = 0
        self.main = threading.get_ident()

    def __enter__(self) -> Self:
        self.base = _depth(sys._getframe(1))
        threading.setprofile(self._profile)
        sys.setprofile(self._profile)
        return self

    def __exit__(self, *exc: object) -> None:
        sys.setprofile(None)
        threading.setprofile(None)  # type: ignore[arg-type]
        self.started.clear()

    def _profile(self, frame: FrameType, event: str, arg: object) -> None:
        if event != "call":
            return
        code = frame.f_code
        folder = self.folders.get(code.co_filename, "?")
        if folder == "?":
            folder = self.folders[code.co_filename] = folder_of(code.co_filename)
        if folder is None:
            return
        if code.co_flags & _RESUMABLE:
            if id(frame) in self.started:
                return
            self.started[id(frame)] = frame
        for name, value in arguments(frame):
            found = self.matcher.find(value)
            if found is not None:
                self._record(frame, folder, name + found)
                return

    def _record(self, frame: FrameType, folder: str, argument: str) -> None:
        code = frame.f_code
        on_main = threading.get_ident() == self.main
        self.calls.append(Call(
            folder=folder,
            function=code.co_qualname,
            file=str(Path(code.co_filename).resolve().relative_to(ROOT)),
            line=code.co_firstlineno,
            depth=_depth(frame) - (self.base if on_main else 0),
            argument=argument,
            thread=threading.current_thread().name,
        ))


def moves_and_climbs(folders: list[str]) -> tuple[int, int]:
    """Moves (consecutive folders that differ) and climbs back (moves to a higher floor after which the speed goes
    down a floor again) of a sequence of folders."""
    pairs = [(a, b) for a, b in itertools.pairwise(folders) if a != b]
    steps = [FLOORS[b] - FLOORS[a] for a, b in pairs]
    return len(pairs), sum(step > 0 and any(later < 0 for later in steps[i + 1:]) for i, step in enumerate(steps))


def ups(folders: list[str]) -> int:
    """Every move to a higher floor, the answer's way back to the caller included."""
    return sum(FLOORS[b] > FLOORS[a] for a, b in itertools.pairwise(folders))


def runs(calls: list[Call]) -> list[dict]:
    """The calls collapsed into runs of one folder: folder, floor, first and last function, count."""
    collapsed: list[dict] = []
    for call in calls:
        if collapsed and collapsed[-1]["folder"] == call.folder:
            collapsed[-1].update(last=call.function, calls=collapsed[-1]["calls"] + 1)
        else:
            collapsed.append({"folder": call.folder, "floor": FLOORS[call.folder], "first": call.function,
                              "last": call.function, "calls": 1})
    return collapsed


@dataclasses.dataclass
class Journey:
    """One journey's counted calls and what they come to."""

    name: str
    calls: list[Call]
    answer: dict

    @property
    def counts(self) -> tuple[int, int]:
        return moves_and_climbs([call.folder for call in self.calls])

    def to_json(self) -> dict:
        moves, climbs = self.counts
        return {"journey": self.name, "moves": moves, "climbs": climbs,
                "ups": ups([call.folder for call in self.calls]), "runs": runs(self.calls),
                "calls": [dataclasses.asdict(call) for call in self.calls], "answer": self.answer}


def shot_body(mph: float, full: bool = False) -> dict:
    """The single-shot request: a driver in launch-monitor units (tests/test_api.py's DRIVER_MPH at `mph`); `full`
    adds every branch a request can take: a normalized replay, a sloped green above the tee (so a flat flight too),
    a trajectory and a log-profile wind."""
    body = {"ball_speed_mph": mph, "launch_angle_deg": 10.4, "back_spin_rpm": 2545.0}
    if full:
        body |= {"normalized": True, "trajectory": {"rate_hz": 30},
                 "ground": {"surface": "green", "elevation_m": 3.0, "slope_deg": 2.0, "slope_dir_deg": 45.0},
                 "wind": {"speed_mps": 4.0, "from_deg": 200.0, "profile": "log"}}
    return body


async def _post_one(app, mph: float, tracer: Tracer, full: bool) -> dict:
    import httpx

    async with app.router.lifespan_context(app):  # the model loads here, before tracing
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://127.0.0.1") as client:
            warm = await client.post("/v1/shots", json=shot_body(120.0, full))  # first-request work, at another speed
            warm.raise_for_status()
            with tracer:
                response = await client.post("/v1/shots", json=shot_body(mph, full))
    response.raise_for_status()
    return response.json()


def http_journey(mph: float = BALL_SPEED_MPH, full: bool = False) -> Journey:
    """One POST /v1/shots through the app `create_app` assembles (default settings, no API key), in process; `full`:
    the request with every branch (`shot_body`)."""
    from golfflight.service.app import create_app
    from golfflight.service.settings import ServiceSettings

    tracer = Tracer(mph)
    answer = asyncio.run(_post_one(create_app(ServiceSettings()), mph, tracer, full))
    return Journey("http-full" if full else "http", tracer.calls, {"carry_m": answer.get("carry_m")})


def _write_row(folder: Path, mph: float, kind: str) -> Path:
    """A one-row launches file (simulate's columns) at `mph`: Parquet (float columns) or CSV (text cells)."""
    import pyarrow as pa

    row = {"shot_id": ["trace"], "ball_speed_mph": [mph], "launch_angle_deg": [10.4], "back_spin_rpm": [2545.0]}
    path = folder / f"one_row.{kind}"
    if kind == "csv":
        import pyarrow.csv as pacsv

        pacsv.write_csv(pa.table(row), path)
    else:
        import pyarrow.parquet as pq

        pq.write_table(pa.table(row), path)
    return path


def sweep_journey(mph: float = BALL_SPEED_MPH, kind: str = "parquet") -> Journey:
    """One row through `open_source` and `run_sweep` on the in-process lane with the ONNX engine (module docstring)."""
    import pyarrow.parquet as pq
    from golfflight.flight.bundle_location import model_dir
    from golfflight.flight.engine import FlightEngine
    from golfflight.sweep.run import run_sweep
    from golfflight.sweep.sources import open_source

    from golfflight.commands.sweep import CHUNK_ROWS

    engine = FlightEngine(model_dir(), batch_threads=1)  # loaded before tracing
    tracer = Tracer(mph)
    with tempfile.TemporaryDirectory() as folder:
        launches, out = _write_row(Path(folder), mph, kind), str(Path(folder) / "swept.parquet")
        with tracer:
            source = open_source(str(launches), None, CHUNK_ROWS)
            summary = run_sweep(source, out, "torch", 1, progress=False, in_process=engine, notice=lambda line: None)
        swept = pq.read_table(out).to_pylist()[0]
    return Journey("sweep", tracer.calls, {"written": summary.written, "carry_m": swept.get("carry_m")})


def table(journey: Journey, every_call: bool = False) -> str:
    """The journey's collapsed folder path and its two counts, as printed."""
    moves, climbs = journey.counts
    lines = [f"{journey.name}: {len(journey.calls)} calls carry the ball speed ({journey.answer})",
             f"  {'#':>3}  {'folder':<14} {'floor':>5} {'calls':>5}  first .. last function"]
    for i, run in enumerate(runs(journey.calls), 1):
        span = run["first"] if run["first"] == run["last"] else f"{run['first']} .. {run['last']}"
        lines.append(f"  {i:>3}  {run['folder']:<14} {run['floor']:>5} {run['calls']:>5}  {span}")
    if every_call:
        lines += [f"      {c.depth:>4} {c.folder:<14} {c.function} ({c.file}:{c.line}) via {c.argument} [{c.thread}]"
                  for c in journey.calls]
    every_up = ups([call.folder for call in journey.calls])
    lines.append(f"  moves between folders: {moves}; climbs back up: {climbs} (moves up, the answer's way back "
                 f"included: {every_up})")
    return "\n".join(lines)


JOURNEYS: dict[str, Callable[[argparse.Namespace], Journey]] = {
    "http": lambda args: http_journey(args.mph),
    "http-full": lambda args: http_journey(args.mph, full=True),
    "sweep": lambda args: sweep_journey(args.mph, args.sweep_input),
}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--journey", choices=("http", "http-full", "sweep", "both", "all"), default="both")
    parser.add_argument("--mph", type=float, default=BALL_SPEED_MPH, help="the ball speed carried (mph)")
    parser.add_argument("--sweep-input", choices=("parquet", "csv"), default="parquet")
    parser.add_argument("--calls", action="store_true", help="also print every counted call")
    parser.add_argument("--out", help="write the journeys as JSON here")
    args = parser.parse_args(argv)
    names = {"both": ("http", "sweep"), "all": tuple(JOURNEYS)}.get(args.journey, (args.journey,))
    journeys = [JOURNEYS[name](args) for name in names]
    for journey in journeys:
        print(table(journey, args.calls), end="\n\n")
    if args.out:
        document = {"ball_speed_mph": args.mph, "ball_speed_mps": args.mph * MPH_TO_MPS,
                    "journeys": [journey.to_json() for journey in journeys]}
        Path(args.out).write_text(json.dumps(document, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())

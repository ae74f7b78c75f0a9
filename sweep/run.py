"""The driver of a sweep: result tables from an engine, in input order, checked for refused rows and streamed into
one Parquet file, whole or not at all.

Memory stays bounded: each result table is written as a row group as soon as it arrives (pyarrow's ParquetWriter)
and dropped. A row the request model refuses stops the sweep with every problem of that piece, each naming the
row's place in the input, its column and the allowed range, and nothing is written; with `skip_bad_rows` such rows
are left out and each is reported, and a piece of which no row is valid is skipped whole (and counted). The file is
written beside its target and renamed over it at the end (`sweep.output.write_whole`, which also removes what a
killed sweep to the same file left, and names the file where a write fails).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import closing, contextmanager, suppress
from dataclasses import dataclass
from typing import Literal

from golfflight.errors import InputError
from golfflight.flight.bundle_location import model_dir
from golfflight.sweep.engines import PIECES_IN_FLIGHT
from golfflight.sweep.flyer import PROBLEM, ROW, ColumnsEngine, Layout, SweepWorker
from golfflight.sweep.output import clear_stale, write_whole, writing
from golfflight.sweep.sources import Source

SHOWN_PROBLEMS = 20
"""Problems listed when a sweep is refused (the rest are counted)."""

Engine = Literal["local", "ray", "torch"]
"""Where the pieces fly: a pool of processes here, Ray, or the torch engine (the one the command line hands
`run_sweep`, or one in each process of a pool here)."""


@dataclass(frozen=True)
class WorkerEngine:
    """What each worker process (a Ray actor, or a process of the pool here under `engine="torch"`) flies with:
    ONNX Runtime on its CPU (`make` None), or the engine `make` builds from the bundle's path on the worker's node
    (`flight.torch_engine.TorchEngineMaker`), with, on Ray, `gpus` GPUs of its own (a fraction where actors
    share one)."""

    make: Callable[[str], ColumnsEngine] | None = None
    gpus: float = 0


@dataclass(frozen=True)
class Summary:
    rows: int
    written: int
    skipped: int
    chunks: int
    """Pieces (chunks of rows) read."""
    chunks_skipped: int
    """Pieces of which no row was valid, skipped whole (`skip_bad_rows`)."""
    failed: int
    """Shots the engine could not fly to the ground (their `error` column says why)."""
    seconds: float

    @property
    def shots_per_second(self) -> float:
        return self.rows / self.seconds if self.seconds > 0 else 0.0


def _tables(source: Source, engine: Engine, workers: int | None, model: str | None, ray_address: str | None,
            in_process: ColumnsEngine | None, worker_engine: WorkerEngine, in_flight: int) -> Iterator:
    """Result tables from the chosen engine, its workers loading the bundle the driver verified here (or flying
    with `in_process`, an engine already loaded from it, `in_flight` pieces at once, or each worker with the engine
    `worker_engine` makes: Ray's actors, and under `engine="torch"` without `in_process` a pool here)."""
    from golfflight.flight.bundle_check import verify_bundle
    from golfflight.sweep.engines import in_process_tables, local_tables, ray_tables

    bundle = model_dir(model).resolve()
    sha256 = verify_bundle(bundle).onnx.sha256
    if engine == "torch":
        if in_process is not None:
            return in_process_tables(source, SweepWorker(str(bundle), sha256, source, engine=in_process), in_flight)
        if worker_engine.make is None or workers is None:
            raise InputError("the torch engine flies in this process (in_process) or in a pool of `workers` "
                             "processes, each with the engine worker_engine.make builds")
        return local_tables(source, str(bundle), sha256, workers, worker_engine.make)
    if engine == "ray":
        return ray_tables(source, str(bundle), sha256, workers, ray_address, worker_engine.make, worker_engine.gpus)
    return local_tables(source, str(bundle), sha256, workers, worker_engine.make)


def _text_columns(schema) -> list[str]:
    """The columns written with a dictionary: text (a few surfaces, profiles and errors over millions of rows). The
    numbers' dictionaries, pyarrow's default, doubled the time to write a sweep's rows for no smaller a file."""
    import pyarrow as pa

    return [field.name for field in schema if pa.types.is_string(field.type)]


@contextmanager
def _parquet_writer(path: str, out: str, schema) -> Iterator:
    """pyarrow's ParquetWriter on `path`, the temporary file of `out`, an OSError opening or closing it named as
    writing `out` (`sweep.output.writing`). Where the sweep stops early the file is thrown away, and what stopped it
    is what is told, not a failure to close it."""
    import pyarrow.parquet as pq

    with writing(out):
        writer = pq.ParquetWriter(path, schema, use_dictionary=_text_columns(schema))
    try:
        yield writer
    except BaseException:
        with suppress(OSError):
            writer.close()
        raise
    with writing(out):
        writer.close()


def _refused(source: Source, table, start: int) -> list[str]:
    """One line per problem of the refused rows of `table`, whose first row is input row `start`."""
    lines = []
    if table[PROBLEM].null_count == table.num_rows:
        return lines
    for i, problem in enumerate(table[PROBLEM].to_pylist()):
        if problem is not None:
            lines += [f"{source.place(start + i)} {line}" for line in problem.split("\n")]
    return lines


def run_sweep(
    source: Source,
    out: str,
    engine: Engine = "local",
    workers: int | None = 2,
    model: str | None = None,
    ray_address: str | None = None,
    skip_bad_rows: bool = False,
    progress: bool = True,
    skipped: Callable[[str], None] = print,
    in_process: ColumnsEngine | None = None,
    worker_engine: WorkerEngine = WorkerEngine(),
    in_flight: int = PIECES_IN_FLIGHT,
    notice: Callable[[str], None] = print,
) -> Summary:
    """Fly every row of `source` on `engine` and write `out` (Parquet): the input row's number, its columns, its
    flight (module docstring). `skipped` gets each problem of a row left out under `skip_bad_rows`; `in_process` is
    the engine `engine="torch"` flies with (`flight.torch_engine.TorchEngine`, loaded from `model`), `in_flight`
    pieces at once; `worker_engine` what each actor of `engine="ray"` flies with (`workers` None: as many as the
    cluster's GPUs hold),
    and, without `in_process`, each of the `workers` processes of `engine="torch"`. `notice` gets a line for each
    temporary file of `out` found from an earlier sweep (`sweep.output.clear_stale`)."""
    import pyarrow as pa
    import pyarrow.compute as pc
    from tqdm import tqdm

    started = time.perf_counter()
    schema = Layout(tuple(source.columns)).schema()
    counts = {"rows": 0, "written": 0, "skipped": 0, "chunks": 0, "chunks_skipped": 0, "failed": 0}

    def write(path: str) -> None:
        tables = _tables(source, engine, workers, model, ray_address, in_process, worker_engine, in_flight)
        bar = tqdm(total=source.total_rows, unit="shot", unit_scale=True, disable=not progress, desc="sweep")
        with closing(tables), bar, _parquet_writer(path, out, schema) as writer:
            for table in tables:
                start, count = counts["rows"], table.num_rows
                table = table.add_column(0, ROW, pa.array(range(start, start + count), pa.int64()))
                problems = _refused(source, table, start)
                none_valid = count > 0 and table[PROBLEM].null_count == 0
                if problems and not skip_bad_rows:
                    shown = "\n  ".join(problems[:SHOWN_PROBLEMS])
                    more = f"\n  ... and {len(problems) - SHOWN_PROBLEMS} more" if len(problems) > SHOWN_PROBLEMS else ""
                    whole = f"none of the {count} rows is valid; " if none_valid else ""
                    raise InputError(
                        f"{len(problems)} invalid values in rows {start} to {start + count - 1} ({whole}nothing "
                        f"written; --skip-bad-rows flies the rest):\n  {shown}{more}"
                    )
                for problem in problems:
                    skipped(problem)
                if problems:
                    table = table.filter(pc.is_null(table[PROBLEM]))
                if table.num_rows:
                    with writing(out):
                        writer.write_table(table.drop_columns([PROBLEM]))
                counts["chunks"] += 1
                counts["chunks_skipped"] += int(none_valid)
                counts["rows"] += count
                counts["written"] += table.num_rows
                counts["skipped"] += count - table.num_rows
                counts["failed"] += table.num_rows - table["error"].null_count
                bar.update(count)

    clear_stale(out, notice)
    write_whole(out, write)
    return Summary(**counts, seconds=time.perf_counter() - started)

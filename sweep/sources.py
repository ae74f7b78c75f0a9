"""Where a sweep's rows come from: a CSV or Parquet file of launches, or a grid, read as Arrow tables of a bounded
number of rows.

Every source gives the same two things. `pieces()`: the input in order as pieces of one row each, read where the
driver runs by both engines (`sweep.ray_input` for Ray): a file's chunk of rows packed into one cell (Arrow IPC), a
grid's range of row numbers; one row, so that Ray Data, which regroups rows into blocks as it likes, hands each actor
call exactly one piece (`batch_size=1`), and a pool worker is sent a few bytes for a grid. `expand(piece)`: the
input rows of a piece, which the worker flies as one engine batch. CSV cells are read as text and parsed as
`golfflight simulate` parses them (`contract.columns.cell_value`).
"""

from __future__ import annotations

import csv
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from golfflight.contract.columns import columns_message
from golfflight.errors import InputError
from golfflight.shots.records import CSV_ENCODING, reading
from golfflight.sweep.grid import Grid

READ_BUFFER_BYTES = 1 << 20
"""Parquet column data is read in buffers of this size, not a column chunk at a time."""


def rebatch(batches, rows: int) -> Iterator:
    """Arrow record batches regrouped into tables of `rows` rows (the last one shorter), holding at most one table's
    worth at a time."""
    import pyarrow as pa

    held, count = [], 0
    for batch in batches:
        held.append(batch)
        count += batch.num_rows
        while count >= rows:
            table = pa.Table.from_batches(held)
            yield table.slice(0, rows)
            rest = table.slice(rows)
            held, count = rest.to_batches(), rest.num_rows
    if count:
        yield pa.Table.from_batches(held)


def packed(tables: Iterator) -> Iterator:
    """Each table as a one-row piece: its Arrow IPC stream in the cell `rows`."""
    import pyarrow as pa

    for table in tables:
        sink = pa.BufferOutputStream()
        with pa.ipc.new_stream(sink, table.schema) as writer:
            writer.write_table(table)
        yield pa.table({"rows": pa.array([sink.getvalue().to_pybytes()], pa.large_binary())})


def unpacked(piece):
    """The rows of one or more pieces from `packed`, in order."""
    import pyarrow as pa

    return pa.concat_tables([pa.ipc.open_stream(cell.as_buffer()).read_all() for cell in piece["rows"]])


@dataclass(frozen=True)
class GridSource:
    grid: Grid
    chunk_rows: int

    @property
    def columns(self) -> tuple[str, ...]:
        return tuple(self.grid.columns)

    @property
    def total_rows(self) -> int:
        return len(self.grid)

    def place(self, row: int) -> str:
        return f"grid row {row}"

    def pieces(self) -> Iterator:
        import pyarrow as pa

        total, step = len(self.grid), self.chunk_rows
        for start in range(0, total, step):
            yield pa.table({"start": [start], "stop": [min(start + step, total)]})

    def expand(self, piece):
        """The grid's rows of the ranges in `piece` (a table of start and stop row numbers)."""
        import pyarrow as pa

        ranges = zip(piece["start"].to_pylist(), piece["stop"].to_pylist(), strict=True)
        return pa.concat_tables([pa.table(self.grid.arrays(start, stop)) for start, stop in ranges])


@dataclass(frozen=True)
class CsvSource:
    """A launches CSV (`golfflight simulate`'s columns); every cell read as text."""

    path: str
    columns: tuple[str, ...]
    chunk_rows: int

    total_rows = None

    @classmethod
    def open(cls, path: Path, chunk_rows: int) -> CsvSource:
        with reading(path), open(path, newline="", encoding=CSV_ENCODING) as handle:
            header = next(csv.reader(handle), [])
        refused = columns_message(str(path), header)
        if refused:
            raise InputError(refused)
        return cls(str(path), tuple(header), chunk_rows)

    def place(self, row: int) -> str:
        return f"{self.path} line {row + 2}"

    def _convert_options(self):
        import pyarrow as pa
        import pyarrow.csv

        # Only a blank cell is null ("not given"): pyarrow's default null spellings (NaN, NA, null, N/A, ...) would turn
        # a "NaN" into a missing value ("Field required") where simulate reads it as a number that is not one.
        return pyarrow.csv.ConvertOptions(
            column_types={c: pa.string() for c in self.columns}, strings_can_be_null=True, null_values=[""]
        )

    def pieces(self) -> Iterator:
        import pyarrow as pa
        import pyarrow.csv

        try:
            reader = pyarrow.csv.open_csv(self.path, convert_options=self._convert_options())
            yield from packed(rebatch(reader, self.chunk_rows))
        except pa.ArrowInvalid as error:
            raise InputError(f"{self.path}: {error}") from None

    def expand(self, piece):
        return unpacked(piece)


@dataclass(frozen=True)
class ParquetSource:
    """A Parquet file with the launches CSV's columns (numbers as numbers, words as strings)."""

    path: str
    columns: tuple[str, ...]
    total_rows: int
    chunk_rows: int

    @classmethod
    def open(cls, path: Path, chunk_rows: int) -> ParquetSource:
        import pyarrow as pa
        import pyarrow.parquet as pq

        try:
            metadata = pq.read_metadata(path)
        except pa.ArrowInvalid as error:
            raise InputError(f"{path}: not a Parquet file ({error})") from None
        columns = metadata.schema.to_arrow_schema().names
        refused = columns_message(str(path), columns)
        if refused:
            raise InputError(refused.replace(" line 1: no header row", ": no columns"))
        return cls(str(path), tuple(columns), metadata.num_rows, chunk_rows)

    def place(self, row: int) -> str:
        return f"{self.path} row {row}"

    def pieces(self) -> Iterator:
        import pyarrow.parquet as pq

        # Buffered column reads, one thread: a file of one big row group is decoded a chunk at a time (about 30 MB less
        # held at 1,000,000 rows than reading each column chunk whole).
        with pq.ParquetFile(self.path, buffer_size=READ_BUFFER_BYTES, pre_buffer=False) as handle:
            batches = handle.iter_batches(batch_size=self.chunk_rows, use_threads=False)
            yield from packed(rebatch(batches, self.chunk_rows))

    def expand(self, piece):
        return unpacked(piece)


Source = GridSource | CsvSource | ParquetSource


def open_source(path: str | None, grid: list[str] | None, chunk_rows: int) -> Source:
    """The source a command line names: a launches file (.csv or .parquet) or a grid (`sweep.grid`), not both."""
    if (path is None) == (not grid):
        raise InputError("give a launches file (CSV or Parquet) or --grid axes, one of the two")
    if grid:
        return GridSource(Grid.parse(grid), chunk_rows)
    file = Path(path)
    if not file.is_file():
        raise FileNotFoundError(f"no such file: {file}")
    if file.suffix.lower() == ".csv":
        return CsvSource.open(file, chunk_rows)
    if file.suffix.lower() in (".parquet", ".pq"):
        return ParquetSource.open(file, chunk_rows)
    raise InputError(f"{file}: a launches file is .csv or .parquet")

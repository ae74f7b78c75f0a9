"""Where a sweep's rows come from: a CSV or Parquet file of launches, or a grid, read as Arrow tables of a bounded
number of rows.

Every source gives the same three things: `pieces()`, small Arrow tables the driver hands out in order (the rows
themselves, or for a grid just the range of row numbers, so a pool worker is sent a few bytes); `expand(piece)`,
which a worker turns into the input rows; and `ray_dataset()`, the same pieces as a Ray Dataset (Ray's own readers
for files, so on a cluster each node reads its part from storage it can reach, cut into blocks of a piece's rows so
that every actor gets some of a single file). CSV cells are read as text and
parsed as `golfflight simulate` parses them (`sweep.columns.cell_value`), whichever engine reads them.
"""

from __future__ import annotations

import csv
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from shots.records import reading
from sweep.columns import columns_message
from sweep.grid import Grid


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

    def _ranges(self) -> list[dict]:
        total, step = len(self.grid), self.chunk_rows
        return [{"start": start, "stop": min(start + step, total)} for start in range(0, total, step)]

    def pieces(self) -> Iterator:
        import pyarrow as pa

        for piece in self._ranges():
            yield pa.Table.from_pylist([piece])

    def expand(self, piece):
        """The grid's rows of the ranges in `piece` (a table of start and stop row numbers)."""
        import pyarrow as pa

        ranges = zip(piece["start"].to_pylist(), piece["stop"].to_pylist(), strict=True)
        return pa.concat_tables([pa.table(self.grid.rows(start, stop)) for start, stop in ranges])

    def ray_dataset(self):
        """One item per range of rows (`map_batches` with batch_size=1 expands and flies one range a call)."""
        import ray.data

        return ray.data.from_items(self._ranges())

    ray_batch_size = 1


@dataclass(frozen=True)
class CsvSource:
    """A launches CSV (`golfflight simulate`'s columns); every cell read as text."""

    path: str
    columns: tuple[str, ...]
    chunk_rows: int

    total_rows = None

    @classmethod
    def open(cls, path: Path, chunk_rows: int) -> CsvSource:
        with reading(path), open(path, newline="") as handle:
            header = next(csv.reader(handle), [])
        refused = columns_message(str(path), header)
        if refused:
            raise ValueError(refused)
        return cls(str(path), tuple(header), chunk_rows)

    def place(self, row: int) -> str:
        return f"{self.path} line {row + 2}"

    def _convert_options(self):
        import pyarrow as pa
        import pyarrow.csv

        return pyarrow.csv.ConvertOptions(column_types={c: pa.string() for c in self.columns}, strings_can_be_null=True)

    def pieces(self) -> Iterator:
        import pyarrow as pa
        import pyarrow.csv

        try:
            reader = pyarrow.csv.open_csv(self.path, convert_options=self._convert_options())
            yield from rebatch(reader, self.chunk_rows)
        except pa.ArrowInvalid as error:
            raise ValueError(f"{self.path}: {error}") from None

    def expand(self, piece):
        return piece

    def ray_dataset(self):
        import ray.data

        return ray.data.read_csv(self.path, convert_options=self._convert_options()).repartition(target_num_rows_per_block=self.chunk_rows)

    @property
    def ray_batch_size(self) -> int:
        return self.chunk_rows


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
            raise ValueError(f"{path}: not a Parquet file ({error})") from None
        columns = metadata.schema.to_arrow_schema().names
        refused = columns_message(str(path), columns)
        if refused:
            raise ValueError(refused.replace(" line 1: no header row", ": no columns"))
        return cls(str(path), tuple(columns), metadata.num_rows, chunk_rows)

    def place(self, row: int) -> str:
        return f"{self.path} row {row}"

    def pieces(self) -> Iterator:
        import pyarrow.parquet as pq

        with pq.ParquetFile(self.path) as handle:
            yield from rebatch(handle.iter_batches(batch_size=self.chunk_rows), self.chunk_rows)

    def expand(self, piece):
        return piece

    def ray_dataset(self):
        import ray.data

        return ray.data.read_parquet(self.path).repartition(target_num_rows_per_block=self.chunk_rows)

    @property
    def ray_batch_size(self) -> int:
        return self.chunk_rows


Source = GridSource | CsvSource | ParquetSource


def open_source(path: str | None, grid: list[str] | None, chunk_rows: int) -> Source:
    """The source a command line names: a launches file (.csv or .parquet) or a grid (`sweep.grid`), not both."""
    if (path is None) == (not grid):
        raise ValueError("give a launches file (CSV or Parquet) or --grid axes, one of the two")
    if grid:
        return GridSource(Grid.parse(grid), chunk_rows)
    file = Path(path)
    if not file.is_file():
        raise FileNotFoundError(f"no such file: {file}")
    if file.suffix.lower() == ".csv":
        return CsvSource.open(file, chunk_rows)
    if file.suffix.lower() in (".parquet", ".pq"):
        return ParquetSource.open(file, chunk_rows)
    raise ValueError(f"{file}: a launches file is .csv or .parquet")

"""A sweep's source as a Ray Data datasource: one read task on the driver's node that streams the same pieces the
local pool is handed (`sweep.sources`), so both engines read the input the same way, a file needs to be on the
driver's machine only, and none of Ray's file readers (with their listing and footer-reading actors, about 190 MB
each) start. Imported only by `sweep.engines.ray_tables`: ray is an optional extra."""

from __future__ import annotations

import ray.data
from ray.data.block import BlockMetadata


class PiecesDatasource(ray.data.Datasource):
    def __init__(self, source):
        self.source = source

    def estimate_inmemory_data_size(self) -> None:
        return None

    @property
    def supports_distributed_reads(self) -> bool:
        """False: Ray runs the read on the driver's node, where the file is."""
        return False

    def get_read_tasks(self, parallelism: int, per_task_row_limit=None, data_context=None) -> list[ray.data.ReadTask]:
        """One task: the pieces in order, each a block (a piece's rows, or a grid's range of row numbers)."""
        metadata = BlockMetadata(num_rows=None, size_bytes=None, exec_stats=None, input_files=None)
        return [ray.data.ReadTask(self.source.pieces, metadata)]

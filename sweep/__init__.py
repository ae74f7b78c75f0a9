"""Sweeps: millions of launches and conditions, from a file or a grid, flown on a pool of local processes or on Ray
and streamed to Parquet (`golfflight sweep`, docs/sweep.md). pyarrow, tqdm and ray are imported where they are used,
so the serving install (no extras) imports `sweep.columns` without them."""

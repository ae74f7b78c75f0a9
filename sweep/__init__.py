"""Sweeps: millions of launches and conditions, from a file or a grid, flown on a pool of local processes or on Ray
and streamed to Parquet (`golfflight sweep`, docs/sweep.md). Needs the `sweep` extra (pyarrow, tqdm), and `ray`
for the Ray engine; nothing here is on the serving path, which shares only the shot contract (`contract.columns`,
`contract.flying`) with it."""

"""The real sources `golfflight train-real` builds its data from, by name, apart from the code that builds them
(`real_data.BUILDERS`, whose keys they are, in its order), so that the command's help lists them without importing
that code."""

SOURCES = ("trackman-outdoor", "sentry-2022", "players-2020", "trackman-model", "tour-championship-2020",
           "pga-2023-table", "synthetic")
"""Every source a run can name (`--sources`)."""

DEFAULT_SOURCES = SOURCES
"""What the shipped model is trained on."""

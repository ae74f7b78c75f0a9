"""Progress of long work on standard error: a tqdm bar over a loop, and a line naming a slow step that has none.

Every long loop a command runs (the synthetic sessions, the ground fit and the reference world's calibration on this
floor; discovery's fits, the accuracy and evaluation reports and training above it) draws through `progress_bar`
and `progress_step`. Whether anything is shown is the caller's plain `progress` flag, as `model_export.training`
and `sweep.run` already take it, which a command sets from its `--quiet`: no hidden global switch, and a library
call inside another long loop (a diagnosis inside `prove`) is simply passed False. The module lives on the shots
floor, the lowest with such a loop, so every floor above may import it (docs/architecture.md).

Progress goes to standard error only, so what a command prints to standard output (a report, JSON, CSV) and the
files it writes are the same with it or without it. On a terminal the bar redraws in place; anywhere else (a log
file, CI) it is still written, so long work is never silent there either, but at most every LOG_INTERVAL_S.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable
from typing import TypeVar

from tqdm import tqdm

T = TypeVar("T")

LOG_INTERVAL_S = 10.0
"""Least time between two redraws of a bar when standard error is not a terminal: a line in a log now and then."""

TERMINAL_INTERVAL_S = 0.1
"""Least time between two redraws on a terminal (tqdm's own default)."""


def _interval() -> float:
    return TERMINAL_INTERVAL_S if sys.stderr.isatty() else LOG_INTERVAL_S


def progress_bar(
    iterable: Iterable[T] | None = None,
    desc: str = "",
    *,
    total: float | None = None,
    unit: str = "it",
    shown: bool = True,
) -> tqdm:
    """A tqdm bar on standard error over `iterable` (or updated by hand up to `total`), drawn at once so the work is
    seen before its first step ends; nothing at all unless `shown`. A bar inside another one's loop is cleared when it
    ends, so only the outer one stays on the screen."""
    return tqdm(
        iterable,
        desc=desc,
        total=total,
        unit=unit,
        disable=not shown,
        file=sys.stderr,
        leave=None,
        mininterval=_interval(),
        dynamic_ncols=True,
    )


def progress_step(message: str, shown: bool = True) -> None:
    """One line on standard error naming the slow step that starts now (above any bar drawn), unless not `shown`."""
    if shown:
        tqdm.write(message, file=sys.stderr)


def print_line(line: str) -> None:
    """Print `line` to standard output as print does; on a terminal, the bars drawn there are cleared first and drawn
    again below it, so a line never lands inside a bar (in a log, clearing would only add blank lines)."""
    if sys.stderr.isatty():
        tqdm.write(line, file=sys.stdout)
    else:
        print(line)

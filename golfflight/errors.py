"""The failures golfflight raises, one family under `GolfflightError`: what the caller gave is wrong (`InputError`),
a shot that cannot be flown (`FlightError`), or the service cannot answer now (`ServiceError`). The kind decides
what a user sees: the command line exits 2 with one line for an input error only (anything else is a bug and keeps
its traceback), and the service answers each kind with one status (`contract.refusals.STATUS`). This module imports
nothing of ours, so every floor may raise these."""

from __future__ import annotations


class GolfflightError(Exception):
    """Every failure golfflight raises on purpose; the message says what and why."""


class InputError(GolfflightError, ValueError):
    """The caller's input is wrong (a field, an option, a file or a bundle): the message names it and what is
    allowed. A ValueError too, so pydantic validators may raise it and older callers that catch ValueError still do."""


class FlightError(GolfflightError):
    """A valid shot the engine could not fly to the ground (the message says why); a batch reports it for that
    shot."""


class ServiceError(GolfflightError):
    """The service cannot answer now (the model still loading, the batch process restarting): try again later."""

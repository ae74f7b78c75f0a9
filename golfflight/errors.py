"""The failures golfflight raises, one family under `GolfflightError`: what the caller gave is wrong (`InputError`),
a shot that cannot be flown (`FlightError`), or the service cannot answer now (`ServiceError`). The kind decides
what a user sees: the command line exits 2 with one line for an input error only (anything else is a bug and keeps
its traceback), and the service answers each kind with one status (`contract.refusals.STATUS`). This module imports
nothing of ours, so every floor may raise these."""

from __future__ import annotations


class GolfflightError(Exception):
    """Every failure golfflight raises on purpose; the message says what and why."""


def refusal_text(field: str, problem: str, value: object = None, allowed: str | None = None) -> str:
    """How every refusal of a field reads, on every surface (the HTTP 422 body's `message`, the Open Connect reply's
    Message, the command line's line): `field: problem (got value); allowed range`, the value and the range where
    known (a value of None is not shown: a field left out has none)."""
    text = f"{field}: {problem}"
    if value is not None:
        text += f" (got {value!r})"
    return text + (f"; allowed {allowed}" if allowed else "")


class InputError(GolfflightError, ValueError):
    """The caller's input is wrong (a field, an option, a file or a bundle): the message names it and what is
    allowed. Given a `field` (a dotted path such as `air.temperature_c`), it carries the field, the `value` sent and
    the `allowed` range too, and reads as `refusal_text` writes them, so that every surface shows the same words and
    the HTTP 422 body the same parts (`contract.refusals.input_detail`). A ValueError too, so pydantic validators may
    raise it and older callers that catch ValueError still do."""

    def __init__(self, problem: str, *, field: str | None = None, value: object = None, allowed: str | None = None):
        super().__init__(problem if field is None else refusal_text(field, problem, value, allowed))
        self.problem, self.field, self.value, self.allowed = problem, field, value, allowed


class FlightError(GolfflightError):
    """A valid shot the engine could not fly to the ground (the message says why); a batch reports it for that
    shot."""


class ServiceError(GolfflightError):
    """The service cannot answer now (the model still loading, the batch process restarting): try again later."""

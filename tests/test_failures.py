"""One family of failures (`golfflight.errors`): every input problem the code raises is an InputError (the tree is
read, not trusted), every exception class of ours is in the family, the command line exits 2 for input errors only,
and the service answers each kind from one table (HTTP and Open Connect alike)."""

from __future__ import annotations

import argparse
import ast
import builtins

import pytest
from golfflight import cli
from golfflight.contract.gspro import GSProMessage, failed_reply
from golfflight.contract.refusals import FAILURES, UNEXPECTED, answer_to
from golfflight.errors import FlightError, GolfflightError, InputError, ServiceError
from golfflight.service.runtime import NotReady
from golfflight.service.runtime.batch_process import BatchProcessDied
from golfflight.shots.records import RecordError

from tests.test_imports import ROOT, _modules

OURS = {name for name, value in vars(__import__("golfflight.errors").errors).items() if isinstance(value, type)}
BUILTIN_EXCEPTIONS = {name for name, value in vars(builtins).items()
                      if isinstance(value, type) and issubclass(value, Exception)}
"""The built-in errors a class of ours might derive from (a BaseException such as the sweep's Interrupted is a
signal, like KeyboardInterrupt, not a failure)."""


def _name(node: ast.AST) -> str | None:
    node = node.func if isinstance(node, ast.Call) else node
    return node.id if isinstance(node, ast.Name) else node.attr if isinstance(node, ast.Attribute) else None


def test_no_module_raises_a_bare_value_error():
    offenders = [
        f"{path.relative_to(ROOT)}:{node.lineno}"
        for path in _modules()
        for node in ast.walk(ast.parse(path.read_text(), str(path)))
        if isinstance(node, ast.Raise) and node.exc is not None and _name(node.exc) == "ValueError"
    ]
    assert offenders == [], "an input problem raises InputError (golfflight.errors), never a bare ValueError"


def test_every_exception_class_of_ours_is_in_the_family():
    offenders = []
    for path in _modules():
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if not isinstance(node, ast.ClassDef) or path == ROOT / "golfflight" / "errors.py":
                continue
            bases = {_name(base) for base in node.bases}
            if bases & BUILTIN_EXCEPTIONS and not bases & OURS:
                offenders.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name}{sorted(bases)}")
    assert offenders == []


def test_the_kinds_subclass_what_callers_catch():
    assert issubclass(InputError, ValueError) and issubclass(RecordError, InputError)
    assert not issubclass(FlightError, ValueError) and not issubclass(ServiceError, ValueError)
    assert issubclass(NotReady, ServiceError) and issubclass(BatchProcessDied, ServiceError)


@pytest.mark.parametrize(
    ("error", "http", "code"),
    [(InputError("x"), 422, 500), (RecordError("x"), 422, 500), (FlightError("x"), 422, 500),
     (NotReady("loading"), 503, 503), (BatchProcessDied("died"), 503, 503), (RuntimeError("bug"), 500, 500)],
)
def test_one_table_answers_each_kind_for_http_and_open_connect(error, http, code):
    answer = answer_to(error)
    assert (answer.http_status, answer.open_connect_code) == (http, code)
    assert answer in FAILURES.values() or answer == UNEXPECTED
    reply = failed_reply(GSProMessage.model_validate({"DeviceID": "d", "ShotNumber": 7}), error)
    assert (reply.Code, reply.Message, reply.ShotNumber) == (code, str(error), 7)


def _main_raising(monkeypatch, error: BaseException) -> int:
    """`golfflight boom` with a command whose run raises `error`."""

    def parser(only: str | None = None) -> argparse.ArgumentParser:
        built = argparse.ArgumentParser(prog="golfflight")
        command = built.add_subparsers(dest="command", required=True).add_parser("boom")
        command.set_defaults(run=lambda args: (_ for _ in ()).throw(error))
        return built

    monkeypatch.setattr(cli, "build_parser", parser)
    return cli.main(["boom"])


def test_the_command_line_exits_2_for_an_input_error_only(monkeypatch, capsys):
    assert _main_raising(monkeypatch, InputError("--shots must be at least 1, got 0")) == 2
    assert capsys.readouterr().err == "golfflight boom: error: --shots must be at least 1, got 0\n"
    assert _main_raising(monkeypatch, FileNotFoundError(2, "No such file or directory", "x.csv")) == 2
    assert _main_raising(monkeypatch, FlightError("did not land")) == 1
    assert capsys.readouterr().err.endswith("golfflight boom: error: did not land\n")


def test_a_bug_keeps_its_traceback_and_is_not_called_the_users(monkeypatch):
    with pytest.raises(ValueError, match="a bug"):
        _main_raising(monkeypatch, ValueError("a bug"))
    with pytest.raises(ZeroDivisionError):
        _main_raising(monkeypatch, ZeroDivisionError())

"""Issue 56, item 8: a benchmark writes its results where `--results FILE` says, and nowhere else; without the flag it
prints its table and writes nothing, so a tracked file of figures (benchmarks/results.json, a script's own JSON file)
changes only when a run names it.

Benchmarks run for real (bench_inprocess.py, one round of 50 shots; bench_validation_gil.py, one round: a few seconds
each) from a copy of benchmarks/ in a temporary folder, so that a script that still rewrote a file of its own folder
changes the copy, never the checkout's. Every script in benchmarks/ is also read (its syntax tree): each file it writes
must be named by a flag, a parameter or a temporary folder, never by a constant of its own or of common.py, so a new
script cannot bring back a tracked default."""

from __future__ import annotations

import ast
import json
import os
import shutil
import subprocess
import sys
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BENCHMARKS = ROOT / "benchmarks"


def _run(scripts: Path, work: Path, *args: str) -> subprocess.CompletedProcess:
    return _run_script(scripts / "bench_inprocess.py", work, "--rounds", "1", "--shots", "50", *args)


def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_a_benchmark_writes_only_the_file_its_flag_names(tmp_path):
    scripts = tmp_path / "benchmarks"
    shutil.copytree(BENCHMARKS, scripts, ignore=shutil.ignore_patterns("__pycache__"))
    work = tmp_path / "work"
    work.mkdir()
    before = _files(scripts)

    printed = _run(scripts, work)
    assert "single shot, 7-iron" in printed.stdout and "results not written" in printed.stdout
    assert _files(scripts) == before and _files(work) == {}, "a run without --results wrote a file"

    chosen = tmp_path / "elsewhere" / "mine.json"
    _run(scripts, work, "--results", str(chosen))
    assert _files(scripts) == before and _files(work) == {}, "a run wrote beside the one file it was given"
    section = json.loads(chosen.read_text())["in_process"]
    assert len(section["rows"]) == 4 and section["machine"]["cores"] == os.cpu_count()


def test_an_own_file_benchmark_writes_only_the_file_its_flag_names(tmp_path):
    scripts = tmp_path / "benchmarks"
    shutil.copytree(BENCHMARKS, scripts, ignore=shutil.ignore_patterns("__pycache__"))
    work = tmp_path / "work"
    work.mkdir()
    before = _files(scripts)
    script = scripts / "bench_validation_gil.py"

    printed = _run_script(script, work, "--rounds", "1")
    assert "worst loop stall ms" in printed.stdout and "results not written" in printed.stdout
    assert _files(scripts) == before and _files(work) == {}, "a run without --results wrote a file"

    chosen = tmp_path / "elsewhere" / "gil.json"
    _run_script(script, work, "--rounds", "1", "--results", str(chosen))
    assert _files(scripts) == before and _files(work) == {}, "a run wrote beside the one file it was given"
    written = json.loads(chosen.read_text())
    assert set(written) == set(json.loads((BENCHMARKS / "validation_gil.json").read_text())), "its format changed"
    assert written["script"] == "benchmarks/bench_validation_gil.py" and len(written["rows"]) == 8


MERGE = """
import sys
from pathlib import Path
import bench_batch_load
path = Path(sys.argv[1]) if len(sys.argv) > 1 else None
bench_batch_load.write_rows([{"label": "after", "scenario": "quiet", "fresh": True}], "after", path)
"""


def test_batch_load_merges_its_label_into_the_file_results_names(tmp_path):
    chosen = tmp_path / "load.json"
    earlier = [{"label": "before", "scenario": "quiet"}, {"label": "after", "scenario": "quiet", "fresh": False}]
    chosen.write_text(json.dumps({"script": "benchmarks/bench_batch_load.py", "machine": {}, "rows": earlier}))
    scripts = tmp_path / "benchmarks"
    shutil.copytree(BENCHMARKS, scripts, ignore=shutil.ignore_patterns("__pycache__"))
    before = _files(scripts)

    printed = _run_code(MERGE, scripts)
    assert "results not written" in printed.stdout and _files(scripts) == before
    _run_code(MERGE, scripts, str(chosen))
    assert _files(scripts) == before, "the merge wrote into benchmarks/ as well as the file named"
    fresh = {"label": "after", "scenario": "quiet", "fresh": True}
    assert json.loads(chosen.read_text())["rows"] == [earlier[0], fresh], "other labels kept, its own replaced"


def _environment() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}


def _run_script(script: Path, work: Path, *args: str) -> subprocess.CompletedProcess:
    command = [sys.executable, str(script), *args]
    done = subprocess.run(command, cwd=work, env=_environment(), capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return done


def _run_code(code: str, scripts: Path, *args: str) -> subprocess.CompletedProcess:
    command = [sys.executable, "-c", code, *args]
    done = subprocess.run(command, cwd=scripts, env=_environment(), capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return done


NAMED = {"flag", "temporary"}
"""Where a written file's path may come from: a flag (`parse_args()`'s), a temporary folder, or a parameter (whose
callers are checked in turn)."""
WRITING_METHODS = {"write_text": None, "write_bytes": None, "touch": None, "dump_stats": 0, "save": 0, "savetxt": 0,
                   "savez": 0, "savez_compressed": 0, "to_csv": 0, "dump": 1, "copy": 1, "copy2": 1, "copyfile": 1,
                   "copytree": 1, "move": 1}
"""A call that writes a file, and which argument names it (None: the object it is called on, a Path)."""
OPENING_MODULES = {"io", "os", "gzip", "codecs"}
"""`module.open(file, mode)`: opened as the builtin `open` is; any other `x.open(mode)` is a Path's."""


@dataclass
class Scope:
    """What a function's names can hold: its (and its enclosing functions') parameters and local bindings."""

    params: set[str] = field(default_factory=set)
    bindings: dict[str, list[ast.expr]] = field(default_factory=dict)

    def inner(self, function: ast.FunctionDef | ast.AsyncFunctionDef) -> Scope:
        """The scope inside `function`, nested in this one."""
        arguments = function.args
        every = [*arguments.posonlyargs, *arguments.args, *arguments.kwonlyargs, arguments.vararg, arguments.kwarg]
        bindings = {name: list(values) for name, values in self.bindings.items()}
        for node in ast.walk(function):
            for target, value in _bound(node):
                for name in (n.id for n in ast.walk(target) if isinstance(n, ast.Name)):
                    bindings.setdefault(name, []).append(value)
        return Scope(self.params | {a.arg for a in every if a is not None}, bindings)


def _bound(node: ast.AST) -> list[tuple[ast.expr, ast.expr]]:
    """The (target, value) pairs a statement or clause binds: assignments, loops, comprehensions, `with ... as`."""
    if isinstance(node, ast.Assign):
        return [(target, node.value) for target in node.targets]
    if isinstance(node, ast.AnnAssign | ast.AugAssign | ast.NamedExpr) and node.value is not None:
        return [(node.target, node.value)]
    if isinstance(node, ast.For | ast.AsyncFor | ast.comprehension):
        return [(node.target, node.iter)]
    if isinstance(node, ast.withitem) and node.optional_vars is not None:
        return [(node.optional_vars, node.context_expr)]
    return []


def _constants(tree: ast.Module) -> set[str]:
    """A script's module-level names and the upper-case names it imports (REPO, TRACKED_RESULTS): fixed paths."""
    names = {"__file__"}
    for node in tree.body:
        for target, _ in _bound(node):
            names |= {n.id for n in ast.walk(target) if isinstance(n, ast.Name)}
        if isinstance(node, ast.ImportFrom):
            names |= {a.asname or a.name for a in node.names if (a.asname or a.name).isupper()}
    return names


def _sources(expr: ast.expr, scope: Scope, constants: set[str], seen: frozenset[str] = frozenset()) -> set[str]:
    """Where `expr`'s value comes from: "flag", "temporary", "param NAME" or "constant NAME", local names followed."""
    found = set()
    for node in ast.walk(expr):
        if isinstance(node, ast.Call) and _called(node) == "parse_args":
            found.add("flag")
        elif isinstance(node, ast.Name) and node.id == "tempfile":
            found.add("temporary")
        elif isinstance(node, ast.Name) and node.id in scope.params:
            found.add(f"param {node.id}")
        elif isinstance(node, ast.Name) and node.id in scope.bindings and node.id not in seen:
            for value in scope.bindings[node.id]:
                found |= _sources(value, scope, constants, seen | {node.id})
        elif isinstance(node, ast.Name) and node.id in constants:
            found.add(f"constant {node.id}")
    return found


def _called(call: ast.Call) -> str | None:
    """The name a call is made by: `f(...)`'s f, `x.f(...)`'s f."""
    func = call.func
    return func.id if isinstance(func, ast.Name) else func.attr if isinstance(func, ast.Attribute) else None


def _argument(call: ast.Call, position: int | None, keyword: str) -> list[ast.expr]:
    """The argument given for a parameter (every positional one where a `*args` hides which)."""
    named = [k.value for k in call.keywords if k.arg == keyword]
    if named:
        return named
    if any(isinstance(a, ast.Starred) for a in call.args):
        return [a.value if isinstance(a, ast.Starred) else a for a in call.args]
    return [call.args[position]] if position is not None and position < len(call.args) else []


def _writing_mode(mode: list[ast.expr]) -> bool:
    """Whether an `open` mode writes (a mode not written out as a string may)."""
    if not mode:
        return False
    return not isinstance(mode[0], ast.Constant) or any(c in str(mode[0].value) for c in "wax+")


def _targets(call: ast.Call, writers: dict[str, list[tuple[int | None, str]]]) -> list[ast.expr]:
    """The paths a call writes: a Path method's object, `open(..., "w")`'s file, or a writing function's argument."""
    func = call.func
    if isinstance(func, ast.Name) and func.id in writers:
        return [arg for position, name in writers[func.id] for arg in _argument(call, position, name)]
    if isinstance(func, ast.Name) and func.id == "open":
        return _argument(call, 0, "file") if _writing_mode(_argument(call, 1, "mode")) else []
    if not isinstance(func, ast.Attribute):
        return []
    if func.attr == "open" and isinstance(func.value, ast.Name) and func.value.id in OPENING_MODULES:
        return _argument(call, 0, "file") if _writing_mode(_argument(call, 1, "mode")) else []
    if func.attr == "open":
        return [func.value] if _writing_mode(_argument(call, 0, "mode")) else []
    if func.attr in WRITING_METHODS:
        position = WRITING_METHODS[func.attr]
        return [func.value] if position is None else _argument(call, position, "")
    return []


def _calls(node: ast.AST, scope: Scope, function: str | None) -> Iterator[tuple[ast.Call, Scope, str | None]]:
    """Every call in `node`, with the scope it is made in and the name of the function making it."""
    for child in ast.iter_child_nodes(node):
        if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef):
            yield from _calls(child, scope.inner(child), child.name)
            continue
        if isinstance(child, ast.Call):
            yield child, scope, function
        yield from _calls(child, scope, function)


def _signature(function: ast.FunctionDef | ast.AsyncFunctionDef, params: set[str]) -> list[tuple[int | None, str]]:
    """Each of `params` with its position in `function`'s signature (None: keyword-only)."""
    positional = [a.arg for a in (*function.args.posonlyargs, *function.args.args)]
    return [(positional.index(p) if p in positional else None, p) for p in sorted(params)]


def unnamed_writes(tree: ast.Module, writers: dict[str, list[tuple[int | None, str]]]) -> tuple[list[str], dict]:
    """Each write in a script whose path is a constant or no flag's, parameter's or temporary folder's ('line: what'),
    and the writing functions known after it (`writers` with the script's own functions whose parameters name a
    file written, so that their callers are checked in turn)."""
    constants, writers = _constants(tree), dict(writers)
    functions = {f.name: f for f in tree.body if isinstance(f, ast.FunctionDef | ast.AsyncFunctionDef)}
    while True:
        problems, params = [], {}
        for call, scope, function in _calls(tree, Scope(), None):
            for target in _targets(call, writers):
                sources = _sources(target, scope, constants)
                params.setdefault(function, set()).update(s.split()[1] for s in sources if s.startswith("param "))
                fixed = sorted(s.split()[1] for s in sources if s.startswith("constant "))
                if fixed or not any(s in NAMED or s.startswith("param ") for s in sources):
                    problems.append(f"{call.lineno}: {ast.unparse(call)[:80]} writes {fixed or 'a fixed path'}")
        found = {name: _signature(functions[name], p) for name, p in params.items() if name in functions and p}
        if all(writers.get(name) == signature for name, signature in found.items()):
            return problems, writers
        writers.update(found)


def _common_writers() -> dict[str, list[tuple[int | None, str]]]:
    """benchmarks/common.py's functions that write the file a parameter names (save_results, write_results)."""
    problems, writers = unnamed_writes(ast.parse((BENCHMARKS / "common.py").read_text()), {})
    assert not problems, problems
    return writers


def test_no_benchmark_writes_a_file_no_flag_named():
    writers = _common_writers()
    assert set(writers) >= {"save_results", "write_results"}
    found = {}
    for script in sorted(BENCHMARKS.glob("*.py")):
        source = script.read_text()
        problems, _ = unnamed_writes(ast.parse(source, filename=str(script)), writers)
        if "--no-write" in source:
            problems.append("takes --no-write: without --results a run writes nothing, nothing to opt out of")
        if any(name in source for name in writers) and "add_results_flag(" not in source:
            problems.append("writes results without common.add_results_flag's --results FILE")
        if problems:
            found[script.name] = problems
    assert found == {}, "benchmarks that write a file no --results named:\n" + json.dumps(found, indent=2)


FIXED_DEFAULTS = {
    "a constant path": 'OUT = REPO / "benchmarks" / "own.json"\ndef main():\n    OUT.write_text("{}")\n',
    "a constant handed to a writing function": 'from common import TRACKED_RESULTS, save_results\n'
    'def keep(data, path):\n    save_results(path, data)\ndef main():\n    keep({}, TRACKED_RESULTS)\n',
    "a constant as the flag's fallback": 'OUT = "own.json"\ndef main():\n    args = parser.parse_args()\n'
    '    with open(args.results or OUT, "w") as out:\n        json.dump({}, out)\n',
    "a file beside the script": 'def main():\n    Path(__file__).with_name("own.json").open("a").write("{}")\n',
    "a relative literal": 'def main():\n    with open("own.json", mode="w") as out:\n        json.dump({}, out)\n',
}


def test_the_check_finds_each_way_of_writing_a_fixed_file_and_passes_flagged_ones():
    writers = _common_writers()
    for way, source in FIXED_DEFAULTS.items():
        assert unnamed_writes(ast.parse(source), writers)[0], f"not found: {way}"
    flagged = ('import tempfile\ndef main():\n    args = parser.parse_args()\n    save_results(args.results, {})\n'
               '    folder = Path(tempfile.mkdtemp())\n    (folder / "x.py").write_text("")\n'
               '    with open(args.results, "r") as kept:\n        json.load(kept)\n')
    assert unnamed_writes(ast.parse(flagged), writers)[0] == []

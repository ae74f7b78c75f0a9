"""A sweep's output file, written whole or not at all: under a hidden temporary name beside it, renamed over it at the
end, the temporary file removed on any failure or signal (`write_whole`). The name holds the host and the process id
of the sweep writing it (`.OUT.HOST.PID.XXXXXXXX.tmp`), so that the next sweep to the same file can tell one left by
a sweep that was killed (SIGKILL, a crash, a machine that went down), which it removes and says so, from one another
sweep is still writing, which it leaves (`clear_stale`). A file that cannot be written is named, with the system's
reason, in one line (`OutputError`).
"""

from __future__ import annotations

import glob
import os
import re
import socket
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from golfflight.errors import GolfflightError

OWNED = re.compile(r"(?P<host>.+)\.(?P<pid>\d+)\.[^.]+\.tmp")
"""What follows `.OUT.` in a temporary file's name: the host and process id of the sweep writing it."""

MODE = 0o644
"""The output's permissions (a temporary file is made readable by its owner alone)."""


class OutputError(GolfflightError, OSError):
    """The output could not be written: the file and the system's reason, in one line (`[Errno 28] Error writing
    bytes to file` named neither the file nor, in so many words, a full disk)."""

    def __str__(self) -> str:
        number = f" (errno {self.errno})" if self.errno is not None else ""
        return f"cannot write {self.filename}: {self.strerror}{number}"


@contextmanager
def writing(path: str | os.PathLike) -> Iterator[None]:
    """An OSError within the block is one writing `path`: an OutputError naming it, with the system's words for the
    error number (pyarrow's own message repeats the number and names no file)."""
    try:
        yield
    except OutputError:
        raise
    except OSError as error:
        reason = os.strerror(error.errno) if error.errno is not None else str(error)
        raise OutputError(error.errno, reason, str(path)) from None


def _running(pid: int) -> bool:
    """Whether process `pid` runs on this host (a zombie, dead but not yet reaped by its parent, does not)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()[0]
    except (OSError, IndexError):
        return True
    return state not in ("Z", "X")


def _verdict(temporary: Path, prefix: str) -> str | None:
    """What to do with the temporary file `temporary`: "stale" (its sweep, of this host, is no longer running),
    "owned" (it is), or None where this host cannot tell (another host's, or a name without a process id)."""
    owner = OWNED.fullmatch(temporary.name[len(prefix) :])
    if owner is None or owner["host"] != socket.gethostname():
        return None
    return "owned" if _running(int(owner["pid"])) else "stale"


def _remove(stale: Path, notice: Callable[[str], None]) -> None:
    """Remove `stale`, left by a sweep that is no longer running, and say so (or why it stays)."""
    try:
        stale.unlink(missing_ok=True)
    except OSError as error:
        notice(f"left {stale}, the temporary file of an interrupted sweep: cannot remove it ({error.strerror})")
        return
    notice(f"removed {stale}, the temporary file of an interrupted sweep (its process is gone); this sweep flies "
           "every row again")


def clear_stale(path: str | os.PathLike, notice: Callable[[str], None]) -> None:
    """Remove the temporary files of `path` that sweeps no longer running left behind, telling `notice` of each; of
    one another sweep is writing, or one this host cannot judge, tell `notice` and leave it. A stale file is not
    resumed from: a Parquet file gets its footer, without which it cannot be read, only when it is closed."""
    path = Path(path)
    prefix = f".{path.name}."
    for temporary in sorted(path.parent.glob(f"{glob.escape(prefix)}*.tmp")):
        verdict = _verdict(temporary, prefix)
        if verdict == "stale":
            _remove(temporary, notice)
        elif verdict == "owned":
            notice(f"left {temporary}: another sweep to {path} is running (its process id is in the name)")
        else:
            notice(f"left {temporary}: a temporary file of a sweep on another host or of an older golfflight; "
                   "remove it if no sweep is writing it")


def write_whole(path: str | os.PathLike, write: Callable[[str], None]) -> None:
    """Call `write(temporary path)`, then rename the temporary file over `path`: a reader never sees half a file, and
    a failure or an interruption (any exception) leaves the old file and no temporary one. An OSError creating,
    renaming or (where `write` marks its writes with `writing`) writing the file names `path` (OutputError)."""
    path = Path(path)
    with writing(path):
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.{socket.gethostname()}.{os.getpid()}.",
                                   suffix=".tmp")
        os.close(fd)
    try:
        with writing(path):
            os.chmod(tmp, MODE)
        write(tmp)
        with writing(path):
            os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise

"""The output of ``python -m sogmm_ray``, checked before any work (as
the `sogmm` tools' check_outputs, tools/sogmm/file_util.hpp): a run of hours
must not end in an unwritable folder, and the map must not replace an input.
The save itself is the library's atomic one (written through symbolic links,
a target that is not a regular file refused)."""

from __future__ import annotations

import os
import stat
import tempfile

from sogmm import InvalidArgumentError, SogmmIOError
from sogmm._input_file import kind_of


def _final_target(path: str) -> str:
    """The file a save replaces: the end of the chain of symbolic links."""
    for _ in range(40):
        if not os.path.islink(path):
            break
        target = os.readlink(path)
        path = target if os.path.isabs(target) else os.path.join(os.path.dirname(path), target)
    return path


def _same_file(a: str, b: str) -> bool:
    if os.path.exists(a) and os.path.exists(b):
        return os.path.samefile(a, b)
    return os.path.realpath(a) == os.path.realpath(b)


def check_output(flag: str, path: str, inputs: list[tuple[str, str]]) -> None:
    """Raises SogmmIOError unless ``path`` can be written (its folder exists
    and is writable; it is absent or a regular file), InvalidArgumentError
    when it is one of the ``inputs`` ((flag, path) pairs)."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        mode = None
    except OSError as e:
        raise SogmmIOError(f"{path}: cannot write ({e.strerror})") from None
    if mode is not None and not stat.S_ISREG(mode):
        raise SogmmIOError(f"{path}: cannot write (it is {kind_of(mode)}, not a regular file)")
    folder = os.path.dirname(_final_target(path)) or "."
    if not os.path.isdir(folder):
        raise SogmmIOError(f"{path}: cannot write (folder {folder} does not exist)")
    try:  # creating a file is the one test that holds for every reason it can fail (read-only mounts, root)
        fd, probe = tempfile.mkstemp(prefix=".sogmm-probe-", dir=folder)
    except OSError as e:
        raise SogmmIOError(f"{path}: cannot write in folder {folder} ({e.strerror})") from None
    os.close(fd)
    os.remove(probe)
    for in_flag, in_path in inputs:
        if in_path and _same_file(path, in_path):
            raise InvalidArgumentError(f"{flag} {path} is also the input {in_flag} {in_path}: "
                                       "writing it would destroy the input")

"""Small input files (intrinsics, trajectories) read without ever blocking:
opened with O_NONBLOCK and refused unless regular, so a FIFO or a device given
as a file fails at once instead of waiting for a writer (as the C++ tools'
read_input_file, tools/sogmm/file_util.hpp)."""

from __future__ import annotations

import os
import stat

from .errors import SogmmIOError


def kind_of(mode: int) -> str:
    """What a non-regular file is, for messages."""
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISSOCK(mode):
        return "a socket"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    return "not a regular file"


def read_input_file(path: str | os.PathLike, what: str) -> str:
    """The UTF-8 text of a regular file. A missing file raises
    FileNotFoundError; any other file that is not regular SogmmIOError
    (both OSError), naming ``path``."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    with os.fdopen(fd, "rb") as f:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise SogmmIOError(f"{os.fspath(path)}: cannot read {what} (it is {kind_of(mode)}, not a regular file)")
        return f.read().decode("utf-8")

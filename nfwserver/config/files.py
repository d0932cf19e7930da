"""Reading a small text file named by the user without ever blocking on it.

The configuration file and the files it names (a horizon table) are read only when they are
*regular* files of bounded size.  A FIFO, a terminal or a device given by mistake would block a
plain ``open()``/``read()`` for ever (the config watcher would hang); here it is opened with
``O_NONBLOCK`` (which never waits for a FIFO writer), checked with ``fstat`` and refused with one
sentence.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

#: Largest configuration or horizon file read (bytes).
MAX_FILE_BYTES = 1 << 20
APP_NAME = "nfwserver"


def default_config_path() -> Path:
    """``config.toml`` in the platform's user configuration directory (here, not in the loader: a command
    asks whether the file exists before it pays for the loader and the configuration's records)."""
    from platformdirs import user_config_dir

    return Path(user_config_dir(APP_NAME, appauthor=False)) / "config.toml"


class FileRefused(ValueError):
    """The path exists but is not a regular file of acceptable size; the message is one sentence."""


class FileTooLarge(FileRefused):
    """The regular file is larger than the limit (or grew past it while being read)."""


def read_regular_file(path: str | Path, limit: int = MAX_FILE_BYTES, errors: str = "strict") -> str:
    """Return the UTF-8 text of the regular file ``path`` (at most ``limit`` bytes).

    Raises :class:`FileNotFoundError` / :class:`OSError` when it cannot be opened,
    :class:`FileRefused` when it is not a regular file or is larger than ``limit``, and
    :class:`UnicodeDecodeError` for undecodable text when ``errors`` is ``"strict"``.
    """
    return read_regular_bytes(path, limit).decode("utf-8", errors)


def read_regular_bytes(path: str | Path, limit: int) -> bytes:
    """The bytes of the regular file ``path``, at most ``limit`` of them, read without ever blocking.

    Raises :class:`OSError` when it cannot be opened, :class:`FileRefused` when it is not a regular file and
    :class:`FileTooLarge` when it holds more than ``limit`` bytes (checked before reading, and again while
    reading, for a file that grows).
    """
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0)
    fd = os.open(path, flags)
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise FileRefused(f"{path} is not a regular file")
        if info.st_size > limit:
            raise FileTooLarge(f"{path} is larger than {_size(limit)}")
        chunks: list[bytes] = []
        total = 0
        while total <= limit:
            chunk = os.read(fd, min(65536, limit + 1 - total))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
        if total > limit:  # it grew while being read
            raise FileTooLarge(f"{path} is larger than {_size(limit)}")
    finally:
        os.close(fd)
    return b"".join(chunks)


def check_regular_file(path: str | Path) -> str | None:
    """None when ``path`` is an existing regular file, else the sentence saying what is wrong."""
    try:
        info = os.stat(path)
    except FileNotFoundError:
        return f"{path} does not exist"
    except OSError as exc:
        return f"{path} cannot be read ({exc.strerror or exc})"
    if not stat.S_ISREG(info.st_mode):
        return f"{path} is not a regular file"
    return None


def _size(limit: int) -> str:
    return f"{limit >> 20} MiB" if limit >= 1 << 20 and limit % (1 << 20) == 0 else f"{limit} bytes"

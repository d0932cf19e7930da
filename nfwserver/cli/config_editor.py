"""``nfwserver config edit``: the configuration file, created from the template when missing, in an editor.

The editor is ``$VISUAL`` or ``$EDITOR`` (run in the foreground; the command returns when it exits), else
the system's own: on Windows the file's "edit" action, or Notepad when ``.toml`` has none; elsewhere
``xdg-open`` (or ``open`` on macOS).  A running station that follows the file applies what is saved.
"""

from __future__ import annotations

import os
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

from nfwserver.cli.errors import CliError


def editor_command(environ: dict[str, str] | None = None) -> list[str] | None:
    """The user's editor as an argument list (``$VISUAL``, then ``$EDITOR``), or None."""
    env = os.environ if environ is None else environ
    for name in ("VISUAL", "EDITOR"):
        value = env.get(name, "").strip()
        if value:
            return shlex.split(value, posix=sys.platform != "win32")
    return None


def _system_open(path: Path) -> None:
    """Open ``path`` with the system's editor for it (does not wait)."""
    if sys.platform == "win32":
        try:
            os.startfile(path, "edit")  # type: ignore[attr-defined,unused-ignore]
        except OSError:
            subprocess.Popen(["notepad.exe", str(path)])
        return
    opener = "open" if sys.platform == "darwin" else "xdg-open"
    if shutil.which(opener) is None:
        raise CliError(f"no editor: set $EDITOR (e.g. EDITOR=nano), or open {path} yourself")
    subprocess.Popen([opener, str(path)], stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                     stderr=subprocess.DEVNULL, start_new_session=True)


def open_in_editor(path: Path | None) -> int:
    """Create the file from the template if it is missing, print its path, open it; the exit code."""
    from nfwserver.config.files import default_config_path
    from nfwserver.config.render import template
    from nfwserver.file_lock import locked
    from nfwserver.storage import atomic_write_text

    target = path if path is not None else default_config_path()
    if not target.exists():
        try:
            with locked(target):
                if not target.exists():  # written meanwhile by another command: keep that one
                    atomic_write_text(target, template())
        except OSError as exc:
            raise CliError(f"cannot write {target}: {exc.strerror or exc}") from None
        print(f"{target} (written from the template)")
    else:
        print(target)
    sys.stdout.flush()
    command = editor_command()
    if command is None:
        _system_open(target)
        return 0
    try:
        code = subprocess.call([*command, str(target)])
    except OSError as exc:
        raise CliError(f"cannot start the editor {command[0]!r}: {exc.strerror or exc}") from None
    if code != 0:
        raise CliError(f"the editor {command[0]!r} exited with status {code}")
    return 0

"""A fresh Wine prefix of its own, with no Python in it, for installing nfwserver's setup.exe (Linux side).

Created with ``wineboot``, switched to Wine's null window driver (no X here), and kept alive by a persistent
``wineserver`` whose system processes (services, explorer, rpcss...) were started with /dev/null as their
standard streams: a system process started by a program run with pipes would inherit them and hold them
open, and reading that program's output would then never end.  Windows programs run with pipes, never
regular files (the CPython inside ``nfwserver.exe`` cannot start with a regular Linux file as a standard
stream under Wine 8.0; docs/WINE.md).
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path, PureWindowsPath


class WinePrefix:
    """One prefix under ``root``; :meth:`close` ends its wineserver and removes it."""

    def __init__(self, root: Path) -> None:
        self.root = root
        self.env = {**os.environ, "WINEPREFIX": str(root), "WINEARCH": "win64", "WINEDEBUG": "-all",
                    "WINEDLLOVERRIDES": "winedbg.exe=d;mscoree=d;mshtml=d"}
        for key in ("NFW_CONTROL_FILE", "DISPLAY", "WAYLAND_DISPLAY"):
            self.env.pop(key, None)
        self._quiet(["wineboot", "-i"], 300)
        self._quiet(["wine", "reg", "add", r"HKCU\Software\Wine\Drivers", "/v", "Graphics", "/d", "null", "/f"], 60)
        self._quiet(["wineserver", "-w"], 60)
        self._quiet(["wineserver", "-p"], 30)
        self._quiet(["wine", "cmd", "/c", "exit"], 120)  # the system processes, on /dev/null
        self.local_appdata = PureWindowsPath(self.run(["cmd", "/c", "echo %LOCALAPPDATA%"]).stdout.strip())
        self.appdata = PureWindowsPath(self.run(["cmd", "/c", "echo %APPDATA%"]).stdout.strip())
        self.profile = PureWindowsPath(self.run(["cmd", "/c", "echo %USERPROFILE%"]).stdout.strip())

    def _quiet(self, argv: list[str], timeout_s: float) -> None:
        subprocess.run(argv, env=self.env, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL, timeout=timeout_s, check=True)

    def run(self, argv: list[str], timeout_s: float = 180.0) -> subprocess.CompletedProcess[str]:
        """``wine ARGV`` to completion, its output decoded (UTF-8, Wine's console output for pipes)."""
        return subprocess.run(["wine", *argv], env=self.env, stdin=subprocess.DEVNULL, capture_output=True,
                              text=True, encoding="utf-8", errors="replace", timeout=timeout_s)

    def run_detached(self, argv: list[str], timeout_s: float = 300.0) -> int:
        """``wine ARGV`` to completion with no pipes, for a program that may start others that outlive it (an
        installer starting the station): those would inherit the pipes and hold them open."""
        return subprocess.run(["wine", *argv], env=self.env, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL, timeout=timeout_s).returncode

    def start(self, argv: list[str]) -> subprocess.Popen[str]:
        """``wine ARGV`` in the background (output to pipes)."""
        return subprocess.Popen(["wine", *argv], env=self.env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True, encoding="utf-8", errors="replace")

    def unix(self, path: PureWindowsPath | str) -> Path:
        """The Linux path of a Windows path on drive C: or Z:."""
        win = PureWindowsPath(path)
        drive = win.drive.rstrip(":").lower()
        rest = Path(*win.parts[1:])
        if drive == "z":
            return Path("/") / rest
        assert drive == "c", f"not on C: or Z: {win}"
        return self.root / "drive_c" / rest

    def reg_values(self, key: str) -> dict[str, str] | None:
        """The values under ``key`` as text (``reg query``), or None when the key does not exist."""
        out = self.run(["reg", "query", key])
        if out.returncode != 0:
            return None
        values: dict[str, str] = {}
        for line in out.stdout.splitlines():
            parts = line.strip().split(None, 2)
            if len(parts) >= 2 and parts[1].startswith("REG_"):
                values[parts[0]] = parts[2] if len(parts) == 3 else ""
        return values

    def close(self) -> None:
        subprocess.run(["wineserver", "-k"], env=self.env, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL, timeout=60, check=False)
        shutil.rmtree(self.root, ignore_errors=True)

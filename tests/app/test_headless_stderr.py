"""What ``nfwserver run --headless`` writes on stderr (#25 item 9): one line per note or log record, each written
whole and prefixed ``nfwserver: `` like every other diagnostic, and daemons never reached are "not reachable"."""

from __future__ import annotations

import io
import os
import subprocess
import sys
from pathlib import Path

from nfwserver.cli import main
from tests.conftest import DATA, ROOT
from tests.hamlib_daemons import free_port


def _config(tmp_path: Path, rotor_port: int, radio_port: int) -> Path:
    path = tmp_path / "config.toml"
    path.write_text('[observer]\nlocation = "JO02ae"\n'
                    f'[elements]\nfiles = ["{DATA / "visual.txt"}"]\nuse_bundled = false\n'
                    '[server]\nsatellite = 25544\ntune = true\ntrack = true\nstate_file = "none"\n'
                    f'[rotor]\nbackend = "rotctld"\nport = {rotor_port}\n'
                    f'[radio]\nbackend = "rigctld"\nport = {radio_port}\nenabled = true\n')
    return path


def test_headless_stderr_is_one_prefixed_line_per_note(tmp_path) -> None:
    rotor_port, radio_port = free_port(), free_port()  # nothing listens there: daemons never reached
    path = _config(tmp_path, rotor_port, radio_port)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    done = subprocess.run([sys.executable, "-m", "nfwserver", "run", "--headless", "--duration", "1.5",
                           "--config", str(path), "--log-file", str(tmp_path / "log.txt")],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    lines = done.stderr.splitlines()
    assert done.stderr.endswith("\n") and all(line.startswith("nfwserver: ") for line in lines), lines
    assert f"nfwserver: configuration: {path}" in lines and "nfwserver: 148 satellites loaded" in lines
    assert (f"nfwserver: warning: rotctld: rotctld not reachable at 127.0.0.1:{rotor_port} (connection refused); "
            "retrying in 0.2 s") in lines
    assert any(line.startswith(f"nfwserver: warning: radio unavailable: rigctld not reachable at 127.0.0.1:"
                               f"{radio_port} (connection refused)") for line in lines), lines
    assert "Errno" not in done.stderr and " lost" not in done.stderr


class _Writes(io.StringIO):
    """stderr that keeps each write apart, to see whether a line was written whole."""

    def __init__(self) -> None:
        super().__init__()
        self.writes: list[str] = []

    def write(self, text: str) -> int:
        self.writes.append(text)
        return super().write(text)


def test_each_start_up_note_is_written_whole(tmp_path, monkeypatch) -> None:
    """A note written in two parts (text, then the newline) lets a record from a station thread land between."""
    config = tmp_path / "c.toml"
    config.write_text('[observer]\nlocation = "JO02ae"\n')
    stderr = _Writes()
    monkeypatch.setattr(sys, "stderr", stderr)
    assert main(["run", "--headless", "--duration", "0.2", "--config", str(config),
                 "--log-file", str(tmp_path / "log.txt")]) == 0
    notes = [w for w in stderr.writes if w.strip()]
    assert len(notes) >= 4 and all(w.startswith("nfwserver: ") and w.endswith("\n") and w.count("\n") == 1
                                   for w in notes), stderr.writes

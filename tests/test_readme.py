"""The README's commands work as written: the test command as root and through sudo, the simulate example."""

from __future__ import annotations

import os
import re
import shlex
import signal
import stat
import subprocess
from pathlib import Path

import pytest

from nfwserver.cli import main
from tests.app.test_element_presets import provider  # noqa: F401 - a fixture
from tests.conftest import ROOT
from tests.waiting import wait_for

README = (ROOT / "README.md").read_text(encoding="utf-8")


def _block_after(heading: str) -> str:
    """The first ```sh block after the line containing ``heading``, continuation lines joined."""
    tail = README[README.index(heading):]
    body = re.search(r"```sh\n(.*?)```", tail, re.S)
    assert body is not None
    return body.group(1).replace("\\\n", " ").strip()


def _tool(directory, name: str, script: str) -> None:
    path = directory / name
    path.write_text("#!/bin/sh\n" + script)
    path.chmod(path.stat().st_mode | stat.S_IXUSR)


@pytest.mark.parametrize(("uid", "expected_prefix"), [("0", ""), ("1000", "sudo ")])
def test_the_test_command_needs_sudo_only_when_not_root(tmp_path, uid, expected_prefix) -> None:
    """Run the README line with the system tools it calls recorded instead of run (no network here)."""
    command = _block_after("Install and run the tests")
    log = tmp_path / "calls.log"
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    record = f'echo "${{0##*/}} $*" >> "{log}"\n'
    _tool(bin_dir, "id", f'[ "$1" = "-u" ] && echo {uid}\n')
    for name in ("apt-get", "python3"):
        _tool(bin_dir, name, record)
    if uid != "0":
        _tool(bin_dir, "sudo", record + '"$@"\n')  # a real sudo runs the command; so does this one
    sh = next(p for p in ("/bin/sh", "/usr/bin/sh") if os.path.exists(p))
    env = {"PATH": f"{bin_dir}:/nonexistent", "HOME": str(tmp_path)}
    done = subprocess.run([sh, "-c", command], env=env, capture_output=True, text=True, timeout=30,
                          cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    calls = log.read_text().splitlines()
    apt = [c for c in calls if "apt-get install" in c]
    assert apt and apt[0].startswith(f"{expected_prefix}apt-get install -y libhamlib-utils")
    assert calls[-1] == "python3 -m pytest -n 2"
    assert not any(c.startswith("sudo python3") for c in calls)


def test_the_simulate_example_uses_files_that_exist(monkeypatch, capsys) -> None:
    command = next(line for line in _block_after("To see exactly what a client").splitlines()
                   if line.startswith("nfwserver simulate"))
    argv = shlex.split(command)[1:]
    files = [argv[i + 1] for i, word in enumerate(argv) if word in ("--elements", "--horizon", "--config")]
    assert files and all((ROOT / f).is_file() for f in files)
    monkeypatch.chdir(ROOT)
    assert main(argv) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split("\t")[1].startswith("ISS AZ:")
    assert lines[-1].split("\t")[1].startswith("SO-50 AZ:")


def test_the_tcp_and_easycomm_examples_are_valid_configuration() -> None:
    from nfwserver.config.loader import parse_config
    from nfwserver.tcp.greeting import GREETING

    section = README[README.index("## Reaching the station from outside"):README.index("## Command line")]
    config = parse_config("".join(re.findall(r"```toml\n(.*?)```", section, re.S)))
    assert config.tcp.enabled and config.tcp.port == 8090 and config.tcp.host == "127.0.0.1"
    assert config.server.satellite == 25544 and config.server.tune and config.server.track
    assert config.easycomm.enabled and config.easycomm.rate_hz == 2 and config.easycomm.uplink == "range-rate"
    assert f"$ nc 127.0.0.1 8090\n{GREETING}\n" in section


def _journey() -> list[str]:
    """The commands of the README's journey block, comments removed, in order."""
    return [line.split("  #", 1)[0].strip() for line in _block_after("## Your station, from install").splitlines()
            if line.strip()]


def test_the_journey_is_on_the_first_screen_after_the_two_newcomer_commands() -> None:
    first_screen = "\n".join(README.splitlines()[:45])
    assert "pip install . && nfwserver run" in first_screen and "nfwserver elements update" in first_screen
    assert first_screen.index("pip install . && nfwserver run") < first_screen.index("## Your station")
    assert "nfwserver watch" in first_screen
    assert [c.split()[:3] for c in _journey()] == [
        ["pip", "install", "."], ["nfwserver", "config", "init"], ["nfwserver", "elements", "update"],
        ["nfwserver", "passes"], ["nfwserver", "config", "set"], ["nfwserver", "run"], ["nfwserver", "watch"],
        ["nfwserver", "config", "set"], ["nfwserver", "schedule"], ["nfwserver", "poke", '"AUTO']]


def test_the_journey_runs_as_written(provider, tmp_path, capsys) -> None:  # noqa: F811 - the imported fixture
    """Each command of the journey, in order, on a fresh user (private configuration and data directories), with
    the element presets pointed at a local HTTP server and the TCP port at a free one."""
    from nfwserver.config.loader import load_config
    from tests.hamlib_daemons import free_port

    base, state = provider
    commands = _journey()
    assert commands[0] == "pip install ."  # the package under test is installed already
    station = None
    try:
        for command in commands[1:]:
            argv = shlex.split(command)[1:]
            if argv[:2] == ["elements", "update"]:  # offline here: the presets' host is the local server
                assert main(["config", "set", "elements.preset_mirror", base]) == 0
            if argv[0] == "run":
                station = _start_station(argv)
                continue
            if argv[0] == "watch":
                argv += ["--count", "2", "--interval", "0.1"]  # a script's way to stop it
            capsys.readouterr()
            assert main(argv) == 0, (command, capsys.readouterr().err)
            out = capsys.readouterr().out
            if argv[:2] == ["config", "init"]:
                config = load_config()
                assert config.observer_configured and config.path is not None
                assert 'location = "JO01ab"' in Path(config.path).read_text()
            if argv[:2] == ["elements", "update"]:
                assert state.requests == ["/gp.php?GROUP=amateur&FORMAT=tle"]
            if argv[0] == "passes":
                assert out.startswith("sat ") and "aos (UTC)" in out.splitlines()[0] and len(out.splitlines()) > 3, out
            if argv[:3] == ["config", "set", "tcp.enabled"]:
                assert main(["config", "set", "tcp.port", str(free_port())]) == 0  # 8090 may be taken here
            if argv[0] == "schedule":
                header, *rows = out.splitlines()
                assert header.split()[0] == "sat" and header.split()[-2:] == ["scheduled", "reason"], out
                assert len(rows) > 3 and {row.split()[1] for row in rows} == {"ISS", "AO-7"}, out
            if argv[0] == "poke":  # the running station works the list by itself from now on
                assert out.strip() == "OK", out
                wait_for(lambda: _planned(capsys), 20.0, "the station to plan the list (it reads the file within 3 s)")
            if argv[0] == "watch":
                lines = out.splitlines()
                assert len(lines) == 2 and all("tune=" in line and "status=0x" in line for line in lines), out
    finally:
        if station is not None:
            station.send_signal(signal.SIGTERM)
            assert station.wait(15) == 0
    assert station is not None


def _planned(capsys: pytest.CaptureFixture[str]) -> bool:
    """Autotrack is on, its list has no problem and it names the next pass it will work (STATUS)."""
    capsys.readouterr()
    assert main(["status"]) == 0
    fields = f" {capsys.readouterr().out.strip()} "
    assert " auto=on " in fields, fields
    return "auto_problems" not in fields and " auto_next=none " not in fields and " auto_next=" in fields


def _start_station(argv: list[str]) -> subprocess.Popen[bytes]:
    """``nfwserver run`` as a process of its own (headless: its stdout is not a terminal), answering on TCP."""
    import sys

    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen([sys.executable, "-m", "nfwserver", *argv], cwd=ROOT, env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    def answers() -> bool:
        assert proc.poll() is None, proc.stderr.read() if proc.stderr else ""  # an exited station fails at once
        return main(["status", "--timeout", "1"]) == 0

    wait_for(answers, 30.0, "nfwserver status to reach the station", interval_s=0.2)
    return proc

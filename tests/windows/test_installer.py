"""nfwserver's Windows installer, built by tools/windows/build, installed, used, upgraded and removed in a
fresh Wine prefix with no Python in it (run by ``tools/windows/test``; docs/WINDOWS.md).

The tests are steps of one story and run in this file's order on one prefix: the build is reproducible; a
silent per-user install registers for Apps & features and makes its Start-menu entries; the installed
``nfwserver.exe`` serves a native DDEML client (C, mingw-w64) on both service names and stops cleanly on
``nfwserver stop``; an upgrade over a running station started at logon stops it, keeps the user's files and
starts it again; the registered quiet uninstall removes the program and keeps the user's files.
"""

from __future__ import annotations

import json
import os
import re
import struct
import subprocess
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path, PureWindowsPath

import pytest

from nfwserver import __version__
from nfwserver.release import windows_version
from tests.conftest import ROOT
from tests.waiting import wait_for
from tests.windows.conftest import NOVA
from tests.windows.wine_prefix import WinePrefix

SETUP = os.environ.get("NFW_INSTALLER")
REBUILT = os.environ.get("NFW_INSTALLER_REBUILT")
pytestmark = [pytest.mark.skipif(not SETUP, reason="run by tools/windows/test (builds the installer, needs Wine)"),
              pytest.mark.timeout(900)]

UNINSTALL_KEY = r"HKCU\Software\Microsoft\Windows\CurrentVersion\Uninstall\nfwserver"
RUN_KEY = r"HKCU\Software\Microsoft\Windows\CurrentVersion\Run"
#: The Start-menu entries and the command line each must run.
MENU = {"nfwserver station.lnk": ("nfwserver.exe", "run"), "nfwserver dashboard.lnk": ("nfwserverw.exe", "dashboard"),
        "nfwserver configuration.lnk": ("nfwserverw.exe", "config edit"),
        "Stop the station.lnk": ("nfwserverw.exe", "stop")}


#: Where an upgrade moves what it finds at the program folder's top and does not know (docs/WINDOWS.md).
KEPT = "Left in the program folder"


def manifest() -> dict[str, int]:
    """The build's list of what the installer puts in the program's folder: relative path -> size in bytes."""
    assert SETUP is not None
    lines = Path(SETUP).with_name(f"nfwserver-{__version__}-files.txt").read_text(encoding="utf-8").splitlines()
    files = {}
    for line in lines[1:]:
        size, name = line.split("\t", 1)
        files[name] = int(size)
    assert lines[0].startswith(f"# {len(files)} files, {sum(files.values())} bytes")
    return files


def program_files(folder: Path) -> dict[str, int]:
    """What is in the installed program's folder: relative path -> size in bytes."""
    return {p.relative_to(folder).as_posix(): p.stat().st_size for p in folder.rglob("*") if p.is_file()}


def version_resource(exe: Path) -> tuple[str, str, str]:
    """(FILEVERSION as four numbers, the FileVersion string, the ProductVersion string) of a PE file's version
    resource, read as Microsoft's VS_FIXEDFILEINFO and StringFileInfo layouts define them."""
    data = exe.read_bytes()
    fixed_at = data.find(struct.pack("<I", 0xFEEF04BD))  # VS_FIXEDFILEINFO.dwSignature
    assert fixed_at > 0, f"{exe.name} has no version resource"
    ms, ls = struct.unpack_from("<II", data, fixed_at + 8)  # dwFileVersionMS, dwFileVersionLS

    def string(key: str) -> str:
        name = (key + "\0").encode("utf-16-le")
        at = data.find(name)
        assert at > 0, key
        at += len(name)
        at += (-at) % 4  # the value starts on a 32-bit boundary
        end = at
        while data[end:end + 2] != b"\0\0":
            end += 2
        return data[at:end].decode("utf-16-le")

    return f"{ms >> 16}.{ms & 0xFFFF}.{ls >> 16}.{ls & 0xFFFF}", string("FileVersion"), string("ProductVersion")


def winpath(path: Path) -> str:
    """A Linux path as Wine's Z: drive names it."""
    return "Z:" + str(path.resolve()).replace("/", "\\")


class Installed:
    """What the tests share: the prefix, the program's folder and the user's folder, the probes."""

    def __init__(self, prefix: WinePrefix, tools: Path) -> None:
        self.prefix = prefix
        self.folder = prefix.local_appdata / "Programs" / "nfwserver"
        self.exe = str(self.folder / "nfwserver.exe")
        self.exe_w = str(self.folder / "nfwserverw.exe")
        self.user_files = prefix.unix(prefix.local_appdata / "nfwserver")
        self.menu = prefix.unix(prefix.appdata / "Microsoft" / "Windows" / "Start Menu" / "Programs" / "nfwserver")
        self.tools = tools

    def nfwserver(self, *args: str, timeout_s: float = 180.0) -> subprocess.CompletedProcess[str]:
        return self.prefix.run([self.exe, *args], timeout_s)

    def setup(self, *args: str) -> int:
        """The installer, silently (``/S``); its exit status."""
        assert SETUP is not None
        return self.prefix.run_detached([winpath(Path(SETUP)), "/S", *args])

    def running_pid(self) -> int | None:
        """The pid the user's running station describes itself with (station.json), or None."""
        info = self.user_files / "station.json"
        try:
            return int(re.search(r'"pid": (\d+)', info.read_text()).group(1))  # type: ignore[union-attr]
        except (OSError, AttributeError):
            return None


def _compile(source: str, out: Path, *libs: str) -> None:
    unicode = ["-municode"] if "lnk" in source else []
    subprocess.run(["x86_64-w64-mingw32-gcc", "-O2", "-Wall", *unicode, "-o", str(out),
                    str(ROOT / "tests" / "windows" / source), *libs], check=True, timeout=120)


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> Iterator[Installed]:
    tools = tmp_path_factory.mktemp("probes")
    _compile("ddeml_probe.c", tools / "ddeml_probe.exe", "-luser32")
    _compile("lnk_probe.c", tools / "lnk_probe.exe", "-lole32", "-luuid", "-lshell32")
    prefix = WinePrefix(tmp_path_factory.mktemp("wine") / "prefix")
    try:
        assert not list((prefix.root / "drive_c").rglob("python*.exe")), "the fresh prefix has a Python"
        yield Installed(prefix, tools)
    finally:
        prefix.close()


def test_two_builds_of_one_commit_are_the_same_bytes_and_the_setup_is_small() -> None:
    """The second build is of a clone of the commit in a folder named with spaces and non-ASCII letters
    (tools/windows/test): a build works from any path, and its bytes do not depend on it."""
    assert SETUP is not None and REBUILT is not None
    first, second = Path(SETUP), Path(REBUILT)
    assert "+" not in __version__  # derived from git, not the fallback of a checkout whose history is unknown
    assert first.name == second.name == f"nfwserver-{__version__}-setup.exe"
    assert first.read_bytes() == second.read_bytes()
    assert first.stat().st_size <= 40 * 1024 * 1024


def test_no_test_code_ships_and_the_documented_size_is_the_builds() -> None:
    files = manifest()
    assert not [name for name in files if name.rsplit("/", 1)[-1] == "conftest.py" or "/tests/" in f"/{name}"
                or name.startswith("Lib/site-packages/numpy/testing/")]
    assert "Lib/site-packages/nfwserver/_version.py" in files
    text = " ".join((ROOT / "docs" / "WINDOWS.md").read_text(encoding="utf-8").split())
    found = re.search(r"installed, the program takes about ([\d.]+) MB \(([\d,]+) files\)", text)
    assert found, "docs/WINDOWS.md gives no installed size and file count"
    documented_mb, documented_files = float(found.group(1)), int(found.group(2).replace(",", ""))
    built_mb = sum(files.values()) / 1e6
    assert abs(documented_files - len(files)) <= 0.02 * len(files), (len(files), "files; correct docs/WINDOWS.md")
    assert abs(documented_mb - built_mb) <= 0.02 * built_mb, (f"{built_mb:.1f} MB; correct docs/WINDOWS.md")


def test_a_silent_install_registers_for_apps_and_features(installed: Installed) -> None:
    assert installed.setup() == 0
    values = installed.prefix.reg_values(UNINSTALL_KEY)
    assert values is not None
    folder = str(installed.folder)
    assert values["DisplayName"] == f"nfwserver {__version__}" and values["DisplayVersion"] == __version__
    assert values["Publisher"] and values["InstallLocation"] == folder
    assert values["DisplayIcon"] == f'"{folder}\\nfwserver.exe",0'
    assert values["UninstallString"] == f'"{folder}\\uninstall.exe"'
    assert values["QuietUninstallString"] == f'"{folder}\\uninstall.exe" /S'
    installed_kib = sum(p.stat().st_size for p in installed.prefix.unix(installed.folder).rglob("*")
                        if p.is_file()) / 1024
    assert 0.9 * installed_kib <= int(values["EstimatedSize"], 16) <= 1.1 * installed_kib
    version = installed.nfwserver("--version")
    assert version.returncode == 0 and version.stdout.strip() == f"nfwserver {__version__}"
    program = installed.prefix.unix(installed.folder)
    assert (program / "nfwserver.exe").is_file() and not (program / "python.exe").exists()
    for exe in ("nfwserver.exe", "nfwserverw.exe"):
        assert version_resource(program / exe) == (windows_version(__version__), __version__, __version__), exe
    assert installed.prefix.reg_values(RUN_KEY) is None or "nfwserver" not in installed.prefix.reg_values(RUN_KEY)


def test_the_start_menu_entries_run_files_that_exist(installed: Installed) -> None:
    links = sorted(p.name for p in installed.menu.glob("*.lnk"))
    assert links == sorted(MENU)
    probe = installed.prefix.run([winpath(installed.tools / "lnk_probe.exe"), *(winpath(installed.menu / name)
                                                                               for name in links)])
    assert probe.returncode == 0, probe.stderr
    for name, line in zip(links, probe.stdout.splitlines()):
        target, args, folder = line.split("|")
        program, expected_args = MENU[name]
        assert PureWindowsPath(target) == installed.folder / program and args == expected_args, name
        assert PureWindowsPath(folder) == installed.prefix.profile, name  # relative paths are the user's
        assert installed.prefix.unix(target).is_file(), target


def test_the_installed_configuration_serves_the_dashboard_on_loopback(installed: Installed) -> None:
    config = installed.user_files / "config.toml"
    assert config.is_file()
    shown = installed.nfwserver("config", "show")
    assert shown.returncode == 0, shown.stderr
    web = shown.stdout.split("[web]", 1)[1].split("\n[", 1)[0]
    assert re.search(r"^enabled = true\b", web, re.M) and re.search(r'^host = "127\.0\.0\.1"', web, re.M)


def test_an_environment_fact_is_shown_under_v_only(installed: Installed) -> None:
    """Under Wine sgp4's compiled TLE reader is wrong and the program works around it: a fact the operator cannot
    act on, so a command says it only with -v (it began every command's output as a warning)."""
    quiet = installed.nfwserver("passes", "--hours", "1")
    assert quiet.returncode == 0, quiet.stderr
    assert "sgp4" not in quiet.stderr
    verbose = installed.nfwserver("-v", "passes", "--hours", "1")
    assert verbose.returncode == 0, verbose.stderr
    notes = [line for line in verbose.stderr.splitlines() if "sgp4" in line]
    assert len(notes) == 1 and notes[0].startswith("nfwserver: info: "), notes


def test_the_installed_program_serves_ddeml_clients_and_stops_on_request(installed: Installed) -> None:
    station = installed.prefix.start([installed.exe, "run", "--headless"])
    try:
        probe = installed.prefix.run([winpath(installed.tools / "ddeml_probe.exe"), "120", "3", "NFW32",
                                      "NFW_SERVER"], 300)
        assert probe.returncode == 0, probe.stderr
        lines = probe.stdout.splitlines()
        for service in ("NFW32", "NFW_SERVER"):
            got = [line.split(": ", 1)[1] for line in lines if line.split(": ", 1)[0].endswith(f" {service}")]
            assert len(got) == 4 and all(NOVA.match(text) for text in got), (service, got)  # 1 request, 3 advises
        dash = installed.nfwserver("dashboard", "--print")
        assert dash.returncode == 0, dash.stderr
        with urllib.request.urlopen(dash.stdout.strip(), timeout=20) as page:
            assert page.status == 200 and b"<html" in page.read(4096).lower()
        pid = installed.running_pid()
        stop = installed.nfwserver("stop")
        assert stop.returncode == 0, stop.stderr
        assert stop.stdout.strip() == f"stopped the station (process {pid})"
        assert station.wait(60) == 0  # a clean stop, not a kill
        log = (installed.user_files / "Logs" / "nfwserver.log").read_text(encoding="utf-8", errors="replace")
        # `stop` set the station's stop event (no file written: nfwserver/cli/stop_event.py)
        assert f"nfwserver stop (event Local\\nfwserver-stop-{pid}-" in log and log.rstrip().endswith("stopped")
        assert log.count("compiled TLE reader is wrong here") == 1  # the first run's log says it, once
        again = installed.nfwserver("stop")
        assert again.returncode == 1 and again.stdout == ""
        assert again.stderr.strip().endswith("no station is running for this user: nothing to stop")
    finally:
        if station.poll() is None:
            station.kill()
            station.wait(30)


def test_the_program_folder_holds_exactly_what_the_installer_put_there(installed: Installed) -> None:
    """After the install's own `config init`, a station's run, `dashboard` and `stop`: nothing was written into
    the program's folder (Python's byte-code cache is in the user's folder instead)."""
    program = installed.prefix.unix(installed.folder)
    expected = manifest()
    expected["uninstall.exe"] = program_files(program).get("uninstall.exe", -1)
    assert program_files(program) == expected
    assert list((installed.user_files / "Cache" / "pycache").rglob("*.pyc"))


def test_an_upgrade_keeps_the_users_files_and_restarts_a_station_started_at_logon(installed: Installed) -> None:
    assert installed.nfwserver("config", "set", "observer.location", "JO01ab").returncode == 0
    config = installed.user_files / "config.toml"
    before = config.read_text()
    assert 'location = "JO01ab"' in before
    state = installed.user_files / "state.json"
    assert json.loads(state.read_text())["satellite"] == 25544, "the earlier run saved no state"
    logon = installed.prefix.start([installed.exe_w, "run", "--headless"])  # as the Run key starts it
    try:
        wait_for(lambda: installed.running_pid() is not None, 120, "the windowless station started", interval_s=0.2)
        site = installed.prefix.unix(installed.folder / "Lib" / "site-packages")
        planted = [site / "nfwserver" / "removed_in_this_version.py", site / "nfwserver" / "__pycache__" / "old.pyc"]
        for path in planted:  # what an older version had and this one has not
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text("# old\n")
        program = installed.prefix.unix(installed.folder)
        foreign = {"notes.txt": program / "notes.txt", "My rotor/setup.ini": program / "My rotor" / "setup.ini"}
        for path in foreign.values():  # a user's files at the program folder's top
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text("mine\n")
        upgrade_started_ns = time.time_ns()
        assert installed.setup("/LOGON") == 0
        assert logon.wait(60) == 0  # the old station was stopped cleanly by the upgrade
    finally:
        if logon.poll() is None:
            logon.kill()
            logon.wait(30)
    run_value = (installed.prefix.reg_values(RUN_KEY) or {}).get("nfwserver")
    assert run_value == f'"{installed.folder}\\nfwserverw.exe" run --headless'
    description = installed.user_files / "station.json"  # removed by the old station, written by the new one
    wait_for(lambda: installed.running_pid() is not None and description.stat().st_mtime_ns > upgrade_started_ns,
             120, "the upgraded station started again", interval_s=0.2, tolerate=(OSError,))
    assert config.read_text() == before
    assert not any(path.exists() for path in planted)  # nothing of the older program stays importable
    expected = manifest()
    expected["uninstall.exe"] = program_files(program).get("uninstall.exe", -1)
    assert program_files(program) == expected  # exactly the new program
    for name in foreign:  # the user's files, kept where docs/WINDOWS.md says
        assert (installed.user_files / KEPT / name).read_text() == "mine\n", name
    assert json.loads(state.read_text())["satellite"] == 25544
    assert (installed.user_files / "Logs" / "nfwserver.log").is_file()
    stop = installed.nfwserver("stop")
    assert stop.returncode == 0, stop.stderr
    # Installed again without /LOGON: start at logon stays as the user chose; /LOGON=0 switches it off.
    assert installed.setup() == 0
    assert "nfwserver" in (installed.prefix.reg_values(RUN_KEY) or {})
    assert installed.setup("/LOGON=0") == 0
    assert "nfwserver" not in (installed.prefix.reg_values(RUN_KEY) or {})
    assert config.read_text() == before


def test_the_quiet_uninstall_removes_the_program_and_keeps_the_users_files(installed: Installed) -> None:
    assert installed.setup("/LOGON") == 0  # a Run entry to remove, and a station started, as at logon
    wait_for(lambda: installed.running_pid() is not None, 120, "the station started at the end of the install",
             interval_s=0.2)
    values = installed.prefix.reg_values(UNINSTALL_KEY)
    assert values is not None
    command = values["QuietUninstallString"]
    program, switch = command.rsplit(" ", 1)
    assert installed.prefix.run_detached([program.strip('"'), switch]) == 0
    folder = installed.prefix.unix(installed.folder)
    # The uninstaller runs on from a copy of itself in %TEMP%: wait for its work to be done.  The station was
    # stopped first (cleanly: its log ends so), or its files in use would have stayed.
    wait_for(lambda: not folder.exists(), 120, f"{folder} removed", interval_s=0.2)
    log = (installed.user_files / "Logs" / "nfwserver.log").read_text(encoding="utf-8", errors="replace")
    assert installed.running_pid() is None and log.rstrip().splitlines()[-1].endswith(" stopped")
    wait_for(lambda: installed.prefix.reg_values(UNINSTALL_KEY) is None, 60, "the uninstall key removed",
             interval_s=1.0)
    assert not installed.menu.exists()
    assert "nfwserver" not in (installed.prefix.reg_values(RUN_KEY) or {})
    assert 'location = "JO01ab"' in (installed.user_files / "config.toml").read_text()
    assert (installed.user_files / "state.json").is_file()
    assert (installed.user_files / "Logs" / "nfwserver.log").is_file()


def test_another_folder_chosen_with_d_is_installed_to_and_removed_from(installed: Installed) -> None:
    folder = PureWindowsPath(r"C:\Radio\nfw server")
    # NSIS takes /D= last and unquoted, spaces and all, as typed in cmd; Wine would quote an argument with a
    # space, so the command line goes through cmd as one string.
    assert SETUP is not None
    assert installed.prefix.run_detached(["cmd", "/c", f"{winpath(Path(SETUP))} /S /D={folder}"]) == 0
    values = installed.prefix.reg_values(UNINSTALL_KEY)
    assert values is not None and values["InstallLocation"] == str(folder)
    version = installed.prefix.run([str(folder / "nfwserver.exe"), "--version"])
    assert version.returncode == 0 and version.stdout.strip() == f"nfwserver {__version__}"
    assert not installed.prefix.unix(installed.folder).exists()
    program, switch = values["QuietUninstallString"].rsplit(" ", 1)
    assert installed.prefix.run_detached([program.strip('"'), switch]) == 0
    wait_for(lambda: not installed.prefix.unix(folder).exists(), 120, f"{folder} removed", interval_s=0.2)
    assert installed.prefix.unix(folder.parent).is_dir()  # only the program's own folder goes


def test_a_folder_holding_other_files_is_refused(installed: Installed) -> None:
    other = installed.prefix.unix(PureWindowsPath(r"C:\Radio\Logbook"))
    (other / "Lib").mkdir(parents=True)
    (other / "Lib" / "mine.txt").write_text("not nfwserver's\n")
    assert SETUP is not None
    status = installed.prefix.run_detached(["cmd", "/c", rf"{winpath(Path(SETUP))} /S /D=C:\Radio\Logbook"])
    assert status == 2  # refused: an upgrade or the uninstaller would remove that Lib folder
    assert (other / "Lib" / "mine.txt").read_text() == "not nfwserver's\n"
    assert sorted(p.name for p in other.iterdir()) == ["Lib"]
    assert installed.prefix.reg_values(UNINSTALL_KEY) is None

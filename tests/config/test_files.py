"""User-named files are read only when regular and at most 1 MiB: a FIFO or a device never blocks (issue 18 #12)."""

from __future__ import annotations

import os
import threading
from collections.abc import Callable

import pytest

from nfwserver.config.files import MAX_FILE_BYTES, FileRefused, read_regular_file
from nfwserver.config.loader import ConfigError, load_config, parse_config

pytestmark = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")


def finishes(call: Callable[[], object], timeout_s: float = 10.0) -> object:
    """Run ``call`` on a thread; fail (instead of hanging the suite) if it blocks."""
    result: list[object] = []

    def run() -> None:
        try:
            result.append(call())
        except BaseException as exc:  # noqa: BLE001 - handed back to the test
            result.append(exc)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(timeout_s)
    assert not thread.is_alive(), "blocked reading a file"
    return result[0]


def test_a_regular_file_is_read(tmp_path) -> None:
    path = tmp_path / "a.txt"
    path.write_text("30 5\n")
    assert read_regular_file(path) == "30 5\n"
    path.write_bytes(b"x" * 100)
    assert read_regular_file(path, limit=100) == "x" * 100
    with pytest.raises(FileRefused, match="is larger than 99 bytes"):
        read_regular_file(path, limit=99)


def test_a_fifo_is_refused_without_waiting_for_a_writer(tmp_path) -> None:
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    outcome = finishes(lambda: read_regular_file(fifo))
    assert isinstance(outcome, FileRefused) and str(outcome) == f"{fifo} is not a regular file"


def test_a_device_is_refused() -> None:
    outcome = finishes(lambda: read_regular_file("/dev/zero"))
    assert isinstance(outcome, FileRefused) and "is not a regular file" in str(outcome)


def test_a_fifo_as_the_configuration_is_refused(tmp_path) -> None:
    fifo = tmp_path / "config.toml"
    os.mkfifo(fifo)
    outcome = finishes(lambda: load_config(fifo))
    assert isinstance(outcome, ConfigError)
    assert outcome.problems == [f"cannot read the file: {fifo} is not a regular file"]


def test_a_fifo_as_the_horizon_file_is_refused(tmp_path) -> None:
    os.mkfifo(tmp_path / "horizon.txt")
    config = tmp_path / "config.toml"
    config.write_text('[horizon]\nfile = "horizon.txt"\n')
    outcome = finishes(lambda: load_config(config))
    assert isinstance(outcome, ConfigError)
    assert outcome.problems == [f"[horizon] file: {tmp_path / 'horizon.txt'} is not a regular file"]


def test_a_fifo_or_directory_as_an_element_file_is_refused(tmp_path) -> None:
    os.mkfifo(tmp_path / "keps.txt")
    (tmp_path / "dir").mkdir()
    with pytest.raises(ConfigError) as info:
        parse_config('[elements]\nfiles = ["keps.txt"]\n', base_dir=tmp_path)
    assert info.value.problems == [f"[elements] files: {tmp_path / 'keps.txt'} is not a regular file"]
    with pytest.raises(ConfigError, match="is not a regular file"):
        parse_config('[elements]\nfiles = ["dir"]\n', base_dir=tmp_path)


def test_oversized_configuration_and_horizon_files_are_refused(tmp_path) -> None:
    big = tmp_path / "config.toml"
    big.write_text("# padding\n" * (MAX_FILE_BYTES // 10 + 1))
    with pytest.raises(ConfigError) as info:
        load_config(big)
    assert info.value.problems == [f"cannot read the file: {big} is larger than 1 MiB"]
    (tmp_path / "h.txt").write_text("0 5\n" * (MAX_FILE_BYTES // 4 + 1))
    with pytest.raises(ConfigError) as info:
        parse_config('[horizon]\nfile = "h.txt"\n', base_dir=tmp_path)
    assert info.value.problems == [f"[horizon] file: {tmp_path / 'h.txt'} is larger than 1 MiB"]


def test_a_configuration_that_is_not_utf8_is_one_sentence(tmp_path) -> None:
    path = tmp_path / "config.toml"
    path.write_bytes(b"[server]\ntopic = \"\xff\xfe\"\n")
    with pytest.raises(ConfigError) as info:
        load_config(path)
    assert info.value.problems == ["cannot read the file: it is not UTF-8 text"]

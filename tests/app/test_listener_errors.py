"""A listener that cannot bind is one sentence naming its port and the setting to change (#25 item 9)."""

from __future__ import annotations

import socket

import pytest

from nfwserver.cli import main


def _run_with(tmp_path, capsys, section: str) -> tuple[int, list[str]]:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as squatter:
        squatter.bind(("127.0.0.1", 0))
        squatter.listen(1)
        port = squatter.getsockname()[1]
        cfg = tmp_path / "c.toml"
        cfg.write_text(f'[observer]\nlocation = "JO02ae"\n[{section}]\nenabled = true\nport = {port}\n')
        assert main(["run", "--headless", "--duration", "0.2", "--config", str(cfg),
                     "--log-file", str(tmp_path / "log.txt")]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err and "Errno" not in err, err
    return port, [line for line in err.splitlines() if not line.startswith("nfwserver: logging to ")]


@pytest.mark.parametrize("section", ["tcp", "web"])
def test_a_busy_port_names_the_port_and_its_setting(tmp_path, capsys, section) -> None:
    port, lines = _run_with(tmp_path, capsys, section)
    assert lines == [f"nfwserver: cannot start the station: [{section}] port {port} is in use "
                     f"(another nfwserver? set [{section}] port)"]

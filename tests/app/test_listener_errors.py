"""A listener that cannot bind is one sentence naming its port and the setting to change (#25 item 9), in the
words issue 42 item 13 asks for on every system; the listeners bind through one module
(:mod:`nfwserver.listen_socket`), whose options are checked here on a real busy port."""

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
    assert lines == [f"nfwserver: cannot start the station: port {port} is already in use (by another program or "
                     f"another station); set [{section}] port to another port"]


def test_a_port_held_by_another_program_with_reuseaddr_is_still_busy_for_every_listener(tmp_path) -> None:
    """SO_REUSEADDR on POSIX only covers TIME_WAIT: another program's listener on the port (with the option too)
    still keeps ours out, for the TCP and web listeners alike, and a second station cannot take our port."""
    from nfwserver.listen_errors import bind_failure
    from nfwserver.listen_socket import datagram_socket, stream_listener

    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as squatter:
        squatter.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        squatter.bind(("127.0.0.1", 0))
        squatter.listen(1)
        port = squatter.getsockname()[1]
        with pytest.raises(OSError) as caught:
            stream_listener("127.0.0.1", port)
    assert bind_failure(caught.value, "tcp", "127.0.0.1", port).strerror == (
        f"port {port} is already in use (by another program or another station); set [tcp] port to another port")
    ours = stream_listener("127.0.0.1", 0)
    try:
        assert ours.getsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR) == 1  # POSIX: a restart within TIME_WAIT
        with pytest.raises(OSError):
            stream_listener("127.0.0.1", ours.getsockname()[1])  # a second station
    finally:
        ours.close()
    udp = datagram_socket("127.0.0.1", 0)
    try:
        assert udp.getsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR) == 0  # on Linux it would share the port
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as other:
            other.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            with pytest.raises(OSError):
                other.bind(udp.getsockname())
    finally:
        udp.close()


def test_the_web_listener_claims_its_port_through_the_shared_module(monkeypatch) -> None:
    """The web dashboard's socket gets its options from nfwserver.listen_socket.claim_port (not socketserver's
    allow_reuse_address, which would set SO_REUSEADDR on Windows too)."""
    from nfwserver.config.schema import WebConfig
    from nfwserver.web.server import WebServer
    from tests.dde.conftest import make_station

    claimed: list[int] = []
    import nfwserver.listen_socket as shared
    import nfwserver.web.server as web_server

    real = shared.claim_port
    monkeypatch.setattr(web_server, "claim_port", lambda sock: claimed.append(sock.fileno()) or real(sock))
    station = make_station()
    web = WebServer(station.core, WebConfig(enabled=True, host="127.0.0.1", port=0))
    web.start()
    try:
        assert len(claimed) == 1
        assert web._httpd is not None and not web._httpd.allow_reuse_address
    finally:
        web.stop()

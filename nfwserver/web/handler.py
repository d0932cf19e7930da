"""HTTP routes of the web dashboard (one :class:`WebHandler` per connection, on its own thread).

======================  ===========================================================================
``GET /``               the page (``static/index.html``)
``GET /static/<name>``  the page's script, style sheet and map data, from the package (no CDN)
``GET /api/state``      the newest frame as JSON, with the last log lines (``docs/WEB.md``)
``GET /api/passes``     passes, the pass track, the ground track and the horizon (``docs/WEB.md``)
``GET /api/help``       the commands the page may send, from the command table
``GET /api/stream``     Server-Sent Events: ``history`` once, then ``state`` with every frame
``POST /api/command``   ``{"command": "TRACK ON", "token": "..."}`` (:mod:`~nfwserver.web.control`)
======================  ===========================================================================

Every response carries a Content-Security-Policy allowing only the station's own scripts and styles,
so nothing from a satellite or client name can run as script even if it reached the HTML (the page
only ever sets ``textContent``).  The request head is read whole within a deadline and a size cap
(:mod:`~nfwserver.web.request_head`), a request for another host name is refused (421) and a command
must come as JSON from the station's own page (:mod:`~nfwserver.web.guard`); request bodies are
limited to :data:`MAX_BODY_BYTES` and read only once control is known to be on.  Nothing a peer does
makes a traceback: a failed connection is one log line (rate-limited) by :meth:`WebServer.connection_failed`.
"""

from __future__ import annotations

import io
import json
import logging
import re
import socket
import time
from http.server import BaseHTTPRequestHandler
from importlib import resources
from typing import Any

from nfwserver.release import package_version
from nfwserver.web.admission import Phase
from nfwserver.web.control import help_entries
from nfwserver.web.guard import cross_site_reason, foreign_site_reason, host_refusal
from nfwserver.web.request_head import SECURITY_HEADERS, HeadReader, error_response, linger_close, read_head

log = logging.getLogger(__name__)

MAX_BODY_BYTES = 4096
KEEPALIVE_S = 15.0  #: an idle event stream gets a comment line this often (real seconds)
_STATIC_NAME = re.compile(r"[a-z0-9][a-z0-9_.-]{0,63}")
_TYPES = {".html": "text/html; charset=utf-8", ".js": "text/javascript; charset=utf-8",
          ".css": "text/css; charset=utf-8", ".json": "application/json", ".svg": "image/svg+xml",
          ".png": "image/png"}


def static_file(name: str) -> bytes | None:
    """A file of the package's ``static`` folder, or None (names outside the pattern are never looked up)."""
    if not _STATIC_NAME.fullmatch(name) or ".." in name:
        return None
    try:
        return resources.files("nfwserver.web").joinpath("static").joinpath(name).read_bytes()
    except (FileNotFoundError, IsADirectoryError, NotADirectoryError, OSError):
        return None


class WebHandler(BaseHTTPRequestHandler):
    server_version = "nfwserver"
    protocol_version = "HTTP/1.0"  # one request per connection: the event stream ends with the connection

    def setup(self) -> None:
        web = self.server.web  # type: ignore[attr-defined]  # our _HttpServer, typed as socketserver's BaseServer
        self.timeout = web.io_timeout_s  # type: ignore[misc]  # socketserver reads it per instance
        super().setup()
        if web.send_buffer_bytes:
            self.connection.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, web.send_buffer_bytes)

    def handle(self) -> None:
        """One request (HTTP/1.0); whatever the peer does to the connection ends it with one log line at most."""
        try:
            self.handle_one_request()
        except Exception as exc:  # noqa: BLE001 - a peer's reset, a write timeout: never a traceback
            self.web.connection_failed(self.client_address[0], exc)

    def handle_one_request(self) -> None:
        web = self.web
        deadline = time.monotonic() + web.head_deadline_s
        head = read_head(self.connection, deadline, io_timeout_s=web.io_timeout_s)
        if head.silent:
            self.close_connection = True
            return
        if head.status:
            self.close_connection = True
            self.requestline, self.command = head.data.split(b"\n", 1)[0].decode("latin-1").strip()[:200], ""
            web.request_refused(self.client_address[0], head.status, head.message)
            self.connection.settimeout(web.io_timeout_s)
            self.connection.sendall(error_response(head.status, head.message))
            linger_close(self.connection)
            return
        self.rfile = io.BufferedReader(HeadReader(head.data, self.connection, deadline, web.io_timeout_s))
        self.connection.settimeout(web.io_timeout_s)
        super().handle_one_request()

    def parse_request(self) -> bool:
        if not super().parse_request():
            return False
        why = host_refusal(self.headers.get("Host"), self.web.config, str(self.connection.getsockname()[0]))
        if why is not None:
            self.web.request_refused(self.client_address[0], 421, why)
            self.close_connection = True
            self._json(421, {"ok": False, "error": why})
            return False
        if self.command != "POST":  # a POST's body is still to come
            self.web.admission.mark(self.connection, Phase.BUSY)
        return True

    def send_error(self, code: int, message: str | None = None, explain: str | None = None) -> None:
        """The standard library's refusals (400, 414, 431 too many headers, 501 an unsupported method such
        as ``OPTIONS``) as ours: a small JSON body with the security headers, counted and logged as a
        refusal of this address."""
        self.close_connection = True
        default, _ = self.responses.get(code, ("Error", ""))
        why = message or default
        self.web.request_refused(self.client_address[0], code, why)
        self.wfile.write(error_response(code, why, head_only=getattr(self, "command", None) == "HEAD",
                                        reason=default))

    @property
    def web(self) -> Any:
        return self.server.web  # type: ignore[attr-defined]  # our _HttpServer (see setup)

    @property
    def peer(self) -> str:
        return f"web {self.client_address[0]}"

    def log_message(self, format: str, *args: Any) -> None:  # noqa: A002 - the base class's name
        log.debug("web %s: " + format, self.client_address[0], *args)

    # -- responses -----------------------------------------------------------------------------------
    def _send(self, status: int, body: bytes, content_type: str, cache: bool = False) -> None:
        self.send_response(status)
        self.send_header("Content-Type", content_type)
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Cache-Control", "max-age=300" if cache else "no-store")
        for name, value in SECURITY_HEADERS:
            self.send_header(name, value)
        self.end_headers()
        if self.command != "HEAD":
            self.wfile.write(body)

    def _json(self, status: int, value: object) -> None:
        self._send(status, json.dumps(value).encode(), "application/json")

    def _raw_json(self, body: bytes) -> None:
        self._send(200, body, "application/json")

    # -- routes --------------------------------------------------------------------------------------
    def do_GET(self) -> None:  # noqa: N802 - http.server's naming
        path = self.path.split("?", 1)[0]
        if path in ("/", "/index.html"):
            body = static_file("index.html")
            assert body is not None
            self._send(200, body.replace(b"@NFW_VERSION@", package_version().encode()), _TYPES[".html"])
        elif path.startswith("/static/") or path == "/favicon.ico":
            name = "icon.svg" if path == "/favicon.ico" else path[len("/static/"):]
            body = static_file(name)
            if body is None:
                self._json(404, {"ok": False, "error": "not found"})
            else:
                suffix = name[name.rfind("."):] if "." in name else ""
                self._send(200, body, _TYPES.get(suffix, "application/octet-stream"), cache=suffix == ".json")
        elif path == "/api/state":
            self._raw_json(self.web.state_json())
        elif path == "/api/passes":
            self._raw_json(self.web.board.encoded())
        elif path == "/api/help":
            self._json(200, {"control": self.web.control.enabled, "commands": help_entries()})
        elif path == "/api/stream":
            self._stream()
        else:
            self._json(404, {"ok": False, "error": "not found"})

    def do_HEAD(self) -> None:  # noqa: N802
        if self.path.split("?", 1)[0] == "/api/stream":
            self._stream_headers()  # the headers a stream would start with, and no body
            return
        self.do_GET()

    def do_POST(self) -> None:  # noqa: N802
        if self.path.split("?", 1)[0] != "/api/command":
            self._json(404, {"ok": False, "error": "not found"})
            return
        # a token or control changed in the file a moment ago applies to this request: the same catch-up every
        # face's command gets (StationCore.before_command), here before the token is checked
        self.web.core.before_command()
        control = self.web.control
        why = cross_site_reason(self.headers, self.headers.get("Host", ""))
        early = control.refuse(self.peer, 403, why) if why is not None else control.closed(self.peer)
        if early is not None:  # refused before a byte of the body is read or parsed
            self.close_connection = True
            self._json(early.status, early.as_json())
            return
        try:
            length = int(self.headers.get("Content-Length", "-1"))
        except ValueError:
            length = -1
        if not 0 <= length <= MAX_BODY_BYTES:
            self._json(413 if length > MAX_BODY_BYTES else 411, {"ok": False, "message": "body of 0..4096 bytes"})
            return
        try:
            data = self.rfile.read(length)
            self.web.admission.mark(self.connection, Phase.BUSY)
            request = json.loads(data.decode("utf-8"))
        except (UnicodeDecodeError, ValueError):
            request = None
        except RecursionError:  # "[[[[..." deeper than the interpreter's stack
            reply = control.refuse(self.peer, 400, "the body is nested too deeply to be a command")
            self._json(reply.status, reply.as_json())
            return
        reply = control.run(request, self.peer)
        self._json(reply.status, reply.as_json())

    # -- the event stream ----------------------------------------------------------------------------
    def _stream_headers(self) -> None:
        self.send_response(200)
        self.send_header("Content-Type", "text/event-stream; charset=utf-8")
        self.send_header("Cache-Control", "no-store")
        for name, value in SECURITY_HEADERS:
            self.send_header(name, value)
        self.end_headers()

    def _stream(self) -> None:
        web = self.web
        foreign = foreign_site_reason(self.headers)
        if foreign is not None:
            web.request_refused(self.client_address[0], 403, foreign)
            self._json(403, {"ok": False, "error": foreign})
            return
        refusal = web.stream_opened(self.peer, self.connection)
        if refusal is not None:
            self._json(503, {"ok": False, "error": refusal})
            return
        web.admission.mark(self.connection, Phase.STREAM)
        reason, dropped = "closed by the browser", False
        try:
            self._stream_headers()
            cursor, history = web.page_log()  # the frames are shared; the log lines are this page's own
            self.wfile.write(b"event: history\ndata: " + json.dumps(history, default=str).encode() + b"\n\n")
            seen, frame = web.hub.newest()

            def taken() -> bool:  # its slot was given to a newer connection (web/admission.py)
                return not web.admission.holds(self.connection)

            while not web.stopping and not taken():
                if frame is not None:
                    self.wfile.write(b"event: state\ndata: " + cursor.attach(frame) + b"\n\n")
                else:
                    self.wfile.write(b": keep-alive\n\n")
                seen, frame = web.hub.wait_newer(seen, KEEPALIVE_S, taken)
            reason = "server stopping" if web.stopping else "closed to make room for a newer connection"
        except TimeoutError:
            reason, dropped = f"stopped reading (nothing sent for {web.io_timeout_s:g} s)", True
        except (BrokenPipeError, ConnectionResetError, ConnectionAbortedError):
            pass
        except OSError as exc:
            reason, dropped = f"send failed: {exc}", True
        finally:
            web.stream_closed(self.peer, reason, dropped)
            self.close_connection = True

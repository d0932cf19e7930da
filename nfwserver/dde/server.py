"""The Nova DDE server core: owns the session and answers every DDE transaction, transport-agnostic.

:class:`NovaServer` implements :class:`~nfwserver.dde.transport.DdeServerHandler`.  Attach it to a
transport (the in-process :mod:`nfwserver.fake_dde`, or the Windows DDEML transport) and call
:meth:`NovaServer.tick` at the publish rate (:mod:`nfwserver.dde.publisher` does that on real or
virtual time).  Each tick computes the selected satellite's look angles for the tick's instant,
formats the Nova string once, and, when ``TUNE ON``, posts it to every advise loop on the items.

Names served (DESIGN.md §3): services ``NFW32`` and ``NFW_SERVER``, topic ``NFW_DATA``, items
``NFW_SERVER`` and ``NFW_DATA``; all compared case-insensitively and configurable.

Threading: transport callbacks may arrive on the transport's thread while ticks run on the
publisher's thread.  State changes happen under one lock; the transport is never called while
that lock is held (the transport calls the handler with its own lock held, so the lock order is
always transport -> core).
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterable
from dataclasses import replace
from datetime import datetime

from nfwserver.clock import Clock
from nfwserver.dde.clipboard import TEXT_FORMATS, decode_text, encode_text, format_name
from nfwserver.dde.events import Direction, EventLog
from nfwserver.dde.protocol import Poke, PokeError, PokeKind, escape_for_log, format_nova, parse_poke
from nfwserver.dde.session import AntennaPosition, SessionSnapshot, TickSample
from nfwserver.dde.status import ArithmeticErrorCode, StatusBit
from nfwserver.dde.transport import ConversationId, DdeServerTransport, PokeResult
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.horizon import HorizonTable
from nfwserver.tracking.look_angles import LookAngleCalculator, LookAngles, PropagationError
from nfwserver.tracking.observer import Observer

log = logging.getLogger(__name__)

DEFAULT_SERVICES = ("NFW32", "NFW_SERVER")
DEFAULT_TOPIC = "NFW_DATA"
DEFAULT_ITEMS = ("NFW_SERVER", "NFW_DATA")
MIN_RATE_HZ, MAX_RATE_HZ, DEFAULT_RATE_HZ = 1.0, 50.0, 5.0

TickListener = Callable[[TickSample], None]


class NovaServer:
    """The session owner and DDE server handler.  See the module docstring."""

    def __init__(
        self,
        catalog: Catalog,
        observer: Observer | None,
        clock: Clock,
        *,
        horizon: HorizonTable | None = None,
        ut1_utc: float = 0.0,
        rate_hz: float = DEFAULT_RATE_HZ,
        services: Iterable[str] = DEFAULT_SERVICES,
        topic: str = DEFAULT_TOPIC,
        items: Iterable[str] = DEFAULT_ITEMS,
        events: EventLog | None = None,
        satellite: int | None = None,
    ) -> None:
        self.clock = clock
        self.events = events if events is not None else EventLog()
        self.services = tuple(services)
        self.topic = topic
        self.items = tuple(items)
        self._item_keys = {i.upper() for i in self.items}
        self._service_keys = {s.upper() for s in self.services}
        self._lock = threading.RLock()
        self._catalog = catalog
        self._horizon = horizon or HorizonTable()
        self._observer = observer
        self._ut1_utc = ut1_utc
        self._calculator = LookAngleCalculator(observer, ut1_utc) if observer is not None else None
        self.rate_hz = self._check_rate(rate_hz)
        self._tune_on = False
        self._track_on = False
        self._catalog_number: int | None = None
        self._antenna = AntennaPosition(None, None, "", None)
        self._last: TickSample | None = None
        self._text = ""
        self._encoded: dict[int, bytes] = {}
        self._arith_error = ArithmeticErrorCode.NONE
        self._dirty = True
        self._conversations: dict[ConversationId, str] = {}
        self._loops: set[tuple[ConversationId, str, int]] = set()
        self._listeners: list[TickListener] = []
        self._transports: list[DdeServerTransport] = []
        if satellite is not None and not self.select_satellite(satellite, source="startup"):
            log.warning("satellite %s is not in the catalog; no satellite selected", satellite)

    # -- configuration -------------------------------------------------------------------
    @staticmethod
    def _check_rate(rate_hz: float) -> float:
        rate = float(rate_hz)
        if not MIN_RATE_HZ <= rate <= MAX_RATE_HZ:
            raise ValueError(f"publish rate {rate_hz} Hz is outside {MIN_RATE_HZ:g}..{MAX_RATE_HZ:g} Hz")
        return rate

    def set_rate(self, rate_hz: float) -> None:
        """Change the publish rate (1-50 Hz); raises :class:`ValueError` outside that range."""
        self.rate_hz = self._check_rate(rate_hz)

    @property
    def catalog(self) -> Catalog:
        return self._catalog

    @property
    def observer(self) -> Observer | None:
        return self._observer

    @property
    def horizon(self) -> HorizonTable:
        return self._horizon

    @property
    def ut1_utc(self) -> float:
        return self._ut1_utc

    def set_observer(self, observer: Observer | None, ut1_utc: float | None = None) -> None:
        """Replace the station (and optionally UT1-UTC)."""
        with self._lock:
            self._observer = observer
            if ut1_utc is not None:
                self._ut1_utc = ut1_utc
            self._calculator = LookAngleCalculator(observer, self._ut1_utc) if observer is not None else None
            self._dirty = True

    def set_horizon(self, horizon: HorizonTable) -> None:
        with self._lock:
            self._horizon = horizon
            self._dirty = True

    def set_catalog(self, catalog: Catalog) -> None:
        """Replace the catalog (an element refresh); the selected satellite stays if still present."""
        with self._lock:
            self._catalog = catalog
            self._dirty = True

    def add_tick_listener(self, listener: TickListener) -> Callable[[], None]:
        """Call ``listener(sample)`` after every tick; returns a function that removes it."""
        with self._lock:
            self._listeners.append(listener)

        def remove() -> None:
            with self._lock:
                if listener in self._listeners:
                    self._listeners.remove(listener)

        return remove

    # -- transports ------------------------------------------------------------------------
    def attach(self, transport: DdeServerTransport) -> None:
        """Register the service names on ``transport``."""
        for service in self.services:
            transport.register_service(service, self)
        self._transports.append(transport)

    def detach(self) -> None:
        """Unregister from every transport (their conversations end)."""
        for transport in self._transports:
            for service in self.services:
                try:
                    transport.unregister_service(service)
                except Exception:
                    log.exception("could not unregister %s", service)
        self._transports.clear()

    # -- session control -------------------------------------------------------------------
    def _note(self, text: str, **fields: object) -> None:
        self.events.add(self.clock.now(), Direction.INFO, "note", text, **fields)

    def set_tune(self, on: bool, source: str = "console") -> None:
        with self._lock:
            changed = self._tune_on != on
            self._tune_on = on
            if not on:
                self._text = ""
                self._encoded.clear()
        if changed:
            self._note(f"TUNE {'ON' if on else 'OFF'}", client=source)

    def set_track(self, on: bool, source: str = "console") -> None:
        with self._lock:
            changed = self._track_on != on
            self._track_on = on
        if changed:
            self._note(f"TRACK {'ON' if on else 'OFF'}", client=source)

    def select_satellite(self, catalog_number: int, source: str = "console") -> bool:
        """Make ``catalog_number`` the AutoTracking satellite; False (and no change) if unknown."""
        with self._lock:
            sat = self._catalog.get(catalog_number)
            if sat is None:
                return False
            changed = self._catalog_number != catalog_number
            self._catalog_number = catalog_number
            self._dirty = True
            self._arith_error = ArithmeticErrorCode.NONE
        if changed:
            self._note(f"satellite {catalog_number} {sat.dde_name} selected", client=source)
        return True

    def clear_satellite(self) -> None:
        with self._lock:
            self._catalog_number = None
            self._dirty = True

    def report_antenna_position(self, azimuth_deg: float | None, elevation_deg: float | None,
                                source: str = "rotor") -> None:
        """Record where the antennas point (a rotor backend's read-back, or ANTAZ/ANTEL)."""
        with self._lock:
            old = self._antenna
            self._antenna = AntennaPosition(
                old.azimuth_deg if azimuth_deg is None else azimuth_deg,
                old.elevation_deg if elevation_deg is None else elevation_deg,
                source,
                self.clock.now(),
            )

    def apply(self, pokes: Iterable[Poke], source: str) -> str | None:
        """Apply parsed commands in order; returns the reason of the first refusal, or None."""
        for poke in pokes:
            if poke.kind is PokeKind.TUNE:
                self.set_tune(bool(poke.value), source)
            elif poke.kind is PokeKind.TRACK:
                self.set_track(bool(poke.value), source)
            elif poke.kind is PokeKind.SAT:
                if not self.select_satellite(int(poke.value), source):
                    return f"satellite {poke.value} is not in the catalog; keeping the current one"
            elif poke.kind is PokeKind.ANTAZ:
                self.report_antenna_position(float(poke.value), None, source)
            elif poke.kind is PokeKind.ANTEL:
                self.report_antenna_position(None, float(poke.value), source)
        return None

    def command(self, text: str, source: str = "console", conversation: int | None = None) -> str | None:
        """Handle a command string as a poke would; returns None when accepted, else the reason."""
        try:
            reason = self.apply(parse_poke(text), source)
        except PokeError as exc:
            reason = str(exc)
        accepted = reason is None
        self.events.add(self.clock.now(), Direction.IN, "poke", text, conversation=conversation, client=source,
                        accepted=accepted, detail=reason or "")
        if not accepted:
            log.warning("refused command %s from %s: %s", escape_for_log(text), source, reason)
        return reason

    # -- ticking ---------------------------------------------------------------------------
    def status_word(self) -> int:
        with self._lock:
            return self._status_locked(self._last)

    def _status_locked(self, sample: TickSample | None) -> int:
        word = 0
        if self._observer is None:
            word |= StatusBit.STATION_MISSING
        if self._catalog_number is None or self._catalog.get(self._catalog_number) is None:
            word |= StatusBit.SATELLITE_MISSING
        if not self._track_on:
            word |= StatusBit.TRACKING_DISABLED
        if not self._tune_on:
            word |= StatusBit.TUNING_DISABLED
        if self._arith_error:
            word |= StatusBit.ARITHMETIC_ERROR
        if sample is not None and sample.look_angles is not None and not sample.above_horizon and self._track_on:
            word |= StatusBit.NOT_IN_VIEW
        if self._dirty:
            word |= StatusBit.NOT_RECOMPUTED
        return int(word)

    @property
    def arithmetic_error(self) -> ArithmeticErrorCode:
        return self._arith_error

    def tick(self, when: datetime | None = None) -> TickSample:
        """Compute and publish for ``when`` (default: the clock's now).  Never raises for bad data."""
        when = self.clock.now() if when is None else when
        with self._lock:
            catnr = self._catalog_number
            sat = self._catalog.get(catnr) if catnr is not None else None
            calc = self._calculator
            horizon = self._horizon
            tune, track = self._tune_on, self._track_on
        angles: LookAngles | None = None
        error = ArithmeticErrorCode.NONE
        if sat is not None and calc is not None:
            try:
                angles = calc.compute(sat.satrec, when)
            except PropagationError as exc:
                error = ArithmeticErrorCode.DEGENERATE_ORBIT
                if self._arith_error != error:
                    log.error("cannot compute %s at %s: %s", sat.dde_name, when.isoformat(), exc)
            except (ValueError, OverflowError, ArithmeticError) as exc:
                error = ArithmeticErrorCode.DOMAIN
                log.error("cannot compute %s at %s: %s", sat.dde_name, when.isoformat(), exc)
        above = angles is not None and horizon.is_above(angles.azimuth_deg, angles.elevation_deg)
        text = ""
        if angles is not None and sat is not None:
            text = format_nova(sat.dde_name, angles.azimuth_deg, angles.elevation_deg,
                               angles.range_rate_km_s, above)
        publish = tune and bool(text)
        with self._lock:
            self._arith_error = error
            self._dirty = False
            if publish:
                self._text = text
                self._encoded = {}
            sample = TickSample(when, catnr, sat.dde_name if sat else None, angles, above, tune, track,
                                text if publish else "", 0)
            sample = replace(sample, status=self._status_locked(sample))
            self._last = sample
            listeners = list(self._listeners)
            transports = list(self._transports)
            loops = len(self._loops)
        if publish:
            for transport in transports:
                for item in self.items:
                    try:
                        transport.post_advise(self.topic, item)
                    except Exception:
                        log.exception("posting advise on %s failed", item)
            self.events.add(when, Direction.OUT, "publish", text, detail=f"{loops} advise loop(s)")
        for listener in listeners:
            try:
                listener(sample)
            except Exception:
                log.exception("tick listener %r failed", listener)
        return sample

    def current_text(self) -> str:
        """What a request answers now: the last published string, empty before TUNE ON."""
        with self._lock:
            return self._text

    def _encoded_text(self, fmt: int) -> bytes:
        with self._lock:
            data = self._encoded.get(fmt)
            if data is None:
                data = encode_text(self._text, fmt)
                self._encoded[fmt] = data
            return data

    def snapshot(self) -> SessionSnapshot:
        with self._lock:
            sat = self._catalog.get(self._catalog_number) if self._catalog_number is not None else None
            return SessionSnapshot(self._tune_on, self._track_on, self._catalog_number,
                                   sat.dde_name if sat else None, self._antenna, self._last,
                                   self._status_locked(self._last), self.rate_hz, len(self._conversations),
                                   len(self._loops))

    # -- DdeServerHandler ------------------------------------------------------------------
    def _label(self, conv: ConversationId) -> str:
        return self._conversations.get(conv, f"conv {conv}")

    def on_connect(self, service: str, topic: str) -> bool:
        ok = service.upper() in self._service_keys and topic.upper() == self.topic.upper()
        self.events.add(self.clock.now(), Direction.IN, "connect", f"{service}|{topic}", accepted=ok)
        return ok

    def on_connect_confirm(self, conv: ConversationId, service: str, topic: str) -> None:
        with self._lock:
            self._conversations[conv] = f"conv {conv} {service}/{topic}"

    def on_request(self, conv: ConversationId, topic: str, item: str, fmt: int) -> bytes | None:
        if item.upper() not in self._item_keys or fmt not in TEXT_FORMATS:
            self.events.add(self.clock.now(), Direction.IN, "request", item, conversation=conv,
                            client=self._label(conv), accepted=False, detail=f"unknown item or {format_name(fmt)}")
            return None
        data = self._encoded_text(fmt)
        self.events.add(self.clock.now(), Direction.OUT, "request", self.current_text(), conversation=conv,
                        client=self._label(conv), detail=item)
        return data

    def on_poke(self, conv: ConversationId, topic: str, item: str, fmt: int, data: bytes) -> PokeResult:
        if fmt not in TEXT_FORMATS:
            self.events.add(self.clock.now(), Direction.IN, "poke", f"<{len(data)} bytes>", conversation=conv,
                            client=self._label(conv), accepted=False, detail=f"unsupported {format_name(fmt)}")
            return PokeResult.FNOTPROCESSED
        text = decode_text(data, fmt)
        reason = self.command(text, source=self._label(conv), conversation=conv)
        return PokeResult.FACK if reason is None else PokeResult.FNOTPROCESSED

    def on_execute(self, conv: ConversationId, topic: str, command: bytes) -> PokeResult:
        text = decode_text(command)
        reason = self.command(text, source=self._label(conv), conversation=conv)
        return PokeResult.FACK if reason is None else PokeResult.FNOTPROCESSED

    def on_advise_start(self, conv: ConversationId, topic: str, item: str, fmt: int) -> bool:
        ok = item.upper() in self._item_keys and fmt in TEXT_FORMATS
        if ok:
            with self._lock:
                self._loops.add((conv, item.upper(), fmt))
        self.events.add(self.clock.now(), Direction.IN, "advise", f"start {item} {format_name(fmt)}",
                        conversation=conv, client=self._label(conv), accepted=ok)
        return ok

    def on_advise_request(self, conv: ConversationId, topic: str, item: str, fmt: int) -> bytes | None:
        if item.upper() not in self._item_keys or fmt not in TEXT_FORMATS:
            return None
        return self._encoded_text(fmt)

    def on_advise_stop(self, conv: ConversationId, topic: str, item: str, fmt: int) -> None:
        with self._lock:
            self._loops.discard((conv, item.upper(), fmt))
        self.events.add(self.clock.now(), Direction.IN, "advise", f"stop {item} {format_name(fmt)}",
                        conversation=conv, client=self._label(conv))

    def on_disconnect(self, conv: ConversationId) -> None:
        with self._lock:
            label = self._conversations.pop(conv, f"conv {conv}")
            self._loops = {loop for loop in self._loops if loop[0] != conv}
        self.events.add(self.clock.now(), Direction.IN, "disconnect", label, conversation=conv, client=label)

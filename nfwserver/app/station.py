"""The running station: catalog, server core, transport, publisher and element refresh, from a Config."""

from __future__ import annotations

import logging
import os
import threading

from nfwserver.app.element_sources import FetchResult, fetch_all
from nfwserver.app.element_store import ElementStore
from nfwserver.app.session_state import SessionState, StateFile
from nfwserver.clock import Clock
from nfwserver.config.schema import Config
from nfwserver.dde.events import Direction
from nfwserver.dde.platform_transport import default_transport
from nfwserver.dde.publisher import Publisher
from nfwserver.dde.server import NovaServer
from nfwserver.dde.transport import DdeServerTransport
from nfwserver.dialects.dde_service import DialectServer
from nfwserver.dialects.orbitron import ORBITRON
from nfwserver.dialects.predict_udp import PredictContext, PredictUdpServer
from nfwserver.dialects.satpc32 import SATPC32
from nfwserver.dialects.wxtrack import WXTRACK
from nfwserver.radio.coupling import RadioCoupling
from nfwserver.radio.rigctld_backend import RigctldBackend
from nfwserver.radio.tuning import DopplerTuner
from nfwserver.rotor.backend import RotorBackend
from nfwserver.rotor.coupling import RotorCoupling
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.rotor.kct_driver import KctDriver
from nfwserver.rotor.rotctld_backend import RotctldBackend
from nfwserver.rotor.sim_backend import SimulatedRotor
from nfwserver.rotor.tracks import SatelliteTracks
from nfwserver.tracking.catalog import Catalog, UpdateSummary

log = logging.getLogger(__name__)

DDE_DIALECTS = {d.name: d for d in (ORBITRON, WXTRACK, SATPC32)}


class Station:
    """Everything ``nfwserver run`` starts; :meth:`start` and :meth:`stop` are idempotent."""

    def __init__(self, config: Config, clock: Clock, transport: DdeServerTransport | None = None) -> None:
        self.config = config
        self.clock = clock
        store = config.elements.store
        self.store = ElementStore(None if store == "default" else store) if store else None
        fetched = fetch_all(config.elements.files, config.elements.urls, config.elements.use_bundled)
        self._report(fetched)
        stored = self.store.load() if self.store is not None else []
        self.catalog = Catalog(stored, dde_names=config.dde_names)
        self.catalog.update(fetched.sets)
        if not len(self.catalog):
            log.warning("no element sets loaded: nothing can be tracked until some are added")
        srv = config.server
        self.server = NovaServer(
            self.catalog, config.observer, clock, horizon=config.horizon, ut1_utc=srv.ut1_utc_s,
            rate_hz=srv.rate_hz, services=srv.services, topic=srv.topic, items=srv.items,
        )
        self.state_file = StateFile(None if config.state_file == "default" else config.state_file) \
            if config.state_file else None
        saved = self.state_file.load() if self.state_file is not None else SessionState()
        first_choice = saved.satellite if saved.satellite in self.catalog else srv.satellite
        if first_choice is not None and not self.server.select_satellite(first_choice, source="config"):
            log.warning("configured satellite %s is not in the loaded elements", first_choice)
        if self.state_file is not None:
            self.server.add_tick_listener(self._save_state)
        if transport is None:
            transport, self.transport_note = default_transport()
        else:
            self.transport_note = "serving on the given transport"
        self.transport = transport
        self.publisher = Publisher(self.server, clock)
        self.dialect_servers = [DialectServer(DDE_DIALECTS[name], self.catalog, config.channels)
                                for name in config.dialects.dde]
        for dialect_server in self.dialect_servers:
            self.server.add_tick_listener(dialect_server.on_tick)
        self.predict: PredictUdpServer | None = None
        if config.dialects.predict_udp:
            context = PredictContext(
                lambda: self.catalog, config.observer, clock,
                lambda: list(dict.fromkeys([*config.favourites, *[s.catalog_number for s in self.catalog]]))[:24],
                mode=lambda: f"{self.server.snapshot().dde_name or 'none'}\n", callsign=config.dialects.callsign,
                ut1_utc=config.server.ut1_utc_s, on_reload=self.refresh_elements,
            )
            self.predict = PredictUdpServer(context, config.dialects.predict_host, config.dialects.predict_port)
        self.rotor: RotorCoupling | None = self._make_rotor(config, clock)
        self.radio: RadioCoupling | None = None
        if config.radio.backend == "rigctld":
            backend = RigctldBackend(clock, config.radio.host, config.radio.port)
            first = next(iter(config.channels.values()), None)
            if first is not None:
                tuner = DopplerTuner(first, backend, config.radio.step_hz, config.radio.knob_tolerance_hz)
                self.radio = RadioCoupling(tuner, config.channels, enabled=config.radio.enabled)
                self.server.add_tick_listener(self.radio.on_tick)
        self._stop = threading.Event()
        self._refresher: threading.Thread | None = None
        self._started = False

    def _save_state(self, sample) -> None:
        if self.state_file is not None:
            self.state_file.save(SessionState(sample.catalog_number))

    def apply_config(self, new: Config) -> list[str]:
        """Apply what can change while running (observer, horizon, UT1-UTC, rate, DDE names);
        returns the settings that need a restart to take effect."""
        server = self.server
        server.set_observer(new.observer, new.server.ut1_utc_s)
        server.set_horizon(new.horizon)
        server.set_rate(new.server.rate_hz)
        for catnr, name in new.dde_names.items():
            try:
                self.catalog.set_dde_name(catnr, name)
            except ValueError as exc:
                log.warning("DDE name for %s not applied: %s", catnr, exc)
        if self.radio is not None:
            self.radio.enabled = new.radio.enabled
        restart = [name for name, old, now in (
            ("[elements]", self.config.elements, new.elements), ("[rotor]", self.config.rotor, new.rotor),
            ("[radio] backend", (self.config.radio.backend, self.config.radio.host, self.config.radio.port),
             (new.radio.backend, new.radio.host, new.radio.port)),
            ("[server] services/topic/items", (self.config.server.services, self.config.server.topic,
                                                self.config.server.items),
             (new.server.services, new.server.topic, new.server.items)),
            ("[dialects]", self.config.dialects, new.dialects)) if old != now]
        self.config = new
        return restart

    def watch_config(self, path: str, interval_s: float = 2.0) -> None:
        """Re-read ``path`` when it changes; an invalid file is refused and the running configuration kept."""
        from nfwserver.config import ConfigError, load_config

        def mtime() -> tuple[int, int] | None:
            try:
                st = os.stat(path)
                return st.st_mtime_ns, st.st_size
            except OSError:
                return None

        def loop() -> None:
            seen = mtime()
            while not self._stop.wait(interval_s):
                now = mtime()
                if now == seen:
                    continue
                # Let a writer finish: read only once the file has stopped changing.
                while not self._stop.wait(max(0.2, interval_s)) and mtime() != now:
                    now = mtime()
                seen = now
                try:
                    new = load_config(path)
                except ConfigError as exc:
                    log.error("configuration change refused, keeping the running one: %s", exc)
                    self.server.events.add(self.clock.now(), Direction.INFO, "note",
                                           f"configuration change refused: {exc}", accepted=False)
                    continue
                restart = self.apply_config(new)
                note = "configuration reloaded" + (f"; restart to apply {', '.join(restart)}" if restart else "")
                log.info(note)
                self.server.events.add(self.clock.now(), Direction.INFO, "note", note, accepted=True)

        threading.Thread(target=loop, name="nfw-config", daemon=True).start()

    def _make_rotor(self, config: Config, clock: Clock) -> RotorCoupling | None:
        rc = config.rotor
        if rc.backend == "none":
            return None
        geometry = RotorGeometry.preset(rc.geometry)
        backend: RotorBackend
        if rc.backend == "sim":
            backend = SimulatedRotor(clock, geometry, rc.speed_deg_s, rc.speed_deg_s)
        else:
            backend = RotctldBackend(clock, geometry, rc.host, rc.port)
        driver = KctDriver(clock, backend, geometry)
        driver.set_parking(rc.park_delay_minutes, rc.park_azimuth_deg, rc.park_elevation_deg)

        def satrec_now():
            number = self.server.snapshot().catalog_number
            sat = self.catalog.get(number) if number is not None else None
            return sat.satrec if sat is not None else None

        tracks = SatelliteTracks(satrec_now, config.observer, config.horizon, config.server.ut1_utc_s)
        coupling = RotorCoupling(
            driver, tracks.predict, tracks.pass_track, rc.threshold_deg, rc.speed_deg_s, rc.max_lead_s,
            rc.after_los, rc.flip,
            on_position=lambda az, el: self.server.report_antenna_position(az, el, "rotor"),
        )
        self.server.add_tick_listener(coupling.on_tick)
        return coupling

    @staticmethod
    def _report(fetched: FetchResult) -> None:
        for problem in fetched.failed:
            log.warning("element source unavailable: %s", problem)
        for rejection in fetched.rejected:
            log.info("element set skipped: %s", rejection)

    def refresh_elements(self) -> UpdateSummary:
        """Read every element source again; newer epochs replace older ones."""
        cfg = self.config.elements
        fetched = fetch_all(cfg.files, cfg.urls, cfg.use_bundled)
        self._report(fetched)
        summary = self.catalog.update(fetched.sets)
        if self.store is not None and (summary.added or summary.updated):
            try:
                self.store.update(fetched.sets)
            except OSError as exc:
                log.error("cannot save the element catalog to %s: %s", self.store.path, exc)
        log.info("elements refreshed: %d added, %d updated", len(summary.added), len(summary.updated))
        return summary

    def _refresh_loop(self) -> None:
        period = self.config.elements.refresh_hours * 3600.0
        while not self._stop.wait(period):
            try:
                self.refresh_elements()
            except Exception:  # never let a refresh take the station down
                log.exception("element refresh failed")

    def start(self) -> None:
        if self._started:
            return
        self._started = True
        self.server.attach(self.transport)
        for dialect_server in self.dialect_servers:
            dialect_server.attach(self.transport)
        if self.predict is not None:
            self.predict.start()
        if self.radio is not None:
            self.radio.start()
        if self.rotor is not None:
            self.rotor.start()
        self.publisher.start()
        if self.config.elements.refresh_hours > 0 and (self.config.elements.files or self.config.elements.urls):
            self._refresher = threading.Thread(target=self._refresh_loop, name="nfw-elements", daemon=True)
            self._refresher.start()

    def stop(self) -> None:
        if not self._started:
            return
        self._started = False
        self._stop.set()
        self.publisher.stop()
        if self.predict is not None:
            self.predict.stop()
        for dialect_server in self.dialect_servers:
            dialect_server.detach()
        if self.radio is not None:
            self.radio.stop()
        if self.rotor is not None:
            self.rotor.stop()
        self.server.detach()
        try:
            self.transport.close()
        except Exception:
            log.exception("closing the transport failed")

"""The running station: one core, and every output attached to it as an adapter, from a Config.

Data flow (docs/ARCHITECTURE.md): configuration and element sets fill the one live
:class:`~nfwserver.core.state.StationState`; the publisher ticks the core's tracker on the clock; each
tick's :class:`~nfwserver.core.sample.TickSample` goes to every adapter — Nova DDE, the other trackers'
DDE dialects, PREDICT, Nova's TCP server (``station.tcp``), the EasyComm I serial output
(``station.easycomm``), the rotor and radio couplings, the session saver, the console.  Adapters read
the state and talk back through the core's ports; none holds a copy, so :meth:`Station.apply_config`
changes the state once and every output follows on the next tick.

Construction is pure (no files, sockets or threads); :meth:`Station.start` does the I/O: it loads
the catalog (stored, files, bundled — URLs are fetched on the refresher thread right after, so a slow
site never delays the first publish), restores the session, binds the listeners and starts the
threads.  :meth:`start` and :meth:`stop` are idempotent.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

from nfwserver.app.autotrack_link import StationAutotrack
from nfwserver.app.config_watcher import ConfigWatcher
from nfwserver.app.devices import make_radio, make_rotor
from nfwserver.app.element_refresher import ElementRefresher
from nfwserver.app.element_sources import FetchResult
from nfwserver.app.live_config import CONFIG_PARTS
from nfwserver.app.long_lived import building_long_lived, release
from nfwserver.app.platform_transport import default_transport
from nfwserver.app.session_state import SessionSaver, SessionState, StateFile
from nfwserver.app.station_catalog import configured_store, configured_urls, fetch_configured, load_station_catalog
from nfwserver.app.status_fields import combined, device_status, elements_status
from nfwserver.app.store_watcher import StoreWatcher
from nfwserver.clock import Clock
from nfwserver.config.live_reload import keep_running, restart_needed
from nfwserver.config.schema import Config
from nfwserver.core.events import Direction
from nfwserver.core.publisher import Publisher
from nfwserver.core.station_core import StationCore
from nfwserver.dde.nova_service import NovaDdeService
from nfwserver.dde.transport import DdeServerTransport
from nfwserver.dialects.dde_service import DialectServer
from nfwserver.dialects.orbitron import ORBITRON
from nfwserver.dialects.predict_udp import PredictContext, PredictUdpServer
from nfwserver.dialects.satpc32 import SATPC32
from nfwserver.dialects.wxtrack import WXTRACK
from nfwserver.easycomm.output import EasyCommOutput
from nfwserver.health import Backoff
from nfwserver.radio.coupling import RadioCoupling
from nfwserver.rotor.coupling import RotorCoupling
from nfwserver.tcp.server import NovaTcpServer
from nfwserver.tracking import SGP4_CHOICE
from nfwserver.tracking.catalog import Catalog, UpdateSummary
from nfwserver.web import StationParts, WebServer

log = logging.getLogger(__name__)

DDE_DIALECTS = {d.name: d for d in (ORBITRON, WXTRACK, SATPC32)}


class Station:
    """Everything ``nfwserver run`` starts; see the module docstring.  Owned by the thread that
    calls :meth:`start`/:meth:`stop` (the main thread); the adapters own their threads."""

    def __init__(self, config: Config, clock: Clock, transport: DdeServerTransport | None = None) -> None:
        self.config = config
        self.clock = clock
        srv = config.server
        self.core = StationCore(Catalog(dde_names=config.dde_names), config.observer, clock, horizon=config.horizon,
                                ut1_utc=srv.ut1_utc_s, rate_hz=srv.rate_hz, channels=config.channels)
        self.store = configured_store(config)
        self.state_file = StateFile(None if config.state_file == "default" else config.state_file) \
            if config.state_file else None
        self._given_transport = transport
        self.transport: DdeServerTransport | None = transport
        self.transport_note = "serving on the given transport" if transport is not None else ""
        self.nova = NovaDdeService(self.core, services=srv.services, topic=srv.topic, items=srv.items)
        self.dialect_servers = [DialectServer(DDE_DIALECTS[name], self.core) for name in config.dialects.dde]
        self.publisher = Publisher(self.core, clock)
        self.refresher = ElementRefresher(self.refresh_elements, clock, config.elements.refresh_hours * 3600.0,
                                          initial=bool(configured_urls(config.elements)))
        self.predict: PredictUdpServer | None = None
        if config.dialects.predict_udp:
            context = PredictContext(self.core.state, clock, self._predict_list,
                                     callsign=config.dialects.callsign, on_reload=self.refresher.request)
            self.predict = PredictUdpServer(context, config.dialects.predict_host, config.dialects.predict_port)
        self.rotor: RotorCoupling | None = make_rotor(config.rotor, self.core, clock)
        self.core.rotor_configured = self.rotor is not None
        self.core.rotor = self.rotor  # FLIP and PARK, from every face
        self.radio: RadioCoupling | None = make_radio(config.radio, self.core, clock)
        self.core.radio_configured = self.radio is not None
        self.autotrack = StationAutotrack(self.core, clock, lambda: self.config)  # AUTO ON|OFF, SAT= switches off
        configured = config.server.satellite if isinstance(config.server.satellite, int) else None  # a name: at start
        self.saver = (SessionSaver(self.state_file, configured,
                                   self.core.health.link("state-file", Backoff(0.2, 0.4)),
                                   current=lambda: self.core.state.catalog_number, autotrack=self.autotrack.mode,
                                   autotrack_enabled=config.autotrack.enabled)
                      if self.state_file else None)
        self.easycomm: EasyCommOutput | None = (
            EasyCommOutput(config.easycomm, self.core.state, clock,
                           health=self.core.health.link("easycomm", Backoff(0.5, 2.0)))
            if config.easycomm.enabled else None)
        self.tcp: NovaTcpServer | None = (
            NovaTcpServer(self.core, config.tcp,
                          combined(device_status(self.rotor, self.radio, self.easycomm),
                                   elements_status(self.core.state, clock, config.elements.stale_days),
                                   self.autotrack.status_fields))
            if config.tcp.enabled else None)
        self.web: WebServer | None = (
            WebServer(self.core, config.web, StationParts(self.rotor, self.radio, self.easycomm, self.tcp, self.nova,
                                                          favourites=lambda: self.config.favourites,
                                                          autotrack_schedule=lambda: self.autotrack.runtime.schedule))
            if config.web.enabled else None)
        self.watcher: ConfigWatcher | None = None
        # a command (and the page's token) is checked against the file as it is now, whatever face it came from
        self.core.before_command = self.catch_up_config
        #: follows the stored catalog, which ``nfwserver elements update`` writes while the station runs
        self.store_watcher = StoreWatcher(self.store.path, clock, self.reload_store) if self.store else None
        self._watcher_lock = threading.Lock()
        self.selection_note = ""  #: which satellite the station started with, and why (set by start())
        self._unsubscribe: list[Callable[[], None]] = []
        self._started = False
        self._stopping = threading.Event()  #: set by stop(): a download in progress is aborted at once

    # -- convenience views -------------------------------------------------------------------------
    @property
    def catalog(self) -> Catalog:
        return self.core.state.catalog

    def _predict_list(self) -> list[int]:
        catalog = self.core.state.catalog
        return list(dict.fromkeys([*self.config.favourites, *(s.catalog_number for s in catalog)]))[:24]

    # -- live configuration ------------------------------------------------------------------------
    def apply_config(self, new: Config) -> list[str]:
        """Apply a changed configuration to the running station; returns what needs a restart.

        One table drives it (:data:`~nfwserver.app.live_config.CONFIG_PARTS`): every live part that changed
        (observer, horizon, UT1-UTC, rate, channels, DDE names, radio tuning) changes the live state at once;
        the restart-only parts are compared with what is *running* and listed when they differ."""
        favourites = self.config.favourites
        for part in CONFIG_PARTS:
            if part.apply is not None and part.differs(self.config, new):
                part.apply(self.core, new)
        restart = restart_needed(CONFIG_PARTS, self.config, new)
        self.config = keep_running(CONFIG_PARTS, self.config, new)  # what needs a restart keeps running as it was
        if self.web is not None:  # control and token at once: an old token stops working with the change
            self.web.configure(self.config.web)
            if self.config.favourites != favourites:
                self.web.board.request()  # the page's pass list follows now, not at the next refresh
        return restart

    def _config_changed(self, new: Config) -> None:
        restart = self.apply_config(new)
        note = "configuration reloaded" + (f"; restart to apply {', '.join(restart)}" if restart else "")
        log.info(note)
        self.core.health.link("config", paced=False).succeeded()
        self.core.events.add(self.clock.now(), Direction.INFO, "note", note, accepted=True)

    def _config_refused(self, message: str) -> None:
        """A changed file that cannot be applied: the ``config`` link shows it (STATUS, console) until a
        good file is applied; the health link writes the log line (repeats rate-limited)."""
        self.core.health.link("config", paced=False).failed(message)
        self.core.events.add(self.clock.now(), Direction.INFO, "note", message, accepted=False)

    def watch_config(self, path: str, interval_s: float = 2.0) -> None:
        """Follow ``path`` while running (see :class:`~nfwserver.app.config_watcher.ConfigWatcher`)."""
        if self.watcher is None:
            self.watcher = ConfigWatcher(path, self.clock, self._config_changed, self._config_refused, interval_s)
            self.watcher.start()

    def catch_up_config(self) -> None:
        """Apply a change of the watched file now, on the caller's thread, if it is whole and valid
        (:meth:`ConfigWatcher.catch_up`); nothing when the station does not follow a file."""
        watcher = self.watcher
        if watcher is not None:
            watcher.catch_up()

    def reload_config(self) -> bool:
        """Re-read the configuration file now, changed or not (SIGHUP; any thread): applied only when whole,
        as a change the watcher sees.  False when the station runs on built-in defaults or is not running."""
        if not self._started:
            return False
        if self.store_watcher is not None:
            self.store_watcher.request()  # the stored catalog too (written by `elements update`)
        with self._watcher_lock:  # any thread: two requests at once make one watcher
            path = self.watcher.path if self.watcher is not None else self.config.path
            if not path:
                log.warning("reload requested, but the station runs on built-in defaults: there is no file to read")
                return False
            if self.watcher is None:  # not watching: a watcher that reads only on request
                self.watcher = ConfigWatcher(path, self.clock, self._config_changed, self._config_refused, None)
                self.watcher.start()
            watcher = self.watcher
        log.info("reloading the configuration from %s", path)
        watcher.request()
        return True

    # -- elements ----------------------------------------------------------------------------------
    @staticmethod
    def _report(fetched: FetchResult, failures: bool = True) -> None:
        for problem in fetched.failed if failures else ():
            log.warning("element source unavailable: %s", problem)
        for rejection in fetched.rejected:
            log.info("element set skipped: %s", rejection)

    def _load_catalog(self) -> None:
        """Stored catalog, element files and the bundled sets (no network: URLs come on the refresher)."""
        with building_long_lived():
            loaded, fetched = load_station_catalog(self.config)
            self._report(fetched)
            catalog = self.core.state.catalog
            catalog.update(loaded.element_sets())
        self.core.state.catalog_changed()
        if not len(catalog):
            log.warning("no element sets loaded: nothing can be tracked until some are added")

    def refresh_elements(self) -> UpdateSummary:
        """Read every element source again (refresher thread); newer epochs replace older ones.

        Everything here runs on the calling thread: reading, parsing, merging and naming the new
        catalog (:meth:`Catalog.update`), and saving the store.  The publish thread only ever sees the
        swap of the catalog's contents, a reference change, and no garbage collection over the new
        sets (:func:`~nfwserver.app.long_lived.building_long_lived`), so a refresh never delays a tick."""
        fetched = fetch_configured(self.config.elements, fetch_urls=True, parsing=building_long_lived,
                                   cancel=self._stopping)
        self._report(fetched, failures=False)  # the failures are the `elements` link's (one line an episode)
        sources = self.core.health.link("elements", paced=False)  # STATUS faults=elements while sources fail
        if fetched.failed:
            sources.failed("; ".join(fetched.failed))
        else:
            sources.succeeded()
        with building_long_lived():
            summary = self.core.state.catalog.update(fetched.sets)
            if summary.added or summary.updated:
                self.core.state.catalog_changed()
            if self.store is not None and (summary.added or summary.updated):
                try:
                    self.store.update(fetched.sets)
                except OSError as exc:
                    log.error("cannot save the element catalog to %s: %s", self.store.path, exc)
            release(fetched.sets)  # the sets that were not newer
        log.info("elements refreshed: %d added, %d updated", len(summary.added), len(summary.updated))
        return summary

    def reload_store(self) -> UpdateSummary | None:
        """Merge the stored catalog into the live one (the store watcher's thread): sets added by ``nfwserver
        elements update`` become selectable, newer epochs replace older ones.  None without a store."""
        if self.store is None:
            return None
        with building_long_lived():
            stored = self.store.load()
            summary = self.core.state.catalog.update(stored)
            if summary.added or summary.updated:
                self.core.state.catalog_changed()
            release(stored)
        if summary.added or summary.updated:
            log.info("stored elements read again: %d added, %d updated", len(summary.added), len(summary.updated))
        return summary

    # -- session -------------------------------------------------------------------------------------
    def _restore_session(self) -> None:
        srv = self.config.server
        saved = self.state_file.load() if self.state_file is not None else SessionState()
        configured, unresolved = configured_satellite(srv.satellite, self.catalog)
        if self.saver is not None:
            self.saver.configured = configured  # the state file records the number, as before
        choice, source = configured, "config"
        if (not unresolved and saved.satellite is not None and saved.satellite != configured
                and saved.satellite in self.catalog and saved.configured == configured):
            choice, source = saved.satellite, "saved-state"  # chosen at run time; the configuration unchanged
        self.selection_note = unresolved or _selection_note(choice, source, configured, saved, self.state_file)
        if unresolved and choice is None:
            log.warning("%s", unresolved)
        elif choice is not None and not self.core.select_satellite(choice, source=source):
            self.selection_note = f"configured satellite {choice} is not in the loaded elements"
            log.warning("%s", self.selection_note)
        else:
            log.info("%s", self.selection_note)
            self.core.selected_by = source
        if srv.tune:
            self.core.set_feed(True, source="config")
        if srv.track:
            self.core.set_track(True, source="config")
        if self.config.radio.enabled:
            self.core.set_doppler(True, source="config")
        where = str(self.state_file.path) if self.state_file is not None else "no state file"
        log.info("%s", self.autotrack.restore(saved.autotrack, saved.autotrack_off, saved.autotrack_enabled, where))

    # -- life cycle ----------------------------------------------------------------------------------
    def start(self) -> None:
        """Load, bind and start everything; raises OSError when a listener cannot bind (nothing keeps running)."""
        if self._started:
            return
        self._stopping.clear()
        for warning in self.config.warnings:
            log.warning("%s", warning)
        if SGP4_CHOICE.mode != "compiled":  # the machine's sgp4, in the log once per start (sgp4_selfcheck)
            log.info("%s", SGP4_CHOICE.detail)
        self._load_catalog()
        self._restore_session()
        if self.predict is not None:
            self.predict.start()
        try:
            for listener in (self.tcp, self.web):
                if listener is not None:
                    listener.start()
        except OSError:
            for started in (self.predict, self.tcp):
                if started is not None:
                    started.stop()
            raise
        if self.transport is None:
            self.transport, self.transport_note = default_transport()
        self._started = True
        self.nova.attach(self.transport)
        for dialect_server in self.dialect_servers:
            dialect_server.attach(self.transport)
        for worker in (self.radio, self.rotor, self.saver, self.easycomm):
            if worker is not None:
                self._unsubscribe.append(self.core.subscribe(worker.on_tick))
                worker.start()
        self.autotrack.start()
        self.publisher.start()
        cfg = self.config.elements
        if configured_urls(cfg) or (cfg.refresh_hours > 0 and cfg.files) or self.predict is not None:
            self.refresher.start()
        if self.store_watcher is not None:
            self.store_watcher.start()

    def stop(self) -> None:
        if not self._started:
            return
        self._started = False
        self._stopping.set()
        if self.watcher is not None:
            self.watcher.stop()
        if self.store_watcher is not None:
            self.store_watcher.stop()
        self.refresher.stop()
        self.publisher.stop()
        for unsubscribe in self._unsubscribe:
            unsubscribe()
        if self.predict is not None:
            self.predict.stop()
        for listener in (self.tcp, self.web):
            if listener is not None:
                listener.stop()
        for dialect_server in self.dialect_servers:
            dialect_server.detach()
        for worker in (self.radio, self.rotor, self.easycomm, self.autotrack):
            if worker is not None:
                worker.stop()
        self.nova.detach()
        if self.transport is not None:
            try:
                self.transport.close()
            except Exception:
                log.exception("closing the transport failed")
        if self.saver is not None:  # last: no face can change the selection any more
            self.saver.stop()


def configured_satellite(value: int | str | None, catalog: Catalog) -> tuple[int | None, str]:
    """``[server] satellite`` as a catalog number: a number as it is, a name resolved against ``catalog`` as
    ``SAT=`` resolves it; with one sentence saying why when a name matches no satellite or several (then None)."""
    if not isinstance(value, str):
        return value, ""
    found = catalog.named(value)
    if len(found) == 1:
        return found[0].catalog_number, ""
    if not found:
        return None, (f"[server] satellite {value!r} names no satellite in the loaded elements, so none is selected "
                      "(give its catalog number or its name as `nfwserver passes` lists it)")
    numbers = ", ".join(str(s.catalog_number) for s in found[:5]) + (", ..." if len(found) > 5 else "")
    return None, f"[server] satellite {value!r} names {len(found)} satellites ({numbers}), so none is selected: " \
                 "give the catalog number"


def _selection_note(choice: int | None, source: str, configured: int | None, saved: SessionState,
                    state_file: StateFile | None) -> str:
    """Which satellite the station starts with, and why (the saved choice or the configuration)."""
    if choice is None:
        return "no satellite selected ([server] satellite is not set)"
    if source == "saved-state":
        where = state_file.path if state_file is not None else "the state file"
        return (f"satellite {choice}: restored from {where} (chosen while running; [server] satellite "
                f"{configured} unchanged since, so the saved choice wins; SAT= or F2 changes it)")
    if saved.satellite is not None and saved.satellite != choice:
        return (f"satellite {choice}: from [server] satellite, which changed since the last run, so it "
                f"replaces the saved choice {saved.satellite}")
    return f"satellite {choice}: from [server] satellite"

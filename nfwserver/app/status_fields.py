"""The extra fields of the TCP ``STATUS`` line: rotor, radio and EasyComm state, and the age of the elements
in use, read when asked.

Reads what the adapters' worker threads last recorded (plain attribute reads, as the console
does); never talks to a device.  Angles in degrees in the rotor's own frame, frequencies in Hz, ages in days.
"""

from __future__ import annotations

from collections.abc import Callable

from nfwserver.clock import Clock
from nfwserver.core.state import StationState
from nfwserver.easycomm.output import EasyCommOutput
from nfwserver.radio.coupling import RadioCoupling
from nfwserver.rotor.coupling import RotorCoupling


def device_status(rotor: RotorCoupling | None, radio: RadioCoupling | None,
                  easycomm: EasyCommOutput | None) -> Callable[[], dict[str, object]]:
    """A callable giving ``rotor``/``rotor_az``/``rotor_el``/``rotor_target``, ``radio``/``radio_rx``/
    ``radio_tx`` and ``easycomm`` fields for the devices that are configured."""

    def fields() -> dict[str, object]:
        out: dict[str, object] = {}
        if rotor is not None:
            _, _, target_el, target_az = rotor.driver.positions()
            position = rotor.driver.rotor_position()
            out["rotor"] = rotor.driver.link_state()
            if position is not None:
                out["rotor_az"], out["rotor_el"] = f"{position[0]:.1f}", f"{position[1]:.1f}"
            if target_az is not None and target_el is not None:
                out["rotor_target"] = f"{target_az:.1f}/{target_el:.1f}"
        if radio is not None:
            out["radio"] = radio.link_state()
            result = radio.current_result()
            if result is not None:
                out["radio_rx"] = result.rx_hz
                if result.tx_hz:
                    out["radio_tx"] = result.tx_hz
        if easycomm is not None:
            out["easycomm"] = "open" if easycomm.connected else "closed"
        return out

    return fields


def elements_status(state: StationState, clock: Clock, stale_days: float) -> Callable[[], dict[str, object]]:
    """A callable giving ``elements_age_d`` (days since the selected satellite's epoch, one decimal) and
    ``elements_stale`` (``yes`` when that is more than ``stale_days``, ``[elements] stale_days``), or nothing
    when no satellite with elements is selected."""

    def fields() -> dict[str, object]:
        sat = state.selected()
        if sat is None:
            return {}
        age = sat.age_days(clock.now())
        return {"elements_age_d": f"{age:.1f}", "elements_stale": "yes" if age > stale_days else "no"}

    return fields


def combined(*parts: Callable[[], dict[str, object]]) -> Callable[[], dict[str, object]]:
    """One fields callable from several, in order."""

    def fields() -> dict[str, object]:
        out: dict[str, object] = {}
        for part in parts:
            out.update(part())
        return out

    return fields

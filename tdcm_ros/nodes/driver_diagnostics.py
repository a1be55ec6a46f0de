"""The tension device's hardware components as ``/diagnostics`` checks of ``tension_driver``.

``serial link`` (link state, firmware, link counters), ``load cell`` (fresh readings, SENSOR and
CAL faults) and ``actuator`` (mode, latched OVER/WATCHDOG/ESTOP faults, armed, setpoints, the
schedule, the roll servo). Every status of a component carries the same keys, also before the
driver's first step (a diagnostics timer may fire first). Each reports the component as it is now (:mod:`tdcm_ros.runtime.diagnostics`), so a
level recovers with the component: the link reconnects, readings flow again, faults are cleared.
"""

from __future__ import annotations

from collections.abc import Mapping

from tdcm_ros.device import DriverStatus, Fault, LinkState, Mode, fault_names
from tdcm_ros.runtime import DiagnosticLevel, Status

OK, WARN, ERROR, STALE = (DiagnosticLevel.OK, DiagnosticLevel.WARN, DiagnosticLevel.ERROR,
                          DiagnosticLevel.STALE)
#: Faults of the load cell; the others (OVER_TENSION, WATCHDOG, ESTOP) released the actuator.
CELL_FAULTS = Fault.SENSOR | Fault.CALIBRATION
#: The message of every component before the driver's first step; the values carry the same
#: keys as later, empty (or 0 for counters), so a reader never misses one.
NOT_STEPPED = "not stepped yet"
LINK_COUNTERS = ("reconnects", "rejected_lines", "nacks", "version_mismatches",
                 "telemetry_frames")


def serial_link(status: DriverStatus | None, counts: Mapping[str, int]) -> Status:
    """ERROR while disconnected, WARN while handshaking, OK once connected."""
    banner = status.banner if status else None
    values = {"link": status.link.value if status else "",
              "firmware": banner.firmware if banner else "",
              "reconnects": status.reconnects if status else 0,
              "rejected_lines": status.rejected_lines if status else 0,
              "nacks": status.nacks if status else 0,
              "version_mismatches": counts.get("version_mismatches", 0),
              "telemetry_frames": counts.get("telemetry_frames", 0)}
    if status is None:
        return Status(STALE, NOT_STEPPED, values)
    if status.link is LinkState.DISCONNECTED:
        return Status(ERROR, status.message, values)
    if status.link is LinkState.HANDSHAKING:
        return Status(WARN, status.message, values)
    return Status(OK, f"connected: firmware {values['firmware']}", values)


def load_cell(status: DriverStatus | None) -> Status:
    """STALE without fresh readings, ERROR with a SENSOR or CAL fault latched, else OK."""
    latest = status.telemetry if status else None
    banner = status.banner if status else None
    values = {"tension": f"{latest.tension:.3f}" if latest else "",
              "raw_counts": str(latest.raw) if latest else "",
              "device_time": f"{latest.time:.3f}" if latest else "",
              "cell": banner.cell if banner else ""}
    if status is None:
        return Status(STALE, NOT_STEPPED, values)
    if status.link is not LinkState.CONNECTED:
        return Status(STALE, f"no readings: link {status.link.value}", values)
    if int(status.level) == STALE:
        return Status(STALE, status.message, values)
    if latest is None:
        return Status(STALE, "connected, no readings yet", values)
    if latest.faults & CELL_FAULTS:
        return Status(ERROR, f"device fault {fault_names(latest.faults & CELL_FAULTS)}; tendon "
                             f"released", values)
    return Status(OK, f"tension {latest.tension:.3f} N", values)


def _roll_values(status: DriverStatus | None, roll_max: float) -> dict[str, str]:
    """The roll servo's fields (rad): where it is, its device target, the host's target and
    slewed setpoint (empty: none), and the limit."""
    roll = status.roll if status else None

    def rad(value: float | None) -> str:
        return "" if value is None else f"{value:.3f}"

    return {"roll": rad(roll.position if roll else None),
            "roll_device_target": rad(roll.target if roll else None),
            "roll_target": rad(status.roll_target if status else None),
            "roll_setpoint": rad(status.roll_setpoint if status else None),
            "roll_pulse_us": str(roll.pulse_us) if roll else "", "roll_max": f"{roll_max:g}"}


def actuator(status: DriverStatus | None, *, tension_max: float, schedule_state: str,
             counts: Mapping[str, int], last_warning: str, clamped_recently: int,
             roll_max: float) -> Status:
    """ERROR with an OVER, WATCHDOG or ESTOP fault latched (the device released, the roll
    held), WARN while disarmed or after a setpoint was clamped within the window, else OK."""
    latest = status.telemetry if status else None
    values = {
        "mode": latest.mode.name.lower() if latest else "",
        "faults": fault_names(latest.faults) if latest else "",
        "pulse_us": str(latest.pulse_us) if latest else "",
        "target": f"{status.target:.3f}" if status else "",
        "setpoint": f"{status.setpoint:.3f}" if status else "",
        "tension_max": f"{tension_max:g}",
        "enabled": str(status.enabled).lower() if status else "",
        "armed": str(status.armed).lower() if status else "",
        "disarm_reason": status.disarm_reason if status else "",
        "schedule": schedule_state, "schedule_done": str(schedule_state == "done").lower(),
        "disarms": status.disarms if status else 0,
        **{key: counts.get(key, 0) for key in ("clamped_setpoints", "rejected_setpoints",
                                                "estops", "clamped_rolls", "rejected_rolls",
                                                "graph_losses", "graph_interruptions")},
        **_roll_values(status, roll_max),
        "last_warning": last_warning}
    if status is None:
        return Status(STALE, NOT_STEPPED, values)
    if latest is not None and latest.faults & ~CELL_FAULTS:
        return Status(ERROR, f"device fault {fault_names(latest.faults)}; tendon released, "
                             f"roll held", values)
    if not status.armed:
        return Status(WARN, f"disarmed ({status.disarm_reason}): tendon held released; call "
                            f"clear_faults to arm, then a new setpoint", values)
    if latest is None:
        return Status(STALE, "mode unknown: no telemetry yet", values)
    mode = "tensioning" if latest.mode is Mode.TENSION else "released"
    text = f"{mode}: tension {latest.tension:.3f} N, setpoint {status.setpoint:.3f} N"
    if clamped_recently:
        return Status(WARN, f"{text}; setpoint clamped to [0, {tension_max:g}] N", values)
    return Status(OK, text, values)

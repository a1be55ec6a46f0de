"""The tension device's hardware components as ``/diagnostics`` checks of ``tension_driver``.

``serial link`` (link state, firmware, link counters), ``load cell`` (fresh readings, SENSOR and
CAL faults) and ``actuator`` (mode, latched OVER/WATCHDOG/ESTOP faults, armed, setpoints, the
schedule, the roll servo). Each reports the component as it is now (:mod:`tdcm_ros.runtime.diagnostics`), so a
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
LINK_COUNTERS = ("reconnects", "rejected_lines", "nacks", "version_mismatches",
                 "telemetry_frames")


def serial_link(status: DriverStatus | None, counts: Mapping[str, int]) -> Status:
    """ERROR while disconnected, WARN while handshaking, OK once connected."""
    if status is None:
        return Status(STALE, "not stepped yet")
    banner = status.banner
    values = {"link": status.link.value, "firmware": banner.firmware if banner else "",
              "reconnects": status.reconnects, "rejected_lines": status.rejected_lines,
              "nacks": status.nacks, "version_mismatches": counts.get("version_mismatches", 0),
              "telemetry_frames": counts.get("telemetry_frames", 0)}
    if status.link is LinkState.DISCONNECTED:
        return Status(ERROR, status.message, values)
    if status.link is LinkState.HANDSHAKING:
        return Status(WARN, status.message, values)
    return Status(OK, f"connected: firmware {values['firmware']}", values)


def load_cell(status: DriverStatus | None) -> Status:
    """STALE without fresh readings, ERROR with a SENSOR or CAL fault latched, else OK."""
    if status is None:
        return Status(STALE, "not stepped yet")
    latest, banner = status.telemetry, status.banner
    values = {"tension": f"{latest.tension:.3f}" if latest else "",
              "raw_counts": str(latest.raw) if latest else "",
              "device_time": f"{latest.time:.3f}" if latest else "",
              "cell": banner.cell if banner else ""}
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


def _roll_values(status: DriverStatus, roll_max: float) -> dict[str, str]:
    """The roll servo's fields (rad): where it is, its device target, the host's target and
    slewed setpoint (empty: none), and the limit."""
    roll = status.roll

    def rad(value: float | None) -> str:
        return "" if value is None else f"{value:.3f}"

    return {"roll": rad(roll.position if roll else None),
            "roll_device_target": rad(roll.target if roll else None),
            "roll_target": rad(status.roll_target), "roll_setpoint": rad(status.roll_setpoint),
            "roll_pulse_us": str(roll.pulse_us) if roll else "", "roll_max": f"{roll_max:g}"}


def actuator(status: DriverStatus | None, *, tension_max: float, schedule_state: str,
             counts: Mapping[str, int], last_warning: str, clamped_recently: int,
             roll_max: float) -> Status:
    """ERROR with an OVER, WATCHDOG or ESTOP fault latched (the device released, the roll
    held), WARN while disarmed or after a setpoint was clamped within the window, else OK."""
    if status is None:
        return Status(STALE, "not stepped yet")
    latest = status.telemetry
    values = {
        "mode": latest.mode.name.lower() if latest else "",
        "faults": fault_names(latest.faults) if latest else "",
        "pulse_us": str(latest.pulse_us) if latest else "",
        "target": f"{status.target:.3f}", "setpoint": f"{status.setpoint:.3f}",
        "tension_max": f"{tension_max:g}", "enabled": str(status.enabled).lower(),
        "armed": str(status.armed).lower(), "disarm_reason": status.disarm_reason,
        "schedule": schedule_state, "schedule_done": str(schedule_state == "done").lower(),
        "disarms": status.disarms,
        **{key: counts.get(key, 0) for key in ("clamped_setpoints", "rejected_setpoints",
                                                "estops", "clamped_rolls", "rejected_rolls")},
        **_roll_values(status, roll_max),
        "last_warning": last_warning}
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

"""Protocol transcripts: one scenario, replayed against the Python core and the firmware core.

A transcript is a JSON-lines file; each line is one step:

``{"eeprom": [tare, scale_mcpn]}``  store a valid calibration record (before boot)
``{"boot": true}``                   boot the device at the current time (t = 0 ms at start)
``{"sensor": counts}`` / ``null``    the load cell delivers this reading every ms, or nothing
``{"send": "text"}``                 bytes from the host (the string's code points 0-255)
``{"advance_ms": n}``                advance time n ms (each ms: sample, then tick)
``{"expect": ["line", ...]}``        every line the device sent since the previous expect
``{"note": "text"}``                 a comment

Steps become the script language of ``firmware/host/sim_main.cpp``; :func:`run_core` runs the
same script on :class:`~tdcm_ros.device.core.TensionCore`, so both produce comparable output.
``python -m tdcm_ros.device.transcript record FILE`` rewrites a file's expectations from the
Python core (review the diff by hand before committing it).
"""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from tdcm_ros.device import constants as c
from tdcm_ros.device.core import TensionCore, pack_calibration
from tdcm_ros.device.errors import DeviceInputError

MARK = "%%"
CELL = "SIM"  #: load-cell name both harnesses put in the banner


def load(path: Path) -> list[dict[str, Any]]:
    """Read a transcript file."""
    steps = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    for number, step in enumerate(steps, 1):
        if len(step) != 1 or next(iter(step)) not in _KEYS:
            raise DeviceInputError(f"{path}:{number}: step = {step!r}; allowed: one of "
                                   f"{sorted(_KEYS)}", parameter="step", value=step,
                                   allowed=str(sorted(_KEYS)))
    return steps


def to_script(steps: Sequence[dict[str, Any]]) -> str:
    """The harness script for ``steps``; each ``expect`` becomes a ``mark``."""
    lines: list[str] = []
    for step in steps:
        key, value = next(iter(step.items()))
        if key == "eeprom":
            lines.append(f"eeprom {int(value[0])} {int(value[1])}")
        elif key == "boot":
            lines.append("boot")
        elif key == "sensor":
            lines.append("sensor off" if value is None else f"sensor {int(value)}")
        elif key == "send":
            lines.append(f"rx {value.encode('latin-1').hex()}")
        elif key == "advance_ms":
            lines.append(f"adv {int(value)}")
        elif key == "expect":
            lines.append("mark")
    return "\n".join(lines) + "\n"


def run_core(script: str) -> str:
    """Run a harness script on the Python core; returns what the device wrote (plus marks)."""
    out = bytearray()
    storage = bytearray(b"\xff" * c.EEPROM_RECORD_SIZE)
    core = TensionCore(storage, cell=CELL, send=out.extend)
    now, sensor = 0, None
    for line in script.splitlines():
        command, _, arg = line.partition(" ")
        if command == "eeprom":
            tare, scale = (int(part) for part in arg.split())
            storage[:] = pack_calibration(tare, scale)
        elif command == "boot":
            core.boot(now)
        elif command == "sensor":
            sensor = None if arg == "off" else int(arg)
        elif command == "rx":
            core.receive(bytes.fromhex(arg), now)
        elif command == "adv":
            for _ in range(int(arg)):
                now += 1
                if sensor is not None:
                    core.sample(sensor, now)
                core.tick(now)
        elif command == "mark":
            out.extend(f"{MARK}\n".encode())
    return out.decode("ascii")


def run_harness(executable: Path, script: str, *, timeout: float = 30.0) -> str:
    """Run a harness script on the compiled firmware harness."""
    done = subprocess.run([str(executable)], input=script, capture_output=True, text=True,
                          timeout=timeout, check=True)
    return done.stdout


def segments(output: str) -> list[list[str]]:
    """Output split at the marks: one list of lines per ``expect`` step."""
    parts: list[list[str]] = [[]]
    for line in output.splitlines():
        if line == MARK:
            parts.append([])
        else:
            parts[-1].append(line)
    return parts[:-1]


def mismatches(steps: Sequence[dict[str, Any]], output: str) -> list[str]:
    """Human-readable differences between the expectations and ``output`` (empty: all match)."""
    expected = [step["expect"] for step in steps if "expect" in step]
    got = segments(output)
    problems = [] if len(got) == len(expected) else [
        f"{len(got)} segments, expected {len(expected)}"]
    for index, (want, have) in enumerate(zip(expected, got, strict=False)):
        if want != have:
            problems.append(f"expect #{index + 1}: wanted {want}, got {have}")
    return problems


def record(steps: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """``steps`` with every expectation replaced by what the Python core produced."""
    got = iter(segments(run_core(to_script(steps))))
    return [{"expect": next(got)} if "expect" in step else dict(step) for step in steps]


_KEYS = frozenset({"eeprom", "boot", "sensor", "send", "advance_ms", "expect", "note"})


def main(argv: Sequence[str] | None = None) -> int:
    """``record FILE``: rewrite the expectations of FILE from the Python core."""
    args = list(sys.argv[1:] if argv is None else argv)
    if len(args) != 2 or args[0] != "record":
        print("usage: python -m tdcm_ros.device.transcript record FILE", file=sys.stderr)
        return 2
    path = Path(args[1])
    steps = record(load(path))
    path.write_text("".join(json.dumps(step) + "\n" for step in steps))
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""The UNO build of the firmware, run in simavr with its UART driven through a small libsimavr
bridge (firmware/host/simavr_uart.c): banner, NACK, e-stop and the 50 Hz telemetry on the AVR."""

from __future__ import annotations

import itertools
import shutil
import subprocess
from pathlib import Path

import pytest

from tdcm_ros.device.protocol import (
    Ack,
    Banner,
    EStop,
    Fault,
    Info,
    LineDecoder,
    Mode,
    Nack,
    Reject,
    SetMode,
    Telemetry,
    encode,
)

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def simulator(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    needed = [Path("/usr/share/arduino/Arduino.mk"), Path("/usr/include/simavr/sim_avr.h")]
    missing = [str(p) for p in needed if not p.exists()]
    missing += [tool for tool in ("avr-gcc", "make", "cc") if shutil.which(tool) is None]
    if missing:
        pytest.skip(f"simavr test needs arduino-mk, gcc-avr, libsimavr-dev, libelf-dev: "
                    f"missing {missing}")
    out = tmp_path_factory.mktemp("avr")
    subprocess.run(["make", "-s", "-C", str(ROOT / "firmware" / "tdcm_tension"),
                    f"OBJDIR={out / 'build'}"], check=True, capture_output=True)
    bridge = out / "simavr_uart"
    source = ROOT / "firmware" / "host" / "simavr_uart.c"
    subprocess.run(["cc", "-O1", "-o", str(bridge), str(source), "-lsimavr", "-lelf"],
                   check=True, capture_output=True)
    return bridge, out / "build" / "tdcm_tension.elf"


def test_firmware_talks_protocol_in_simavr(simulator: tuple[Path, Path]) -> None:
    bridge, elf = simulator
    script = "".join(f"{ms} {data.hex()}\n" for ms, data in [
        (300, encode(Info())), (400, b"$1,S,4.000*00\n"), (500, encode(SetMode(Mode.TENSION))),
        (600, encode(EStop()))])
    done = subprocess.run([str(bridge), str(elf), "0.8"], input=script, capture_output=True,
                          text=True, timeout=120, check=True)
    decoder = LineDecoder()
    messages = decoder.feed(done.stdout.encode())
    assert set(decoder.rejects) <= {Reject.NOISE}  # simavr's own "Loaded ..." lines
    replies = [m for m in messages if not isinstance(m, Telemetry)]
    banner = replies[0]
    assert isinstance(banner, Banner) and banner.cell == "HX711"
    # blank EEPROM in the simulator: CAL fault, so mode T is refused
    assert replies[1:] == [banner, Nack("?", Reject.CKSUM), Nack("M", Reject.FAULT), Ack("E")]
    telemetry = [m for m in messages if isinstance(m, Telemetry)]
    assert len(telemetry) >= 35
    assert all(round((b.time - a.time) * 1000) == 20 for a, b in itertools.pairwise(telemetry))
    assert telemetry[-1].faults == Fault.CALIBRATION | Fault.ESTOP
    assert telemetry[-1].pulse_us == 1000

"""The UNO build of the firmware, run in simavr with its UART driven through a small libsimavr
bridge (firmware/host/simavr_uart.c): banner, NACK, e-stop, the 50 Hz telemetry and the roll
servo on the AVR."""

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
    RollState,
    SetMode,
    SetRoll,
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


def test_roll_servo_in_simavr(simulator: tuple[Path, Path]) -> None:
    """On the AVR too: R is accepted despite the CAL fault of the blank EEPROM, J frames follow
    every T from then on, slewing 40 mrad per tick; after an e-stop R is refused FAULT."""
    bridge, elf = simulator
    script = "".join(f"{ms} {data.hex()}\n" for ms, data in [
        (300, encode(SetRoll(0.3))), (500, encode(EStop())), (520, encode(SetRoll(-0.3)))])
    done = subprocess.run([str(bridge), str(elf), "0.8"], input=script, capture_output=True,
                          text=True, timeout=120, check=True)
    messages = LineDecoder().feed(done.stdout.encode())
    replies = [m for m in messages if isinstance(m, Ack | Nack)]
    assert replies == [Ack("R"), Ack("E"), Nack("R", Reject.FAULT)]
    first = messages.index(Ack("R"))
    assert not any(isinstance(m, RollState) for m in messages[:first])
    after = messages[first + 1:]
    kinds = [type(m) for m in after if isinstance(m, Telemetry | RollState)]
    assert kinds[:10] == [Telemetry, RollState] * 5
    rolls = [m for m in after if isinstance(m, RollState)]
    assert [round(r.position * 1000) for r in rolls[:8]] == [40, 80, 120, 160, 200, 240, 280, 300]
    assert rolls[7].pulse_us == 1500 + 300 * 637 // 1000
    assert len(rolls) >= 20 and rolls[-1].position == rolls[-1].target  # held after the e-stop

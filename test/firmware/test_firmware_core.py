"""The firmware core compiled for the host with g++ runs the shared transcripts, agrees with the
Python core byte for byte on random input, and uses the same constants."""

from __future__ import annotations

import random
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from tdcm_ros.device import constants
from tdcm_ros.device.protocol import Mode, SetMode, SetRoll, SetSetpoint, encode
from tdcm_ros.device.transcript import (
    load,
    mismatches,
    run_core,
    run_harness,
    to_script,
)

ROOT = Path(__file__).resolve().parents[2]
FIRMWARE = ROOT / "firmware"
TRANSCRIPTS = sorted((ROOT / "test" / "device" / "transcripts").glob("*.jsonl"))


@pytest.fixture(scope="module")
def harness(tmp_path_factory: pytest.TempPathFactory) -> Path:
    compiler = shutil.which("g++")
    if compiler is None:
        pytest.skip("g++ not found: the host build of the firmware core cannot be tested")
    out = tmp_path_factory.mktemp("firmware") / "sim"
    core = FIRMWARE / "tdcm_tension"
    subprocess.run([compiler, "-std=c++11", "-O1", "-Wall", "-Wextra", "-Werror",
                    "-fsanitize=undefined", "-fno-sanitize-recover", "-o", str(out),
                    str(FIRMWARE / "host" / "sim_main.cpp"), str(core / "tension_core.cpp"),
                    str(core / "protocol.cpp")], check=True, capture_output=True, text=True)
    return out


@pytest.mark.parametrize("path", TRANSCRIPTS, ids=lambda p: p.stem)
def test_transcript_on_firmware_core(harness: Path, path: Path) -> None:
    steps = load(path)
    assert mismatches(steps, run_harness(harness, to_script(steps))) == []


def _random_script(seed: int, extra: tuple[bytes, ...] = ()) -> str:
    rng = random.Random(seed)
    lines = ["eeprom 8000 1000000" if rng.random() < 0.8 else "", "boot"]
    pieces = [encode(SetSetpoint(rng.randint(0, 22000) / 1000)), encode(SetMode(Mode.TENSION)),
              b"$1,H*79\n", b"$1,E*58\n", b"$1,C*5E\n", b"$1,Z*47\n", b"$1,K,1.000*55\n",
              b"$1,M,R*2E\n", b"$1,I*54\n"]
    pieces += [pieces[1], pieces[1], b"$1,C*5E\n", b"$1,C*5E\n", b"$1,H*79\n", b"$1,H*79\n"]
    pieces += list(extra)
    for _ in range(150):
        roll = rng.random()
        if roll < 0.35:
            data = rng.choice(pieces)
            if rng.random() < 0.3:  # corrupt one byte
                position = rng.randrange(len(data))
                data = data[:position] + bytes([rng.randrange(256)]) + data[position + 1:]
            lines.append(f"rx {data.hex()}")
        elif roll < 0.45:
            lines.append(f"rx {bytes(rng.randrange(256) for _ in range(rng.randint(1, 90))).hex()}")
        elif roll < 0.6:
            lines.append("sensor off" if rng.random() < 0.05 else
                         f"sensor {rng.randint(-2000, 30000) if rng.random() < 0.9 else 33001}")
        else:
            # mostly whole control periods, so exact boundaries (e.g. the watchdog) are hit
            steps = [20, 40, 100, 240, 500]
            lines.append(f"adv {rng.choice(steps) if rng.random() < 0.95 else rng.randint(1, 99)}")
    return "\n".join(line for line in lines if line) + "\nmark\n"


@pytest.mark.parametrize("seed", range(20))
def test_random_sessions_agree_with_python_core(harness: Path, seed: int) -> None:
    script = _random_script(seed)
    firmware, python = run_harness(harness, script), run_core(script)
    assert firmware.count("\n") > 10
    assert firmware == python


@pytest.mark.parametrize("seed", range(10))
def test_random_roll_sessions_agree_with_python_core(harness: Path, seed: int) -> None:
    rng = random.Random(1000 + seed)
    rolls = tuple(encode(SetRoll(rng.randint(-constants.ROLL_MAX_MRAD, constants.ROLL_MAX_MRAD)
                                 / 1000)) for _ in range(6))
    script = _random_script(1000 + seed, rolls + (b"$1,R,1.572*4C\n", b"$1,R,-0.000*60\n"))
    firmware, python = run_harness(harness, script), run_core(script)
    assert ",R" in firmware  # R was decoded (accepted, or refused FAULT/RANGE/FIELDS)
    assert firmware == python


def _firmware_constants() -> dict[str, object]:
    text = (FIRMWARE / "tdcm_tension" / "config.h").read_text()
    values: dict[str, object] = {}
    for name, expression in re.findall(r"constexpr int32_t (\w+) = ([^;]+);", text):
        values[name] = eval(expression, {}, dict(values))  # arithmetic on earlier names only
    values["FIRMWARE_VERSION"] = re.search(r'#define TDCM_FIRMWARE_VERSION "([^"]+)"', text)[1]
    return values


def test_constants_match() -> None:
    firmware = _firmware_constants()
    python = {name: value for name, value in vars(constants).items() if name.isupper()}
    assert len(firmware) >= 25
    assert firmware == python

"""Plant, twin CLI (threaded, over a pty) and the pyserial transports."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
import serial

from tdcm_ros.device.errors import PortError
from tdcm_ros.device.plant import Plant, PlantConfig
from tdcm_ros.device.protocol import Banner, Info, LineDecoder, Telemetry, encode
from tdcm_ros.device.transport import open_transport
from tdcm_ros.errors import InputError
from test.support.waiting import eventually


def test_plant_noise_is_seeded_and_quantised() -> None:
    config = PlantConfig(noise=0.5, quantum=8, seed=3)
    first, second = Plant(config), Plant(config)
    readings = [first.read_counts() for _ in range(50)]
    assert readings == [second.read_counts() for _ in range(50)]
    assert all(r % 8 == 0 for r in readings) and len(set(readings)) > 5


def test_plant_lag_rate_and_stiffness() -> None:
    plant = Plant(PlantConfig(stroke=0.02, rate=0.01, lag=0.01, stiffness=1000.0, slack=0.002))
    plant.step(2000, 0.1)
    assert plant.position == pytest.approx(0.001)  # rate-limited: 10 mm/s for 0.1 s
    for _ in range(5000):
        plant.step(1500, 0.001)
    assert plant.position == pytest.approx(0.01)
    assert plant.tension == pytest.approx(8.0)  # 1 N/mm over 8 mm past the slack


def test_plant_config_errors_name_the_parameter() -> None:
    with pytest.raises(InputError, match="stiffness = -1"):
        PlantConfig(stiffness=-1.0)


def test_twin_cli_serves_a_pty_and_stops_cleanly(tmp_path: Path) -> None:
    link = tmp_path / "port"
    process = subprocess.Popen([sys.executable, "-m", "tdcm_ros.device.twin", "--print-port",
                                "--link", str(link), "--speed", "4", "--stiffness", "1500"],
                               stdout=subprocess.PIPE, text=True)
    try:
        assert process.stdout is not None
        assert process.stdout.readline().strip() == str(link)
        with serial.Serial(str(link), 115200, timeout=5.0) as port:
            port.write(encode(Info()))
            decoder, got = LineDecoder(), []
            while not any(isinstance(m, Banner) for m in got):
                line = port.readline()
                assert line, "no banner within 5 s"
                got.extend(decoder.feed(line))
            while not any(isinstance(m, Telemetry) for m in got):
                line = port.readline()
                assert line, "no telemetry within 5 s"
                got.extend(decoder.feed(line))
    finally:
        process.send_signal(signal.SIGTERM)
        try:
            status = process.wait(timeout=10)
        finally:
            if process.poll() is None:  # never leave it running past the test
                process.kill()
                process.wait()
    assert status == 0
    assert not os.path.lexists(link)


def test_loop_url_transport_round_trip() -> None:
    """``loop://`` has no file descriptor: the reader thread reads it through pyserial."""
    transport = open_transport("loop://")
    got = bytearray()
    transport.write(b"$1,H*79\n")
    eventually(lambda: got.extend(transport.read()) or bytes(got) == b"$1,H*79\n", 5.0,
               "the looped-back line")
    assert transport.read() == b""
    transport.close()


def test_missing_port_is_a_port_error(tmp_path: Path) -> None:
    with pytest.raises(PortError, match="cannot open"):
        open_transport(str(tmp_path / "nothing"))


def test_line_delay_holds_the_devices_lines_back_in_order() -> None:
    """With ``line_delay`` what the device sends reaches the host only after the delay, whole
    lines in order; a negative delay is a typed error."""
    from tdcm_ros.device.twin import DeviceTwin, PtyTwin

    host_s = [100.0]  # the twin's host clock, moved by the test
    server = PtyTwin(DeviceTwin(), line_delay=lambda: 0.3, clock=lambda: host_s[0])
    host = os.open(server.port, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)

    def read() -> bytes:
        try:
            return os.read(host, 65536)
        except BlockingIOError:
            return b""

    try:
        server.pump(0.1)                          # banner and telemetry, all held back
        assert read() == b""
        host_s[0] += 0.299
        server.pump(0.0)
        assert read() == b""                      # 1 ms short of the delay: still held
        host_s[0] += 0.001
        server.pump(0.0)
        lines = read().split(b"\n")
        assert len(lines) > 2 and lines[-1] == b""
        decoder = LineDecoder()
        frames = [m for line in lines[:-1] for m in decoder.feed(line + b"\n")]
        assert isinstance(frames[0], Banner)
        times = [f.time for f in frames if isinstance(f, Telemetry)]
        assert times == sorted(times) and times
        server.line_delay = lambda: -1.0
        server.twin.receive(encode(Info()))
        with pytest.raises(InputError, match="line_delay"):
            server.pump(0.05)
    finally:
        os.close(host)
        server.stop()

"""Device twin: the firmware's logic (:class:`~tdcm_ros.device.core.TensionCore`) on a simulated
bench (:class:`~tdcm_ros.device.plant.Plant`), served behind a real pty.

:class:`DeviceTwin` has no I/O and runs in simulated time (1 ms steps). :class:`PtyTwin` puts it
behind ``os.openpty``: either pumped by the caller (:meth:`PtyTwin.pump`, lock-step tests) or by
its own thread (:meth:`PtyTwin.start`) at ``speed`` times real time. Command line::

    python -m tdcm_ros.device.twin --print-port [--link PATH] [--speed 1.0] [--stiffness 2000]

prints the port path (the symlink if ``--link`` is given) on stdout and serves until SIGINT or
SIGTERM.
"""

from __future__ import annotations

import argparse
import bisect
import errno
import math
import os
import select
import signal
import sys
import threading
import time
import tty
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import fields
from typing import Self

from tdcm_ros.device.core import TensionCore, pack_calibration
from tdcm_ros.device.errors import DeviceInputError
from tdcm_ros.device.plant import ROLL_SPEED, Plant, PlantConfig
from tdcm_ros.errors import out_of_range

TRUTH_KEPT = 4096  #: ground-truth samples kept until taken (older ones are dropped)
RX_BUFFER = 64     #: bytes the UNO's serial receive buffer holds while its loop does not read
#: Host s: a turn of the threaded twin later than this after the last one is *late* (its thread
#: was not scheduled): the host's bytes of the gap reach the device spread over it. It is the
#: driver's default heartbeat period.
LATE_TURN_S = 0.1

#: Queue depth (samples) of the truth topics (``sim/tension_true``,
#: ``sim/joint_states_true``) at the twin and at mocap_node: a backlog of 4 s of a
#: 1 kHz truth (51 s at the twin's default 80 Hz) is delivered whole. With depth 10, a mocap_node
#: 3.7 s behind on a loaded machine kept 10 samples of its backlog and interpolated across the
#: rest: the body bent 0.4 s before the tendon pulled (a red CI, the ideal demo on rclpy).
TRUTH_DEPTH = 4096

#: Host s: the longest gap between two turns that the threaded twin catches up; a longer one (a
#: suspended process) is a pause of the simulation for the rest.
MAX_GAP = 2.0


class DeviceTwin:
    """Firmware core + plant in simulated time; ``output`` collects the bytes it sends.

    The EEPROM starts with a calibration matching the plant's load cell unless ``storage``
    (an ``EEPROM_RECORD_SIZE`` byte buffer) is given; ``roll_speed`` (rad/s) is the roll servo's. At every load-cell sample ``truth`` gets
    ``(simulated time s, true tendon tension N)`` and ``roll_truth`` ``(simulated time s, true
    roll servo angle rad)`` (the newest ``TRUTH_KEPT`` of each are kept).

    Failures: :meth:`reboot` (a reset: fresh firmware state, boot banner, EEPROM kept) and
    :attr:`hung` (the firmware's loop stalls while time and the bench go on; see :meth:`advance`);
    the host bytes of a stall beyond the first ``rx_buffer`` are lost.
    """

    def __init__(self, plant: PlantConfig | None = None, *, cell: str = "TWIN",
                 storage: bytearray | None = None, rx_buffer: int = RX_BUFFER,
                 roll_speed: float = ROLL_SPEED) -> None:
        self.plant = Plant(plant or PlantConfig(), roll_speed=roll_speed)
        cfg = self.plant.config
        self.storage = storage if storage is not None else bytearray(
            pack_calibration(cfg.tare_counts, cfg.scale_mcpn))
        self.output = bytearray()
        self.truth: deque[tuple[float, float]] = deque(maxlen=TRUTH_KEPT)
        self.roll_truth: deque[tuple[float, float]] = deque(maxlen=TRUTH_KEPT)
        self.cell = cell
        self.core = TensionCore(self.storage, cell=cell, send=self.output.extend)
        self.now_ms = 0
        self._next_sample_ms = 0.0
        #: While true the firmware's loop is stalled; time and the bench go on (see
        #: :meth:`advance`).
        self.hung = False
        self.rx_buffer = rx_buffer
        self._held = bytearray()
        self._stalled = False
        self._boot_ms = 0
        self.core.boot(self.now_ms)

    def reboot(self) -> None:
        """Reset the device now (as a UNO does when its port is opened): fresh firmware state --
        released, no latched fault but CAL if the EEPROM is invalid, clock from 0 ms -- and a boot
        banner. The EEPROM, the bench and the simulated time go on."""
        self.core = TensionCore(self.storage, cell=self.cell, send=self.output.extend)
        self.core.boot(0)
        self._boot_ms = self.now_ms

    @property
    def time(self) -> float:
        """Simulated time, in s."""
        return self.now_ms / 1000

    @property
    def device_ms(self) -> int:
        """The firmware's clock (ms since its last boot)."""
        return self.now_ms - self._boot_ms

    def receive(self, data: bytes) -> None:
        """Bytes from the host arrive now; while :attr:`hung` the first ``rx_buffer`` of them
        wait in the receive buffer and the rest are lost."""
        if self.hung:
            self._held += data[:max(0, self.rx_buffer - len(self._held))]
            return
        if self._held:
            data, self._held = bytes(self._held) + data, bytearray()
        self.core.receive(data, self.device_ms)

    def advance(self, seconds: float) -> None:
        """Run the bench and the firmware for ``seconds`` of simulated time (1 ms steps).

        While :attr:`hung` the firmware neither samples, ticks nor sends: the actuator and the roll
        servo hold their last pulses. Once it is cleared, the buffered host bytes are read first."""
        if not self.hung and self._held:
            self.receive(b"")
        period_ms = self.plant.config.sample_period * 1000
        for _ in range(round(seconds * 1000)):
            self.now_ms += 1
            self.plant.step(self.core.pulse_us, 0.001, self.core.roll_pulse_us)
            due = self.now_ms >= self._next_sample_ms
            if due:
                self._next_sample_ms += period_ms
                self.truth.append((self.time, self.plant.tension))
                self.roll_truth.append((self.time, self.plant.roll))
            if self.hung:
                self._stalled = True
                continue
            if due or self._stalled:  # a resumed loop reads the load cell first
                self._stalled = False
                self.core.sample(self.plant.read_counts(), self.device_ms)
            self.core.tick(self.device_ms)

    def take_output(self) -> bytes:
        """Bytes sent since the last call."""
        data = bytes(self.output)
        self.output.clear()
        return data

    def take_truth(self) -> list[tuple[float, float]]:
        """Ground-truth samples ``(simulated time s, tension N)`` since the last call."""
        samples = list(self.truth)
        self.truth.clear()
        return samples

    def take_roll_truth(self) -> list[tuple[float, float]]:
        """Ground-truth roll samples ``(simulated time s, roll rad)`` since the last call."""
        samples = list(self.roll_truth)
        self.roll_truth.clear()
        return samples


class PtyTwin:
    """A :class:`DeviceTwin` behind a pty; :attr:`port` is the path a host opens.

    With ``link`` the port is a symlink to the current pty, kept pointing at the new one by
    :meth:`reopen` (a cable pulled and plugged back). Bytes the twin sends while nobody reads
    are dropped once the pty buffer is full, as a UART would. With ``line_delay``, each line the
    device sends reaches the pty ``line_delay()`` s (drawn per line) later, in order.

    The threaded twin maps simulated time onto host time (``clock``, monotonic s; ``epoch_ns``,
    ns since the epoch) at ``speed``. Each turn of its thread reads the host's bytes, then runs
    the simulated time due since the last turn. A turn more than ``LATE_TURN_S`` late (its thread
    was not scheduled: on a loaded machine up to 0.8 s, waiting for a CPU, for the GIL held by a
    preempted thread of its process, or in the tty layer, ``n_tty_poll`` waiting for the pty's
    flush worker) delivers the host's complete lines of the gap spread evenly over it, the
    ``k``-th of ``n`` at ``k/n`` of the gap, as a host writing steadily would have: a device
    given them all at the gap's start would then run the gap without a host byte and trip its
    watchdog although the host kept writing, and a simulation paused for the gap would put the
    bench behind the host's schedule (a 1.5 s hold cut short). Its output of the gap (readings
    carrying the device clock) leaves at the end of the turn. A gap longer than ``max_gap`` s of
    host time (a suspended process) is caught up to ``max_gap`` and a pause of the simulation for
    the rest. Truth samples keep their host times across pauses (:meth:`host_time_ns`);
    :attr:`late_turns`, :attr:`pauses` and :attr:`paused_s` count them.
    """

    def __init__(self, twin: DeviceTwin, *, speed: float = 1.0, link: str | None = None,
                 line_delay: Callable[[], float] | None = None, max_gap: float = MAX_GAP,
                 clock: Callable[[], float] = time.monotonic,
                 epoch_ns: Callable[[], int] = time.time_ns) -> None:
        if not speed > 0:
            raise out_of_range("speed", speed, "> 0", error=DeviceInputError)
        if not max_gap > 0:
            raise out_of_range("max_gap", max_gap, "> 0", unit="s", error=DeviceInputError)
        self.twin = twin
        self.line_delay = line_delay
        self._delayed: deque[tuple[float, bytes]] = deque()
        self._partial = b""
        self.speed = speed
        self.max_gap = max_gap
        self.link = link
        self._clock = clock
        self._epoch_ns = epoch_ns
        self.late_turns = 0   #: turns over ``LATE_TURN_S`` late (the host's bytes spread)
        self.pauses = 0       #: turns that did not catch up the whole gap (the simulation paused)
        self.paused_s = 0.0   #: host s the simulation paused in all
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._master = -1
        self._slave = -1
        self.pty_path = ""
        self._anchor()
        self._open()

    def _anchor(self) -> None:
        """Simulated time now is host time now; no pause yet."""
        self._start_wall, self._start_epoch_ns = self._clock(), self._epoch_ns()
        #: (simulated s, host monotonic s) from which simulated time runs at ``speed`` again
        #: after a pause; the first is the start.
        self._segments: list[tuple[float, float]] = [(self.twin.time, self._start_wall)]

    @property
    def port(self) -> str:
        """Path to open: the symlink if one was asked for, else the pty itself."""
        return self.link or self.pty_path

    def _open(self) -> None:
        self._master, self._slave = os.openpty()
        tty.setraw(self._slave)  # no echo, no line editing before the host configures it
        os.set_blocking(self._master, False)
        self.pty_path = os.ttyname(self._slave)
        if self.link:
            temporary = f"{self.link}.{os.getpid()}.tmp"
            os.symlink(self.pty_path, temporary)
            os.replace(temporary, self.link)

    def _close_fds(self) -> None:
        for fd in (self._master, self._slave):
            if fd >= 0:
                os.close(fd)
        self._master = self._slave = -1

    def reopen(self, *, reboot: bool = False) -> None:
        """Close the pty (the host's reads fail) and open a new one behind the same link; with
        ``reboot`` the device also resets (a UNO resets when its port is opened)."""
        with self._lock:
            self._close_fds()
            self._open()
            if reboot:
                self.twin.reboot()

    def _exchange(self) -> None:
        data = self._read_host()
        if data:
            self.twin.receive(data)

    def _read_host(self) -> bytes:
        """Every byte the host has written (b"" if none)."""
        data = bytearray()
        while True:  # all the host wrote, however long the twin was not scheduled
            try:
                chunk = os.read(self._master, 4096)
            except BlockingIOError:
                break
            data += chunk
            if len(chunk) < 4096:
                break
        return bytes(data)

    def _delay_lines(self, out: bytes) -> bytes:
        """Queue each complete line ``line_delay()`` s (host time) after now, in order (a serial
        line cannot reorder); return the bytes now due."""
        assert self.line_delay is not None
        now = self._clock()
        *lines, self._partial = (self._partial + out).split(b"\n")
        for line in lines:
            delay = float(self.line_delay())
            if not (math.isfinite(delay) and delay >= 0.0):
                raise out_of_range("line_delay", delay, "[0, inf)", unit="s",
                                   error=DeviceInputError)
            due = now + delay
            if self._delayed:
                due = max(due, self._delayed[-1][0])
            self._delayed.append((due, line + b"\n"))
        ready = bytearray()
        while self._delayed and self._delayed[0][0] <= now:
            ready += self._delayed.popleft()[1]
        return bytes(ready)

    def _flush(self) -> None:
        out = self.twin.take_output()
        if self.line_delay is not None:
            out = self._delay_lines(out)
        try:
            os.write(self._master, out)
        except BlockingIOError:
            return  # nobody reading: the bytes are lost, as on a real UART
        except OSError as error:
            if error.errno != errno.EIO:
                raise

    @contextmanager
    def frozen(self) -> Iterator[None]:
        """Inside this block the device and its bench pause (a stalled simulation; for a
        stalled firmware loop on a running bench see :meth:`hung`).

        The threaded twin then catches the block up with the host's bytes of it spread over it;
        past ``max_gap`` the rest is a pause of the simulated time (see the class).
        """
        with self._lock:
            yield

    @contextmanager
    def hung(self) -> Iterator[None]:
        """Inside this block the firmware's loop is stalled (:attr:`DeviceTwin.hung`): time and
        the bench go on, the actuator holds its pulse, nothing is sent, the host's first
        ``rx_buffer`` bytes wait to be read when the loop resumes at the end of the block."""
        with self._lock:
            self.twin.hung = True
        try:
            yield
        finally:
            with self._lock:
                self.twin.hung = False

    def pump(self, seconds: float) -> None:
        """Lock-step use: take the host's bytes, run ``seconds`` of simulated time, send output."""
        with self._lock:
            self._exchange()
            self.twin.advance(seconds)
            self._flush()

    def take_truth(self) -> list[tuple[int, float]]:
        """Ground-truth samples since the last call as ``(host time ns since the epoch, N)``.

        Meaningful for the threaded twin (:meth:`start`): simulated time maps onto host time at
        ``speed``. The samples are taken under the lock, so no sample is seen twice or lost
        (beyond ``TRUTH_KEPT`` untaken ones).
        """
        with self._lock:  # mapped under the lock: a pause may forget older mappings
            return [(self.host_time_ns(t), tension) for t, tension in self.twin.take_truth()]

    def take_roll_truth(self) -> list[tuple[int, float]]:
        """Ground-truth roll samples since the last call as ``(host time ns since the epoch,
        rad)``, taken like :meth:`take_truth`."""
        with self._lock:
            return [(self.host_time_ns(t), roll) for t, roll in self.twin.take_roll_truth()]

    def host_time_ns(self, sim_time: float) -> int:
        """Host time (ns since the epoch) at which the threaded twin reaches ``sim_time`` s:
        at ``speed`` from its start, shifted by every pause before ``sim_time`` (a time before
        the oldest pause still kept maps as if after it; pauses older than every untaken truth
        sample are forgotten)."""
        segments = self._segments
        index = max(0, bisect.bisect_right(segments, (sim_time, math.inf)) - 1)
        sim, host = segments[index]
        seconds = host - self._start_wall + (sim_time - sim) / self.speed
        return self._start_epoch_ns + round(seconds * 1e9)

    def turn(self) -> None:
        """One turn of the serving thread (:meth:`start` calls it in a loop): take the host's
        bytes, run the simulated time due at ``clock()`` -- a late turn with the host's lines
        spread over it, at most ``max_gap`` s of host time since the last turn and the rest a
        pause (see the class) -- and send the output."""
        with self._lock:
            # the clock after the read: a read of a pty waits for the kernel's flush worker while
            # no input is queued (n_tty_read, as n_tty_poll), so the bytes it returns may have
            # waited there for a second, and the gap they belong to ends now
            data = self._read_host()
            now = self._clock()
            sim, host = self._segments[-1]
            due = sim + (now - host) * self.speed - self.twin.time
            bound = self.max_gap * self.speed
            if due > bound:
                self.pauses += 1
                self.paused_s += (due - bound) / self.speed
                self._segments.append((self.twin.time, now - self.max_gap))
                self._forget_old_pauses()
                due = bound
            if due > LATE_TURN_S * self.speed:
                self.late_turns += 1
                self._spread(data, due)
            else:
                if data:
                    self.twin.receive(data)
                self.twin.advance(max(0.0, due))
            self._flush()

    def _spread(self, data: bytes, due: float) -> None:
        """Run ``due`` s of simulated time with the complete lines of ``data`` delivered evenly
        over it, the ``k``-th of ``n`` at ``k/n`` of it (to the simulated ms); a trailing partial
        line goes with the last one."""
        lines = data.split(b"\n")
        pieces = [line + b"\n" for line in lines[:-1]]
        if lines[-1]:
            if pieces:
                pieces[-1] += lines[-1]
            else:
                pieces.append(lines[-1])
        start_ms, due_ms = self.twin.now_ms, round(due * 1000)
        for k, piece in enumerate(pieces, start=1):
            at_ms = start_ms + due_ms * k // len(pieces)
            self.twin.advance((at_ms - self.twin.now_ms) / 1000)
            self.twin.receive(piece)
        self.twin.advance((start_ms + due_ms - self.twin.now_ms) / 1000)

    def _forget_old_pauses(self) -> None:
        """Drop the pauses no untaken truth sample (nor a future one) is mapped through."""
        twin = self.twin
        oldest = min([twin.time] + [samples[0][0] for samples in (twin.truth, twin.roll_truth)
                                    if samples])
        keep = max(0, bisect.bisect_right(self._segments, (oldest, math.inf)) - 1)
        del self._segments[:keep]

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                select.select([self._master], [], [], 0.002)
            except (OSError, ValueError):  # reopen() swapped the fd under us: just go on
                time.sleep(0.002)
            self.turn()

    def start(self) -> Self:
        """Serve from a daemon thread at ``speed`` times real time."""
        self._stop.clear()
        with self._lock:
            self._anchor()
        self._thread = threading.Thread(target=self._run, name="tdcm-twin", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        """Stop the thread (if any), close the pty and remove the link."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        with self._lock:
            self._close_fds()
        if self.link and os.path.islink(self.link):
            os.unlink(self.link)

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m tdcm_ros.device.twin",
                                     description="Serve the tension device twin on a pty.")
    parser.add_argument("--print-port", action="store_true", help="print the port path on stdout")
    parser.add_argument("--link", help="also expose the pty as this symlink")
    parser.add_argument("--speed", type=float, default=1.0, help="simulated / real time")
    parser.add_argument("--roll-speed", type=float, default=ROLL_SPEED,
                        help="roll servo speed limit (rad/s)")
    for field in fields(PlantConfig):
        parser.add_argument(f"--{field.name.replace('_', '-')}", type=type(field.default),
                            default=field.default, help=f"plant {field.name} (SI)")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """CLI entry: serve until SIGINT/SIGTERM."""
    args = _parser().parse_args(argv)
    plant = PlantConfig(**{f.name: getattr(args, f.name) for f in fields(PlantConfig)})
    server = PtyTwin(DeviceTwin(plant, roll_speed=args.roll_speed), speed=args.speed,
                     link=args.link)
    done = threading.Event()

    def on_signal(signum: int, frame: object) -> None:
        # set from another thread: Event.set in the handler waits for the Event's lock, which
        # this (main) thread may hold inside done.wait() when the signal lands there: a
        # deadlock that left the twin running after SIGTERM (seen in CI at cbea303)
        threading.Thread(target=done.set, daemon=True).start()

    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, on_signal)
    server.start()
    if args.print_port:
        print(server.port, flush=True)
    done.wait()
    server.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main())

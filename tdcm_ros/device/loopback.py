"""An in-process cable between a host (the driver) and a :class:`~tdcm_ros.device.twin.DeviceTwin`.

No I/O, no threads: bytes the host writes reach :meth:`.DeviceTwin.receive` at once and
:meth:`LoopbackLink.read` returns what the twin has sent since (:meth:`.DeviceTwin.take_output`).
Whoever advances the twin owns the time (:meth:`Loopback.pump`), so a driver stepped on the same
simulated clock runs in lock step with the device, deterministically::

    loop = Loopback(twin)
    driver = TensionDriver(config, clock=lambda: twin.time, open_port=loop.open)

A pty cannot give that lock step: the bytes written at one end reach the other through a kernel
worker, asynchronously (:class:`~tdcm_ros.device.transport.SerialTransport`).

:meth:`Loopback.unplug` pulls the cable (the open link's reads and writes raise
:class:`.PortError`, opening fails) until :meth:`Loopback.plug`; :meth:`Loopback.reopen` pulls and
plugs it back at once (like :meth:`.PtyTwin.reopen`), optionally rebooting the device. Bytes the
device sends while no link is open are lost, as on a UART nobody reads.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING

from tdcm_ros.device.errors import PortError

if TYPE_CHECKING:
    from tdcm_ros.device.twin import DeviceTwin


class LoopbackLink:
    """One open link (a :class:`~tdcm_ros.device.transport.Transport`); dead once the cable is
    pulled or it is closed."""

    def __init__(self, loopback: Loopback, url: str) -> None:
        self._loopback = loopback
        self.url = url
        self.closed = False

    @property
    def alive(self) -> bool:
        """True while this is the plugged-in, open link."""
        return not self.closed and self._loopback.link is self

    def _check(self, what: str) -> None:
        if not self.alive:
            raise PortError(f"port {self.url!r}: {what} failed: "
                            f"{'closed' if self.closed else 'cable pulled'}")

    def read(self) -> bytes:
        """What the device sent since the last read; never blocks."""
        self._check("read")
        return self._loopback.twin.take_output()

    def write(self, data: bytes) -> None:
        """Hand ``data`` to the device now."""
        self._check("write")
        self._loopback.writes += 1
        self._loopback.twin.receive(data)

    def close(self) -> None:
        """Release the link; the device's output is dropped until the next open."""
        self.closed = True
        if self._loopback.link is self:
            self._loopback.link = None


class Loopback:
    """The cable to ``twin``; :meth:`open` is a port opener for the driver."""

    def __init__(self, twin: DeviceTwin) -> None:
        self.twin = twin
        self.plugged = True
        self.link: LoopbackLink | None = None
        self.opens = 0    #: links opened so far
        self.writes = 0   #: writes by the host so far

    def open(self, url: str) -> LoopbackLink:
        """Open a new link (the device's earlier output is discarded, as a host flushes its
        input when it opens a port); :class:`.PortError` while unplugged."""
        if not self.plugged:
            raise PortError(f"port {url!r}: cannot open: cable pulled")
        if self.link is not None:
            self.link.close()
        self.twin.take_output()
        self.link = LoopbackLink(self, url)
        self.opens += 1
        return self.link

    def unplug(self) -> None:
        """Pull the cable: the open link fails from now on, opening fails until :meth:`plug`."""
        self.plugged = False
        self.link = None

    def plug(self, *, reboot: bool = False) -> None:
        """Plug the cable back; with ``reboot`` the device resets (a UNO does when its port is
        opened)."""
        self.plugged = True
        if reboot:
            self.twin.reboot()

    def reopen(self, *, reboot: bool = False) -> None:
        """Pull the cable and plug it back at once: the open link fails, the next open works."""
        self.unplug()
        self.plug(reboot=reboot)

    def pump(self, seconds: float) -> None:
        """Lock-step use (as :meth:`.PtyTwin.pump`): run ``seconds`` of simulated time; what the
        device sends waits for the open link's next read."""
        self.twin.advance(seconds)
        self.tick()

    @contextmanager
    def hung(self) -> Iterator[None]:
        """Inside this block the firmware's loop is stalled (as :meth:`.PtyTwin.hung`)."""
        self.twin.hung = True
        try:
            yield
        finally:
            self.twin.hung = False

    def tick(self) -> None:
        """Drop what the device sent while no link is open (call after advancing the twin)."""
        if self.link is None:
            self.twin.take_output()

"""Host times of device-clock times: the least-delay bound, its window and a reboot."""

from __future__ import annotations

from tdcm_ros.device.clock_map import WINDOW_S, DeviceClockMap

HOST0 = 1_800_000_000_000_000_000  #: ns since the epoch at device time 0


def test_the_least_delayed_read_sets_the_offset() -> None:
    clock = DeviceClockMap()
    clock.observe(1.0, HOST0 + 1_000_000_000 + 7_000_000)   # read 7 ms after it was taken
    clock.observe(1.1, HOST0 + 1_100_000_000 + 2_000_000)   # 2 ms
    clock.observe(2.0, HOST0 + 2_000_000_000 + 900_000_000)  # a burst read 0.9 s late
    assert clock.host_ns(1.5) == HOST0 + 1_500_000_000 + 2_000_000
    assert clock.host_ns(2.0) == HOST0 + 2_000_000_000 + 2_000_000


def test_a_bound_older_than_the_window_is_forgotten_so_drift_is_followed() -> None:
    clock = DeviceClockMap()
    clock.observe(0.0, HOST0 + 1_000_000)
    clock.observe(WINDOW_S + 0.5, HOST0 + round((WINDOW_S + 0.5) * 1e9) + 5_000_000)
    assert clock.host_ns(WINDOW_S + 0.5) == HOST0 + round((WINDOW_S + 0.5) * 1e9) + 5_000_000


def test_a_reboot_starts_the_map_again() -> None:
    clock = DeviceClockMap()
    clock.observe(100.0, HOST0 + 1_000_000)                 # device time 100 s at host HOST0
    clock.observe(0.05, HOST0 + 3_000_000_000)              # rebooted: its clock from 0
    assert clock.host_ns(0.05) == HOST0 + 3_000_000_000

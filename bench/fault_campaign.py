"""Fault campaign of issue 13: hostile and unlucky inputs against every external input path.

Run: ``python bench/fault_campaign.py [--tries N] [--only CLASS ...] [--seed S]
[--results FILE]``.

Bounded (every class has a fixed number of tries and every wait a timeout) and loopback only
(a private zenoh router on 127.0.0.1; the device on the in-process cable for ``reconnect``, a pty
for the others). Each class prints one row
``class | tries | failures | what a failure is``; the exit status is 1 if any try failed.
``--results FILE`` also writes the printed figures as tables to a results file
(``bench/results.py``).

Classes:
- ``reconnect``: the twin holds 10 N; unplug/replug, reboot on reopen, reboot with the port open,
  and a freeze, in turns. Failure: the tendon is re-tensioned (mode T or tension > 0.3 N) before
  ``clear_faults``, or a setpoint is accepted while disarmed.
- ``limits``: raising ``tension_max`` or ``setpoint_rate`` of a running tension_driver through
  the parameter interface. Failure: the change is accepted.
- ``param_queries``: random bytes, JSON bodies, and well-formed CDR requests with hostile contents
  (unknown type codes, non-finite and extreme numbers, undeclared and read-only names) sent with
  rmw_zenoh's attachment to model_node's six rcl_interfaces parameter services. Failure: no reply
  within 5 s, or the node dies.
- ``callbacks``: random bytes published as CDR on model_node's ``tension`` key. Failure: the node
  dies or stops answering a valid tension with a midline.
- ``yaml``: alias bombs, deep nesting, duplicate keys, huge and random text as scenes and
  parameter files. Failure: anything but the package's typed error, or more than 1 s.
- ``solver``: random designs over the whole field ranges and their corners, both load models and
  profiles, strict or not. Failure: an untyped exception, or a result with non-finite values.
- ``protocol``: random and mutated device lines into the decoder. Failure: anything but a
  decoded frame or ``FrameError``.
- ``bag``: random byte flips and truncations of a small recorded bag, then ``tdcm``'s reader and
  evaluation. Failure: anything but the package's typed errors or warnings, or more than 20 s.
- ``occlusion``: exact-zero and NaN markers written into a bag. Failure: ``evaluate`` does not
  count every one of them as occluded.
- ``recorder``: a 1 kHz counter that starts after ``tdcm record`` named its topic, then SIGINT.
  Failure: a message missing at the head, inside, or at the tail of the bag.

Issue 25 (each failed on the main of its filing):
- ``wildcard_setpoints``: 12 N put on random wildcard keys overlapping the driver's
  ``tension_setpoint`` key, with rmw_zenoh's attachment. Failure: the tendon tensions.
- ``big_parameters``: multi-megabyte ``frame_id`` and ``schedule.levels`` set on the driver.
  Failure: accepted.
- ``router_loss``: ``tdcm up --twin`` holds 8 N, its router is killed (SIGKILL). The driver's
  guarantee: a graph gone for ``safety.graph_timeout_s`` (1 s) releases the tendon; a shorter
  gap (``tdcm up`` restarts its router in ~0.2 s) holds it but is counted
  (``graph_interruptions``) and warned about. Failure: neither within 30 s (the tendon held
  with no interruption reported, or not slack after a loss), or no router comes back.
- ``full_disk``: the bag writer under a random file-size limit. Failure: it crashes, or the bag
  does not read back as the messages it kept, with ``metadata.yaml``.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import random
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
from results import BenchResults, Column, add_results_argument

from tdcm_ros.errors import TdcmError

Failures = list[str]
#: Time (s) the device may take to release after a fault: its 0.5 s watchdog, or the driver's
#: release once reconnected (the driver's first backoff is 0.2 s here).
RELEASE_WITHIN_S = 1.0


def free_port() -> int:
    """A TCP port on 127.0.0.1 that was free a moment ago."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def private_endpoint(port: int) -> dict[str, str]:
    """The environment of a graph on ``tcp/127.0.0.1:port`` (also applied to this process)."""
    env = {**os.environ, "TDCM_ZENOH_ENDPOINT": f"tcp/127.0.0.1:{port}", "TDCM_RUNTIME": "zenoh",
           "ROS_DOMAIN_ID": "0"}
    env.pop("TDCM_ZENOH_CONFIG", None)
    os.environ.update({k: env[k] for k in ("TDCM_ZENOH_ENDPOINT", "TDCM_RUNTIME", "ROS_DOMAIN_ID")})
    return env


def stop_child(child: subprocess.Popen[Any]) -> None:
    """SIGINT, then SIGKILL after 10 s."""
    if child.poll() is None:
        child.send_signal(signal.SIGINT)
        try:
            child.wait(10)
        except subprocess.TimeoutExpired:
            child.kill()
            child.wait()


@contextlib.contextmanager
def zenoh_graph(*nodes: list[str]) -> Iterator[dict[str, str]]:
    """A private router on loopback and ``nodes`` (argv tails of ``python -m``); yields the env."""
    port = free_port()
    env = private_endpoint(port)
    children = [subprocess.Popen([sys.executable, "-m", "tdcm_ros.runtime.router", "--listen",
                                  f"tcp/127.0.0.1:{port}"], env=env, stderr=subprocess.DEVNULL)]
    time.sleep(1.0)
    children += [subprocess.Popen([sys.executable, "-m", *argv], env=env,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                 for argv in nodes]
    try:
        yield env
    finally:
        for child in reversed(children):
            stop_child(child)


def wait_until(predicate: Callable[[], bool], timeout: float, spin: Callable[[float], None]
               ) -> bool:
    """Spin until ``predicate``; False after ``timeout`` s."""
    end = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > end:
            return False
        spin(0.05)
    return True


def typed_within(what: str, call: Callable[[], object], budget_s: float) -> Failures:
    """Run ``call``: the package's typed errors are fine; an untyped escape, or more than
    ``budget_s`` s, is a failure described with ``what``."""
    failures: Failures = []
    start = time.perf_counter()
    try:
        call()
    except TdcmError:
        pass
    except Exception as error:  # noqa: BLE001 - an untyped escape is what we count
        failures.append(f"{what}: {type(error).__name__}: {str(error)[:80]}")
    if (took := time.perf_counter() - start) > budget_s:
        failures.append(f"{what}: {took:.2f} s (budget {budget_s:g} s)")
    return failures


# --- device -------------------------------------------------------------------------------------

def campaign_reconnect(tries: int, rng: random.Random, tmp: Path) -> Failures:
    """Unplug, reboot on open, reboot with the port open, freeze; never re-tensioned (lock-step
    on the in-process cable)."""
    from tdcm_ros.device.driver import DriverConfig, LinkState, TensionDriver
    from tdcm_ros.device.loopback import Loopback
    from tdcm_ros.device.protocol import Mode
    from tdcm_ros.device.twin import DeviceTwin

    failures: Failures = []
    kinds = ("unplug", "reboot_on_open", "reboot_open_port", "freeze")
    for attempt in range(tries):
        kind = kinds[attempt % len(kinds)]
        twin = DeviceTwin(rx_buffer=64)
        cable = Loopback(twin)
        driver = TensionDriver(DriverConfig(port=str(tmp / f"port_{attempt}"),
                                            backoff_initial=0.2),
                               clock=lambda twin=twin: twin.time, open_port=cable.open,
                               warn=lambda text: None)

        def run(seconds: float, twin: DeviceTwin = twin, cable: Loopback = cable,
                driver: TensionDriver = driver) -> Any:
            end, status = twin.time + seconds, None
            while twin.time < end - 1e-9:
                cable.pump(0.005)
                status = driver.step().status
            return status

        try:
            for _ in range(400):
                if run(0.005).link is LinkState.CONNECTED:
                    break
            driver.enable()
            driver.set_setpoint(10.0)
            run(3.0)
            if abs(twin.plant.tension - 10.0) > 0.3:
                failures.append(f"{kind}: the bench never held 10 N ({twin.plant.tension:.2f})")
                continue
            if kind == "unplug":
                cable.reopen(reboot=False)
            elif kind == "reboot_on_open":
                run(rng.uniform(0.5, 3.0))
                cable.reopen(reboot=True)
            elif kind == "reboot_open_port":
                twin.reboot()
            else:
                with cable.hung():
                    run(rng.uniform(0.6, 3.0))
            run(RELEASE_WITHIN_S)  # the device watchdog or the driver's release acts
            end = twin.time + 4.0
            while twin.time < end:
                if twin.core.mode is Mode.TENSION or twin.plant.tension > 0.3:
                    failures.append(f"{kind}: tensioned ({twin.core.mode.name}, "
                                    f"{twin.plant.tension:.2f} N) {twin.time:.1f} s into the run")
                    break
                run(0.1)
            if driver.set_setpoint(10.0) != 0.0:
                failures.append(f"{kind}: a setpoint was accepted while disarmed")
        finally:
            driver.close()
    return failures


def campaign_limits(tries: int, rng: random.Random, tmp: Path) -> Failures:
    """Raise the driver's force limits through its parameter interface: always refused."""
    from tdcm_ros.device.twin import DeviceTwin, PtyTwin
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext

    twin = PtyTwin(DeviceTwin(), link=str(tmp / "limits_port")).start()
    params = tmp / "driver.yaml"
    params.write_text(f"tension_driver:\n  ros__parameters:\n    port: {twin.port}\n")
    failures: Failures = []
    try:
        with zenoh_graph(["tdcm_ros.runtime.run_node",
                          "tdcm_ros.nodes.tension_driver:TensionDriverNode",
                          "--params", str(params)]):
            context = ZenohContext()
            try:
                for attempt in range(tries):
                    name = ("tension_max", "setpoint_rate")[attempt % 2]
                    value = rng.uniform(21.0, 1000.0)
                    if _set_when_up(context, "/tension_driver", name, value):
                        failures.append(f"{name} = {value:.1f} accepted")
            finally:
                context.close()
    finally:
        twin.stop()
    return failures


def _set_when_up(context: Any, node: str, name: str, value: Any, timeout: float = 30.0) -> bool:
    """Whether ``node`` accepted ``name = value`` (asked until it answers; it may be starting)."""
    from tdcm_ros.runtime.param_client import ParameterClient

    end = time.monotonic() + timeout
    while True:
        try:
            return ParameterClient(context, node, timeout=2.0).set(name, value).successful
        except TdcmError:
            if time.monotonic() > end:
                return False


# --- runtime ------------------------------------------------------------------------------------

def hostile_json(rng: random.Random, depth: int = 0) -> Any:
    """A random JSON value, often of the wrong shape for a parameter request."""
    pick = rng.randrange(9 if depth < 3 else 6)
    if pick == 0:
        return None
    if pick == 1:
        return rng.choice([0, -1, 7, 2**63, 1e308, -0.0])
    if pick == 2:
        return "".join(chr(rng.randrange(32, 0x2FFF)) for _ in range(rng.randrange(0, 40)))
    if pick == 3:
        return rng.choice([True, False])
    if pick == 4:
        return {"name": hostile_json(rng, depth + 1), "value": hostile_json(rng, depth + 1)}
    if pick == 5:
        return {"name": rng.choice(["design.E", "frame_id", "solver.tol", "nope", ""]),
                "value": hostile_json(rng, depth + 1)}
    if pick == 6:
        return [hostile_json(rng, depth + 1) for _ in range(rng.randrange(4))]
    return {str(rng.random()): hostile_json(rng, depth + 1) for _ in range(rng.randrange(4))}


@contextlib.contextmanager
def model_graph() -> Iterator[Any]:
    """A router and model_node; yields a zenoh context of this process."""
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext

    with zenoh_graph(["tdcm_ros.runtime.run_node", "tdcm_ros.nodes.model_node:ModelNode"]):
        context = ZenohContext()
        try:
            yield context
        finally:
            context.close()


def midline_answers(context: Any, timeout: float = 20.0) -> bool:
    """True if model_node answers a valid 8 N tension with a midline of that stamp."""
    from tdcm_ros.bagio import from_dict

    port = context.create_port(f"campaign_probe_{random.randrange(10**9)}")
    stamps: set[int] = set()
    port.create_subscription("midline", "nav_msgs/msg/Path", lambda m: stamps.add(
        m.header.stamp.sec * 10**9 + m.header.stamp.nanosec))
    publisher = port.create_publisher("tension", "geometry_msgs/msg/WrenchStamped")
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        stamp = time.time_ns()
        publisher.publish(from_dict("geometry_msgs/msg/WrenchStamped", {
            "header": {"stamp": {"sec": stamp // 10**9, "nanosec": stamp % 10**9}},
            "wrench": {"force": {"z": 8.0}}}))
        context.spin_for(0.2)
        if stamp in stamps:
            return True
    return False


def hostile_parameter_value(rng: random.Random) -> dict[str, Any]:
    """A ``ParameterValue`` (as a dict) with any type code and extreme field values."""
    return {"type": rng.randrange(256),
            "integer_value": rng.choice([0, -1, 2**63 - 1, -2**63]),
            "double_value": rng.choice([math.nan, math.inf, -0.0, 1e308, 5e-324]),
            "string_value": "".join(chr(rng.randrange(32, 0x2FFF)) for _ in range(rng.randrange(40))),
            "bool_array_value": [rng.random() < 0.5 for _ in range(rng.randrange(4))],
            "double_array_value": [rng.choice([math.nan, 1.0, -1e308]) for _ in range(rng.randrange(4))]}


def hostile_parameter_request(rng: random.Random, type_name: str) -> bytes:
    """Random bytes, a JSON body, or a well-formed CDR request of ``type_name`` with hostile
    names and values."""
    from tdcm_ros.bagio import from_dict, serialize

    pick = rng.randrange(3)
    if pick == 0:
        return rng.randbytes(rng.randrange(64))
    if pick == 1:
        return json.dumps(hostile_json(rng))[:2000].encode()
    names = [rng.choice(["design.E", "frame_id", "solver.tol", "use_sim_time", "nope", ""])
             for _ in range(rng.randrange(4))]
    fields: dict[str, Any] = {"names": names}
    if type_name.endswith("/ListParameters"):
        fields = {"prefixes": names, "depth": rng.choice([0, 1, 2, 2**64 - 1])}
    elif "/SetParameters" in type_name:
        fields = {"parameters": [{"name": n, "value": hostile_parameter_value(rng)} for n in names]}
    return serialize(from_dict(f"{type_name}_Request", fields))


def campaign_param_queries(tries: int, rng: random.Random, tmp: Path) -> Failures:
    """Hostile requests to model_node's parameter services; each answered, the node alive."""
    from tdcm_ros.bagio import service_type_hash
    from tdcm_ros.runtime import wire
    from tdcm_ros.runtime.param_services import SERVICES

    failures: Failures = []
    gid = bytes(range(16))
    with model_graph() as context:
        if not midline_answers(context, 30.0):
            return ["model_node never answered before the campaign"]
        for seq in range(1, tries + 1):
            service, type_name = rng.choice(sorted(SERVICES.items()))
            body = hostile_parameter_request(rng, type_name)
            key = wire.topic_key(0, f"/model_node/{service}", type_name,
                                 service_type_hash(type_name))
            replies = list(context.session.get(
                key, payload=body, timeout=5.0,
                attachment=wire.encode_attachment(seq, time.time_ns(), gid)))
            if not replies:
                failures.append(f"{service} {body[:40]!r}: no reply within 5 s")
        if not midline_answers(context):
            failures.append("model_node stopped answering after the queries")
    return failures


def campaign_callbacks(tries: int, rng: random.Random, tmp: Path) -> Failures:
    """Random bytes as CDR on model_node's ``tension``; the node must go on solving."""
    from tdcm_ros.bagio import type_hash
    from tdcm_ros.runtime import wire

    failures: Failures = []
    type_name = "geometry_msgs/msg/WrenchStamped"
    with model_graph() as context:
        if not midline_answers(context, 30.0):
            return ["model_node never answered before the campaign"]
        key = wire.topic_key(0, "/tension", type_name, type_hash(type_name))
        publisher = context.session.declare_publisher(key)
        for attempt in range(tries):
            size = rng.choice([0, 1, 3, 4, 8, 20, 64, 200, 5000])
            payload = bytes(rng.randrange(256) for _ in range(size))
            if attempt % 3 == 0 and size >= 8:  # a valid CDR header before the noise
                payload = b"\x00\x01\x00\x00" + payload[4:]
            publisher.put(payload)
        publisher.undeclare()
        if not midline_answers(context):
            failures.append(f"model_node stopped answering after {tries} garbage messages")
    return failures


# --- config, model, protocol, bags --------------------------------------------------------------

def hostile_yaml(rng: random.Random) -> str:
    """An alias bomb, deep nesting, duplicate keys, huge or random text."""
    kind = rng.randrange(6)
    if kind == 0:
        levels = rng.randrange(5, 12)
        lines = ['a0: &a0 ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]']
        lines += [f"a{i}: &a{i} [{','.join([f'*a{i - 1}'] * 9)}]" for i in range(1, levels)]
        return "\n".join(lines) + "\n"
    if kind == 1:
        depth = rng.randrange(100, 20_000)
        return "x: " + "[" * depth + "]" * depth + "\n"
    if kind == 2:
        depth = rng.randrange(70, 3000)
        return "".join("  " * i + f"k{i}:\n" for i in range(depth)) + "  " * depth + "v: 1\n"
    if kind == 3:
        return "name: a\nname: b\neffects:\n  - {gravity: {}, gravity: {}}\n"
    if kind == 4:
        return "x: " + "a" * rng.randrange(70_000, 3_000_000) + "\n"
    return "".join(rng.choice("{}[]:,-&*!|>'\"#%@` \n\tab0.e") for _ in range(rng.randrange(200)))


def campaign_yaml(tries: int, rng: random.Random, tmp: Path) -> Failures:
    """Hostile YAML as a scene and as a parameter file: typed error or value, within 1 s."""
    from tdcm_ros.runtime.params import node_parameters
    from tdcm_ros.scenes.load import scene_from_text

    failures: Failures = []
    path = tmp / "hostile.yaml"
    for _ in range(tries):
        text = hostile_yaml(rng)
        path.write_text(text)
        for what, load in (("scene", lambda text=text: scene_from_text(text)),
                           ("params", lambda: node_parameters([path], "/model_node"))):
            failures += typed_within(f"{what} {text[:40]!r}", load, 1.0)
    return failures


def random_design(rng: random.Random) -> dict[str, Any]:
    """Field overrides: half the time each field scaled 0.1-10x around the paper's design, else
    across the field's whole range and at its corners."""
    from tdcm_ros.model import FIELD_SPECS, preset

    base = preset("paper-experiment")
    values: dict[str, Any] = {}
    near = rng.random() < 0.5
    for name, spec in FIELD_SPECS.items():
        if rng.random() < 0.5:
            continue
        if near:
            scaled = getattr(base, name) * math.exp(rng.uniform(-2.3, 2.3))
            values[name] = max(1, round(scaled)) if spec.integer else scaled
            continue
        low = spec.low if not spec.low_open else spec.low + (1 if spec.integer else 1e-12)
        if spec.integer:
            values[name] = rng.choice([int(low), int(spec.high), rng.randint(int(low), 64)])
        else:
            values[name] = rng.choice([low, spec.high, rng.uniform(low, spec.high),
                                       math.exp(rng.uniform(math.log(max(low, 1e-12)),
                                                            math.log(spec.high)))])
    return values


def campaign_solver(tries: int, rng: random.Random, tmp: Path) -> Failures:
    """Random designs and settings: a finite result or a typed error, nothing else."""
    from tdcm_ros.model import RectangularProfile, SolverSettings, preset, solve

    failures: Failures = []
    solved = 0
    for _ in range(tries):
        overrides = random_design(rng)
        tension = rng.choice([0.0, 1e-9, rng.uniform(0, 40), rng.uniform(0, 1e4), 200.0])
        try:
            design = preset("paper-experiment").with_overrides(**overrides)
            if rng.random() < 0.3:
                design = design.with_overrides(profile=RectangularProfile())
            settings = SolverSettings(loads=rng.choice(["closed", "literal"]),
                                      routing=rng.choice(["paper", "free"]))
            result = solve(design, tension, settings=settings, strict=rng.random() < 0.5)
        except TdcmError:
            continue
        except Exception as error:  # noqa: BLE001 - an untyped escape is what we count
            failures.append(f"{type(error).__name__}: {str(error)[:60]} for {overrides}")
            continue
        solved += 1
        arrays = [np.asarray(getattr(result, name)) for name in ("positions", "tip_position")
                  if hasattr(result, name)]
        if not all(np.isfinite(a).all() for a in arrays):
            failures.append(f"non-finite result for {overrides}, {tension} N")
    NOTES["solver"] = f"{solved} returned a result, the rest a typed error"
    return failures


def campaign_protocol(tries: int, rng: random.Random, tmp: Path) -> Failures:
    """Random and mutated device lines: a decoded frame or ``FrameError``."""
    from tdcm_ros.device.errors import FrameError
    from tdcm_ros.device.protocol import Heartbeat, SetSetpoint, decode, encode

    seeds = [encode(SetSetpoint(12.5)), encode(Heartbeat())]
    failures: Failures = []
    for _ in range(tries):
        line = bytearray(rng.choice(seeds))
        for _ in range(rng.randrange(1, 6)):
            position = rng.randrange(len(line) + 1)
            line[position:position] = bytes([rng.randrange(256)])
        if rng.random() < 0.3:
            line = bytearray(rng.randbytes(rng.randrange(200)))
        try:
            decode(bytes(line))
        except FrameError:
            continue
        except Exception as error:  # noqa: BLE001 - an untyped escape is what we count
            failures.append(f"{type(error).__name__}: {error} for {bytes(line)[:40]!r}")
    return failures


def small_bag(tmp: Path, name: str, mutate: Callable[[Any], None] | None = None) -> Path:
    """A 1-trial simulated recording written as a bag (``mutate`` edits the recording first)."""
    from tdcm_ros.metrics.synthetic import simulate
    from tdcm_ros.metrics.synthetic_bag import write_recording
    from tdcm_ros.model import preset

    recording = simulate(preset("paper-experiment"), hold_s=1.5, trials=1, seed=3)
    if mutate is not None:
        mutate(recording)
    return write_recording(recording, tmp / name)


def campaign_bag(tries: int, rng: random.Random, tmp: Path) -> Failures:
    """Byte flips and truncations of a bag: typed errors or warnings, within 20 s."""
    from tdcm_ros.bagio.reader import open_bag
    from tdcm_ros.metrics.api import evaluate_paths

    clean = small_bag(tmp, "clean_bag")
    original = next(clean.glob("*.mcap")).read_bytes()
    failures: Failures = []
    for attempt in range(tries):
        data = bytearray(original)
        if rng.random() < 0.3:
            data = data[:rng.randrange(len(data))]
        for _ in range(rng.randrange(1, 8)):
            if data:
                data[rng.randrange(len(data))] ^= 1 << rng.randrange(8)
        path = tmp / f"flipped_{attempt}.mcap"
        path.write_bytes(bytes(data))
        failures += typed_within(f"bag {attempt}", lambda path=path: (open_bag(path),
                                                                    evaluate_paths([path])), 20.0)
        path.unlink()
    return failures


def campaign_occlusion(tries: int, rng: random.Random, tmp: Path) -> Failures:
    """Exact zeros and NaN in a bag's markers: every one counted as occluded by evaluate."""
    from tdcm_ros.metrics.api import evaluate_paths

    failures: Failures = []
    for attempt in range(tries):
        injected: list[int] = []

        def occlude(recording: Any, injected: list[int] = injected) -> None:
            positions = recording.markers.positions
            for _ in range(rng.randrange(1, 20)):
                frame, marker = rng.randrange(len(positions)), rng.randrange(positions.shape[1])
                if not np.isnan(positions[frame, marker, 0]) and not (
                        positions[frame, marker] == 0).all():
                    positions[frame, marker] = 0.0
                    injected.append(1)

        bag = small_bag(tmp, f"occluded_{attempt}", occlude)
        try:
            evaluation = evaluate_paths([bag])
        except TdcmError as error:
            failures.append(f"evaluate refused the bag: {error}")
            continue
        counted = sum(evaluation.to_json().get("details", {}).get("occluded_markers",
                                                                   {}).values())
        if counted != len(injected):
            failures.append(f"{len(injected)} zero markers written, {counted} counted occluded")
    return failures


def campaign_recorder(tries: int, rng: random.Random, tmp: Path) -> Failures:
    """A 1 kHz counter started after ``tdcm record`` named its topic: nothing lost."""
    from tdcm_ros.bagio import from_dict
    from tdcm_ros.bagio.reader import open_bag
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext

    failures: Failures = []
    for attempt in range(tries):
        bag = tmp / f"recorded_{attempt}"
        with zenoh_graph(["tdcm_ros.cli.main", "record", str(bag), "/campaign_count"]) as env:
            time.sleep(2.0)  # the recorder is up and subscribed before the publisher exists
            context = ZenohContext()
            try:
                publisher = context.create_port("counter").create_publisher(
                    "/campaign_count", "std_msgs/msg/UInt32")
                count = rng.randrange(500, 1500)
                start = time.monotonic()
                for n in range(count):
                    publisher.publish(from_dict("std_msgs/msg/UInt32", {"data": n}))
                    time.sleep(max(0.0, start + (n + 1) / 1000.0 - time.monotonic()))
                context.spin_for(0.5)
            finally:
                context.close()
            del env
        values = sorted(int(message.data) for _, _, message in
                        open_bag(bag).messages(["/campaign_count"]))
        if values != list(range(count)):
            missing = sorted(set(range(count)) - set(values))
            failures.append(f"{len(missing)} of {count} lost (first missing {missing[:5]})")
    return failures


# --- issue 25: the graph's guarantees -------------------------------------------------------------

def wildcard_key(rng: random.Random, exact: str) -> str:
    """A key expression that overlaps ``exact`` without being it: a chunk made ``*``, a chunk's
    tail made ``$*``, or a ``**`` in place of the tail."""
    chunks = exact.split("/")
    pick, where = rng.randrange(3), rng.randrange(1, len(chunks))
    if pick == 0:
        chunks[where] = "*"
    elif pick == 1:
        chunks[where] = chunks[where][:rng.randrange(1, len(chunks[where]))] + "$*"
    else:
        chunks[where:] = ["**"]
    return "/".join(chunks)


@contextlib.contextmanager
def driver_graph(tmp: Path, name: str, *extra: str) -> Iterator[tuple[Any, Any]]:
    """A threaded twin, a router and tension_driver on it; yields (twin, a zenoh context)."""
    from tdcm_ros.device.twin import DeviceTwin, PtyTwin
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext

    twin = PtyTwin(DeviceTwin(), link=str(tmp / f"{name}_port")).start()
    params = tmp / f"{name}.yaml"
    params.write_text(f"tension_driver:\n  ros__parameters:\n    port: {twin.port}\n")
    try:
        with zenoh_graph(["tdcm_ros.runtime.run_node",
                          "tdcm_ros.nodes.tension_driver:TensionDriverNode", "--params",
                          str(params), *extra]):
            context = ZenohContext()
            try:
                yield twin, context
            finally:
                context.close()
    finally:
        twin.stop()


def campaign_wildcard_setpoints(tries: int, rng: random.Random, tmp: Path) -> Failures:
    """12 N setpoints put on wildcard keys overlapping the driver's ``tension_setpoint`` key,
    with rmw_zenoh's attachment: the tendon stays slack."""
    from tdcm_ros.bagio import from_dict, serialize, type_hash
    from tdcm_ros.device.protocol import Mode
    from tdcm_ros.runtime import wire

    float64 = "std_msgs/msg/Float64"
    exact = wire.topic_key(0, "/tension_setpoint", float64, type_hash(float64))
    payload = bytes(serialize(from_dict(float64, {"data": 12.0}), float64))
    failures: Failures = []
    with driver_graph(tmp, "wildcard") as (twin, context):
        if not wait_until(lambda: twin.twin.core.mode is Mode.TENSION, 30.0, context.spin_for):
            return ["the driver never armed the device"]
        for seq in range(1, tries + 1):
            key = wildcard_key(rng, exact)
            context.session.put(key, payload,
                                attachment=wire.encode_attachment(seq, time.time_ns(),
                                                                  bytes(16)))
            context.spin_for(0.05)
            if twin.twin.plant.tension > 0.3:
                failures.append(f"{key}: the tendon went to {twin.twin.plant.tension:.2f} N")
                break
        context.spin_for(1.0)
        if twin.twin.plant.tension > 0.3 and not failures:
            failures.append(f"the tendon went to {twin.twin.plant.tension:.2f} N")
    return failures


def campaign_big_parameters(tries: int, rng: random.Random, tmp: Path) -> Failures:
    """Multi-megabyte strings and arrays set as the driver's ``frame_id`` and
    ``schedule.levels``: refused."""
    failures: Failures = []
    with driver_graph(tmp, "big") as (_twin, context):
        for attempt in range(tries):
            size = rng.randrange(10_000, 10_000_000)
            name, value = (("frame_id", "x" * size) if attempt % 2 == 0
                           else ("schedule.levels", [1.0] * (size // 8)))
            if _set_when_up(context, "/tension_driver", name, value):
                failures.append(f"{name} of {size} elements accepted")
    return failures


def campaign_router_loss(tries: int, rng: random.Random, tmp: Path) -> Failures:
    """``tdcm up --twin`` holding 8 N; ``kill -9`` of its router: the router comes back, and the
    driver either reports the interruption (holding) or is disarmed for the lost graph with the
    tendon slack (see the module docstring)."""
    failures: Failures = []
    for _ in range(tries):
        port = free_port()
        up = subprocess.Popen([sys.executable, "-m", "tdcm_ros.cli.main", "up", "--twin"],
                              env=private_endpoint(port), stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)
        try:
            time.sleep(3.0)
            failure = _router_loss_once(port)
            if failure:
                failures.append(failure)
        finally:
            stop_child(up)
    return failures


def _router_loss_once(port: int) -> str:
    """Hold 8 N through the running graph, kill its router; what went wrong ("" if nothing)."""
    from tdcm_ros.bagio import from_dict
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext

    context = ZenohContext()
    try:
        node = context.create_port("campaign")
        truth: list[float] = []
        states: list[dict[str, str]] = []
        node.create_subscription("sim/tension_true", "geometry_msgs/msg/WrenchStamped",
                                 lambda m: truth.append(m.wrench.force.z))
        node.create_subscription("device_state", "diagnostic_msgs/msg/DiagnosticStatus",
                                 lambda m: states.append({kv.key: kv.value for kv in m.values}))
        setpoint = node.create_publisher("tension_setpoint", "std_msgs/msg/Float64")

        def held() -> bool:
            setpoint.publish(from_dict("std_msgs/msg/Float64", {"data": 8.0}))
            return bool(truth) and abs(truth[-1] - 8.0) < 0.3

        if not wait_until(held, 60.0, context.spin_for):
            return "the twin never held 8 N"
        routers = [int(p.name) for p in Path("/proc").iterdir() if p.name.isdigit()
                   and _cmdline_has(p, b"tdcm_ros.runtime.router", str(port).encode())]
        if not routers:
            return "no router process of tdcm up found"
        os.kill(routers[0], signal.SIGKILL)
        truth.clear()
        states.clear()

        def released() -> bool:
            return (bool(truth) and truth[-1] < 0.3 and bool(states)
                    and "graph lost" in states[-1].get("disarm_reason", ""))

        def reported() -> bool:
            return (bool(truth) and abs(truth[-1] - 8.0) < 0.3 and bool(states)
                    and int(states[-1].get("graph_interruptions", "0")) >= 1
                    and states[-1].get("armed") == "true")

        if wait_until(lambda: released() or reported(), 30.0, context.spin_for):
            return ""
        last = states[-1] if states else {}
        return (f"after kill -9 of the router: true tension "
                f"{truth[-1] if truth else 'not heard'} N, driver armed {last.get('armed')}, "
                f"disarmed for {last.get('disarm_reason')!r}, graph interruptions "
                f"{last.get('graph_interruptions')}")
    finally:
        context.close()


def _cmdline_has(proc: Path, *parts: bytes) -> bool:
    try:
        argv = (proc / "cmdline").read_bytes()
    except OSError:
        return False
    return all(part in argv for part in parts)


FULL_DISK_WRITER = """
import sys
from tdcm_ros.bagio import from_dict, serialize
from tdcm_ros.bagio.writer import BagWriter

writer = BagWriter(sys.argv[1], chunk_size=4096)
writer.add_topic("/tick", "std_msgs/msg/UInt32")
n = 0
while n < 200_000 and not getattr(writer, "failure", ""):
    writer.write("/tick", 1_000_000_000 + n, bytes(serialize(
        from_dict("std_msgs/msg/UInt32", {"data": n}), "std_msgs/msg/UInt32")))
    n += 1
writer.close()
print(writer.counts.get("/tick", 0))
"""


def campaign_full_disk(tries: int, rng: random.Random, tmp: Path) -> Failures:
    """The bag writer under a random file-size limit (a write fails as on a full disk): it ends
    cleanly, the bag reads back as the messages it says it kept, with ``metadata.yaml``."""
    import resource

    import yaml

    from tdcm_ros.bagio import writer
    from tdcm_ros.bagio.reader import open_bag

    reserve = getattr(writer, "RESERVE_BYTES", 0)  # bytes (0 before the writer held a reserve)
    failures: Failures = []
    for attempt in range(tries):
        limit = reserve + rng.randrange(2_000, 400_000)
        bag = tmp / f"full_{attempt}"
        child = subprocess.run(
            [sys.executable, "-c", FULL_DISK_WRITER, str(bag)], capture_output=True, text=True,
            check=False, timeout=120, preexec_fn=lambda limit=limit: resource.setrlimit(
                resource.RLIMIT_FSIZE, (limit, limit)))
        if child.returncode != 0:
            failures.append(f"limit {limit}: exit {child.returncode}: {child.stderr[-120:]!r}")
            continue
        kept = int(child.stdout)
        try:
            read = sum(1 for _ in open_bag(bag).messages(["/tick"]))
            meta = yaml.safe_load((bag / "metadata.yaml").read_text())
            counted = meta["rosbag2_bagfile_information"]["message_count"]
        except (TdcmError, OSError) as error:
            failures.append(f"limit {limit}: {type(error).__name__}: {error}")
            continue
        if not read == counted == kept:
            failures.append(f"limit {limit}: kept {kept}, read {read}, metadata {counted}")
    return failures


#: A short note per class printed under its row (e.g. how many tries reached the code under test).
NOTES: dict[str, str] = {}

CAMPAIGNS: dict[str, tuple[Callable[[int, random.Random, Path], Failures], int, str]] = {
    "reconnect": (campaign_reconnect, 8, "re-tensioned before clear_faults"),
    "limits": (campaign_limits, 10, "a force limit raised at run time"),
    "param_queries": (campaign_param_queries, 300, "no reply, or model_node died"),
    "callbacks": (campaign_callbacks, 300, "model_node died or stopped solving"),
    "yaml": (campaign_yaml, 200, "untyped error or > 1 s"),
    "solver": (campaign_solver, 2000, "untyped error or non-finite result"),
    "protocol": (campaign_protocol, 5000, "anything but a frame or FrameError"),
    "bag": (campaign_bag, 60, "untyped error or > 20 s"),
    "occlusion": (campaign_occlusion, 5, "a zero marker not counted as occluded"),
    "recorder": (campaign_recorder, 2, "a message lost at the head, inside or tail"),
    "wildcard_setpoints": (campaign_wildcard_setpoints, 200, "a wildcard key tensioned the tendon"),
    "big_parameters": (campaign_big_parameters, 6, "a multi-megabyte parameter accepted"),
    "router_loss": (campaign_router_loss, 2, "after kill -9: held unreported, or no router"),
    "full_disk": (campaign_full_disk, 10, "a crash, or the bag unreadable or miscounted"),
}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tries", type=float, default=1.0,
                        help="scale every class's number of tries (default 1.0)")
    parser.add_argument("--only", nargs="+", choices=sorted(CAMPAIGNS), help="classes to run")
    parser.add_argument("--seed", type=int, default=13)
    add_results_argument(parser, "fault_campaign")
    args = parser.parse_args()
    results = BenchResults("fault_campaign")
    names = args.only or list(CAMPAIGNS)
    print(f"{'class':14s} {'tries':>6s} {'failures':>9s} {'s':>7s}  failure means")
    total = 0
    rows = []
    with tempfile.TemporaryDirectory(prefix="tdcm_faults_") as folder:
        for name in names:
            run, tries, meaning = CAMPAIGNS[name]
            tries = max(1, round(tries * args.tries))
            rng = random.Random(f"{args.seed}:{name}")
            start = time.monotonic()
            try:
                failures = run(tries, rng, Path(folder))
            except Exception as error:  # noqa: BLE001 - the campaign itself must report, not die
                failures = [f"campaign error: {type(error).__name__}: {error}"]
            total += len(failures)
            took = time.monotonic() - start
            print(f"{name:14s} {tries:6d} {len(failures):9d} {took:7.1f}  "
                  f"{meaning}", flush=True)
            if name in NOTES:
                print(f"    ({NOTES[name]})")
            for failure in failures[:5]:
                print(f"    {failure}")
            rows.append([name, tries, len(failures), took, meaning,
                         NOTES.get(name), "; ".join(failures[:5]) or None])
    print(f"total failures: {total}")
    results.table(
        "Fault campaign", [Column("class"), Column("tries"), Column("failures"),
                           Column("time", "s", ".1f"), Column("failure means"), Column("note"),
                           Column("first failures")], rows,
        note=f"total failures: {total}; seed {args.seed}, tries scaled by {args.tries:g}; "
             "first failures: up to five, as printed")
    if args.results:
        results.write(args.results)
    return 1 if total else 0


if __name__ == "__main__":
    sys.exit(main())

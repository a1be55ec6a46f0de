"""Zenoh security on loopback with the shipped ``config/zenoh/`` files: TLS, user/password and the
access-control list, with certificates made by ``openssl`` at test time; and the warning for
listeners beyond loopback without authentication (checked on configs, nothing binds there)."""

from __future__ import annotations

import argparse
import logging
import os
import shutil
import signal
import subprocess
import sys
from collections.abc import Callable, Iterator
from contextlib import ExitStack
from pathlib import Path
from typing import Any

import pytest
import zenoh

from tdcm_ros.bagio import from_dict, service_type_hash, type_hash
from tdcm_ros.errors import InputError
from tdcm_ros.runtime import wire, zenoh_config
from tdcm_ros.runtime.errors import RuntimePortError
from tdcm_ros.runtime.zenoh_runtime import CONFIG_ENV, ZenohContext
from test.support.processes import listening
from test.support.waiting import Together, eventually

Spawn = Callable[..., subprocess.Popen[bytes]]
EXAMPLES = Path(__file__).resolve().parents[2] / "config" / "zenoh"
PLACEHOLDER_DIR = "/etc/tdcm/zenoh/"
PASSWORDS = {"operator": "op-pass-7f3a", "observer": "obs-pass-91c2"}
SECTION = "Several hosts: TLS, authentication, access control"


def openssl(folder: Path, *args: str) -> None:
    subprocess.run(["openssl", *args], cwd=folder, check=True, capture_output=True, timeout=30)


def make_certificates(folder: Path) -> None:
    """A CA and a router certificate for localhost and 127.0.0.1 (EC P-256, one day)."""
    ec = ("-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes")
    openssl(folder, "req", "-x509", *ec, "-keyout", "ca.key", "-out", "ca.pem", "-days", "1",
            "-subj", "/CN=tdcm test CA")
    openssl(folder, "req", *ec, "-keyout", "router.key", "-out", "router.csr",
            "-subj", "/CN=localhost")
    (folder / "san.cnf").write_text("subjectAltName=DNS:localhost,IP:127.0.0.1\n")
    openssl(folder, "x509", "-req", "-in", "router.csr", "-CA", "ca.pem", "-CAkey", "ca.key",
            "-CAcreateserial", "-out", "router.pem", "-days", "1", "-extfile", "san.cnf")


def render(example: str, folder: Path, name: str, user: str = "operator",
           password: str | None = None) -> Path:
    """The example file with the test's folder, user and password in place of placeholders."""
    text = (EXAMPLES / example).read_text().replace(PLACEHOLDER_DIR, f"{folder}/")
    text = text.replace('user: "operator"', f'user: "{user}"')
    text = text.replace('"CHANGE-ME-operator"', f'"{password or PASSWORDS[user]}"')
    path = folder / name
    path.write_text(text)
    return path


@pytest.fixture
def secrets(tmp_path: Path) -> dict[str, Path]:
    """Certificates, users.txt and the rendered configs: router, operator, observer, wrong."""
    if shutil.which("openssl") is None:
        pytest.skip("openssl is not installed")
    make_certificates(tmp_path)
    (tmp_path / "users.txt").write_text("".join(f"{u}:{p}\n" for u, p in PASSWORDS.items()))
    return {"router": render("router.json5", tmp_path, "router.json5"),
            "operator": render("peer.json5", tmp_path, "operator.json5"),
            "observer": render("peer.json5", tmp_path, "observer.json5", user="observer"),
            "wrong": render("peer.json5", tmp_path, "wrong.json5", password="not-the-password")}


@pytest.fixture
def tls_port(zenoh_env: dict[str, str]) -> int:
    return int(zenoh_env["ZENOH_TEST_PORT"])


@pytest.fixture
def probes() -> Iterator[Callable[[Path, str], ZenohContext]]:
    """``probe(config, endpoint)``: a peer context with that config; closed at teardown."""
    with ExitStack() as stack:
        def probe(config: Path, endpoint: str) -> ZenohContext:
            session = zenoh.open(zenoh_config.build(mode="peer", endpoint=endpoint,
                                                    path=str(config)))
            context = ZenohContext(session)
            stack.callback(context.close)
            return context

        yield probe


def listen_to(context: ZenohContext, topic: str, type_name: str) -> list[Any]:
    got: list[Any] = []
    context.create_port("probe").create_subscription(topic, type_name, got.append)
    return got


def test_tdcm_up_secure_graph_admits_only_authenticated_tls_peers(
        secrets: dict[str, Path], tls_port: int, spawn: Spawn,
        probes: Callable[[Path, str], ZenohContext]) -> None:
    endpoint = f"tls/127.0.0.1:{tls_port}"
    launcher = spawn("tdcm_ros.cli.main", "up", "--nodes", "talker", "--endpoint", endpoint,
                     "--zenoh-config", str(secrets["operator"]),
                     "--router-config", str(secrets["router"]))
    eventually(lambda: listening(tls_port), 15.0, "the TLS router of tdcm up")
    good = probes(secrets["operator"], endpoint)
    wrong = probes(secrets["wrong"], endpoint)
    plain = probes(secrets["operator"], f"tcp/127.0.0.1:{tls_port}")
    heard = {name: listen_to(ctx, "chatter", "std_msgs/msg/String")
             for name, ctx in (("good", good), ("wrong", wrong), ("plain", plain))}
    eventually(lambda: heard["good"], 20.0, "the talker over TLS", spin=good)
    eventually(lambda: len(heard["good"]) >= 3, 10.0, "two more messages",
               spin=Together(good, wrong, plain))
    assert heard["wrong"] == [] and heard["plain"] == []
    assert list(good.session.info.routers_zid())
    assert not list(wrong.session.info.routers_zid())
    assert not list(plain.session.info.routers_zid())
    launcher.send_signal(signal.SIGINT)
    assert launcher.wait(15) == 0
    assert b"beyond loopback" not in launcher.communicate(timeout=5)[1]


def test_acl_denies_observer_commands_and_allows_operator(
        secrets: dict[str, Path], tls_port: int, spawn: Spawn,
        probes: Callable[[Path, str], ZenohContext]) -> None:
    endpoint = f"tls/127.0.0.1:{tls_port}"
    spawn("tdcm_ros.runtime.router", "--listen", endpoint, "--config", str(secrets["router"]))
    eventually(lambda: listening(tls_port), 15.0, "the TLS router")
    driver = probes(secrets["operator"], endpoint)
    setpoints = listen_to(driver, "tension_setpoint", "std_msgs/msg/Float64")
    estops = listen_to(driver, "estop", "std_msgs/msg/Empty")
    observer_port = probes(secrets["observer"], endpoint).create_port("observer")
    operator_port = probes(secrets["operator"], endpoint).create_port("operator")
    denied = observer_port.create_publisher("tension_setpoint", "std_msgs/msg/Float64")
    allowed = observer_port.create_publisher("estop", "std_msgs/msg/Empty")
    commands = operator_port.create_publisher("tension_setpoint", "std_msgs/msg/Float64")

    def observer_sends() -> bool:
        denied.publish(from_dict("std_msgs/msg/Float64", {"data": 1.0}))
        allowed.publish(from_dict("std_msgs/msg/Empty", {}))
        return len(estops) >= 10  # the observer's route to the driver works: keep going a while

    eventually(observer_sends, 20.0, "the observer's estop messages", spin=driver)

    def operator_sends() -> bool:
        commands.publish(from_dict("std_msgs/msg/Float64", {"data": 2.0}))
        return any(m.data == 2.0 for m in setpoints)

    eventually(operator_sends, 20.0, "the operator's setpoint", spin=driver)
    assert [m.data for m in setpoints if m.data != 2.0] == []


def test_acl_denies_observer_command_services_but_estop(
        secrets: dict[str, Path], tls_port: int, spawn: Spawn,
        probes: Callable[[Path, str], ZenohContext]) -> None:
    """The shipped ACL: an observer's call of the driver's clear_faults never reaches it (no
    answer), its estop call does; the operator's clear_faults does."""
    import threading

    endpoint = f"tls/127.0.0.1:{tls_port}"
    spawn("tdcm_ros.runtime.router", "--listen", endpoint, "--config", str(secrets["router"]))
    eventually(lambda: listening(tls_port), 15.0, "the TLS router")
    driver = probes(secrets["operator"], endpoint)
    port = driver.create_port("tension_driver")
    calls: list[str] = []

    def serve(name: str) -> None:
        def handle(_request: Any) -> Any:
            calls.append(name)
            return from_dict("std_srvs/srv/Trigger_Response", {"success": True, "message": name})
        port.create_service(f"~/{name}", "std_srvs/srv/Trigger", handle)

    serve("clear_faults")
    serve("estop")
    spinner = threading.Thread(target=driver.spin, daemon=True)
    spinner.start()
    try:
        observer = probes(secrets["observer"], endpoint)
        operator = probes(secrets["operator"], endpoint)
        assert observer.call_service("/tension_driver/estop", "std_srvs/srv/Trigger",
                                     timeout=15.0).message == "estop"
        with pytest.raises(RuntimePortError, match="did not answer"):
            observer.call_service("/tension_driver/clear_faults", "std_srvs/srv/Trigger",
                                  timeout=3.0)
        assert operator.call_service("/tension_driver/clear_faults", "std_srvs/srv/Trigger",
                                     timeout=15.0).message == "clear_faults"
        assert calls == ["estop", "clear_faults"]
    finally:
        driver.request_stop()
        spinner.join(5.0)


@pytest.mark.parametrize("endpoint", ["tcp/0.0.0.0:7447", "tcp/[::]:7447",
                                      "tls/192.168.1.20:7447", "tcp/robot.lan:7447"])
def test_router_beyond_loopback_without_auth_is_exposed(endpoint: str,
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(zenoh_config.ROUTER_CONFIG_ENV, raising=False)
    config = zenoh_config.build(mode="router", endpoint=endpoint, path=None)
    assert zenoh_config.exposed_endpoints(config, "router") == [endpoint]


@pytest.mark.parametrize("endpoint", ["tcp/127.0.0.1:7447", "tcp/localhost:7447",
                                      "tcp/[::1]:7447", "unixsock-stream//tmp/z.sock"])
def test_loopback_router_is_not_exposed(endpoint: str, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(zenoh_config.ROUTER_CONFIG_ENV, raising=False)
    config = zenoh_config.build(mode="router", endpoint=endpoint, path=None)
    assert zenoh_config.exposed_endpoints(config, "router") == []


def test_authentication_removes_the_exposure(secrets: dict[str, Path], tmp_path: Path,
                                             monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(zenoh_config.ROUTER_CONFIG_ENV, raising=False)
    router = zenoh_config.build(mode="router", endpoint="tls/0.0.0.0:7447",
                                path=str(secrets["router"]))  # usrpwd dictionary
    assert zenoh_config.exposed_endpoints(router, "router") == []
    tls_only = tmp_path / "tls_only.json5"
    tls_only.write_text('{transport: {link: {tls: {enable_mtls: false}}}}')
    mtls = tmp_path / "mtls.json5"
    mtls.write_text('{transport: {link: {tls: {enable_mtls: true}}}}')
    for path, exposed in ((tls_only, ["tls/0.0.0.0:7447"]), (mtls, [])):
        config = zenoh_config.build(mode="router", endpoint="tls/0.0.0.0:7447", path=str(path))
        assert zenoh_config.exposed_endpoints(config, "router") == exposed
    tcp_mtls = zenoh_config.build(mode="router", endpoint="tcp/0.0.0.0:7447", path=str(mtls))
    assert zenoh_config.exposed_endpoints(tcp_mtls, "router") == ["tcp/0.0.0.0:7447"]


def test_peer_file_sets_role_keys_and_keeps_zenoh_default_listen_off_the_network(
        tmp_path: Path, secrets: dict[str, Path]) -> None:
    bare = tmp_path / "bare.json5"
    bare.write_text('{mode: "client", connect: {endpoints: ["tcp/10.0.0.9:7447"]}}')
    config = zenoh_config.build(mode="peer", endpoint="tls/127.0.0.1:7000", path=str(bare))
    assert config.get_json("mode") == '"peer"'
    assert config.get_json("connect/endpoints") == '["tls/127.0.0.1:7000"]'
    assert zenoh_config.listen_endpoints(config, "peer") == [zenoh_config.LOOPBACK_LISTEN]
    example = zenoh_config.build(mode="peer", endpoint="tls/127.0.0.1:7000",
                                 path=str(secrets["operator"]))
    assert zenoh_config.listen_endpoints(example, "peer") == []


def test_router_main_warns_before_listening_beyond_loopback(
        monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture) -> None:
    from tdcm_ros.runtime import router

    def refuse(**kwargs: Any) -> None:
        raise RuntimePortError("not opened in this test")

    for name in (CONFIG_ENV, zenoh_config.ROUTER_CONFIG_ENV):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setattr(router, "open_session", refuse)
    with caplog.at_level(logging.WARNING, logger="tdcm.zenoh"):
        assert router.main(["--listen", "tcp/0.0.0.0:7447"]) == 1
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warnings) == 1
    assert "tcp/0.0.0.0:7447" in warnings[0] and SECTION in warnings[0]


def test_tdcm_up_exports_configs_and_warns_for_exposed_nodes(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        caplog: pytest.LogCaptureFixture) -> None:
    from tdcm_ros.cli import up

    for name in (CONFIG_ENV, zenoh_config.ROUTER_CONFIG_ENV):
        monkeypatch.setenv(name, "")  # restored after the test
    open_peer = tmp_path / "open_peer.json5"
    open_peer.write_text('{listen: {endpoints: ["tcp/0.0.0.0:0"]}}')
    args = argparse.Namespace(zenoh_config=str(open_peer), router_config=None)
    with caplog.at_level(logging.WARNING, logger="tdcm.zenoh"):
        up.export_zenoh_configs(args, "tcp/127.0.0.1:7447")
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warnings) == 1
    assert "tcp/0.0.0.0:0" in warnings[0] and SECTION in warnings[0]
    assert os.environ[CONFIG_ENV] == str(open_peer)


def test_tdcm_up_rejects_a_bad_config_and_configs_on_rclpy(tmp_path: Path,
                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    from tdcm_ros.cli import up

    for name in (CONFIG_ENV, zenoh_config.ROUTER_CONFIG_ENV):
        monkeypatch.setenv(name, "")
    parser = argparse.ArgumentParser()
    up.register(parser.add_subparsers())
    rclpy_args = parser.parse_args(["up", "--runtime", "rclpy", "--zenoh-config", "peer.json5"])
    with pytest.raises(InputError) as error:
        up.plan(rclpy_args, 1)
    assert error.value.parameter == "--zenoh-config"
    broken = tmp_path / "broken.json5"
    broken.write_text("{transport: ")
    with pytest.raises(RuntimePortError, match="cannot load zenoh config"):
        up.export_zenoh_configs(parser.parse_args(["up", "--router-config", str(broken)]),
                                "tcp/127.0.0.1:7447")


def test_build_rejects_an_unknown_role() -> None:
    with pytest.raises(InputError) as error:
        zenoh_config.build(mode="client", endpoint="tcp/127.0.0.1:7447", path=None)
    assert (error.value.parameter, error.value.value) == ("mode", "client")


# --- the generated access-control list, attacked by an observer with raw zenoh keys ----------
def data_key(topic: str, type_name: str) -> str:
    """rmw_zenoh's data key of ``topic`` in domain 0."""
    return wire.topic_key(0, topic, type_name, type_hash(type_name))


def service_key(name: str, type_name: str) -> str:
    """rmw_zenoh's queryable key of the service ``name`` in domain 0."""
    return wire.topic_key(0, name, type_name, service_type_hash(type_name))


FLOAT64 = "std_msgs/msg/Float64"
#: Puts the README says an observer cannot make: command inputs, sensor topics, wildcard keys.
DENIED_PUTS = {
    "tension_setpoint": data_key("tension_setpoint", FLOAT64),
    "roll_setpoint": data_key("roll_setpoint", FLOAT64),
    "target_angle": data_key("target_angle", FLOAT64),
    "target_point": data_key("target_point", "geometry_msgs/msg/PointStamped"),
    "tension": data_key("tension", "geometry_msgs/msg/WrenchStamped"),
    "wildcard in the topic": "0/tension_setpoin$*/std_msgs::msg::dds_::Float64_/*",
    "wildcard topic of a type": "0/*/std_msgs::msg::dds_::Float64_/*",
    "everything": "**",
}
SET_PARAMETERS = "rcl_interfaces/srv/SetParameters"
#: Queries the README says an observer cannot make: parameter changes, command services, wildcards.
DENIED_QUERIES = {
    "set_parameters": service_key("tension_driver/set_parameters", SET_PARAMETERS),
    "set_parameters_atomically": service_key("model_node/set_parameters_atomically",
                                             "rcl_interfaces/srv/SetParametersAtomically"),
    "clear_faults": service_key("tension_driver/clear_faults", "std_srvs/srv/Trigger"),
    "start_schedule": service_key("tension_driver/start_schedule", "std_srvs/srv/Trigger"),
    "release": service_key("tension_driver/release", "std_srvs/srv/Trigger"),
    "wildcard set_parameters": "*/**/set_parameters/**",
    "everything": "**",
}
ESTOP_KEY = data_key("estop", "std_msgs/msg/Empty")
ESTOP_SERVICE_KEY = service_key("tension_driver/estop", "std_srvs/srv/Trigger")
GET_PARAMETERS_KEY = service_key("tension_driver/get_parameters",
                                 "rcl_interfaces/srv/GetParameters")
#: A service the observer tries to serve (it asked by an operator; the victim serves it too).
IMPERSONATED_KEY = service_key("model_node/get_parameters", "rcl_interfaces/srv/GetParameters")


class Victim:
    """An operator session that takes every sample and query the router routes to it, and
    answers each query with its own key."""

    def __init__(self, config: Path, endpoint: str) -> None:
        self.session = zenoh.open(zenoh_config.build(mode="peer", endpoint=endpoint,
                                                     path=str(config)))
        self.samples: list[tuple[str, bytes]] = []
        self.queries: list[str] = []
        self._subscriber = self.session.declare_subscriber(
            "**", lambda s: self.samples.append((str(s.key_expr), s.payload.to_bytes())))
        self._queryable = self.session.declare_queryable("**", self._answer, complete=False)

    def _answer(self, query: Any) -> None:
        self.queries.append(str(query.key_expr))
        if "*" not in str(query.key_expr):
            query.reply(query.key_expr, b"answer")

    def attacks(self) -> list[str]:
        """Keys of the observer's samples and queries that reached this operator."""
        allowed = (GET_PARAMETERS_KEY, ESTOP_SERVICE_KEY, IMPERSONATED_KEY)
        return [key for key, payload in self.samples if payload == b"attack"] + [
            key for key in self.queries if key not in allowed]

    def close(self) -> None:
        self.session.close()


def test_the_generated_acl_lets_an_observer_watch_stop_and_read_but_nothing_else(
        secrets: dict[str, Path], tls_port: int, spawn: Spawn) -> None:
    """With the shipped router.json5 (its generated block), user ``observer`` on raw zenoh keys:
    every put of DENIED_PUTS and query of DENIED_QUERIES (exact keys, wildcard keys, wildcard
    queries) never reaches an operator's subscriber or queryable on ``**``, and a queryable it
    declares is never asked; its e-stop puts, e-stop and get_parameters queries do, and it
    receives the answers and the operator's samples."""
    endpoint = f"tls/127.0.0.1:{tls_port}"
    spawn("tdcm_ros.runtime.router", "--listen", endpoint, "--config", str(secrets["router"]))
    eventually(lambda: listening(tls_port), 15.0, "the TLS router")
    victim = Victim(secrets["operator"], endpoint)
    observer, asker = (zenoh.open(zenoh_config.build(mode="peer", endpoint=endpoint,
                                                     path=str(secrets[user])))
                       for user in ("observer", "operator"))
    try:
        heard: list[str] = []
        observer.declare_subscriber("0/chatter/**", lambda s: heard.append(str(s.key_expr)))
        impostor: list[str] = []
        observer.declare_queryable(IMPERSONATED_KEY, lambda q: impostor.append(str(q.key_expr)),
                                   complete=True)
        answers: list[str] = []
        asked: list[str] = []

        def attack_then_stop() -> bool:
            for key in DENIED_PUTS.values():
                observer.put(key, b"attack")
            for key in DENIED_QUERIES.values():
                observer.get(key, lambda _reply: None, timeout=1.0)
            observer.put(ESTOP_KEY, b"estop")
            observer.get(ESTOP_SERVICE_KEY, lambda _reply: None, timeout=1.0)
            observer.get(GET_PARAMETERS_KEY,
                         lambda reply: answers.append(reply.ok.payload.to_bytes().decode()),
                         timeout=1.0)
            victim.session.put("0/chatter/std_msgs::msg::dds_::String_/x", b"hello")
            asker.get(IMPERSONATED_KEY,
                      lambda reply: asked.append(reply.ok.payload.to_bytes().decode()),
                      timeout=1.0)
            return (sum(p == b"estop" for _, p in victim.samples) >= 5 and "answer" in answers
                    and ESTOP_SERVICE_KEY in victim.queries and len(heard) >= 5
                    and len(asked) >= 5)

        eventually(attack_then_stop, 30.0, "the observer's e-stops, reads and watching",
                   every=0.1, detail=lambda: (f"{len(victim.samples)} samples, queries "
                                              f"{victim.queries[-3:]}, {len(answers)} answers, "
                                              f"{len(heard)} heard, {len(asked)} asked"))
        # the observer's own wildcard queries reach its queryable inside its session: not counted
        assert victim.attacks() == [] and IMPERSONATED_KEY not in impostor
    finally:
        for session in (observer, asker):
            session.close()
        victim.close()


# --- a misconfigured peer fails closed, with the cause ----------------------------------------
def other_certificates(folder: Path) -> None:
    """Another CA (``other_ca.pem``) and a router certificate of the test CA for another name
    (``bench.pem``/``bench.key``: DNS bench-pc only)."""
    ec = ("-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes")
    openssl(folder, "req", "-x509", *ec, "-keyout", "other_ca.key", "-out", "other_ca.pem",
            "-days", "1", "-subj", "/CN=another CA")
    openssl(folder, "req", *ec, "-keyout", "bench.key", "-out", "bench.csr", "-subj",
            "/CN=bench-pc")
    (folder / "bench_san.cnf").write_text("subjectAltName=DNS:bench-pc\n")
    openssl(folder, "x509", "-req", "-in", "bench.csr", "-CA", "ca.pem", "-CAkey", "ca.key",
            "-CAcreateserial", "-out", "bench.pem", "-days", "1", "-extfile", "bench_san.cnf")


MISCONFIGURED = {  # case -> (router file edit, peer file edit, the cause the error names)
    "wrong password": ({}, {"op-pass-7f3a": "not-the-password"},
                       "user 'operator' with this password is not in its users file"),
    "another CA": ({}, {"/ca.pem": "/other_ca.pem"},
                   "fails verification: unable to get local issuer certificate"),
    "another name": ({"/router.pem": "/bench.pem", "/router.key": "/bench.key"}, {},
                     "a certificate for another name than '127.0.0.1'"),
    "missing CA file": ({}, {"/ca.pem": "/no_such_ca.pem"},
                        "root_ca_certificate = "),
}


@pytest.mark.parametrize("case", sorted(MISCONFIGURED))
def test_a_misconfigured_peer_fails_closed_naming_the_cause(
        case: str, secrets: dict[str, Path], tls_port: int, spawn: Spawn,
        monkeypatch: pytest.MonkeyPatch) -> None:
    from tdcm_ros.runtime.zenoh_runtime import ENDPOINT_ENV, open_session

    folder = secrets["router"].parent
    other_certificates(folder)
    router_edits, peer_edits, cause = MISCONFIGURED[case]
    router, peer = folder / "bad_router.json5", folder / "bad_peer.json5"
    for source, target, edits in ((secrets["router"], router, router_edits),
                                  (secrets["operator"], peer, peer_edits)):
        text = source.read_text()
        for old, new in edits.items():
            assert old in text
            text = text.replace(old, new)
        target.write_text(text)
    endpoint = f"tls/127.0.0.1:{tls_port}"
    spawn("tdcm_ros.runtime.router", "--listen", endpoint, "--config", str(router))
    eventually(lambda: listening(tls_port), 15.0, "the TLS router")
    monkeypatch.setenv(CONFIG_ENV, str(peer))
    monkeypatch.setenv(ENDPOINT_ENV, endpoint)
    with pytest.raises(RuntimePortError, match="cannot be read|no zenoh router after") as error:
        open_session().close()
    assert cause in str(error.value)


def test_tdcm_up_with_a_wrong_password_exits_with_the_cause(
        secrets: dict[str, Path], tls_port: int) -> None:
    """No node starts: the launcher's own peer check fails first and tdcm up exits non-zero."""
    endpoint = f"tls/127.0.0.1:{tls_port}"
    up = subprocess.run([sys.executable, "-m", "tdcm_ros.cli.main", "up", "--nodes", "talker",
                         "--endpoint", endpoint, "--router-config", str(secrets["router"]),
                         "--zenoh-config", str(secrets["wrong"])], cwd=EXAMPLES.parents[1],
                        env=os.environ, capture_output=True, text=True, check=False, timeout=120)
    assert up.returncode != 0
    assert "user 'operator' with this password is not in its users file" in up.stderr
    assert "starting talker" not in up.stderr

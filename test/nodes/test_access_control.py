"""The generated access-control list: the shipped router config holds exactly what the generator
gives, the keys it opens are the ones the nodes serve, and bad input is refused. What the list
does on a router is tested in test/runtime/test_zenoh_security.py."""

from __future__ import annotations

from pathlib import Path

import pytest

from tdcm_ros.errors import InputError
from tdcm_ros.nodes import access_control as acl
from tdcm_ros.runtime import wire
from tdcm_ros.runtime.param_services import SERVICES
from test.nodes.driver_bench import DriverBench

ROUTER = Path(__file__).resolve().parents[2] / "config" / "zenoh" / "router.json5"


def test_the_shipped_router_config_holds_the_generated_block() -> None:
    text = ROUTER.read_text(encoding="utf-8")
    assert acl.update(ROUTER, acl.access_control()) == text
    assert acl.block(acl.access_control()) in text


def test_update_replaces_only_the_block(tmp_path: Path) -> None:
    path = tmp_path / "router.json5"
    path.write_text(f"{{\n  a: 1,\n  {acl.BEGIN}\n  old: 2,\n  {acl.END}\n  b: 3,\n}}\n")
    assert acl.main(["--operators", "alice", "bob", "--observers", "eve",
                     "--update", str(path)]) == 0
    text = path.read_text()
    assert text.startswith("{\n  a: 1,\n") and text.endswith("  b: 3,\n}\n") and "old" not in text
    assert '"usernames": ["alice", "bob"]' in text and '"usernames": ["eve"]' in text


def test_a_config_without_the_markers_is_refused(tmp_path: Path, capsys) -> None:
    path = tmp_path / "router.json5"
    path.write_text("{}\n")
    assert acl.main(["--update", str(path)]) == 2
    assert "has no generated access_control block" in capsys.readouterr().err
    assert path.read_text() == "{}\n"


@pytest.mark.parametrize(("operators", "observers", "parameter"), [
    (["op erator"], ["observer"], "operators"), ([""], ["observer"], "operators"),
    (["operator"], ["a:b"], "observers"), (["alice"], ["alice"], "observers")])
def test_bad_user_names_are_refused(operators: list[str], observers: list[str],
                                    parameter: str) -> None:
    with pytest.raises(InputError) as error:
        acl.access_control(operators, observers)
    assert error.value.parameter == parameter


def test_without_observers_only_operators_get_a_policy() -> None:
    section = acl.access_control(["operator"], [])
    assert section["default_permission"] == "deny"
    assert section["policies"] == [{"rules": ["operate"], "subjects": ["operators"]}]


def test_the_opened_keys_are_the_drivers_estop_and_the_read_only_parameter_services() -> None:
    """The tension driver's own estop topic and service keys (as its zenoh runtime declares
    them) are included in the opened keys; no set_parameters service is."""
    bench = DriverBench()
    port = bench.port
    try:
        opened = {rule["id"]: rule["key_exprs"] for rule in acl.access_control()["rules"]}
        estop_type = port.subscriptions[acl.ESTOP_TOPIC][0]
        estop_key = acl.topic_key(acl.ESTOP_TOPIC, estop_type)
        assert opened["stop the tendon"] == [estop_key]
        assert f"~/{acl.ESTOP_SERVICE}" in port.services
        service_type = port.services[f"~/{acl.ESTOP_SERVICE}"][0]
        assert opened["call estop"] == [acl.service_key(acl.ESTOP_SERVICE, service_type)]
        read = " ".join(opened["read parameters"])
        assert "set_parameters" not in read
        assert all(f"/{name}/" in read for name in acl.READ_ONLY_SERVICES)
        assert set(acl.READ_ONLY_SERVICES) < set(SERVICES)
        assert estop_key == "*/**/" + wire.topic_key(0, "estop", estop_type,
                                                      estop_key.rsplit("/", 1)[1])[2:]
    finally:
        bench.close()

"""Service types in the message model: std_srvs/srv/Trigger as rosidl generates it."""

from __future__ import annotations

import pytest

from tdcm_ros.bagio import (
    BagError,
    deserialize,
    from_dict,
    normalize_service_type,
    serialize,
    service_type_hash,
    type_hash,
)

#: From the ``type_hashes`` of ROS 2 Jazzy's ``share/std_srvs/srv/Trigger.json`` (std_srvs 5.3,
#: written by rosidl_generator_type_description): the hashes rmw implementations use.
TRIGGER_HASHES = {
    "std_srvs/srv/Trigger":
        "RIHS01_eeff2cd6fa5ad9d27cdf4dec64818317839b62f212a91e6b5304b634b2062c5f",
    "std_srvs/srv/Trigger_Request":
        "RIHS01_d010825374ce8918e72bfd826c82603e60f45419e932ea976f807b74a863a199",
    "std_srvs/srv/Trigger_Response":
        "RIHS01_2d946c21e2fc3f1e9ca6986a8191d85fcc70097a8bb7771a053564bc47009cdf",
}


def test_trigger_hashes_equal_rosidls() -> None:
    assert service_type_hash("std_srvs/srv/Trigger") == TRIGGER_HASHES["std_srvs/srv/Trigger"]
    for name in ("std_srvs/srv/Trigger_Request", "std_srvs/srv/Trigger_Response"):
        assert type_hash(name) == TRIGGER_HASHES[name]


#: From the ``type_hashes`` of ROS 2 Jazzy's ``share/rcl_interfaces/srv/<Name>.json``
#: (rcl_interfaces 2.0.3, the rclpy venv of .ci/ros.sh): the keys ``ros2 param`` queries on rmw_zenoh.
PARAMETER_SERVICE_HASHES = {
    "DescribeParameters": "845b484d71eb0673dae682f2e3ba3c4851a65a3dcfb97bddd82c5b57e91e4cff",
    "GetParameterTypes": "da199c878688b3e530bdfe3ca8f74cb9fa0c303101e980a9e8f260e25e1c80ca",
    "GetParameters": "bf9803d5c74cf989a5de3e0c2e99444599a627c7ff75f97b8c05b01003675cbc",
    "ListParameters": "3e6062bfbb27bfb8730d4cef2558221f51a11646d78e7bb30a1e83afac3aad9d",
    "SetParameters": "56eed9a67e169f9cb6c1f987bc88f868c14a8fc9f743a263bc734c154015d7e0",
    "SetParametersAtomically": "0e192ef259c07fc3c07a13191d27002222e65e00ccec653ca05e856f79285fcd",
}


@pytest.mark.parametrize("name", sorted(PARAMETER_SERVICE_HASHES))
def test_parameter_service_hashes_equal_rosidls(name: str) -> None:
    assert service_type_hash(f"rcl_interfaces/srv/{name}") == (
        f"RIHS01_{PARAMETER_SERVICE_HASHES[name]}")


def test_trigger_request_and_response_cdr() -> None:
    """The empty request carries rosidl's one-byte placeholder; the response bool + string."""
    assert serialize(from_dict("std_srvs/srv/Trigger_Request", {})) == b"\x00\x01\x00\x00\x00"
    response = from_dict("std_srvs/srv/Trigger_Response", {"success": True, "message": "ok"})
    data = serialize(response)
    assert data == b"\x00\x01\x00\x00\x01\x00\x00\x00\x03\x00\x00\x00ok\x00"
    assert deserialize(data, "std_srvs/srv/Trigger_Response") == response


def test_service_type_names() -> None:
    assert normalize_service_type("std_srvs/Trigger") == "std_srvs/srv/Trigger"
    with pytest.raises(BagError, match="unknown service type 'std_srvs/srv/SetBool'; known: "
                                       "std_srvs/srv/Trigger"):
        normalize_service_type("std_srvs/srv/SetBool")

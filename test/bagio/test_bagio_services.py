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

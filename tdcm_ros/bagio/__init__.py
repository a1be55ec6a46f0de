"""One message model for every carrier: the rosbags Jazzy typestore plus ``msg_defs/``.

``serialize``/``deserialize`` move CDR bytes; ``type_hash`` gives the REP-2016 RIHS01 hash
that rmw_zenoh puts in its key expressions (``service_type_hash`` for ``pkg/srv/Name``);
:class:`CdrWriter` writes the same bytes directly where building message objects costs too much.
"""

from tdcm_ros.bagio.cdr import (
    CDR_LITTLE_ENDIAN,
    CdrWriter,
    PayloadRows,
    cdr_align,
    cdr_header,
    cdr_string,
    cdr_strings,
    joint_state_cdr,
)
from tdcm_ros.bagio.convert import from_dict, prepare_codec, to_dict
from tdcm_ros.bagio.errors import BagError
from tdcm_ros.bagio.services import normalize_service_type
from tdcm_ros.bagio.typestore import (
    deserialize,
    message_definition,
    msg_class,
    normalize_type_name,
    serialize,
    service_type_hash,
    type_hash,
    type_name_of,
    typestore,
)

__all__ = [
    "CDR_LITTLE_ENDIAN",
    "BagError",
    "CdrWriter",
    "PayloadRows",
    "cdr_align",
    "cdr_header",
    "cdr_string",
    "cdr_strings",
    "deserialize",
    "from_dict",
    "joint_state_cdr",
    "message_definition",
    "msg_class",
    "normalize_service_type",
    "normalize_type_name",
    "prepare_codec",
    "serialize",
    "service_type_hash",
    "to_dict",
    "type_hash",
    "type_name_of",
    "typestore",
]

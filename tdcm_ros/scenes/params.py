"""Scene parameters: :class:`~tdcm_ros.spec.Spec` (here also named ``Param``) bound to
:class:`InvalidSceneError`.

:func:`parse_params` checks a YAML mapping against a tuple of specs, rejecting unknown keys with
the list of valid ones. Every message names the full key (e.g. ``effects.tendon_friction.mu``).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from tdcm_ros.scenes.errors import InvalidSceneError
from tdcm_ros.spec import Spec, parse_mapping, spec_table
from tdcm_ros.spec import as_mapping as _as_mapping

#: A scene parameter is a package parameter spec.
Param = Spec
__all__ = ["Param", "as_mapping", "param_table", "parse_params", "parse_value"]


def as_mapping(where: str, raw: Any) -> Mapping[str, Any]:
    """``raw`` as a mapping (``None`` is empty); anything else raises naming ``where``."""
    return _as_mapping(where, raw, error=InvalidSceneError)


def parse_value(where: str, spec: Spec, value: Any) -> Any:
    """``value`` of the key ``where`` parsed against ``spec``; :class:`InvalidSceneError`."""
    return spec.parse(value, where, error=InvalidSceneError)


def parse_params(where: str, specs: Iterable[Spec], raw: Any) -> dict[str, Any]:
    """Values for every spec from ``raw`` (defaults filled in); unknown keys raise."""
    return parse_mapping(where, specs, raw, error=InvalidSceneError)


def param_table(specs: Iterable[Spec]) -> list[dict[str, str]]:
    """Rows ``name, unit, default, allowed, description`` for documentation and the CLI."""
    return spec_table(specs)

"""Tiny stand-ins for ``launch`` and ``launch_ros`` (not installable here), to run launch files.

Each class takes the keyword arguments of the real one it stands for (an unknown keyword is a
``TypeError``, as in launch), records them, and :func:`resolve` evaluates the substitutions the
package's launch files use. ``FindPackageShare("tdcm_ros")`` resolves to the source tree, whose
``config/`` is what setup.py installs under ``share/tdcm_ros/config``.
"""

from __future__ import annotations

import os
import runpy
import sys
import types
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any
from unittest import mock

REPO = Path(__file__).resolve().parents[1]


class LaunchDescription:
    def __init__(self, initial_entities: list[Any] | None = None) -> None:
        self.entities = list(initial_entities or [])


class DeclareLaunchArgument:
    def __init__(self, name: str, *, default_value: Any = None, description: str | None = None,
                 choices: list[str] | None = None) -> None:
        self.name, self.default_value, self.choices = name, default_value, choices
        self.description = description


class LaunchConfiguration:
    def __init__(self, variable_name: str, *, default: Any = None) -> None:
        self.variable_name, self.default = variable_name, default


class PathJoinSubstitution:
    def __init__(self, substitutions: list[Any]) -> None:
        self.substitutions = list(substitutions)


class FindPackageShare:
    def __init__(self, package: str) -> None:
        self.package = package


class IfCondition:
    """launch's condition: true for ``true``/``1``, false for ``false``/``0`` (any case); other
    text is an error, as in launch."""

    def __init__(self, predicate_expression: Any) -> None:
        self.predicate_expression = predicate_expression

    def evaluate(self, arguments: Mapping[str, str]) -> bool:
        text = str(resolve(self.predicate_expression, arguments)).lower()
        if text not in ("true", "1", "false", "0"):
            raise ValueError(f"IfCondition: {text!r} is no boolean")
        return text in ("true", "1")


class OpaqueFunction:
    def __init__(self, *, function: Any, args: list[Any] | None = None,
                 kwargs: dict[str, Any] | None = None, condition: IfCondition | None = None) -> None:
        self.function, self.condition = function, condition
        self.args, self.kwargs = list(args or []), dict(kwargs or {})


class PythonLaunchDescriptionSource:
    def __init__(self, launch_file_path: Any) -> None:
        self.launch_file_path = launch_file_path


class IncludeLaunchDescription:
    def __init__(self, launch_description_source: PythonLaunchDescriptionSource, *,
                 launch_arguments: Any = None, condition: IfCondition | None = None) -> None:
        self.source, self.condition = launch_description_source, condition
        self.launch_arguments = list(launch_arguments or [])


class LaunchContext:
    """What an ``OpaqueFunction`` gets: the launch configurations, all resolved to text."""

    def __init__(self, launch_configurations: Mapping[str, str]) -> None:
        self.launch_configurations = dict(launch_configurations)


class ParameterValue:
    """launch_ros's typed parameter value: ``value_type=str`` keeps the substituted text as it
    is (no YAML reading), the way the launch files pass ``frame_prefix``."""

    def __init__(self, value: Any, *, value_type: Any = None) -> None:
        self.value, self.value_type = value, value_type


class Node:
    def __init__(self, *, executable: str, package: str | None = None, name: str | None = None,
                 namespace: Any = None, exec_name: str | None = None,
                 parameters: list[Any] | None = None, remappings: list[Any] | None = None,
                 ros_arguments: list[Any] | None = None, arguments: list[Any] | None = None,
                 output: str = "log", condition: IfCondition | None = None,
                 **_other: Any) -> None:
        self.executable, self.package, self.name, self.namespace = executable, package, name, namespace
        self.parameters = list(parameters or [])
        self.remappings = list(remappings or [])
        self.arguments, self.condition = list(arguments or []), condition


def _share(package: str) -> str:
    if package != "tdcm_ros":
        raise LookupError(f"package {package!r} not found")
    return str(REPO)


def resolve(value: Any, arguments: Mapping[str, str]) -> Any:
    """The value of a substitution (or a plain value) under the launch ``arguments``."""
    if isinstance(value, LaunchConfiguration):
        return arguments[value.variable_name]
    if isinstance(value, PathJoinSubstitution):
        return os.path.join(*(str(resolve(part, arguments)) for part in value.substitutions))
    if isinstance(value, FindPackageShare):
        return _share(value.package)
    if isinstance(value, ParameterValue):
        return ParameterValue(resolve(value.value, arguments), value_type=value.value_type)
    if isinstance(value, (list, tuple)):
        return type(value)(resolve(item, arguments) for item in value)
    if isinstance(value, dict):
        return {key: resolve(item, arguments) for key, item in value.items()}
    return value


def _modules() -> dict[str, types.ModuleType]:
    def module(name: str, **members: Any) -> types.ModuleType:
        made = types.ModuleType(name)
        made.__dict__.update(members)
        return made

    return {
        "launch": module("launch", LaunchDescription=LaunchDescription),
        "launch.actions": module("launch.actions", DeclareLaunchArgument=DeclareLaunchArgument,
                                 IncludeLaunchDescription=IncludeLaunchDescription,
                                 OpaqueFunction=OpaqueFunction),
        "launch.conditions": module("launch.conditions", IfCondition=IfCondition),
        "launch.launch_description_sources": module(
            "launch.launch_description_sources",
            PythonLaunchDescriptionSource=PythonLaunchDescriptionSource),
        "launch.substitutions": module("launch.substitutions",
                                       LaunchConfiguration=LaunchConfiguration,
                                       PathJoinSubstitution=PathJoinSubstitution),
        "launch_ros": module("launch_ros"),
        "launch_ros.actions": module("launch_ros.actions", Node=Node),
        "launch_ros.parameter_descriptions": module("launch_ros.parameter_descriptions",
                                                    ParameterValue=ParameterValue),
        "launch_ros.substitutions": module("launch_ros.substitutions",
                                           FindPackageShare=FindPackageShare),
        # the older style (os.path.join over the share directory) still loads, to be judged
        "ament_index_python": module("ament_index_python"),
        "ament_index_python.packages": module("ament_index_python.packages",
                                              get_package_share_directory=_share),
    }


@contextmanager
def fake_launch() -> Iterator[None]:
    """``launch``, ``launch_ros`` and ``ament_index_python`` replaced by the stand-ins."""
    with mock.patch.dict(sys.modules, _modules()):
        yield


def load(path: Path) -> LaunchDescription:
    """Run ``path``'s ``generate_launch_description()`` on the stand-ins."""
    with fake_launch():
        return runpy.run_path(str(path))["generate_launch_description"]()


def launch_arguments(description: LaunchDescription, given: Mapping[str, str],
                     inherited: Mapping[str, str] | None = None) -> dict[str, str]:
    """Declared arguments with their defaults, overridden by what an including file set
    (``inherited``), then by ``given``; an undeclared or an off-``choices`` argument raises as
    ``ros2 launch`` refuses it."""
    declared = [e for e in description.entities if isinstance(e, DeclareLaunchArgument)]
    names = {d.name for d in declared}
    unknown = set(given) - names
    if unknown:
        raise KeyError(f"undeclared launch arguments {sorted(unknown)}")
    values = {d.name: str(resolve(d.default_value, {})) for d in declared
              if d.default_value is not None}
    values.update(inherited or {})
    values.update(given)
    for d in declared:
        if d.choices is not None and values.get(d.name) not in d.choices:
            raise ValueError(f"{d.name}:={values.get(d.name)} not in {d.choices}")
    return values


def nodes(description: LaunchDescription) -> list[Node]:
    return [e for e in description.entities if isinstance(e, Node)]


def launched(path: Path, given: Mapping[str, str],
             inherited: Mapping[str, str] | None = None) -> list[tuple[Node, dict[str, str]]]:
    """The nodes ``ros2 launch PATH given...`` starts, each with the launch configurations its
    substitutions see: conditions evaluated, opaque functions run, included files expanded (an
    included file sees the including file's configurations and its ``launch_arguments``)."""
    description = load(path)
    arguments = launch_arguments(description, given, inherited)
    out: list[tuple[Node, dict[str, str]]] = []
    entities = list(description.entities)
    while entities:
        entity = entities.pop(0)
        if getattr(entity, "condition", None) is not None \
                and not entity.condition.evaluate(arguments):
            continue
        if isinstance(entity, Node):
            out.append((entity, arguments))
        elif isinstance(entity, OpaqueFunction):
            made = entity.function(LaunchContext(arguments), *entity.args, **entity.kwargs)
            entities[:0] = list(made or [])
        elif isinstance(entity, IncludeLaunchDescription):
            included = {str(resolve(key, arguments)): str(resolve(value, arguments))
                        for key, value in entity.launch_arguments}
            out += launched(Path(resolve(entity.source.launch_file_path, arguments)), included,
                            arguments)
    return out

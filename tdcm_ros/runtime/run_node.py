"""Run one node class on a chosen runtime; also the ``tdcm_node`` executable.

``python -m tdcm_ros.runtime.run_node tdcm_ros.nodes.talker:Talker --params config.yaml``
Runtime: ``--runtime`` if not ``auto``, else ``TDCM_RUNTIME`` if set, else rclpy when importable,
else zenoh. Arguments after ``--ros-args`` go to rclpy unchanged.
"""

from __future__ import annotations

import argparse
import faulthandler
import importlib
import importlib.util
import logging
import os
import signal
import sys
import threading
import time
from collections.abc import Sequence
from pathlib import Path
from types import FrameType
from typing import Any

from tdcm_ros.errors import InputError, TdcmError
from tdcm_ros.runtime.names import fully_qualified_node_name
from tdcm_ros.runtime.params import (
    CliParam,
    Source,
    node_entries,
    node_parameters,
    ros_arguments,
    sources_in_order,
)
from tdcm_ros.runtime.port import NodeLogic, NodePort

RUNTIMES = ("auto", "zenoh", "rclpy")
RUNTIME_ENV = "TDCM_RUNTIME"
#: Exit status of a node whose loop died of an unexpected error (callbacks are isolated, see
#: :mod:`tdcm_ros.runtime.guard`; this is what is left), so ``tdcm up`` and launch see it.
LOOP_DIED = 70
#: Exit status of a node stopped by a signal while it was being built (128 + SIGINT, as Ctrl-C).
INTERRUPTED_EXIT = 130
#: s a node interrupted while it is built has to stop before it exits without its clean-up: a
#: library the build calls may run the signal's handler and drop its error (seen: an importlib
#: weakref callback, "Exception ignored in ... KeyboardInterrupt"), and the build goes on for
#: seconds. Well inside ``tdcm up``'s and launch's 5 s before a kill.
STUCK_BUILD_S = 2.0
#: s a built node may take to stop (leave its loop, close, close its context) after a signal
#: before it writes every thread's stack to stderr (Python's faulthandler, headed "Timeout"):
#: where a slow stop spends its time, in the launcher's log, before its SIGTERM at 5 s.
SLOW_STOP_S = 3.0


def _exit_if_still_running(seconds: float, what: str) -> None:
    """After ``seconds``, if the process is still here, say so and exit ``INTERRUPTED_EXIT`` at
    once (no clean-up: nothing of a node not yet built needs it; its sockets close with it,
    and a device it opened releases on its own watchdog)."""
    time.sleep(seconds)
    print(f"{executable_name()}: {what} while starting; the build did not stop within "
          f"{seconds:g} s: exiting", file=sys.stderr, flush=True)
    os._exit(INTERRUPTED_EXIT)


def resolve_runtime(choice: str = "auto") -> str:
    """``zenoh`` or ``rclpy``: the flag, else ``TDCM_RUNTIME``, else rclpy if importable."""
    for value, source in ((choice, "--runtime"), (os.environ.get(RUNTIME_ENV, "auto"), RUNTIME_ENV)):
        if value not in RUNTIMES:
            raise InputError(f"{source} = {value!r} is invalid; allowed: {', '.join(RUNTIMES)}",
                             parameter=source, value=value, allowed=", ".join(RUNTIMES))
        if value != "auto":
            return value
    return "rclpy" if importlib.util.find_spec("rclpy") is not None else "zenoh"


def load_node_class(target: str) -> type[NodeLogic]:
    """Import ``package.module:Class`` and check it is a :class:`NodeLogic`."""
    module_name, _, class_name = target.partition(":")
    try:
        node_class = getattr(importlib.import_module(module_name), class_name)
    except (ImportError, AttributeError, ValueError) as error:
        raise InputError(f"cannot load node class {target!r}: {error}", parameter="node",
                         value=target, allowed="package.module:Class") from error
    if not (isinstance(node_class, type) and issubclass(node_class, NodeLogic)):
        raise InputError(f"{target!r} is not a NodeLogic subclass", parameter="node", value=target)
    return node_class


def configure_logging(level: str = "INFO") -> None:
    """ROS-like log lines on stderr: ``[LEVEL] [time] [logger]: message``."""
    logging.basicConfig(level=level, stream=sys.stderr,
                        format="[%(levelname)s] [%(created).6f] [%(name)s]: %(message)s")


def open_context(runtime: str, ros_args: Sequence[str] = (),
                 params_files: Sequence[str] = (), *, require_graph: bool = False) -> Any:
    """A new context of ``runtime`` (``zenoh`` or ``rclpy``; ``ros_args`` and the parameter
    files whose values its nodes take are for rclpy). ``require_graph`` (the graph tools): on
    zenoh, ``RuntimePortError`` saying why if no router is reached (rclpy has none to reach)."""
    if runtime == "rclpy":
        from tdcm_ros.runtime.rclpy_runtime import RclpyContext

        return RclpyContext(ros_args, params_files)
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext

    context = ZenohContext()
    if require_graph:
        try:
            context.require_router()
        except BaseException:
            context.close()
            raise
    return context


def warn_unused_overrides(port: NodePort, sources: Sequence[Source]) -> None:
    """Warn of each name an entry that names this node (``/ns/node``, ``node``, ``/**/node``)
    sets and the node does not declare: it has no effect (a typo, or a parameter of another
    node). Entries for any node (``/**``, ``/ns/*``) are meant for many nodes, so their extra
    names are not warned of."""
    fqn = fully_qualified_node_name(port.namespace, port.node_name)
    exact = {name for key, values in node_entries(sources, fqn)
             if key.rpartition("/")[2] not in ("*", "**") for name in values}
    origin = " or ".join(f"-p {source.item}" if isinstance(source, CliParam)
                         else f"parameter file {source}" for source in sources)
    for name in port.unused_overrides():
        if name in exact:
            port.logger.warning("%s sets %s for %s, which does not declare it: ignored",
                                origin, name, fqn)


def embedded_sources(params_file: str | None, ros_args: Sequence[str]) -> list[Source]:
    """The parameter sources of a node on the embedded runtime: ``params_file`` and the
    ``--params-file``/``-p`` items of ``ros_args``; any other ROS argument (a remap, an
    enclave) is refused by name, since this runtime would not apply it."""
    for flag, _ in ros_arguments(ros_args):
        if flag not in ("--params-file", "-p", "--param"):
            raise InputError(f"ROS argument {flag!r} is not supported by the embedded runtime "
                             "(it would be ignored); use --runtime rclpy, or the node's own "
                             "options", parameter="--ros-args", value=" ".join(ros_args),
                             allowed="--params-file FILE, -p [NODE:]NAME:=VALUE")
    return sources_in_order([params_file] if params_file else [], ros_args)


def run_node(node_class: type[NodeLogic], *, runtime: str = "auto", params_file: str | None = None,
             name: str | None = None, namespace: str = "/",
             ros_args: Sequence[str] = ()) -> int:
    """Run ``node_class`` on ``runtime`` (``auto``, ``zenoh`` or ``rclpy``) until SIGINT/SIGTERM.

    The node's ``close`` runs before its context shuts down, so what it logs or sends on the way
    out (the driver's release) still reaches the graph. A signal while the node is still being
    built (imports, compiled kernels, a first solve: seconds on a loaded machine) interrupts
    the build at once (:class:`KeyboardInterrupt`) instead of waiting for it to finish, and is
    remembered, so that a library which runs the handler and drops its error cannot make the
    node spin on, and the process leaves ``STUCK_BUILD_S`` later whatever the build does; once
    built, it ends the loop, and a stop still under way ``SLOW_STOP_S`` later writes every
    thread's stack to stderr.
    """
    node_name = name or node_class.default_name
    chosen = resolve_runtime(runtime)
    overrides: dict[str, Any] | None = None  # rclpy: by the node's final name, in create_port
    sources: list[Source] = []
    if chosen == "zenoh":
        sources = embedded_sources(params_file, ros_args)
        overrides = node_parameters(sources, fully_qualified_node_name(namespace, node_name))

    interrupted: list[str] = []

    def interrupt(signum: int, frame: FrameType | None) -> None:
        for sig in previous:  # a second signal on the way out must not interrupt the close
            signal.signal(sig, stop)
        interrupted.append(signal.Signals(signum).name)
        threading.Thread(target=_exit_if_still_running, args=(STUCK_BUILD_S, interrupted[-1]),
                         name="tdcm-stuck-build", daemon=True).start()
        raise KeyboardInterrupt(interrupted[-1])

    def stop(signum: int, frame: FrameType | None) -> None:
        context.request_stop()
        faulthandler.dump_traceback_later(SLOW_STOP_S)  # cancelled once closed

    context = open_context(chosen, ros_args, [params_file] if params_file else [])
    # after the context: opening a zenoh session installs its own SIGTERM handler
    previous = {s: signal.signal(s, interrupt) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        port = context.create_port(node_name, namespace, overrides)
        node = node_class(port)
        for sig in previous:
            signal.signal(sig, stop)
        try:
            if interrupted:  # a library the build called ran the handler and dropped its error
                raise KeyboardInterrupt(interrupted[0])
            warn_unused_overrides(port, sources if chosen == "zenoh" else context.param_sources)
            port.logger.info("running on %s (domain %d)", chosen, context.domain_id)
            context.spin()
        except Exception as error:  # noqa: BLE001 - the loop died: close, then exit non-zero
            port.logger.error("the node's loop died (%s: %s); closing it and exiting with %d",
                              type(error).__name__, error, LOOP_DIED)
            return LOOP_DIED
        finally:
            node.close()
    finally:
        context.close()
        faulthandler.cancel_dump_traceback_later()
        _restore(previous)
    return 0


def _restore(handlers: dict[signal.Signals, Any]) -> None:
    for sig, handler in handlers.items():
        signal.signal(sig, handler)


def build_parser(prog: str = "tdcm_node", *, with_target: bool = True,
                 description: str = "Run a tdcm_ros node.") -> argparse.ArgumentParser:
    """Arguments shared by ``tdcm_node`` and the per-node executables."""
    parser = argparse.ArgumentParser(prog=prog, description=description)
    if with_target:
        parser.add_argument("node", help="node class as package.module:Class")
    parser.add_argument("--name", help="node name (default: the class's default_name)")
    parser.add_argument("--namespace", default="/", help="node namespace (default /)")
    parser.add_argument("--params", help="ROS 2 parameter YAML (ros__parameters layout)")
    parser.add_argument("--runtime", default="auto", choices=RUNTIMES,
                        help=f"auto: rclpy if importable, else zenoh; env {RUNTIME_ENV}")
    parser.add_argument("--log-level", default="INFO", help="DEBUG, INFO, WARNING, ERROR")
    return parser


def main_for(node_class: type[NodeLogic] | None, argv: Sequence[str] | None = None) -> int:
    """Entry point body; ``node_class=None`` takes the class from the command line."""
    args_in = list(sys.argv[1:] if argv is None else argv)
    ros_args: list[str] = []
    if "--ros-args" in args_in:
        cut = args_in.index("--ros-args")
        args_in, ros_args = args_in[:cut], args_in[cut:]
    if node_class is None:
        parser = build_parser()
    else:
        parser = build_parser(executable_name(), with_target=False,
                              description=f"Run the {node_class.default_name} node.")
    args = parser.parse_args(args_in)
    configure_logging(args.log_level)
    try:
        target = node_class or load_node_class(args.node)
        return run_node(target, runtime=args.runtime, params_file=args.params, name=args.name,
                        namespace=args.namespace, ros_args=ros_args)
    except TdcmError as error:
        print(f"{parser.prog}: {error}", file=sys.stderr)
        return error.exit_code
    except KeyboardInterrupt as interrupted:
        print(f"{parser.prog}: {str(interrupted) or 'SIGINT'} while starting; stopped", file=sys.stderr)
        return INTERRUPTED_EXIT


def executable_name() -> str:
    """The name this process was started as (``tdcm_model_node``, ``model_node``, ...)."""
    return Path(sys.argv[0]).stem or "tdcm_node"


def main(argv: Sequence[str] | None = None) -> int:
    """``tdcm_node <package.module:Class> [--params FILE] [--runtime R]``."""
    return main_for(None, argv)


if __name__ == "__main__":
    sys.exit(main())

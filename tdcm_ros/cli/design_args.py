"""The design and solver options shared by the commands that solve one design (``solve``,
``inverse``, ``design``): ``--design``, ``--set``, ``--profile``, ``--routing`` and ``--loads``;
and the tip targets of ``inverse`` and ``design`` (``--tip-deflection``, ``--tip-angle``)."""

from __future__ import annotations

import argparse
from typing import Any

from tdcm_ros.errors import InputError
from tdcm_ros.model import (
    PRESETS,
    PROFILE_NAMES,
    SOLVER_SPECS,
    BodySpec,
    Design,
    InvalidTargetError,
    SolverSettings,
    candidate,
    is_body_file,
    parse_field,
    preset,
    read_body_file,
)
from tdcm_ros.spec import spelled_as

DEFAULT_DESIGN = "paper-experiment"


def add_design_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the design preset, its field overrides, the notch profile and the solver's routing
    and load form to ``parser``."""
    parser.add_argument("--design", metavar="NAME|FILE",
                        help=f"design preset: {', '.join(PRESETS)} (default: {DEFAULT_DESIGN}); "
                             "the same as --set design.preset=NAME; or a body file (.yaml, "
                             "see doc/reference/body_file.md), whose tendon routing is the default")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="override a design field in SI units, e.g. --set E=1.2e9 (or "
                             "design.E=1.2e9, as evaluate takes it); L (the length, m) sets w_t "
                             "as tdcm design --free L does")
    parser.add_argument("--profile", choices=PROFILE_NAMES, help="notch profile")
    for name in ("routing", "loads", "axial"):  # choices and defaults from the settings' specs
        spec = SOLVER_SPECS[name]
        parser.add_argument(f"--{name}", choices=spec.choices, help=spec.description +
                            f" (default: {spec.default}" +
                            ("; a body file's tendon routing)" if name == "routing" else ")"))


def design_and_settings(args: argparse.Namespace) -> tuple[str, Design, SolverSettings]:
    """The design's name, the design and the solver settings that the options of
    :func:`add_design_arguments` give."""
    body = read_body_file(args.design) if is_body_file(args.design) else None
    name, design = _design(args.design, args.set, body)
    if args.profile:
        design = design.with_overrides(profile=args.profile)
    routing = args.routing or (body.routing if body else SOLVER_SPECS["routing"].default)
    return name, design, SolverSettings(routing=routing,
                                        loads=args.loads or SOLVER_SPECS["loads"].default,
                                        axial=args.axial or SOLVER_SPECS["axial"].default)


def _design(named: str | None, pairs: list[str], body: BodySpec | None = None
            ) -> tuple[str, Design]:
    """The design's name (``--design`` or ``--set design.preset``, once) and the design: that
    preset, or ``body`` (the body file ``named``), with the ``--set`` fields (``NAME`` or
    ``design.NAME``) over it."""
    values: dict[str, Any] = {}
    for pair in pairs:
        name, sep, text = pair.partition("=")
        name = name.strip().removeprefix("design.")
        if not sep or not name:
            raise InputError(f"--set {pair!r} is not NAME=VALUE", parameter="--set", value=pair,
                             allowed="NAME=VALUE with a design field name")
        if name == "L":
            values[name] = _length(text.strip())
        elif name != "preset":
            values[name] = parse_field(name, text.strip())
        elif named is not None:
            raise InputError(f"--design {named!r} and --set {pair.strip()!r} both name the "
                             "design; allowed: one of them", parameter="--design", value=named,
                             allowed="--design NAME or --set design.preset=NAME, not both")
        else:
            named = text.strip()
    fields = {k: v for k, v in values.items() if k != "L"}
    base = body.design() if body is not None else preset(named or DEFAULT_DESIGN)
    base.require_free(list(fields), "--set")
    design = base.with_overrides(**fields)
    if "L" in values:  # w_t (w_tip for one notch) from the length, as tdcm design --free L
        design = candidate(design, {"L": values["L"]})
    name = (str(named) if body is not None else
            spelled_as(named or DEFAULT_DESIGN, PRESETS) or DEFAULT_DESIGN)
    return (f"{name} modified ({', '.join(sorted(values))})" if values else name), design


def _length(text: str) -> float:
    """``--set L=VALUE``: a length in m, > 0."""
    try:
        length = float(text)
    except ValueError:
        length = float("nan")
    if not length > 0 or length == float("inf"):
        raise InputError(f"--set L = {text!r} is not a length > 0 m", parameter="L", value=text,
                         allowed="a finite number > 0 (m)")
    return length


def add_tip_targets(group: argparse._MutuallyExclusiveGroup) -> None:
    """Add ``--tip-deflection M`` and ``--tip-angle RAD`` to a target ``group``."""
    group.add_argument("--tip-deflection", metavar="M",
                       help="tip distance from the undeformed axis (m)")
    group.add_argument("--tip-angle", metavar="RAD", help="tip angle from +z toward +x (rad)")


def add_sought_tendon(parser: argparse.ArgumentParser) -> None:
    """Add ``--tendon NAME`` and ``--tensions N,N,...``: which tendon of a body with several
    a stroke or tip target seeks, and the others' tensions held (:func:`sought_tendon`)."""
    parser.add_argument("--tendon", metavar="NAME", help="the tendon whose tension is sought, by "
                        "its name in the body file (a body with several tendons)")
    parser.add_argument("--tensions", metavar="N,N,...", help="the other tendons' tensions held "
                        "constant (N, one per tendon in the body file's order, the sought one's "
                        "entry unused; default 0)")


def sought_tendon(args: argparse.Namespace) -> dict[str, Any]:
    """The ``tendon`` and ``tensions`` keywords of :func:`~tdcm_ros.model.solve_inverse` that
    :func:`add_sought_tendon`'s options give."""
    held = None if args.tensions is None else [
        target_number("--tensions", part, "N, one per tendon") for part in args.tensions.split(",")]
    return {"tendon": args.tendon, "tensions": held}


def target_number(option: str, text: str, allowed: str) -> float:
    """``text`` of ``option`` (a target or a tension bound) as a float; the model checks its
    range."""
    try:
        return float(text)
    except ValueError:
        raise InvalidTargetError(f"{option} = {text!r} is not a number; allowed: {allowed}",
                                 parameter=option, value=text, allowed=allowed) from None

"""The body as a URDF kinematic chain, and the joint values that put it in a solved shape.

The chain starts at ``base_link`` (the model's ``tdcm_base``: +z along the unbent body, +x
toward the tendon), turns by the ``roll`` joint (revolute about +z, rad: the joint the tension
driver publishes on ``joint_states``) and then runs through the body's segments base to tip
(tubes and notches, :meth:`~tdcm_ros.model.design.Design.segment_ends`). Segment ``k`` is three
joints, so that any bent segment's end pose is reached exactly, whatever its curvature along
it: ``{name}_seg{k}_turn`` (revolute about +y by ``a``, the direction of the segment's chord
from its start tangent), ``{name}_seg{k}_chord`` (prismatic along +z, the chord's length, m)
and ``{name}_seg{k}_bend`` (revolute about +y by ``phi - a``, ``phi`` the segment's bend), into
the link ``{name}_seg{k}``, whose frame is the midline's frame at the segment's end; the last
is ``{name}_tip``. A straight segment is ``a = 0``, chord = its length, ``phi = 0``; a notch's
bend is its ``phi`` (:attr:`~tdcm_ros.model.result.SolveResult.notch_angles_rad`).

Each segment's visual hangs on its turn link (the chord's direction): a tube is a cylinder of
``R_outer`` (a lumen is not drawn), a notch is a box of its backbone (``w_d`` across x at
``w_o``, the tube's diameter across y, ``w_n`` long), so the notches show as waists. Every
link and joint name is put after ``prefix`` (a robot's ``frame_prefix``).

:func:`body_urdf` writes the chain as a robot of its own (robot_state_publisher's
``robot_description``); :func:`body_xacro` as a xacro macro that a larger robot's description
includes under its tool link.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.model.design import Design
from tdcm_ros.model.errors import InvalidDesignError
from tdcm_ros.model.grid import on_clear
from tdcm_ros.model.result import SolveResult

Array = NDArray[np.float64]

DEFAULT_NAME = "tdcm_body"
ROLL_JOINT = "roll"
#: Joint limits written into the URDF: bend (rad) and chord (m, up to the segment's length).
BEND_LIMIT_RAD = math.pi
#: URDF needs an effort and a velocity limit on every revolute or prismatic joint; the body's
#: joints are driven by the model, not by motors: nominal values.
NOMINAL_EFFORT = 1.0
NOMINAL_VELOCITY = 10.0


def _quoteattr(text: str) -> str:
    """:func:`xml.sax.saxutils.quoteattr`, imported on first use: that module pulls in
    ``urllib.request`` and ``ssl`` (about 2 MiB and 10 ms) for every process that imports the
    model face, ``tdcm evaluate`` included, which writes no URDF."""
    from xml.sax.saxutils import quoteattr

    return quoteattr(text)


def _segments(design: Design) -> list[tuple[float, float, int | None]]:
    """``(start, end, notch index or None)`` of each segment (m), base to tip."""
    ends = design.segment_ends()
    starts = np.concatenate([[0.0], ends[:-1]])
    left, _ = design.notch_bounds()
    hits = np.isclose(left[None, :], starts[:, None], rtol=0.0, atol=1e-12)  # segment x notch
    first = hits.argmax(axis=1) if left.size else np.zeros(len(starts), dtype=int)
    return [(start, end, int(k) if row.any() else None) for start, end, k, row
            in zip(starts.tolist(), ends.tolist(), first.tolist(), hits, strict=True)]


def _segment_nodes(design: Design, s: Array) -> list[list[int]]:
    """Per segment of ``design``, the indices of the nodes ``s`` (m) nearest its start and end
    (the first of equals, as argmin); kept for the last pair, by identity (a node draws the same
    design on the same cached grid again and again; :func:`~tdcm_ros.model.grid.clear_grid_cache`
    forgets it)."""
    last = _last_segment_nodes.get("pair")
    if last is not None and last[0] is design and last[1] is s:
        return last[2]
    bounds = np.array([(start, end) for start, end, _ in _segments(design)])
    nearest = np.argmin(np.abs(s[None, None, :] - bounds[:, :, None]), axis=2).tolist()
    _last_segment_nodes["pair"] = (design, s, nearest)
    return nearest


_last_segment_nodes: dict[str, tuple[Design, Array, list[list[int]]]] = {}
on_clear(_last_segment_nodes.clear)


def joint_names(design: Design, *, name: str = DEFAULT_NAME, prefix: str = "") -> list[str]:
    """The chain's joint names, roll first, then each segment's turn, chord and bend."""
    out = [prefix + ROLL_JOINT]
    for k in range(len(_segments(design))):
        out += [f"{prefix}{name}_seg{k}_{part}" for part in ("turn", "chord", "bend")]
    return out


def joint_positions(result: SolveResult, roll: float = 0.0) -> Array:
    """The positions (rad, m) of :func:`joint_names`' joints that put the chain in
    ``result``'s shape, rolled by ``roll`` (rad)."""
    nearest = _segment_nodes(result.design, result.s)
    x, z, thetas = (result.positions[:, 0].tolist(), result.positions[:, 2].tolist(),
                    result.theta.tolist())
    out = [roll]
    for i, j in nearest:
        dx, dz = x[j] - x[i], z[j] - z[i]
        theta = thetas[i]
        # the chord in the segment's start frame (+z along the tangent, +x toward the tendon)
        along = dz * math.cos(theta) + dx * math.sin(theta)
        across = dx * math.cos(theta) - dz * math.sin(theta)
        turn = math.atan2(across, along)
        out += [turn, math.hypot(dx, dz), thetas[j] - theta - turn]
    return np.array(out)


def body_urdf(design: Design, *, name: str = DEFAULT_NAME, prefix: str = "",
              base_link: str = "tdcm_base") -> str:
    """The URDF of ``design`` (see the module docstring) as text, its root ``base_link``."""
    _check_names(name, base_link)
    return "\n".join([
        '<?xml version="1.0"?>', _comment(design, name),
        f"<robot name={_quoteattr(prefix + name)}>",
        *_chain(design, name, prefix, base_link), "</robot>"]) + "\n"


def body_xacro(design: Design, *, name: str = DEFAULT_NAME, base_link: str = "tdcm_base") -> str:
    """A xacro file defining the macro ``name`` that puts ``design``'s chain under a larger
    robot's link: ``<xacro:NAME parent="tool0" [prefix="left_"] [xyz="0 0 0"] [rpy="0 0 0"]/>``
    adds a fixed joint ``{prefix}{name}_mount`` from ``parent`` to ``{prefix}{base_link}`` at
    ``xyz`` (m) and ``rpy`` (rad), then the chain of :func:`body_urdf`, every name after
    ``prefix``."""
    _check_names(name, base_link)
    prefix = "${prefix}"
    mount = (f"  <joint name={_quoteattr(f'{prefix}{name}_mount')} type=\"fixed\">\n"
             "    <parent link=\"${parent}\"/>\n"
             f"    <child link={_quoteattr(prefix + base_link)}/>\n"
             "    <origin xyz=\"${xyz}\" rpy=\"${rpy}\"/>\n  </joint>")
    return "\n".join([
        '<?xml version="1.0"?>', _comment(design, name),
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro">',
        (f"  <xacro:macro name={_quoteattr(name)} "
         "params=\"parent prefix:='' xyz:='0 0 0' rpy:='0 0 0'\">"),
        *_chain(design, name, prefix, base_link), mount, "  </xacro:macro>", "</robot>"]) + "\n"


def _check_names(name: str, base_link: str) -> None:
    for what, value in (("name", name), ("base_link", base_link)):
        if not value or any(c.isspace() or c in "<>&\"'$" for c in value):
            raise out_of_range(what, value, "a non-empty name without spaces, $ or XML markup",
                               error=InvalidDesignError)


def _comment(design: Design, name: str) -> str:
    return (f"<!-- {name}: tdcm_ros body, {design.N} notches, {design.length * 1e3:.6g} mm; "
            "joints set by model_node on joint_states -->")


def _chain(design: Design, name: str, prefix: str, base_link: str) -> list[str]:
    """The links and joints from ``base_link`` through the roll joint to the tip."""
    segments = _segments(design)
    lines = [f"  <link name={_quoteattr(prefix + base_link)}/>",
             f"  <link name={_quoteattr(f'{prefix}{name}_rolled')}/>",
             _joint(prefix + ROLL_JOINT, "revolute", prefix + base_link, f"{prefix}{name}_rolled",
                    "0 0 1", -math.pi, math.pi)]
    parent = f"{prefix}{name}_rolled"
    for k, (start, end, notch) in enumerate(segments):
        length = end - start
        turn, chord = f"{prefix}{name}_seg{k}_turned", f"{prefix}{name}_seg{k}_along"
        link = f"{prefix}{name}_tip" if k == len(segments) - 1 else f"{prefix}{name}_seg{k}"
        lines += [f"  <link name={_quoteattr(turn)}>", _visual(design, length, notch),
                  "  </link>", f"  <link name={_quoteattr(chord)}/>",
                  f"  <link name={_quoteattr(link)}/>",
                  _joint(f"{prefix}{name}_seg{k}_turn", "revolute", parent, turn, "0 1 0",
                         -BEND_LIMIT_RAD, BEND_LIMIT_RAD),
                  _joint(f"{prefix}{name}_seg{k}_chord", "prismatic", turn, chord, "0 0 1", 0.0,
                         length),
                  _joint(f"{prefix}{name}_seg{k}_bend", "revolute", chord, link, "0 1 0",
                         -BEND_LIMIT_RAD, BEND_LIMIT_RAD)]
        parent = link
    return lines


def _joint(name: str, kind: str, parent: str, child: str, axis: str, low: float,
           high: float) -> str:
    return (f"  <joint name={_quoteattr(name)} type=\"{kind}\">\n"
            f"    <parent link={_quoteattr(parent)}/>\n    <child link={_quoteattr(child)}/>\n"
            f"    <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n    <axis xyz=\"{axis}\"/>\n"
            f"    <limit lower=\"{low!r}\" upper=\"{high!r}\" effort=\"{NOMINAL_EFFORT!r}\" "
            f"velocity=\"{NOMINAL_VELOCITY!r}\"/>\n  </joint>")


def _visual(design: Design, length: float, notch: int | None) -> str:
    """A tube's cylinder or a notch's backbone box along the segment's chord (m)."""
    if notch is None:
        shape = f"<cylinder radius=\"{design.R_outer!r}\" length=\"{length!r}\"/>"
        x = 0.0
    else:
        width = float(design.per_notch("w_d")[notch])
        x = float(design.per_notch("w_o")[notch])
        shape = f"<box size=\"{width!r} {2.0 * design.R_outer!r} {length!r}\"/>"
    return (f"    <visual>\n      <origin xyz=\"{x!r} 0 {length / 2.0!r}\" rpy=\"0 0 0\"/>\n"
            f"      <geometry>{shape}</geometry>\n    </visual>")

"""The solution of one solve: midline poses along ``s`` in frame ``tdcm_base`` (SI units)."""

from __future__ import annotations

import math
from dataclasses import FrozenInstanceError
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import PhysicsError
from tdcm_ros.model.design import Design
from tdcm_ros.model.errors import ModelError
from tdcm_ros.model.grid import Grid
from tdcm_ros.model.kinematics import PlanarShape, quaternions_y
from tdcm_ros.model.limits import closure_angles, notch_gaps
from tdcm_ros.model.moment_model import CompiledRun
from tdcm_ros.model.settings import SolverSettings
from tdcm_ros.model.tendons import TendonLayout

if TYPE_CHECKING:
    from tdcm_ros.model.loading import Loading

Array = NDArray[np.float64]


FIELDS = ("design", "settings", "tension_n", "s", "positions", "theta", "cell_moments",
          "iterations", "residual_history", "converged", "strategy", "solve_time_s", "grid",
          "loading", "contact_scale", "tendon_tension", "tendon_tensions_n", "material_scale")
"""A :class:`SolveResult`'s fields, in the order its constructor takes them."""
_REPR_FIELDS = tuple(name for name in FIELDS if name not in (
    "grid", "contact_scale", "tendon_tension", "material_scale"))


class SolveResult:
    """Shape of the midline for one tension.

    Node arrays (one entry per cell boundary, base to tip): ``s`` (m), ``positions`` (n, 3) m,
    ``theta`` (rad, about +y), ``quaternions`` (n, 4) as ``(x, y, z, w)``. ``cell_moments``
    (cells, 2) holds each cell's end moments (N m), the fixed point of Algorithm 1.

    Under a :class:`~tdcm_ros.model.loading.Loading`: ``loading`` is it; ``tendon_tension``
    (N, per node, just past each node's kink) is set when the tension varies along ``s``;
    ``contact_scale`` (per cell) is set with notch contact: the curvature follows
    ``cell_moments * contact_scale`` (:attr:`bend_moments`). With several tendons
    (``Design.tendons``) ``tendon_tensions_n`` holds each one's base tension (N) and
    ``tension_n`` the largest.

    Immutable: assigning or deleting a field raises ``dataclasses.FrozenInstanceError``; two
    results are equal only when they are the same object. A result of the compiled plain
    iteration (:meth:`of_run`) keeps the kernel's buffer and makes ``positions``, ``theta``,
    ``cell_moments`` and ``residual_history`` from it on first use.
    """

    def __init__(self, design: Design, settings: SolverSettings, tension_n: float, s: Array,
                 positions: Array, theta: Array, cell_moments: Array, iterations: int,
                 residual_history: tuple[float, ...], converged: bool, strategy: str,
                 solve_time_s: float, grid: Grid, loading: Loading | None = None,
                 contact_scale: Array | None = None, tendon_tension: Array | None = None,
                 tendon_tensions_n: tuple[float, ...] = (),
                 material_scale: Array | None = None) -> None:
        vars(self).update(
            design=design, settings=settings, tension_n=tension_n, s=s, positions=positions,
            theta=theta, cell_moments=cell_moments, iterations=iterations,
            residual_history=residual_history, converged=converged, strategy=strategy,
            solve_time_s=solve_time_s, grid=grid, loading=loading, contact_scale=contact_scale,
            tendon_tension=tendon_tension, tendon_tensions_n=tendon_tensions_n,
            material_scale=material_scale)

    @classmethod
    def of_run(cls, grid: Grid, settings: SolverSettings, tension_n: float, out: Array,
               steps: int, strategy: str, solve_time_s: float) -> SolveResult:
        """The result of the paper's closed form at ``tension_n`` (N) whose compiled plain
        iteration converged in ``steps`` steps into the buffer ``out``
        (:class:`~tdcm_ros.model.moment_model.CompiledRun`), solved in ``solve_time_s`` (s)."""
        result = cls.__new__(cls)
        fields = result.__dict__  # one store per field: no keyword dict to build
        fields["design"] = grid.design
        fields["settings"] = settings
        fields["tension_n"] = tension_n
        fields["s"] = grid.s_nodes
        fields["converged"] = True
        fields["strategy"] = strategy
        fields["solve_time_s"] = solve_time_s
        fields["grid"] = grid
        fields["_out"] = out
        fields["iterations"] = steps
        return result

    def __setattr__(self, name: str, value: Any) -> None:
        raise FrozenInstanceError(f"cannot assign to field {name!r}")

    def __delattr__(self, name: str) -> None:
        raise FrozenInstanceError(f"cannot delete field {name!r}")

    def __repr__(self) -> str:
        return f"{type(self).__name__}(" + ", ".join(
            f"{name}={getattr(self, name)!r}" for name in _REPR_FIELDS) + ")"

    @cached_property
    def positions(self) -> Array:
        """Node positions (n, 3) m in ``tdcm_base``: ``(x, 0, z)``."""
        return self._run.shape.positions

    @cached_property
    def theta(self) -> Array:
        """Tangent angle at each node (rad, about +y)."""
        return self._run.theta

    @cached_property
    def cell_moments(self) -> Array:
        """Each cell's end moments (cells, 2) N m."""
        return self._run.x.reshape(2, -1).T

    @cached_property
    def residual_history(self) -> tuple[float, ...]:
        """The largest node displacement (m) of every iteration."""
        return self._run.history

    @cached_property
    def _run(self) -> CompiledRun:
        """The kernel's buffer of a result of :meth:`of_run`, read."""
        return CompiledRun(self._out, self.grid.n_cells, self.iterations)

    loading: Loading | None = None
    contact_scale: Array | None = None
    tendon_tension: Array | None = None
    tendon_tensions_n: tuple[float, ...] = ()
    material_scale: Array | None = None
    """The optional fields' defaults (a result of :meth:`of_run` has them)."""

    if TYPE_CHECKING:  # the fields every result has (set by the constructors)
        design: Design
        settings: SolverSettings
        tension_n: float
        s: Array
        converged: bool
        strategy: str
        solve_time_s: float
        grid: Grid
        iterations: int
        _out: Array

    @property
    def tensions_n(self) -> tuple[float, ...]:
        """Each tendon's base tension (N), in the design's tendon order (one: ``tension_n``)."""
        return self.tendon_tensions_n or (self.tension_n,)

    @property
    def tendons(self) -> TendonLayout:
        """The design's tendons on the grid (:class:`~tdcm_ros.model.tendons.TendonLayout`)."""
        return self.grid.tendons(self.settings.routing)

    def _axis_tensions(self) -> Array:
        """Tension (N) of every tendon pulling on each cell."""
        return self.tendons.cell_tensions(np.array(self.tensions_n))[2]

    @property
    def bend_moments(self) -> Array:
        """Per-cell end moments (N m) that set the curvature: ``cell_moments``, scaled in
        closed notches when notch contact is on, and at each cell end by a nonlinear
        material's curvature ratio (``material_scale``, (cells, 2))."""
        moments = self.cell_moments
        if self.contact_scale is not None:
            moments = moments * self.contact_scale[:, None]
        if self.material_scale is not None:
            moments = moments * self.material_scale
        return moments

    @property
    def closed_notches(self) -> tuple[int, ...]:
        """1-based indices of the notches in contact (empty without notch contact)."""
        if self.contact_scale is None:
            return ()
        closed = np.unique(self.grid.notch_index[self.contact_scale < 1.0])
        return tuple(int(i) + 1 for i in closed)

    @property
    def curvature_profile(self) -> tuple[Array, Array]:
        """``(s, kappa)``: curvature (1/m) inside every cell and one-sidedly at its ends (m),
        so the jumps at ``l_i`` and ``r_i`` show."""
        grid = self.grid
        moments = self.bend_moments
        m_a = moments[:, 0:1]
        m_b = moments[:, 1:2]
        m_q = m_a * (1.0 - grid.xi_q) + m_b * grid.xi_q
        s = np.concatenate([grid.s_nodes[:-1, None], grid.s_q, grid.s_nodes[1:, None]], axis=1)
        kappa = np.concatenate([m_a * grid.c_start[:, None], m_q * grid.c_q,
                                m_b * grid.c_end[:, None]], axis=1)
        return s.ravel(), kappa.ravel()

    @property
    def notch_angles_rad(self) -> Array:
        """Bend across each notch (rad), base to tip: the tangent angle's change from the
        notch's start ``l_i`` to its end ``r_i``."""
        grid = self.grid
        return self.theta[grid.notch_right_node] - self.theta[grid.notch_left_node]

    @cached_property
    def notch_gaps_m(self) -> Array:
        """Smallest gap (m) between each notch's two faces at the tube's surface, base to tip
        (:func:`~tdcm_ros.model.limits.notch_gaps`; 0 where they touch)."""
        p = self.positions[:, 2] + 1j * self.positions[:, 0]
        shape = PlanarShape(p=p, theta=self.theta, tangent=np.exp(1j * self.theta))
        return notch_gaps(self.grid, shape)

    @property
    def notch_stop_margins_rad(self) -> Array:
        """Bend each notch has left before its faces touch (rad), base to tip: the closure
        angle under a moment uniform across the notch
        (:func:`~tdcm_ros.model.limits.closure_angles`, ``w_n / R_outer`` for a uniform
        curvature) less :attr:`notch_angles_rad`."""
        return closure_angles(self.grid) - self.notch_angles_rad

    @property
    def notch_peak_strains(self) -> Array:
        """Largest bending strain in each notch, base to tip: ``|kappa|`` times the distance from
        the section's centroid to its farthest material (``min(h1, R_outer)`` for the paper's
        section; a polygon's own) at ``PEAK_SAMPLES``
        equally spaced probes of each of its cells (the batch solver's
        ``max_bending_strain`` is the largest of these)."""
        grid = self.grid
        moments = self.bend_moments
        strain = np.abs(moments[:, 0:1] * grid.strain0 + moments[:, 1:2] * grid.strain1)
        out = np.zeros(grid.notch_left_node.size)
        notch = grid.is_notch
        np.maximum.at(out, grid.notch_index[notch], np.max(strain[notch], axis=1))
        return out

    @cached_property
    def tendon_lengths_m(self) -> Array:
        """Length of each tendon's path from the base to its anchor (m), one per tendon: along
        the curve at its offset ``r`` from the tube axis where it follows the body, ``(1 - (r -
        x_bar) kappa) ds`` (the axis's stretch ``x_bar kappa`` less the offset's ``r kappa``,
        integrated by the cells' own quadrature), and straight across each chord."""
        layout = self.tendons
        out = np.empty(layout.count)
        grid = self.grid
        axis = self._axis_tensions() if grid.off_axis or grid.compressible else np.zeros(0)
        for j in range(layout.count):
            r_c = float(layout.offsets[j])
            follows = layout.follow_cells[j]
            along = layout.follow_lengths[j] - r_c * float(
                np.sum(self.theta[follows + 1] - self.theta[follows]))
            if grid.off_axis:  # the axis's stretch (zero where every centroid is on it)
                m = self.bend_moments[follows]
                along += float(np.sum(m[:, 0:1] * grid.K0[follows] + m[:, 1:2] * grid.K1[follows]
                                      - axis[follows, None] * grid.K2[follows]))
            if grid.compressible:  # the body's shortening under the axial load
                along -= float(np.sum(axis[follows, None] * grid.W_A[follows]))
            nodes = layout.chord_nodes[j]  # the tendon at each chord's ends: r along +x_b
            theta = self.theta[nodes]
            x = self.positions[nodes, 0] + r_c * np.cos(theta)
            z = self.positions[nodes, 2] - r_c * np.sin(theta)
            out[j] = along + float(np.sum(np.hypot(x[1] - x[0], z[1] - z[0])))
        return out

    @property
    def tendon_strokes_m(self) -> Array:
        """How far each tendon has been pulled in (m), one per tendon: its path's length on the
        straight body (its anchor's arc length, ``L`` at the tip) less
        :attr:`tendon_lengths_m`."""
        return self.grid.s_nodes[self.tendons.anchors] - self.tendon_lengths_m

    @property
    def actuator_strokes_m(self) -> Array:
        """How far each tendon's actuator has travelled (m), one per tendon: the tendon's
        ``slack`` taken up, :attr:`tendon_strokes_m` and its stretch ``T / stiffness``
        (:meth:`~tdcm_ros.model.Tendon.actuator_stroke`; the path stroke itself for an
        inextensible tendon without slack). At 0 N: where the tendon just becomes taut."""
        return np.array([tendon.actuator_stroke(float(stroke), tension) for tendon, stroke, tension
                         in zip(self.design.tendon_list(), self.tendon_strokes_m,
                                self.tensions_n, strict=True)])

    @property
    def quaternions(self) -> Array:
        """Orientation of the body frame at each node, ``(x, y, z, w)``."""
        return quaternions_y(self.theta)

    @property
    def tip_position(self) -> Array:
        """Tip position ``(x, y, z)`` (m)."""
        return self.positions[-1]

    @property
    def tip_quaternion(self) -> Array:
        """Tip orientation ``(x, y, z, w)``."""
        return self.quaternions[-1]

    @property
    def tip_angle_rad(self) -> float:
        """Tip tangent angle from +z toward +x (rad)."""
        return float(self.theta[-1])

    @property
    def tip_deflection_m(self) -> float:
        """Distance of the tip from the undeformed axis (+z) (m)."""
        return float(np.hypot(self.positions[-1, 0], self.positions[-1, 1]))

    @property
    def tip_displacement_m(self) -> float:
        """Distance of the tip from the unloaded tip ``(0, 0, L)`` (m)."""
        unloaded = np.array([0.0, 0.0, self.design.length])
        return float(np.linalg.norm(self.positions[-1] - unloaded))

    def pose_at(self, s: Any) -> tuple[Array, Array]:
        """Positions (k, 3) m and quaternions (k, 4) at arc lengths ``s`` (m) in ``[0, L]``.

        Exact within the solution's moment field: each query integrates eq. 2 from the start
        of its cell by the kernel and quadrature that integrated the cells for the solve
        (:meth:`tdcm_ros.model.grid.Grid.query`). On a chord cell (the tubes under ``paper``
        routing, the notches under ``free``) the moment is taken linear between the cell's end
        moments, without the chord's ``-T c m`` part that the solve adds over the whole cell:
        paper-experiment at 20 N, a station just short of a chord cell's end is up to 0.26 nm
        (``paper``) and 1.3 nm (``free``) from the solve's node there.
        """
        from tdcm_ros.errors import out_of_range

        query = np.atleast_1d(np.asarray(s, dtype=float))
        length = self.design.length
        if not np.all(np.isfinite(query)) or np.any(query < 0.0) or np.any(query > length):
            raise out_of_range("s", query.tolist(), f"[0, {length:g}] m")
        found = self.grid.query(query)
        cells = found.cells
        moments = self.bend_moments
        m_a = moments[cells, 0]
        m_b = moments[cells, 1]
        phi_r = m_a[:, None] * found.a0_r + m_b[:, None] * found.a1_r
        w_r = found.w_r
        theta_a = self.theta[cells]
        theta = theta_a + m_a * found.a0_s + m_b * found.a1_s
        pull = self._axis_tensions()[cells] if self.grid.off_axis or self.grid.compressible \
            else np.zeros(0)
        if self.grid.off_axis:  # the centroid's motion, the axis's stretch
            phi_r = phi_r - pull[:, None] * found.d_r
            w_r = w_r + m_a[:, None] * found.k0_r + m_b[:, None] * found.k1_r \
                - pull[:, None] * found.k2_r
            theta = theta - pull * found.d_s
        if self.grid.compressible:  # the body's shortening under the axial load
            w_r = w_r - pull[:, None] * found.wa_r
        along = np.sum(w_r * np.cos(phi_r), axis=1)
        across = np.sum(w_r * np.sin(phi_r), axis=1)
        x = self.positions[cells, 0] + along * np.sin(theta_a) + across * np.cos(theta_a)
        z = self.positions[cells, 2] + along * np.cos(theta_a) - across * np.sin(theta_a)
        positions = np.stack([x, np.zeros_like(x), z], axis=1)
        return positions, quaternions_y(theta)

    def summary(self) -> dict[str, Any]:
        """The JSON-ready summary used by ``tdcm solve --json`` (SI units; a notch whose faces
        never meet, its section keeping the wall on both sides, has ``null`` gap and margin)."""
        return {
            "converged": self.converged,
            "iterations": self.iterations,
            "strategy": self.strategy,
            "tension_n": self.tension_n,
            "tip_position_m": self.tip_position.tolist(),
            "tip_quaternion_xyzw": self.tip_quaternion.tolist(),
            "tip_angle_rad": self.tip_angle_rad,
            "tip_deflection_m": self.tip_deflection_m,
            "tip_displacement_m": self.tip_displacement_m,
            "notch_angles_rad": self.notch_angles_rad.tolist(),
            "notch_gaps_m": _finite_or_none(self.notch_gaps_m),
            "notch_stop_margins_rad": _finite_or_none(self.notch_stop_margins_rad),
            "notch_peak_strains": self.notch_peak_strains.tolist(),
            "tendon_names": list(self.tendons.names),
            "tendon_tensions_n": list(self.tensions_n),
            "tendon_lengths_m": self.tendon_lengths_m.tolist(),
            "tendon_strokes_m": self.tendon_strokes_m.tolist(),
            "actuator_strokes_m": self.actuator_strokes_m.tolist(),
            "solve_time_s": self.solve_time_s,
            "residual_history_m": list(self.residual_history),
            "design": self.design.to_dict(),
            "settings": self.settings.to_dict(),
            **({} if self.loading is None else {"loading": self.loading.describe()}),
        }


def _finite_or_none(values: Array) -> list[float | None]:
    """``values`` as a list with ``None`` (JSON ``null``) for each infinite entry."""
    return [float(v) if math.isfinite(v) else None for v in values]


class ConvergenceError(ModelError, PhysicsError):
    """Algorithm 1 did not reach the tolerance; ``result`` holds the last finite iterate, if any."""

    kind = "non_convergence"

    def __init__(self, message: str, *, result: SolveResult | None = None) -> None:
        super().__init__(message)
        self.result = result

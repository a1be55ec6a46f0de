"""The typed protocol of each stage: what the compile step, the world and the twin call on an
effect (SI units).

- mechanics (:class:`Mechanics`): returns the part of the world's loading it sets, once, when
  the scene compiles; a stateful one also hands over its :class:`SolveHistory`.
- actuation (:class:`Actuation`): returns the part of the twin's plant it sets, once.
- sensing (:class:`Sensing`): called per motion-capture frame (and once per world for the
  published transform).
- timing (:class:`Timing`): one delay draw per message.

The effect classes of :mod:`tdcm_ros.scenes.effects` implement these; the compiled bundle and
the world depend only on them.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model import SolveResult
from tdcm_ros.scenes.parts import LoadingPart, PlantPart

Array = NDArray[np.float64]
Pose = tuple[Array, Array]  #: translation (3,) m, quaternion (x, y, z, w)


class Metered(Protocol):
    """Every effect: its registered name, the calls it served and their mean wall time (s)."""

    @property
    def name(self) -> str: ...

    @property
    def calls(self) -> int: ...

    @property
    def cost_s(self) -> float: ...


class SolveHistory(Protocol):
    """What a stateful mechanics effect keeps between solves (e.g. the stuck tendon tension);
    the world then caches no shape by tension."""

    def advance(self, result: SolveResult) -> None:
        """``result`` converged and is the world's new state."""


class Mechanics(Metered, Protocol):
    """A load on the body inside the world's solve."""

    @property
    def history(self) -> SolveHistory | None: ...

    def loading_part(self) -> LoadingPart:
        """The fields of the world's Loading this effect sets."""


class Actuation(Metered, Protocol):
    """A property of the device twin's bench."""

    def plant_part(self) -> PlantPart:
        """The fields of the twin's PlantConfig this effect sets."""


class Sensing(Metered, Protocol):
    """A property of the markers or the motion capture."""

    def placement(self, s: Array, radius: float, side: float) -> tuple[Array, float, float]:
        """True marker arc lengths (m), distance from the midline (m) and side (rad)."""

    def published(self, pose: Pose) -> Pose:
        """The mocap -> tdcm_base transform the mocap node publishes, given the true one."""

    def observe(self, positions: Array, stamp_s: float) -> Array:
        """Reported marker positions (k, 3) m in ``mocap`` at ``stamp_s`` s; NaN = not seen."""


class Timing(Metered, Protocol):
    """A delay of the messages of a topic."""

    def delay(self, topic: str) -> float:
        """One delay draw (s) for ``topic``."""

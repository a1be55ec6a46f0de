"""Public entry points: evaluate (and calibrate, :mod:`tdcm_ros.metrics.calibration`) bags.

::

    from tdcm_ros.metrics.api import evaluate_paths
    from tdcm_ros.metrics.options import options_from_sets
    ev = evaluate_paths(["run.mcap"], options_from_sets(["E=0.7e9"]))
    ev.metrics.rmse_m, ev.to_json()
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from tdcm_ros.errors import InputError
from tdcm_ros.metrics.bagdata import BagSource, load_bag
from tdcm_ros.metrics.evaluation import Evaluation, combine, evaluate_series
from tdcm_ros.metrics.options import EvaluateOptions
from tdcm_ros.metrics.registration import Registration


@dataclass(frozen=True)
class Topics:
    """Topic names read from the bags."""

    tension: str = "tension"
    markers: str = "markers"


def load_paths(paths: Sequence[str | Path], options: EvaluateOptions,
               topics: Topics | None = None) -> list[BagSource]:
    """Read every bag (in order); at least one path."""
    if not paths:
        raise InputError("no bag given; allowed: one or more bag folders or .mcap files",
                         parameter="BAG", value=[], allowed="one or more paths")
    names = topics or Topics()
    return [load_bag(p, labels=options.layout.labels, tension_topic=names.tension,
                     markers_topic=names.markers) for p in paths]


def evaluate_sources(sources: Sequence[BagSource], options: EvaluateOptions,
                     registration: Registration | None = None) -> Evaluation:
    """Evaluate loaded bags; each uses ``registration``, else its ``/tf_static``, else an
    estimate from its own zero-tension and largest-tension steps."""
    parts = []
    for source in sources:
        part = evaluate_series(source.tension, source.markers, options,
                               registration or source.registration)
        parts.append(Evaluation(part.records, part.metrics, part.registrations, options,
                                (*(f"{source.path}: {w}" for w in source.warnings),
                                 *(f"{source.path}: {w}" for w in part.warnings))))
    return combine(parts, [str(s.path) for s in sources])


def evaluate_paths(paths: Sequence[str | Path], options: EvaluateOptions | None = None, *,
                   topics: Topics | None = None,
                   registration: Registration | None = None) -> Evaluation:
    """Evaluate bags (rosbag2 folders or ``.mcap`` files) against the model of
    ``options.design``; see :class:`~tdcm_ros.metrics.evaluation.Evaluation`."""
    opts = options or EvaluateOptions()
    return evaluate_sources(load_paths(paths, opts, topics), opts, registration)

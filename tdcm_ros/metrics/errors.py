"""Errors of the metrics package (all :class:`~tdcm_ros.errors.InputError`: bad or unusable data)."""

from __future__ import annotations

from tdcm_ros.errors import InputError


class MetricsError(InputError):
    """The recorded data cannot be evaluated as given."""


class MarkersNotVisibleError(MetricsError):
    """A marker (or every marker) never came into view."""


class NoStepsError(MetricsError):
    """No tension hold long and steady enough to count as a step."""


class TensionTopicError(MetricsError):
    """The tension topics given do not fit the body's tendons, or a topic carries another
    number of tensions than it is asked for."""

"""ROS-free evaluation of the model against motion capture (Table I metrics, never imports rclpy).

In memory: :class:`EvaluateOptions` (``--set`` syntax: :func:`options_from_sets`), steps and
series in, an :class:`Evaluation` (Table I, per-step records) out, live with
:class:`RunningEvaluation`; text with :func:`format_evaluation`, plots with :func:`write_plots`.

Separate entry points, kept out of this face because they pull heavier libraries:

- :mod:`tdcm_ros.metrics.api` -- evaluate and calibrate bags (``evaluate_paths``,
  ``calibrate_paths``; reads MCAP);
- :mod:`tdcm_ros.metrics.calibration` -- least-squares calibration (scipy.optimize);
- :mod:`tdcm_ros.metrics.synthetic`, :mod:`tdcm_ros.metrics.synthetic_bag` -- simulated
  recordings and bags for tests, benchmarks and demos.
"""

from tdcm_ros.metrics.errors import (
    MarkersNotVisibleError,
    MetricsError,
    NoStepsError,
    TensionTopicError,
)
from tdcm_ros.metrics.evaluation import Evaluation, StepRecord, evaluate_series
from tdcm_ros.metrics.geometry import DEFLECTION_AXES
from tdcm_ros.metrics.options import OPTION_SPECS, EvaluateOptions, options_from_sets
from tdcm_ros.metrics.plots import write_calibration_plots, write_plots
from tdcm_ros.metrics.report import format_calibration, format_evaluation
from tdcm_ros.metrics.series import MarkerSeries, RollSeries, TensionSeries
from tdcm_ros.metrics.steps import STEP_SPECS, StepSettings, settings_for_hold
from tdcm_ros.metrics.streaming import RunningEvaluation
from tdcm_ros.metrics.table import TableMetrics
from tdcm_ros.model import MARKER_SPECS, MarkerLayout

__all__ = [
    "DEFLECTION_AXES",
    "MARKER_SPECS",
    "OPTION_SPECS",
    "STEP_SPECS",
    "EvaluateOptions",
    "Evaluation",
    "MarkerLayout",
    "MarkerSeries",
    "MarkersNotVisibleError",
    "MetricsError",
    "NoStepsError",
    "RollSeries",
    "RunningEvaluation",
    "StepRecord",
    "StepSettings",
    "TableMetrics",
    "TensionSeries",
    "TensionTopicError",
    "evaluate_series",
    "format_calibration",
    "format_evaluation",
    "options_from_sets",
    "settings_for_hold",
    "write_calibration_plots",
    "write_plots",
]

"""The end-to-end demo: a scene's simulated bench, the live node graph, a bag, metrics, calibration."""

from tdcm_ros.demo.plan import RECORDED_TOPICS, DemoPlan, make_plan
from tdcm_ros.demo.report import report, scene_options, tracking_report
from tdcm_ros.demo.run import record_live

__all__ = ["RECORDED_TOPICS", "DemoPlan", "make_plan", "record_live", "report",
           "scene_options", "tracking_report"]

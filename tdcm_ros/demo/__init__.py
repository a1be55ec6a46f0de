"""The end-to-end demo: a scene's simulated bench, the live node graph, a bag, metrics, calibration."""

"""The tracking figures' captions say what a newcomer sees, from the scene's truth."""

from __future__ import annotations

from tdcm_ros.demo.tracking_plots import error_caption, paths_caption


def test_the_paths_caption_names_which_way_the_model_is_off() -> None:
    assert "stiffer than this world (E_model / E_world = 1.1057)" in paths_caption(1.10572)
    assert "bends further" in paths_caption(1.1)
    assert "softer" in paths_caption(0.9) and "bends less" in paths_caption(0.9)
    assert "misses it by the model's error" in paths_caption(None)
    assert "misses it by the model's error" in paths_caption(1.0)


def test_the_error_caption_explains_the_prior_band() -> None:
    assert "the prior's until feedback starts" in error_caption()

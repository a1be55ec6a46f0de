"""Evaluation plots explain themselves: legend entries for every kind of line and marker, axis
labels with units, a caption saying why markers and measured midline are apart (checked
against the data), panels large enough to read. Figures are inspected as matplotlib objects."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tdcm_ros.metrics.api import evaluate_paths
from tdcm_ros.metrics.evaluation import Evaluation
from tdcm_ros.metrics.plots import (
    FONT_SIZE,
    error_figure,
    marker_offset_m,
    shapes_caption,
    shapes_figure,
    write_plots,
)
from tdcm_ros.metrics.synthetic import simulate
from tdcm_ros.metrics.synthetic_bag import write_recording
from tdcm_ros.model import preset

plt = pytest.importorskip("matplotlib.pyplot")


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    rec = simulate(preset("paper-experiment").with_overrides(E=0.8e9),
                   levels=(0.0, 8.0, 16.0), hold_s=2.0, trials=2, tension_hz=200.0,
                   mocap_hz=40.0, seed=3)
    return write_recording(rec, tmp_path_factory.mktemp("plots") / "bag")


@pytest.fixture(scope="module")
def evaluation(bag: Path) -> Evaluation:
    return evaluate_paths([bag])


def _legend_texts(fig: Any) -> list[str]:
    legends = [*fig.legends, *(ax.get_legend() for ax in fig.axes if ax.get_legend())]
    return [text.get_text() for legend in legends for text in legend.get_texts()]


def test_shapes_legend_names_markers_measured_spline_and_model(evaluation: Evaluation) -> None:
    fig = shapes_figure(plt, evaluation)
    try:
        texts = _legend_texts(fig)
        assert any(t.startswith("model midline") for t in texts)
        assert any(t.startswith("model markers") for t in texts)
        assert any(t.startswith("measured midline") and "4.9 mm" in t for t in texts)
        assert any(t.startswith("measured markers") and "4.9 mm" in t for t in texts)
        assert all(legend.get_texts()[0].get_fontsize() >= FONT_SIZE - 1
                   for legend in fig.legends)
    finally:
        plt.close(fig)


def test_shapes_axes_have_units_a_tension_scale_and_readable_panels(
        evaluation: Evaluation) -> None:
    fig = shapes_figure(plt, evaluation)
    try:
        panels = [ax for ax in fig.axes if ax.get_title().startswith("trial")]
        assert [ax.get_title() for ax in panels] == ["trial 1", "trial 2"]
        assert all(ax.get_xlabel() == "x in tdcm_base (mm)" for ax in panels)
        assert panels[0].get_ylabel() == "z in tdcm_base (mm)"
        colourbar = [ax for ax in fig.axes if ax not in panels]
        assert [ax.get_ylabel() for ax in colourbar] == ["step mean tension (N)"]
        width, height = fig.get_size_inches()
        assert width / len(panels) >= 3.5 and height >= 8.0
        assert shapes_caption(evaluation) in fig.get_suptitle().replace("\n", " ")
    finally:
        plt.close(fig)


def test_the_caption_states_the_offset_the_data_has(evaluation: Evaluation) -> None:
    offset = marker_offset_m(evaluation)
    assert offset == pytest.approx(3.92e-3 + 1e-3)
    assert f"{offset * 1e3:.2f} mm from the midline (on the body surface" in shapes_caption(
        evaluation)
    for record in evaluation.records:
        assert record.measured_midline is not None
        gap = np.linalg.norm(record.measured_markers[-1] - record.measured_midline[-1])
        assert gap == pytest.approx(offset, abs=2e-5)  # the tip marker and the spline's tip


def test_error_plot_has_units_and_a_legend(evaluation: Evaluation) -> None:
    fig = error_figure(plt, evaluation)
    try:
        ax = fig.axes[0]
        assert ax.get_xlabel() == "step mean tension (N)"
        assert "(mm)" in ax.get_ylabel()
        assert _legend_texts(fig) == ["trial 1", "trial 2", "no error"]
    finally:
        plt.close(fig)


def test_write_plots_names_its_option_in_errors(evaluation: Evaluation, tmp_path: Path) -> None:
    from tdcm_ros.figures import PlotPathError

    with pytest.raises(PlotPathError, match="--plots = "):
        write_plots(evaluation, tmp_path / "a" / "b", option="--plots")
    assert [p.name for p in write_plots(evaluation, tmp_path / "p")] == [
        "shapes.png", "error_vs_tension.png"]


def test_the_caption_follows_markers_radial_offset(evaluation: Evaluation) -> None:
    from dataclasses import replace

    def with_offset(metres: float) -> Evaluation:
        layout = replace(evaluation.options.layout, radial_offset=metres)
        return replace(evaluation, options=replace(evaluation.options, layout=layout))

    assert "2.50 mm from the midline (markers.radial_offset)" in shapes_caption(with_offset(2.5e-3))
    assert shapes_caption(with_offset(0.0)).startswith("Markers are on the midline")


def test_the_calibration_plot_shows_each_trials_error_before_and_after(
        tmp_path: Path, bag: Path) -> None:
    """The world's E is 0.8 GPa, the estimator starts from the preset's 1.85: the fit moves
    the errors toward zero, and the figure says which field moved from where to where."""
    from tdcm_ros.metrics.api import calibrate_paths
    from tdcm_ros.metrics.plots import (
        calibration_figure,
        step_errors,
        write_calibration_plots,
    )

    fit = calibrate_paths([bag], ("E",))
    fig = calibration_figure(plt, fit)
    try:
        texts = _legend_texts(fig)
        assert {"trial 1, before calibration", "trial 1, after calibration"} <= set(texts)
        assert "E 1.85e+09 -> " in fig.axes[0].get_title()
        lines = {line.get_label(): line for line in fig.axes[0].get_lines()}
        before = lines["trial 1, before calibration"].get_ydata()
        after = lines["trial 1, after calibration"].get_ydata()
        assert np.array_equal(before, step_errors(fit.before, 1)[1] * 1e3)
        assert np.mean(np.abs(after)) < 0.5 * np.mean(np.abs(before))
    finally:
        plt.close(fig)
    paths = write_calibration_plots(fit, tmp_path / "plots")
    assert [p.name for p in paths] == ["calibration.png", "shapes_calibrated.png"]
    assert all(p.stat().st_size > 10_000 for p in paths)

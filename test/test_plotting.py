"""``tdcm solve --plot``'s figure explains itself (inspected as matplotlib objects)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tdcm_ros.model import named_design, preset, solve
from tdcm_ros.plotting import solution_figure

plt = pytest.importorskip("matplotlib.pyplot")
BODIES = Path(__file__).resolve().parents[1] / "config" / "bodies"


def test_solution_figure_has_legends_and_units() -> None:
    fig = solution_figure(plt, solve(preset("paper-experiment"), 12.0))
    try:
        shape, curvature = fig.axes
        assert [t.get_text() for t in shape.get_legend().get_texts()] == [
            "body, as cut", "midline", "notch centres", "unloaded (T = 0 N)"]
        assert [t.get_text() for t in curvature.get_legend().get_texts()] == [
            "curvature κ(s)", "notches"]
        assert (shape.get_xlabel(), shape.get_ylabel()) == ("x in tdcm_base (mm)",
                                                           "z in tdcm_base (mm)")
        assert curvature.get_xlabel() == "arc length s from the base (mm)"
        assert curvature.get_ylabel() == "curvature κ (1/m)"
        assert shape.get_title() == "body at T = 12 N"
    finally:
        plt.close(fig)


@pytest.mark.parametrize(("design", "tension"), [("paper-experiment", 1.0),
                                                 ("paper-experiment", 30.0),
                                                 (str(BODIES / "tee_notches.yaml"), 5.0)])
def test_the_legend_never_covers_the_body_and_the_body_is_whole(design: str, tension: float
                                                                 ) -> None:
    """The legend sat over the top of the body (the upper left of the axes, where a straight
    body of radius ~4 mm reaches): it is below the axes now."""
    fig = solution_figure(plt, solve(named_design(design), tension))
    try:
        shape = fig.axes[0]
        fig.canvas.draw()
        body = next(p for p in shape.patches if p.get_label() == "body, as cut")
        legend = shape.get_legend().get_window_extent()
        assert not legend.overlaps(body.get_window_extent())
        x_low, x_high = shape.get_xlim()
        vertices = body.get_path().vertices
        assert x_low < vertices[:, 0].min() and vertices[:, 0].max() < x_high
    finally:
        plt.close(fig)

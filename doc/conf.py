"""Sphinx configuration of tdcm_ros's documentation: MyST Markdown pages (what rosdoc2 builds).

Build: ``python3 -m sphinx -W -n -b html doc doc/_build/html`` (``bash .ci/docs.sh`` in CI). The
reference pages are generated: ``python3 .ci/docs_reference.py write``.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from sphinx.application import Sphinx

# autodoc imports the checkout's package; rosdoc2 runs this file from a copy elsewhere (then its
# own sys.path entry finds the package)
_CHECKOUT = Path(__file__).resolve().parents[1]
if (_CHECKOUT / "tdcm_ros" / "__init__.py").is_file():
    sys.path.insert(0, str(_CHECKOUT))

project = "tdcm_ros"
author = "tdcm_ros developers"
copyright = "2026, tdcm_ros developers"

# No napoleon: the docstrings are reST, and napoleon reads a property's "Tension (N): ..." as a type.
extensions = ["myst_parser", "sphinx.ext.autodoc", "sphinx.ext.viewcode", "sphinx.ext.graphviz"]
graphviz_output_format = "svg"  # the node graph (reference/nodes.md); needs Graphviz's dot
source_suffix = {".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build"]

myst_enable_extensions = ["colon_fence", "deflist", "dollarmath"]
myst_heading_anchors = 4  # [text](page.md#a-heading) links resolve, and -W fails a broken one

autodoc_member_order = "bysource"
autodoc_typehints = "description"

# The build is offline (no intersphinx): references to other projects' types stay plain text.
nitpick_ignore_regex = [
    # third-party types in annotations and docstrings
    (r"py:.*", r"(numpy|np|scipy|serial|trimesh|rosbags|zenoh)(\..*)?|NDArray|ArrayLike"),
    # the standard library's, likewise
    (r"py:.*", r"(collections|collections\.abc|pathlib|typing)\..*"),
    # the package's aliases of NumPy arrays (Array = NDArray[np.float64], ...) and its type
    # variables, as autodoc leaves them in signatures
    (r"py:class", r"(Int|Bool|Complex)?Array|~?P|tdcm_ros\.model\.(quiet\.R|grid\.Scalar)"),
    # annotations autodoc leaves as text (their function's or class's other annotations are for
    # type checkers: write_calibration_plots's Calibration, which evaluate must not import)
    (r"py:class", r"MomentModel|MarkerWorld|Path"),
]

html_theme = "sphinx_rtd_theme"  # rosdoc2's, as on docs.ros.org
html_title = "tdcm_ros"
html_static_path = ["_static"]
html_css_files = ["tdcm.css"]  # wider pages, wrapping table cells


def setup(app: Sphinx) -> None:
    """Load the docs' own extensions from ``_ext`` of the source folder Sphinx reads: found from
    the app's ``srcdir``, not from this file's path, because rosdoc2 runs this file from a
    wrapping configuration in another folder. ``bench_results``: the ``bench-results`` directive
    (tables of a benchmark's results file, ``doc/results/*.json``)."""
    ext = str(Path(app.srcdir) / "_ext")
    if ext not in sys.path:
        sys.path.insert(0, ext)
    app.setup_extension("bench_results")

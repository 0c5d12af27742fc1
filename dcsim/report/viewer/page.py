"""The viewer page: one HTML file with plotly.js, the player script and the scene inside.

The page needs no server and no network: plotly.js (from the ``plotly`` Python
package), the player (``dcsim/templates/viewer/view.js``) and the scene (JSON) are
written into it. Most of its size is plotly.js (about 4.8 MB); the scene adds a few
hundred kB for a run of a handful of objects at :data:`~dcsim.report.viewer.scene.MAX_FRAMES`
frames.
"""

from __future__ import annotations

import html
import json
import re
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from dcsim import __version__
from dcsim.report.viewer.records import ViewError, read_run
from dcsim.report.viewer.scene import MAX_FRAMES, build_scene

PAGE_NAME = "view.html"
"""File name of the page in the run directory."""

DECIMALS = 4
"""Decimals kept of every number in the scene (0.1 mm, 0.1 ms)."""

_PLACEHOLDER = re.compile(r"\{\{(\w+)\}\}")


def write_view(run_dir: Path, out: Path | None = None, max_frames: int = MAX_FRAMES) -> Path:
    """Write the page that replays the run in ``run_dir``.

    Parameters
    ----------
    run_dir : Path
        A run directory written by ``dcsim run``.
    out : Path, optional
        The page to write; default ``run_dir/view.html``.
    max_frames : int
        Frames the page holds at most (telemetry rows evenly spread over the run).

    Returns
    -------
    Path
        The page written.

    Raises
    ------
    ViewError
        If ``run_dir`` is not a run directory, its records cannot be read, plotly is
        missing or the page cannot be written.
    """
    records = read_run(run_dir)
    scene = build_scene(records, max_frames)
    target = out if out is not None else run_dir / PAGE_NAME
    text = page_html(scene)
    try:
        target.write_text(text, encoding="utf-8")
    except OSError as error:
        raise ViewError(f"cannot write {target}: {error.strerror or error}") from None
    return target


def page_html(scene: dict[str, Any]) -> str:
    """The page's HTML for ``scene`` (:func:`dcsim.report.viewer.scene.build_scene`)."""
    values = {
        "title": html.escape(scene["title"]),
        "subtitle": html.escape(scene["subtitle"]),
        "version": html.escape(__version__),
        "scene": scene_json(scene),
        "plotly": plotly_js(),
        "viewer": _template("view.js"),
    }
    return _PLACEHOLDER.sub(lambda match: values[match.group(1)], _template("view.html"))


def scene_json(scene: dict[str, Any]) -> str:
    """``scene`` as JSON safe inside a ``<script>`` element: numbers rounded to
    :data:`DECIMALS`, non-finite numbers as null, ``<`` escaped."""
    text = json.dumps(_plain(scene), separators=(",", ":"), allow_nan=False)
    return text.replace("<", "\\u003c")


def plotly_js() -> str:
    """The minified plotly.js that the ``plotly`` package carries.

    Raises
    ------
    ViewError
        If the ``plotly`` package is not installed.
    """
    try:
        from plotly.offline import get_plotlyjs
    except ImportError:
        raise ViewError(
            "the run viewer needs the plotly package: pip install plotly "
            "(it comes with dcsim; reinstall dcsim with pip install -e . to get it)"
        ) from None
    return get_plotlyjs()


def _template(name: str) -> str:
    return resources.files("dcsim.templates.viewer").joinpath(name).read_text(encoding="utf-8")


def _plain(value: Any) -> Any:
    """``value`` with numpy arrays and numbers as JSON-ready lists and numbers."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray | np.generic | float):
        return _numbers(np.asarray(value))
    return value


def _numbers(array: np.ndarray) -> Any:
    if array.dtype.kind in "iub":
        return array.tolist()
    rounded = np.round(array.astype(float), DECIMALS)
    finite = np.isfinite(rounded)
    if finite.all():
        return rounded.tolist()
    values = rounded.astype(object)
    values[~finite] = None
    return values.tolist()

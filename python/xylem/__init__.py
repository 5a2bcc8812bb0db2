"""xylem: a wood-appearance simulator, from Python.

Thin bindings of the Rust library (every number comes from it):

- ``WoodBsdf(params)``: the finished-wood BSDF, ``eval`` / ``pdf`` / ``sample`` over numpy
  arrays of local-frame directions (one or N shading points);
- ``WoodVolume(preset, seed=...)``: the procedural solid wood, ``eval(points, needs)`` over an
  (N, 3) array of tree-space points (mm), returning named arrays;
- ``WoodSurface(preset, ...)``: the volume under a finish placed in the tree, shaded in world
  space as xylem's renderer shades a hit (what the Mitsuba 3 plugin calls);
- ``render(scene, spp=..., res=...)`` and ``sweep(scene, ...)``: scene files rendered to numpy
  images, the GIL released while rendering;
- ``fit(capture, out, texels=None, threads=0)``: one board's capture folder fitted into maps in
  ``out`` (as ``xylem fit``), returning the report; many boards fit in parallel with a Dask
  pool (python/examples/fit_boards_dask.py).

``xylem.mitsuba.register()`` registers the ``xylem_wood`` BSDF with Mitsuba 3.
"""

import json as _json

from . import _xylem
from ._xylem import PRESETS, WoodBsdf, WoodSurface, WoodVolume, render, sweep


def fit(capture, out, texels=None, threads=0):
    """Fits the capture folder ``capture`` into maps and a report in ``out``; returns the report.

    ``texels`` is (width, height) or None (the board's size in pixels); ``threads`` 0 uses all
    cores (give 1 when a pool runs one fit per core). Raises OSError for unreadable files and
    ValueError for a fit that cannot run (map size, memory).
    """
    return _json.loads(_xylem.fit(str(capture), str(out), texels, threads))


__all__ = ["PRESETS", "WoodBsdf", "WoodSurface", "WoodVolume", "fit", "render", "sweep"]

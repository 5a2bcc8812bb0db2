"""xylem: a wood-appearance simulator, from Python.

Thin bindings of the Rust library (every number comes from it):

- ``WoodBsdf(params)``: the finished-wood BSDF, ``eval`` / ``pdf`` / ``sample`` over numpy
  arrays of local-frame directions (one or N shading points);
- ``WoodVolume(preset, seed=...)``: the procedural solid wood, ``eval(points, needs)`` over an
  (N, 3) array of tree-space points (mm), returning named arrays;
- ``WoodSurface(preset, ...)``: the volume under a finish placed in the tree, shaded in world
  space as xylem's renderer shades a hit; ``prepare(p, frame)`` shades a batch of hits once
  into a ``WoodHits`` whose BSDF calls do not evaluate the wood again (what the Mitsuba 3
  plugin calls);
- ``load_file(path)`` / ``load_dict(dict)``: a scene loaded once (``Scene``), from a file or from
  a dict with the keys of a scene file (as ``mitsuba.load_dict``);
- ``render(scene, spp=..., res=...)`` and ``sweep(scene, ...)``: a scene (file, built-in name,
  dict or ``Scene``) rendered to numpy images, the GIL released while rendering;
- ``fit(capture, out, texels=None, threads=0)``: one board's capture folder fitted into maps in
  ``out`` (as ``xylem fit``), returning the report; many boards fit in parallel with a Dask
  pool (python/examples/fit_boards_dask.py).

Array arguments broadcast over their leading dimensions as numpy does (an ``(H, W, 3)`` grid of
directions gives ``(H, W, 3)`` values; an empty batch gives empty results), and every input must
be finite (NaN or infinity raises ``ValueError`` naming the argument and the element).

``xylem.mitsuba.register()`` registers the ``xylem_wood`` BSDF (the solid wood, per interaction)
and ``xylem_wood_baked`` (``xylem.mitsuba_baked``: the BSDF in Dr.Jit over baked maps) with
Mitsuba 3.

Distributed on PyPI as ``xylem-wood`` (the name ``xylem`` there is an unrelated project); the
import name is ``xylem``.
"""

import json as _json

from . import _xylem
from ._xylem import (
    PRESETS,
    Scene,
    WoodBsdf,
    WoodHits,
    WoodSurface,
    WoodVolume,
    __version__,
    load_dict,
    load_file,
    render,
    sweep,
)


def fit(capture, out, texels=None, threads=0):
    """Fits the capture folder ``capture`` into maps and a report in ``out``; returns the report.

    ``texels`` is (width, height) or None (the board's size in pixels); ``threads`` 0 uses all
    cores (give 1 when a pool runs one fit per core). Raises OSError for unreadable files and
    ValueError for a fit that cannot run (map size, memory).
    """
    return _json.loads(_xylem.fit(str(capture), str(out), texels, threads))


__all__ = [
    "PRESETS",
    "Scene",
    "WoodBsdf",
    "WoodHits",
    "WoodSurface",
    "WoodVolume",
    "__version__",
    "fit",
    "load_dict",
    "load_file",
    "render",
    "sweep",
]

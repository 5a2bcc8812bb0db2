"""xylem: a wood-appearance simulator, from Python.

Thin bindings of the Rust library (every number comes from it):

- ``WoodBsdf(params)``: the finished-wood BSDF, ``eval`` / ``pdf`` / ``sample`` over numpy
  arrays of local-frame directions (one or N shading points);
- ``WoodVolume(preset, seed=...)``: the procedural solid wood, ``eval(points, needs)`` over an
  (N, 3) array of tree-space points (mm), returning named arrays;
- ``WoodSurface(preset, ...)``: the volume under a finish placed in the tree, shaded in world
  space as xylem's renderer shades a hit (what the Mitsuba 3 plugin calls);
- ``render(scene, spp=..., res=...)`` and ``sweep(scene, ...)``: scene files rendered to numpy
  images, the GIL released while rendering.

``xylem.mitsuba.register()`` registers the ``xylem_wood`` BSDF with Mitsuba 3.
"""

from ._xylem import PRESETS, WoodBsdf, WoodSurface, WoodVolume, render, sweep

__all__ = ["PRESETS", "WoodBsdf", "WoodSurface", "WoodVolume", "render", "sweep"]

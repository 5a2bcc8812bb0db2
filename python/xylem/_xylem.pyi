"""Type stubs of the native module ``xylem._xylem`` (python/src/lib.rs); checked against the
module by ``mypy.stubtest`` in the test suite (python/tests/test_package.py)."""

import os
from typing import Any, Mapping, Sequence, Union, final

import numpy as np
import numpy.typing as npt

__all__ = [
    "WoodBsdf",
    "WoodVolume",
    "WoodSurface",
    "WoodHits",
    "Scene",
    "load_file",
    "load_dict",
    "__version__",
    "render",
    "sweep",
    "fit",
    "max_lobe_albedo",
    "rough_finish_nodes",
    "PRESETS",
]

__version__: str
PRESETS: list[str]

_ArrayLike = npt.ArrayLike
_FloatArray = npt.NDArray[np.float32]
_BoolArray = npt.NDArray[np.bool_]
_PathLike = Union[str, "os.PathLike[str]"]
_SceneLike = Union[_PathLike, Mapping[str, Any], "Scene"]

@final
class WoodBsdf:
    FIELDS: list[str]
    def __new__(cls, params: Mapping[str, _ArrayLike] | None = None, **fields: _ArrayLike) -> WoodBsdf: ...
    def __len__(self) -> int: ...
    @property
    def shape(self) -> tuple[int, ...]: ...
    def params(self) -> dict[str, _FloatArray]: ...
    def has_delta(self) -> _BoolArray: ...
    def eval(self, wo: _ArrayLike, wi: _ArrayLike) -> _FloatArray: ...
    def pdf(self, wo: _ArrayLike, wi: _ArrayLike) -> _FloatArray: ...
    def sample(self, wo: _ArrayLike, uc: _ArrayLike, u: _ArrayLike) -> dict[str, npt.NDArray[Any]]: ...

@final
class WoodVolume:
    def __new__(
        cls, preset: str | None = None, *, preset_file: _PathLike | None = None, seed: int = 0
    ) -> WoodVolume: ...
    @property
    def seed(self) -> int: ...
    def eval(self, points: _ArrayLike, needs: str | Sequence[str] | None = None) -> dict[str, _FloatArray]: ...

@final
class WoodSurface:
    def __new__(
        cls,
        preset: str | None = None,
        *,
        preset_file: _PathLike | None = None,
        seed: int = 0,
        eta: float = 1.5,
        roughness: float = 0.0,
        origin: Sequence[float] = (0.0, 0.0, 0.0),
        axis: Sequence[float] = (0.0, 0.0, 1.0),
        rotation_deg: float = 0.0,
        scale: float = 1.0,
    ) -> WoodSurface: ...
    @property
    def shade_count(self) -> int: ...
    def prepare(self, p: _ArrayLike, frame: _ArrayLike) -> WoodHits: ...
    def shade(self, p: _ArrayLike, n: _ArrayLike) -> dict[str, _FloatArray]: ...
    def eval(self, p: _ArrayLike, n: _ArrayLike, wo: _ArrayLike, wi: _ArrayLike) -> _FloatArray: ...
    def pdf(self, p: _ArrayLike, n: _ArrayLike, wo: _ArrayLike, wi: _ArrayLike) -> _FloatArray: ...
    def sample(
        self, p: _ArrayLike, n: _ArrayLike, wo: _ArrayLike, uc: _ArrayLike, u: _ArrayLike
    ) -> dict[str, npt.NDArray[Any]]: ...

@final
class WoodHits:
    def __len__(self) -> int: ...
    @property
    def shape(self) -> tuple[int, ...]: ...
    def eval(self, wo: _ArrayLike, wi: _ArrayLike) -> _FloatArray: ...
    def pdf(self, wo: _ArrayLike, wi: _ArrayLike) -> _FloatArray: ...
    def eval_pdf(self, wo: _ArrayLike, wi: _ArrayLike) -> tuple[_FloatArray, _FloatArray]: ...
    def mirror_probability(self, wo: _ArrayLike) -> _FloatArray: ...
    def sample(self, wo: _ArrayLike, uc: _ArrayLike, u: _ArrayLike) -> dict[str, npt.NDArray[Any]]: ...

@final
class Scene:
    @property
    def name(self) -> str: ...
    @property
    def res(self) -> tuple[int, int]: ...
    @property
    def spp(self) -> int: ...
    @property
    def warnings(self) -> list[str]: ...

def load_file(scene: _PathLike) -> Scene: ...
def load_dict(scene: Mapping[str, Any], *, name: str = "scene", base: _PathLike | None = None) -> Scene: ...
def render(
    scene: _SceneLike,
    spp: int | None = None,
    res: tuple[int, int] | None = None,
    seed: int | None = None,
    threads: int = 0,
    quality: str | None = None,
    footprint_filter: bool | None = None,
    sampling: str | None = None,
) -> dict[str, Any]: ...
def sweep(
    scene: _SceneLike,
    frames: int | None = None,
    arc: tuple[float, float] | None = None,
    spp: int | None = None,
    res: tuple[int, int] | None = None,
    seed: int | None = None,
    threads: int = 0,
    quality: str | None = None,
    footprint_filter: bool | None = None,
) -> dict[str, Any]: ...
def fit(
    capture: _PathLike, out: _PathLike, texels: tuple[int, int] | None = None, threads: int = 0
) -> str: ...
def max_lobe_albedo(beta: float, dip: float) -> float: ...
def rough_finish_nodes(alpha: float, eta: float) -> dict[str, Any]: ...

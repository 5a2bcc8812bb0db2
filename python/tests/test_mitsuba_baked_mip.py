"""Mip-mapped lookups of `xylem_wood_baked` (`pixel_angle`; python/xylem/mitsuba_baked.py
`_halve`, `_lookup`): a minified checker does not alias against a supersampled reference where
point sampling does (the negative control), the mean is kept, a magnified view is not blurred,
and a level's fibre axes widen beta by their spread (Toksvig)."""

import math

import numpy as np
import pytest

mi = pytest.importorskip("mitsuba")
import drjit as dr  # noqa: E402

import xylem.mitsuba_baked as baked  # noqa: E402
from test_mitsuba import luminance, record, use  # noqa: E402

# A 512 x 512 bake whose base colour is a checker of 2-texel squares (0.08 / 0.70), the rest
# constant: fibres along x (beta 0.2), no rays, a flat normal.
TEXELS, SQUARE = 512, 2


@pytest.fixture(scope="module")
def checker(tmp_path_factory):
    use("llvm_ad_rgb")
    folder = tmp_path_factory.mktemp("checker")
    i, j = np.indices((TEXELS, TEXELS))
    check = ((i // SQUARE + j // SQUARE) % 2).astype(np.float32)
    ones, zeros = np.ones_like(check), np.zeros_like(check)
    maps = {"base_color": np.stack([0.08 + 0.62 * check] * 3, -1),
            "highlight_width": 0.2 * ones, "fiber_color": np.stack([0.5 * ones] * 3, -1),
            "ray_mask": zeros, "fiber_direction": np.stack([ones, zeros, zeros], -1),
            "ray_direction": np.stack([zeros, zeros, ones], -1),
            "normal": np.stack([zeros, zeros, ones], -1)}
    for name, a in maps.items():
        a = np.ascontiguousarray(a if a.ndim == 3 else a[..., None], dtype=np.float32)
        mi.Bitmap(a).write(str(folder / f"{name}.exr"))
    return folder


def scene(maps, spp, mip, distance=1.0):
    """The 0.3 m board (a rectangle, its uv square the bake's) filling a 32 x 32 view seen at
    40 degrees, under a directional light, `direct` integrator and box filter: each pixel is
    the mean of f cos E over its samples, with no noise but the texture's. `distance` scales
    the camera's distance (1: about 5 texels a pixel)."""
    T = mi.ScalarTransform4f
    sc = mi.load_dict({
        "type": "scene", "integrator": {"type": "direct"},
        "sensor": {"type": "perspective", "fov": 30,
                   "to_world": T().look_at(origin=[0, -0.1 * distance, 0.12 * distance],
                                           target=[0, 0, 0], up=[0, 0, 1]),
                   "film": {"type": "hdrfilm", "width": 32, "height": 32, "pixel_format": "rgba",
                            "rfilter": {"type": "box"}},
                   "sampler": {"type": "independent", "sample_count": spp}},
        "sun": {"type": "directional", "direction": [0.3, 0.2, -1], "irradiance": 3.0},
        "board": {"type": "rectangle", "to_world": T().scale([0.15, 0.15, 1.0]),
                  "bsdf": {"type": "xylem_wood_baked", "maps": str(maps), "eta": 1.5}}})
    if mip:
        baked.set_pixel_angle(sc)
    return sc


def render(sc, seed):
    img = np.array(mi.render(sc, seed=seed))
    assert img[..., 3].min() > 0.999, "the board fills the view"
    return luminance(img[..., :3])


def test_minified_checker_does_not_alias(checker):
    """At 1 spp (each sample's footprint a whole pixel, about 5 x 4 texels, 1.2 to 1.5
    checker periods) the mip-mapped render is within 5 % rms of a 1024 spp point-sampled
    reference (the box-filtered checker), with the same mean to 1 %; the same render point
    sampled (`pixel_angle` 0, the negative control) is off by more than 20 % rms: aliasing."""
    use("llvm_ad_rgb")
    ref = render(scene(checker, 1024, False), seed=99)
    out = {}
    for name, mip in (("mip", True), ("point", False)):
        imgs = [render(scene(checker, 1, mip), seed=s) for s in (1, 2, 3)]
        rms = [float(np.sqrt(np.mean((im - ref) ** 2)) / ref.mean()) for im in imgs]
        mean = float(np.mean([im.mean() for im in imgs]) / ref.mean() - 1.0)
        out[name] = {"rms_relative": float(np.mean(rms)), "mean_relative": mean}
    record("baked/mip/minified_checker", out)
    assert out["mip"]["rms_relative"] < 0.05, out
    assert abs(out["mip"]["mean_relative"]) < 0.01, out
    assert out["point"]["rms_relative"] > 0.2, out


def test_magnified_view_is_not_blurred(checker):
    """Closer than a texel a sample (footprint < 1 texel: level 0), the mip-mapped render is
    the point-sampled one (to 1e-3: level 0 read from the atlas rounds its coordinates
    differently; measured 7e-5); the control, the minified view, differs by more than 1 %."""
    use("llvm_ad_rgb")
    near = [render(scene(checker, 4, mip, distance=0.1), seed=5) for mip in (True, False)]
    np.testing.assert_allclose(near[0], near[1], rtol=1e-3, atol=1e-6)
    far = [render(scene(checker, 4, mip), seed=5) for mip in (True, False)]
    assert not np.allclose(far[0], far[1], rtol=1e-2)


def test_levels_widen_beta_by_the_fibre_spread():
    """`_halve` of 2 x 2 texels whose fibre axes alternate +-30 degrees in the face (and one
    turned to its opposite: the same lobe) gives the mean axis x, beta^2 = beta^2 + (1 - L) / L
    with L = cos 30 degrees, the colours averaged; the control, aligned axes, keeps beta."""
    use("llvm_ad_rgb")
    jit = baked._Jit(mi, dr)
    a = math.radians(30.0)
    t = np.zeros((2, 2, 17), np.float32)
    t[..., 0:3] = [[[0.2] * 3, [0.4] * 3], [[0.6] * 3, [0.8] * 3]]
    t[..., 3] = 0.1
    axes = [(math.cos(a), math.sin(a)), (math.cos(a), -math.sin(a)),
            (-math.cos(a), -math.sin(a)), (math.cos(a), -math.sin(a))]
    t[..., 8:10] = np.array(axes, np.float32).reshape(2, 2, 2)
    t[..., 11:14] = [0, 0, 1]
    t[..., 14:17] = [0, 0, 1]
    half = np.array(jit.out(baked._halve(dr, jit, mi.TensorXf(t))))
    assert half.shape == (1, 1, 17)
    length = math.cos(a)
    np.testing.assert_allclose(half[0, 0, 0:3], 0.5, rtol=1e-6)
    np.testing.assert_allclose(half[0, 0, 8:11], [1, 0, 0], atol=1e-6)
    np.testing.assert_allclose(half[0, 0, 3], math.sqrt(0.01 + (1 - length) / length), rtol=1e-5)
    t[..., 8:10] = [1, 0]
    same = np.array(jit.out(baked._halve(dr, jit, mi.TensorXf(t))))
    np.testing.assert_allclose(same[0, 0, 3], 0.1, rtol=1e-6)

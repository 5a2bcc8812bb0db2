"""The Dr.Jit-native plugin `xylem_wood_baked` (python/xylem/mitsuba_baked.py): it evaluates
xylem's WoodBsdf at the baked texel, its sampling passes Mitsuba's chi-square test, it renders
the board as the per-interaction `xylem_wood` does, its derivatives are right, and it runs in
Dr.Jit's symbolic modes without breaking other scenes. Each check has a negative control."""

import contextlib
import gc
import math
import os
import pathlib
import subprocess

import numpy as np
import pytest

import xylem

mi = pytest.importorskip("mitsuba")
import drjit as dr  # noqa: E402

import xylem.mitsuba  # noqa: E402
import xylem.mitsuba_baked  # noqa: E402
from test_mitsuba import FLAGS, chi2_run, chi2_sf, flags, luminance, record, use  # noqa: E402

# The board `xylem bake` cuts by default (tangential, centre 150 mm from the pith, seed 1),
# 300 x 120 x 20 mm, and where the per-interaction plugin finds the same wood: the face's
# centre at tree (0, 160, 0), the board's length (world x) along the pith, world y (the image's
# up) along tree x, in a metre-unit scene.
PRESET, BOARD_MM, RES = "african_mahogany", (300.0, 120.0, 20.0), 1024
SOLID = {"type": "xylem_wood", "preset": PRESET, "seed": 1, "eta": 1.5, "roughness": 0.0,
         "origin": "0, 160, 0", "axis": "1, 0, 0", "rotation_deg": -90.0, "units": "m"}


def xylem_bake(root, out, *args):
    """Runs `xylem bake PRESET ARGS --res RES --out OUT` (XYLEM_BIN: the binary cargo test
    built) and returns OUT."""
    exe = os.environ.get("XYLEM_BIN") or str(root / "target/release/xylem")
    if not pathlib.Path(exe).exists():
        pytest.skip("no xylem binary: run through `cargo test --release --test python`")
    subprocess.run([exe, "bake", PRESET, *args, "--res", str(RES), "--out", str(out)],
                   check=True, capture_output=True)
    return out


@pytest.fixture(scope="session")
def maps(tmp_path_factory, root):
    """A `xylem bake` folder of the board."""
    board = "x".join(f"{x:g}" for x in BOARD_MM)
    return xylem_bake(root, tmp_path_factory.mktemp("bake") / PRESET, "--board", board)


def baked(maps, **extra):
    return dict({"type": "xylem_wood_baked", "maps": str(maps), "eta": 1.5}, **extra)


def read_maps(maps):
    """The maps as (H, W, C) float arrays, by name."""
    names = ("base_color", "fiber_color", "fiber_direction", "highlight_width", "ray_mask",
             "ray_direction", "normal")
    bitmaps = {n: mi.Bitmap(str(maps / f"{n}.exr")) for n in names}
    return {n: np.array(b, np.float32).reshape(b.height(), b.width(), -1)
            for n, b in bitmaps.items()}


def unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def hemisphere(rng, n):
    z = rng.uniform(0.05, 1.0, n)
    phi = rng.uniform(0, 2 * np.pi, n)
    r = np.sqrt(1 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], 1).astype(np.float32)


def texel_hits(maps, n, seed, bump=1.0, frames=False):
    """n interactions at texel centres with tilted shading frames and tangents (dp/du, dp/dv
    not orthogonal to the normal), directions in the shading frame, and the WoodBsdf
    parameters there, worked out here in world space with numpy: the texel's values, its fibre
    and ray axes decoded from their tangent-space maps, all in a frame about the normal that
    the baked normal map (its slope scaled by `bump`) tilts. Returns the interactions, the
    light directions, the parameters, the directions in the shading frame (view, light) and in
    the bumped one; with `frames`, also the matrices that take the bumped frame's coordinates
    to the shading frame's."""
    m = read_maps(maps)
    h, w = m["base_color"].shape[:2]
    rng = np.random.default_rng(seed)
    ix, iy = rng.integers(0, w, n), rng.integers(0, h, n)
    uv = np.stack([(ix + 0.5) / w, (iy + 0.5) / h], 1).astype(np.float32)
    normal = unit(hemisphere(rng, n) + np.array([0, 0, 2.0], np.float32))
    du = (np.array([1.0, 0.0, 0.0]) + 0.3 * rng.normal(size=(n, 3))).astype(np.float32)
    dv = (np.array([0.0, -1.0, 0.0]) + 0.3 * rng.normal(size=(n, 3))).astype(np.float32)
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.uv = mi.Point2f(uv.T)
    si.sh_frame = mi.Frame3f(mi.Vector3f(normal.T))
    si.dp_du, si.dp_dv = mi.Vector3f(du.T), mi.Vector3f(dv.T)
    wo_l, wi_l = hemisphere(rng, n), hemisphere(rng, n)
    si.wi = mi.Vector3f(wo_l.T)
    # Tangent space: x = dp/du in the surface, y = n x x on the side of -dp/dv (bake/mod.rs).
    right = unit(du - normal * (du * normal).sum(1, keepdims=True))
    up = np.cross(normal, right)
    up *= np.where((up * dv).sum(1, keepdims=True) > 0, -1.0, 1.0)
    def axis(name):
        t = unit(m[name][iy, ix])
        return unit(t[:, :1] * right + t[:, 1:2] * up + t[:, 2:3] * normal)

    fibre, ray = axis("fiber_direction"), axis("ray_direction")
    rows = np.stack([np.array(c).reshape(3, -1).T for c in (si.sh_frame.s, si.sh_frame.t,
                                                            si.sh_frame.n)], 1)
    tn = m["normal"][iy, ix]
    bumped = unit(bump * tn[:, :1] * right + bump * tn[:, 1:2] * up + tn[:, 2:3] * normal)
    # Any frame about the bumped normal: the BSDF sees only dot products with its axes.
    s_b = unit(right - bumped * (right * bumped).sum(1, keepdims=True))
    rows_b = np.stack([s_b, np.cross(bumped, s_b), bumped], 1)
    local = lambda v: np.einsum("nij,nj->ni", rows_b, v).astype(np.float32)
    world = lambda v: np.einsum("nji,nj->ni", rows, v)
    params = dict(diffuse=np.clip(m["base_color"][iy, ix], 0, 1),
                  fiber_color=np.clip(m["fiber_color"][iy, ix], 0, 1),
                  fiber_dir=unit(local(fibre)), ray_dir=unit(local(ray)),
                  ray_mask=np.clip(m["ray_mask"][iy, ix, 0], 0, 1),
                  highlight_width=np.clip(m["highlight_width"][iy, ix, 0], 1e-3, np.pi / 2),
                  eta=np.full(n, 1.5, np.float32), roughness=np.zeros(n, np.float32))
    out = (si, mi.Vector3f(wi_l.T), params, (wo_l, wi_l),
           (local(world(wo_l)), local(world(wi_l))))
    return out + (np.einsum("nij,nkj->nik", rows, rows_b),) if frames else out


def rel_error(got, want, floor):
    return float(np.max(np.abs(got - want) / np.maximum(np.abs(want), floor)))


ROUGHNESS = [0.0, 0.05, 0.3, 0.8]


@pytest.mark.parametrize("roughness", ROUGHNESS)
def test_baked_evaluates_woodbsdf(maps, roughness):
    """eval (with the cosine) and pdf equal xylem's WoodBsdf for the texel's parameters at
    4000 texel / direction pairs to 2e-4 relative (values below 1e-3 of the largest compared
    absolutely), with the smooth finish and with rough ones (GGX roughness 0.05, 0.3, 0.8: the
    tables read through `rough_finish_nodes`). Measured, smooth: 99th percentile 6e-6, largest
    1e-4, deep in a lobe's tail at 7 beta, where exp(-x^2 / 2 beta^2) magnifies the float32
    rounding of psi about 50 times; rough: largest 1.5e-4 (f) at the peak of the 0.05 GGX lobe,
    2e-5 at 0.3 and 0.8. The control, WoodBsdf with the lobe width 5 % wider (smooth) or the
    roughness 10 % higher (rough), differs by more than 1e-2."""
    use("llvm_ad_rgb")
    n = 4000
    si, wo, params, _, (wo_l, wi_l) = texel_hits(maps, n, seed=3)
    params["roughness"] = np.full(n, roughness, np.float32)
    bsdf = mi.load_dict(baked(maps, roughness=roughness))
    ctx = mi.BSDFContext()
    f, pdf = bsdf.eval_pdf(ctx, si, wo)
    f, pdf = np.array(f).reshape(3, -1).T, np.array(pdf).ravel()
    np.testing.assert_array_equal(f, np.array(bsdf.eval(ctx, si, wo)).reshape(3, -1).T)
    np.testing.assert_array_equal(pdf, np.array(bsdf.pdf(ctx, si, wo)).ravel())

    def want(p):
        b = xylem.WoodBsdf(p)
        return b.eval(wo_l, wi_l) * wi_l[:, 2:3], b.pdf(wo_l, wi_l)

    wf, wp = want(params)
    err_f = rel_error(f, wf, 1e-3 * wf.max())
    err_pdf = rel_error(pdf, wp, 1e-3 * wp.max())
    if roughness > 0:
        control = dict(params, roughness=np.minimum(params["roughness"] * 1.1, 1.0))
    else:
        control = dict(params,
                       highlight_width=np.minimum(params["highlight_width"] * 1.05, np.pi / 2))
    cf, cp = want(control)
    ctrl_f, ctrl_pdf = rel_error(f, cf, 1e-3 * cf.max()), rel_error(pdf, cp, 1e-3 * cp.max())
    # The bump's control: the same hits evaluated about the shading normal (no pore bump).
    _, _, flat, _, (fo, fi) = texel_hits(maps, n, seed=3, bump=0.0)
    flat["roughness"] = params["roughness"]
    b = xylem.WoodBsdf(flat)
    ff = b.eval(fo, fi) * fi[:, 2:3]
    ctrl_bump = rel_error(f, ff, 1e-3 * ff.max())
    record(f"baked/evaluates/roughness_{roughness:g}", {
        "pairs": n, "f_rel": err_f, "pdf_rel": err_pdf, "control_f_rel": ctrl_f,
        "control_pdf_rel": ctrl_pdf, "control_no_bump_f_rel": ctrl_bump,
        "ray_lobe_texels": int((params["ray_mask"] > 0.05).sum())})
    assert (params["ray_mask"] > 0.05).sum() > 50, "the ray lobe is exercised"
    assert err_f < 2e-4 and err_pdf < 2e-4, (err_f, err_pdf)
    assert ctrl_f > 1e-2 and ctrl_pdf > 1e-2 and ctrl_bump > 1e-2, (ctrl_f, ctrl_pdf, ctrl_bump)


def test_baked_two_sided_turns_the_frame_as_xylem(maps):
    """`two_sided`: a hit seen from behind is shaded as xylem's renderer shades it, in the
    frame turned half round the fibre's projection into the (bumped) face, (s, t, n) -> (s, -t,
    -n): at 2000 texel hits, eval and pdf of the back-side directions (the front ones turned so)
    equal the front side's to 1e-4 relative, rough 0.3 with the pore bump (measured 8.4e-5 /
    1.1e-5). The control: without `two_sided` the back side is black (but where the bump tilts
    the view above the bumped face)."""
    use("llvm_ad_rgb")
    n = 2000
    si, wo, params, _, (wo_b, wi_b), to_shading = texel_hits(maps, n, seed=5, frames=True)
    ctx = mi.BSDFContext()
    front = mi.load_dict(baked(maps, roughness=0.3)).eval_pdf(ctx, si, wo)
    s = params["fiber_dir"] * np.array([1, 1, 0], np.float32)
    s /= np.linalg.norm(s, axis=1, keepdims=True)

    def back(w):
        turned = 2 * (s * w).sum(1, keepdims=True) * s - w
        return np.einsum("nij,nj->ni", to_shading, turned).astype(np.float32)

    si_back = mi.SurfaceInteraction3f(si)
    si_back.wi = mi.Vector3f(back(wo_b).T)
    wi_back = mi.Vector3f(back(wi_b).T)
    # Seen from behind: the view below the shading frame (a view within the bump's tilt of
    # the horizon may turn to above it).
    keep = back(wo_b)[:, 2] < 0
    assert keep.sum() > 0.9 * n
    got = mi.load_dict(baked(maps, roughness=0.3, two_sided=True)).eval_pdf(ctx, si_back,
                                                                           wi_back)
    (f, pdf), (wf, wp) = ([np.array(x[0]).reshape(3, -1).T[keep], np.array(x[1]).ravel()[keep]]
                          for x in (got, front))
    err_f, err_pdf = rel_error(f, wf, 1e-3 * wf.max()), rel_error(pdf, wp, 1e-3 * wp.max())
    one_sided = np.array(mi.load_dict(baked(maps, roughness=0.3)).eval(ctx, si_back,
                                                                        wi_back))[:, keep]
    black = float((one_sided.max(0) == 0).mean())
    ctrl = rel_error(one_sided.T, wf, 1e-3 * wf.max())
    record("baked/two_sided", {"hits": int(keep.sum()), "f_rel": err_f, "pdf_rel": err_pdf,
                               "control_one_sided_f_rel": ctrl,
                               "control_one_sided_black": black})
    assert wf.max() > 0 and err_f < 1e-4 and err_pdf < 1e-4, (err_f, err_pdf)
    assert ctrl > 0.5 and black > 0.9, (ctrl, black)


CHI2_CASES = [("normal", [0.0, 0.0, 1.0], [0.3, 0.4], 1.5, 0.0),
              ("grazing", [0.8, 0.1, 0.59], [0.61, 0.52], 1.5, 0.0),
              ("across_fibres", [0.0, -0.6, 0.8], [0.1, 0.9], 1.5, 0.0),
              ("unfinished", [0.5, 0.0, 0.866], [0.75, 0.2], 1.0, 0.0),
              ("rough_normal", [0.0, 0.0, 1.0], [0.3, 0.4], 1.5, 0.3),
              ("rough_grazing", [0.8, 0.1, 0.59], [0.61, 0.52], 1.5, 0.1),
              ("rough_across_fibres", [0.0, -0.6, 0.8], [0.1, 0.9], 1.5, 0.7),
              ("rough_high_index", [0.5, 0.0, 0.866], [0.75, 0.2], 2.2, 0.2),
              ("pore_bump", [0.5, 0.0, 0.866], "pore", 1.5, 0.0),
              ("pore_bump_rough", [0.5, 0.0, 0.866], "pore", 1.5, 0.3)]


def pore_uv(maps, tilt_deg=25.0):
    """The uv of the texel centre whose baked normal is tilted closest to `tilt_deg` (a pore's
    wall: the pore bump turns the BSDF's frame there)."""
    n = read_maps(maps)["normal"]
    tilt = np.degrees(np.arccos(np.clip(n[..., 2], -1.0, 1.0)))
    iy, ix = np.unravel_index(np.argmin(np.abs(tilt - tilt_deg)), tilt.shape)
    return [float((ix + 0.5) / n.shape[1]), float((iy + 0.5) / n.shape[0])]


@pytest.mark.parametrize("name,wi,uv,eta,roughness", CHI2_CASES,
                         ids=[c[0] for c in CHI2_CASES])
def test_baked_chi2(maps, name, wi, uv, eta, roughness, tmp_path, monkeypatch):
    """sample() against pdf(), with the pore bump (the two pore cases at a texel whose normal
    the bump tilts 25 degrees): with the smooth finish its mirror (a delta, component 1)
    masked out by the context; with a rough one everything (component 0 holds the GGX
    reflection too). The bins' pdf is integrated on 8 x 8 points instead of 4 x 4: at 2
    million samples Mitsuba's own roughconductor of roughness 0.1 is rejected (p = 0) with
    4 x 4 for the integration's error at its narrow peak, and the unfinished case (eta 1, whose
    lobes' density does not vanish at the horizon) at 400 000 (p = 1e-4) once the bump tilts
    that horizon across the bins. The control, the pdf tilted by 1 + 0.1 (2 cos - 1), is
    rejected (in a temporary folder: a rejecting ChiSquareTest writes chi2_data.py into the
    current one)."""
    use("llvm_ad_rgb")
    monkeypatch.chdir(tmp_path)
    from mitsuba.chi2 import BSDFAdapter

    ctx = mi.BSDFContext()
    ctx.component = 0
    wi = [float(x) for x in np.array(wi) / np.linalg.norm(wi)]
    uv = pore_uv(maps) if uv == "pore" else uv
    sample, pdf = BSDFAdapter("xylem_wood_baked", baked(maps, eta=eta, roughness=roughness),
                              wi=wi, uv=uv, ctx=ctx)
    ok, test = chi2_run(sample, pdf, ires=8)
    tilted = lambda wo, *a: pdf(wo, *a) * (1 + 0.1 * (2 * mi.Frame3f.cos_theta(wo) - 1))
    bad, control = chi2_run(sample, tilted, ires=8)
    record(f"baked/chi2/{name}", {"p_value": float(test.p_value), "wi": wi, "uv": uv,
                                  "eta": eta, "roughness": roughness,
                                  "control_p_value": float(control.p_value)})
    assert ok, test.messages
    assert not bad, "the tilted pdf should be rejected"


def test_baked_mirror_sample(maps):
    """With every component on, a sample whose lobe choice falls below P(specular) is the
    finish's mirror: delta, component 1, weight F / P(specular) (F the Fresnel reflectance);
    the control, a choice above P(specular), is not."""
    use("llvm_ad_rgb")
    bsdf = mi.load_dict(baked(maps, bump=0.0))      # the mirror about the shading normal
    si = texel_hits(maps, 1, seed=4)[0]
    si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
    si.wi = mi.Vector3f(0.6, 0.0, 0.8)
    f_r = float(np.array(mi.fresnel(mi.Float(0.8), 1.5)[0])[0])
    bs, w = bsdf.sample(mi.BSDFContext(), si, mi.Float(1e-4), mi.Point2f(0.3, 0.7))
    assert int(np.array(bs.sampled_type)[0]) == int(mi.BSDFFlags.DeltaReflection)
    assert int(np.array(bs.sampled_component)[0]) == 1
    np.testing.assert_allclose(np.array(bs.wo).ravel(), [-0.6, 0.0, 0.8], atol=1e-6)
    np.testing.assert_allclose(np.array(w).ravel(), f_r / np.array(bs.pdf)[0], rtol=1e-5)
    bs, _ = bsdf.sample(mi.BSDFContext(), si, mi.Float(0.99), mi.Point2f(0.3, 0.7))
    assert int(np.array(bs.sampled_type)[0]) != int(mi.BSDFFlags.DeltaReflection)


def board_mesh(bsdf, flip_u=False):
    """The board's top face as a two-triangle mesh in metres (world x along its length, y up
    the image) with `bsdf`, uv as the bake lays the texels out (v down the image); `flip_u`
    mirrors the maps along the length (the image check's control)."""
    L, W = BOARD_MM[0] / 1000, BOARD_MM[1] / 1000
    xy = np.array([[-L / 2, -W / 2], [L / 2, -W / 2], [L / 2, W / 2], [-L / 2, W / 2]])
    u, v = xy[:, 0] / L + 0.5, 0.5 - xy[:, 1] / W
    if flip_u:
        u = 1 - u
    props = mi.Properties()
    props["bsdf"] = mi.load_dict(bsdf)
    mesh = mi.Mesh("board", 4, 2, props, has_vertex_normals=False, has_vertex_texcoords=True)
    params = mi.traverse(mesh)
    params["vertex_positions"] = np.c_[xy, np.zeros(4)].astype(np.float32).ravel()
    params["vertex_texcoords"] = np.c_[u, v].astype(np.float32).ravel()
    params["faces"] = np.array([0, 1, 2, 0, 2, 3], np.uint32)
    params.update()
    return mesh


def board_scene(bsdf, spp, flip_u=False, width=48, height=24):
    """The board seen obliquely under one directional light, direct lighting by emitter
    sampling only, box filter, independent sampler: each pixel estimates the same integral
    with either plugin."""
    T = mi.ScalarTransform4f
    light_to = np.array([0.35, 0.25, 0.9]) / np.linalg.norm([0.35, 0.25, 0.9])
    return mi.load_dict({
        "type": "scene",
        "integrator": {"type": "direct", "emitter_samples": 1, "bsdf_samples": 0},
        "sensor": {"type": "perspective", "fov": 36.0, "fov_axis": "x",
                   "to_world": T().look_at(origin=[0.03, -0.25, 0.3], target=[0, 0, 0],
                                           up=[0, 0, 1]),
                   "film": {"type": "hdrfilm", "width": width, "height": height,
                            "pixel_format": "rgb", "rfilter": {"type": "box"}},
                   "sampler": {"type": "independent", "sample_count": spp}},
        "light": {"type": "directional", "direction": (-light_to).tolist(),
                  "irradiance": {"type": "rgb", "value": [3.0, 3.0, 3.0]}},
        "board": board_mesh(bsdf, flip_u),
    })


def mean_and_error(scene, seeds, evaluated, integrator=None):
    """Per-pixel mean luminance over renders with `seeds` (by the scene's integrator, or by
    `integrator`) and its standard error (spread of the renders / sqrt(count))."""
    imgs = []
    for seed in seeds:
        with xylem.mitsuba.evaluated() if evaluated else contextlib.nullcontext():
            img = mi.render(scene, seed=seed, integrator=integrator)
            imgs.append(luminance(np.array(img, np.float64)))
    imgs = np.array(imgs)
    return imgs.mean(0), imgs.std(0, ddof=1) / math.sqrt(len(seeds))


def z_scores(a, b):
    """Per-pixel z of the difference of two (mean, standard error) images, over the pixels
    that either sees something in."""
    (am, ase), (bm, bse) = a, b
    on = (ase > 0) | (bse > 0)
    return ((am - bm) / np.maximum(np.hypot(ase, bse), 1e-12))[on]


def z_stats(z):
    return {"mean_z": float(z.mean()), "rms_z": float(np.sqrt((z ** 2).mean())),
            "max_abs_z": float(np.abs(z).max()), "p_pooled": chi2_sf(float((z ** 2).sum()), z.size)}


def within_bake_noise(z, mean, reference):
    """The image checks' criterion: |mean z| < 0.5, rms z < 1.5, mean luminances within 1 %."""
    return (abs(z.mean()) < 0.5 and np.sqrt((z ** 2).mean()) < 1.5
            and abs(mean.mean() / reference.mean() - 1) < 0.01)


def test_baked_render_matches_solid_wood(maps):
    """The board rendered with xylem_wood_baked (symbolic modes) and with the per-interaction
    xylem_wood (evaluated mode, the solid wood at every hit) agree to the bake's approximation:
    per board pixel z of the luminance difference, standard errors from 16 independent renders
    of each (16 spp each). Asserted: |mean z| < 0.5, rms z < 1.5 and the mean luminances within
    1 %. Not asserted, recorded: the pooled chi-square p, which at 256 spp per pixel does see
    the bake (measured at --res 1024: mean z 0.22, rms z 1.23, p 2e-21; the means 0.3 % apart;
    at --res 2048 rms z 1.10: the texels' interpolation is most of it). The control, the maps
    mirrored along the board, fails (rms z 16)."""
    use("llvm_ad_rgb")
    gc.collect()
    spp, seeds = 16, range(1, 17)
    flat = baked(maps, bump=0.0)                   # xylem_wood has no pore bump
    baked_ = mean_and_error(board_scene(flat, spp), seeds, evaluated=False)
    mirrored = mean_and_error(board_scene(flat, spp, flip_u=True), seeds, False)
    solid = mean_and_error(board_scene(SOLID, spp), [s + 100 for s in seeds], True)
    gc.collect()
    z, zc = z_scores(baked_, solid), z_scores(mirrored, solid)
    b_mean, s_mean = baked_[0], solid[0]
    record("baked/render_match", {
        "pixels": z.size, "spp": spp, "renders": len(seeds), **z_stats(z),
        "mean_luminance_baked": float(b_mean.mean()), "mean_luminance_solid": float(s_mean.mean()),
        "relative_difference_of_means": float(b_mean.mean() / s_mean.mean() - 1),
        "control_mirrored": z_stats(zc)})
    assert s_mean.mean() > 1e-3 and z.size > 0.5 * b_mean.size, "the board is lit and in view"
    assert within_bake_noise(z, b_mean, s_mean), z_stats(z)
    assert not within_bake_noise(zc, mirrored[0], s_mean), z_stats(zc)


def test_particle_tracer_renders_the_board_as_the_path_tracer(maps):
    """Mitsuba's particle tracer (`ptracer`: light paths, the BSDF called in importance transport,
    si.wi towards the light) renders the board as the `direct` integrator (radiance transport)
    does, with either plugin. The plugins do not read the transport mode: xylem's BSDF is
    reciprocal (Rust: wood/tests.rs `eval_is_reciprocal`), so its adjoint is itself and
    Mitsuba's `eval`, which carries the cosine of its second direction, gives importance
    transport's integrand too. Per board pixel z of the luminance difference over 16 renders of
    each, the image checks' criterion (`within_bake_noise`); the pore bump is off (a bumped
    frame about a normal other than the shading normal would need Veach's adjoint correction,
    which neither plugin nor Mitsuba's own bump maps apply). Control: the plugin with the
    mistake a mode-aware BSDF could make, the cosine of si.wi instead of wo in `eval` under
    importance transport, fails it."""
    use("llvm_ad_rgb")
    gc.collect()
    spp, seeds = 16, range(1, 17)
    flat = baked(maps, bump=0.0, roughness=0.25)

    # The same scene with light paths: emitter -> board -> sensor (max_depth 2).
    ptracer = mi.load_dict({"type": "ptracer", "max_depth": 2})

    def particles(bsdf, evaluated=False):
        return mean_and_error(board_scene(bsdf, spp), seeds, evaluated, ptracer)

    base = xylem.mitsuba_baked.bsdf_class(mi, dr)

    class WrongCosine(base):
        """Under importance transport, f times the cosine of si.wi rather than of wo."""

        def eval_pdf(self, ctx, si, wo, active=True):
            f, pdf = super().eval_pdf(ctx, si, wo, active)
            swap = dr.abs(si.wi.z) / dr.maximum(dr.abs(wo.z), 1e-6)
            importance = ctx.mode == mi.TransportMode.Importance
            return (f * swap if importance else f), pdf

        def eval(self, ctx, si, wo, active=True):
            return self.eval_pdf(ctx, si, wo, active)[0]

    mi.register_bsdf("xylem_wood_baked_wrong_cosine", lambda props: WrongCosine(props))
    camera = mean_and_error(board_scene(flat, spp), [s + 100 for s in seeds], evaluated=False)
    light = particles(flat)
    wrong = particles(dict(flat, type="xylem_wood_baked_wrong_cosine"))
    gc.collect()
    z, zc = z_scores(light, camera), z_scores(wrong, camera)
    record("baked/particle_tracer", {
        "pixels": z.size, "spp": spp, "renders": len(seeds), **z_stats(z),
        "mean_luminance_ptracer": float(light[0].mean()),
        "mean_luminance_direct": float(camera[0].mean()),
        "relative_difference_of_means": float(light[0].mean() / camera[0].mean() - 1),
        "mean_luminance_control": float(wrong[0].mean()), "control_wrong_cosine": z_stats(zc)})
    assert camera[0].mean() > 1e-3 and z.size > 0.5 * camera[0].size, "the board is lit"
    assert within_bake_noise(z, light[0], camera[0]), z_stats(z)
    assert not within_bake_noise(zc, wrong[0], camera[0]), z_stats(zc)
    # The per-interaction plugin too (its wood evaluated at each hit, `evaluated()` mode).
    solid = dict(SOLID, roughness=0.25)
    camera = mean_and_error(board_scene(solid, spp), [s + 100 for s in seeds], evaluated=True)
    light = particles(solid, evaluated=True)
    gc.collect()
    z = z_scores(light, camera)
    record("solid/particle_tracer", {
        "pixels": z.size, **z_stats(z), "mean_luminance_ptracer": float(light[0].mean()),
        "mean_luminance_direct": float(camera[0].mean())})
    assert within_bake_noise(z, light[0], camera[0]), z_stats(z)


def test_baked_render_freezes(maps):
    """A render with xylem_wood_baked can be a Dr.Jit frozen function (`dr.freeze`: its
    kernels recorded once and replayed, without tracing the plugin's Python at every render,
    python/benchmarks/plugin_speed.py `--frozen`): the replayed images equal the plain renders
    to float rounding (≤ 1e-5), later renders replay rather than record, and after the maps are
    changed through `mi.traverse` the frozen render follows them. Control: the image of before
    the change differs from the one after it."""
    use("llvm_ad_rgb")
    gc.collect()
    scene = board_scene(baked(maps, roughness=0.25), spp=4)

    @dr.freeze
    def render(scene, seed):
        return mi.render(scene, seed=seed)

    def both(seed):
        plain = np.array(mi.render(scene, seed=seed))
        return plain, np.array(render(scene, mi.UInt32(seed)))

    for seed in range(4):                        # records, then replays
        plain, frozen = both(seed)
        assert np.abs(plain - frozen).max() <= 1e-5, seed
    recordings = render.n_recordings
    for seed in range(4, 7):
        plain, frozen = both(seed)
        assert np.abs(plain - frozen).max() <= 1e-5, seed
    assert render.n_recordings == recordings <= 3, (recordings, render.n_recordings)
    before = frozen
    params = mi.traverse(scene)
    key = next(k for k in params.keys() if k.endswith("bsdf.maps"))
    params[key] = params[key] * 0.5
    params.update()
    plain, frozen = both(6)
    record("baked/frozen", {"recordings": recordings,
                            "max_difference_after_update": float(np.abs(plain - frozen).max()),
                            "control_change": float(np.abs(before - frozen).max())})
    assert np.abs(plain - frozen).max() <= 1e-5
    assert np.abs(before - frozen).max() > 1e-3


# A sphere of radius SPHERE_MM (a UV sphere: u around the pole, OBJ v from the south pole to
# the north), carved at tree (0, 150, 0) with the fibres along z, seen from one side under one
# distant light: the same OBJ file is baked by `xylem bake --mesh`, loaded by Mitsuba's OBJ
# loader with xylem_wood_baked, and rendered by xylem with its solid wood.
SPHERE_MM, SEGMENTS, RINGS = 40.0, 64, 32
SPHERE_TREE = {"origin": [0.0, 150.0, 0.0], "axis": [0.0, 0.0, 1.0]}
SPHERE_VIEW = {"eye": [60.0, -200.0, 90.0], "target": [0.0, 0.0, 0.0], "up": [0.0, 0.0, 1.0],
               "fov_deg": 28.0, "width": 64, "height": 48,
               "light": list(np.array([0.5, -0.3, 0.8]) / np.linalg.norm([0.5, -0.3, 0.8]))}


def write_sphere(path, mirrored):
    """The sphere as an OBJ (mm) with exact vertex normals and u = phi / 2 pi, or 1 - that
    (`mirrored`: every triangle's UV chart mirrored, the tangent frames' other handedness)."""
    lines = []
    for j in range(RINGS + 1):
        theta = math.pi * j / RINGS
        for i in range(SEGMENTS + 1):
            phi = 2 * math.pi * i / SEGMENTS
            n = (math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta))
            u = i / SEGMENTS
            lines += ["v %.6f %.6f %.6f" % tuple(SPHERE_MM * c for c in n), "vn %.6f %.6f %.6f" % n,
                      "vt %.6f %.6f" % (1 - u if mirrored else u, 1 - j / RINGS)]
    corner = lambda i, j: j * (SEGMENTS + 1) + i + 1
    for j in range(RINGS):
        for i in range(SEGMENTS):
            a, b, c, d = corner(i, j), corner(i + 1, j), corner(i + 1, j + 1), corner(i, j + 1)
            for tri in ((a, d, c), (a, c, b)):
                lines.append("f " + " ".join(f"{k}/{k}/{k}" for k in tri))
    path.write_text("\n".join(lines) + "\n")
    return path


# The built-in teapot as `xylem bake --mesh teapot` places it (scenes/teapot.toml: 30 mm per
# unit, 10 steps per patch, tree (0, 110, 0), fibres along z), seen as that scene sees it.
TEAPOT_TREE = {"origin": [0.0, 110.0, 0.0], "axis": [0.0, 0.0, 1.0]}
TEAPOT_VIEW = {"eye": [0.0, -330.0, 190.0], "target": [10.0, 0.0, 45.0], "up": [0.0, 0.0, 1.0],
               "fov_deg": 30.0, "width": 64, "height": 48,
               "light": list(np.array([0.5, -0.4, 0.75]) / np.linalg.norm([0.5, -0.4, 0.75]))}


# The built-in bowl as `xylem bake --mesh bowl` places it (scenes/turned_bowl.toml: the lathe
# profile at 128 segments, tree (0, 250, 300), the tree axis across the bowl along x), seen from
# that scene's camera, lit from its key light's side.
BOWL_PROFILE = [[0.0, 0.0], [40.0, 0.0], [44.0, 4.0], [70.0, 25.0], [92.0, 55.0], [100.0, 75.0],
                [96.0, 77.0], [88.0, 60.0], [66.0, 32.0], [40.0, 14.0], [0.0, 10.0]]
BOWL_TREE = {"origin": [0.0, 250.0, 300.0], "axis": [1.0, 0.0, 0.0]}
BOWL_VIEW = {"eye": [0.0, -200.0, 330.0], "target": [0.0, 0.0, 35.0], "up": [0.0, 0.0, 1.0],
             "fov_deg": 36.0, "width": 64, "height": 48,
             "light": list(np.array([0.45, -0.25, 0.86]) / np.linalg.norm([0.45, -0.25, 0.86]))}


@pytest.fixture(scope="session")
def mesh_bakes(tmp_path_factory, root):
    """{subject: (its OBJ, its `xylem bake --mesh` folder, the xylem object table, the view)}:
    the sphere in both UV layouts (the OBJ the test writes) and the built-in teapot and bowl
    (the OBJ the bake writes beside its maps; xylem renders its own `teapot` and `lathe`
    shapes)."""
    out = {}
    for mirrored in (False, True):
        d = tmp_path_factory.mktemp("sphere")
        obj = write_sphere(d / "sphere.obj", mirrored)
        tree = [",".join(f"{x:g}" for x in SPHERE_TREE[k]) for k in ("origin", "axis")]
        maps = xylem_bake(root, d / "maps", "--mesh", str(obj), "--origin", tree[0], "--axis",
                          tree[1])
        out["sphere_mirrored" if mirrored else "sphere"] = (
            obj, maps, {"shape": "mesh", "file": str(obj), "tree": SPHERE_TREE}, SPHERE_VIEW)
    maps = xylem_bake(root, tmp_path_factory.mktemp("teapot") / "maps", "--mesh", "teapot")
    out["teapot"] = (maps / f"{PRESET}.obj", maps, {"shape": "teapot", "size": [30.0],
                                                    "resolution": 10, "tree": TEAPOT_TREE},
                     TEAPOT_VIEW)
    maps = xylem_bake(root, tmp_path_factory.mktemp("bowl") / "maps", "--mesh", "bowl")
    out["bowl"] = (maps / f"{PRESET}.obj", maps, {"shape": "lathe", "segments": 128,
                                                  "profile": BOWL_PROFILE, "tree": BOWL_TREE},
                   BOWL_VIEW)
    return out


def mesh_mitsuba(view, obj, bsdf, spp):
    """A mesh scene in Mitsuba (mm): the OBJ with `bsdf`, `view`'s camera and distant light,
    direct lighting by emitter sampling, box filter."""
    v = view
    return mi.load_dict({
        "type": "scene",
        "integrator": {"type": "direct", "emitter_samples": 1, "bsdf_samples": 0},
        "sensor": {"type": "perspective", "fov": v["fov_deg"], "fov_axis": "y",
                   "to_world": mi.ScalarTransform4f().look_at(origin=v["eye"], target=v["target"],
                                                              up=v["up"]),
                   "film": {"type": "hdrfilm", "width": v["width"], "height": v["height"],
                            "pixel_format": "rgb", "rfilter": {"type": "box"}},
                   "sampler": {"type": "independent", "sample_count": spp}},
        "light": {"type": "directional", "direction": [-x for x in v["light"]],
                  "irradiance": {"type": "rgb", "value": [3.0, 3.0, 3.0]}},
        "mesh": {"type": "obj", "filename": str(obj), "bsdf": bsdf},
    })


def mesh_xylem(view, obj_table, roughness, bump, spp):
    """The same scene for xylem's renderer: its solid wood (the volume the bake sampled, with
    the pore bump `bump`, point-sampled as the plugin is: no footprint filter)."""
    v = view
    return xylem.load_dict({
        "render": {"width": v["width"], "height": v["height"], "spp": spp,
                   "integrator": "direct", "filter": "box", "footprint_filter": False},
        "camera": {k: v[k] for k in ("eye", "target", "up", "fov_deg")},
        "lights": [{"type": "distant", "direction": v["light"], "irradiance": 3.0}],
        "materials": {"wood": {"type": "wood", "preset": PRESET, "seed": 1, "eta": 1.5,
                               "roughness": roughness, "bump": bump}},
        "objects": [dict(obj_table, material="wood")],
    })


# (name, subject, roughness, bump, the control's maps). The teapot's patches are not all
# oriented alike (some vertex normals point inwards), and Mitsuba's BSDFs are one-sided:
# Mitsuba's `twosided` wraps the plugin there, as xylem's renderer shades both sides, or
# (`_own_two_sided`) the plugin's `two_sided` turns the frame as xylem's renderer does.
MESH_CASES = [("sphere_smooth", "sphere", 0.0, 0.0, "sphere_mirrored"),
              ("sphere_rough_bump_mirrored_uv", "sphere_mirrored", 0.2, 1.0, "sphere"),
              ("teapot_rough_bump", "teapot", 0.2, 1.0, "sphere"),
              ("teapot_rough_bump_own_two_sided", "teapot", 0.2, 1.0, "sphere"),
              ("bowl_rough_bump", "bowl", 0.2, 1.0, "teapot")]


@pytest.mark.parametrize("name,subject,roughness,bump,wrong", MESH_CASES,
                         ids=[c[0] for c in MESH_CASES])
def test_baked_mesh_renders_as_xylem(mesh_bakes, name, subject, roughness, bump, wrong):
    """A `xylem bake --mesh` rendered end to end: Mitsuba with the OBJ and xylem_wood_baked
    against xylem's own render of the solid wood, per mesh pixel z of the luminance difference
    (standard errors from 16 renders x 16 spp of each): the sphere smooth without the pore
    bump, and rough with it (the baked normal map against xylem's bump of the volume) on the
    mirrored UV layout; the built-in teapot (the bake's OBJ against xylem's own teapot shape),
    rough with the bump. Asserted as for the board: |mean z| < 0.5, rms z < 1.5, mean
    luminances within 1 %. The control, another bake's maps on this mesh (the sphere's other
    UV layout; on the teapot, the sphere's), fails."""
    use("llvm_ad_rgb")
    gc.collect()
    spp, seeds = 16, range(1, 17)
    obj, maps, table, view = mesh_bakes[subject]

    def bsdf(m):
        if name.endswith("own_two_sided"):
            return baked(m, roughness=roughness, bump=bump, two_sided=True)
        b = baked(m, roughness=roughness, bump=bump)
        return {"type": "twosided", "bsdf": b} if subject == "teapot" else b

    plugin = mean_and_error(mesh_mitsuba(view, obj, bsdf(maps), spp), seeds, False)
    control = mean_and_error(mesh_mitsuba(view, obj, bsdf(mesh_bakes[wrong][1]), spp), seeds,
                             False)
    scene = mesh_xylem(view, table, roughness, bump, spp)
    # Sampled as Mitsuba is, 16 spp in every pixel: the criterion's tolerance is the noise of
    # equal sampling (xylem's adaptive default lowers its noise where the pore bump's highlights
    # are, and the bake's approximation there then shows: rms z 1.52-1.60 on the rough cases).
    imgs = np.array([luminance(xylem.render(scene, seed=s + 100, sampling="uniform")["beauty"]
                               .astype(np.float64)) for s in seeds])
    own = imgs.mean(0), imgs.std(0, ddof=1) / math.sqrt(len(seeds))
    gc.collect()
    z, zc = z_scores(plugin, own), z_scores(control, own)
    record(f"baked/mesh_render_match/{name}", {
        "pixels": z.size, "spp": spp, "renders": len(seeds), **z_stats(z),
        "relative_difference_of_means": float(plugin[0].mean() / own[0].mean() - 1),
        "control_other_maps": z_stats(zc)})
    assert own[0].mean() > 1e-3 and z.size > 0.2 * own[0].size, "the mesh is lit and in view"
    assert within_bake_noise(z, plugin[0], own[0]), z_stats(z)
    assert not within_bake_noise(zc, control[0], own[0]), z_stats(zc)


def theta_direction(theta, phi):
    s, c = dr.sincos(theta)
    return mi.Vector3f(s * math.cos(phi), s * math.sin(phi), c)


@pytest.mark.parametrize("roughness,theta_o", [(0.0, 0.6), (0.3, 0.9)])
def test_baked_gradients_match_finite_differences(maps, roughness, theta_o):
    """d f / d theta of the light (Mitsuba's wo) and of the view (si.wi) by Dr.Jit's AD equal
    central finite differences (step 1e-3 rad) to 2 %, near the fibre highlight where the lobe
    dominates; so does d f / d (a texel's base colour). The control, the derivative of the
    cosine alone (what the old plugin's AD gave: issue 30 measured -0.067 against -0.369),
    misses by more than 30 %. With the smooth finish and a rough one (0.3; the view at 0.9 rad,
    off the GGX peak, where d f / d theta of the view is not within float32 noise of 0)."""
    use("llvm_ad_rgb")
    bsdf = mi.load_dict(baked(maps, roughness=roughness))
    si = texel_hits(maps, 1, seed=8)[0]
    si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
    si.dp_du, si.dp_dv = mi.Vector3f(1, 0, 0), mi.Vector3f(0, -1, 0)
    ctx, h = mi.BSDFContext(), 1e-3
    phi_o, phi_i = 0.0, math.pi                        # near the fibre's specular cone

    def f_of(theta_light, theta_view):
        si.wi = theta_direction(theta_view, phi_o)
        return dr.sum(bsdf.eval(ctx, si, theta_direction(theta_light, phi_i)))

    results = {}
    for name, at in (("light", lambda t: f_of(t, theta_o)), ("view", lambda t: f_of(0.55, t))):
        t0 = 0.55 if name == "light" else theta_o
        theta = mi.Float(t0)
        dr.enable_grad(theta)
        value = at(theta)
        dr.backward(value)
        ad = float(np.array(dr.grad(theta))[0])
        value_at = lambda t: float(np.array(at(mi.Float(t)))[0])
        fd = (value_at(t0 + h) - value_at(t0 - h)) / (2 * h)
        results[name] = {"ad": ad, "fd": fd}
        assert abs(ad - fd) <= 0.02 * abs(fd), (name, ad, fd)
    # The control: only the cosine's derivative (f held constant), as the numpy plugin gave.
    theta = mi.Float(0.55)
    dr.enable_grad(theta)
    wo = theta_direction(theta, phi_i)
    si.wi = theta_direction(mi.Float(theta_o), phi_o)
    cos_only = dr.sum(dr.detach(bsdf.eval(ctx, si, wo) / wo.z) * wo.z)
    dr.backward(cos_only)
    ctrl = float(np.array(dr.grad(theta))[0])
    results["control_cosine_only"] = ctrl
    assert abs(ctrl - results["light"]["fd"]) > 0.3 * abs(results["light"]["fd"]), results
    # A map value: the red base colour of the texels around the lookup (all four taps).
    params = mi.traverse(bsdf)
    colour = params["maps"]                 # channel 0: the base colour's red
    si.wi = theta_direction(mi.Float(theta_o), phi_o)
    wo = theta_direction(mi.Float(0.55), phi_i)
    dr.enable_grad(colour)
    params.update()
    value = bsdf.eval(ctx, si, wo).x
    dr.backward(value)
    grad = np.array(dr.grad(colour)).reshape(np.array(colour).shape)
    dr.disable_grad(colour)
    k = np.unravel_index(np.argmax(np.abs(grad[..., 0])), grad.shape[:2])
    base = np.array(colour)

    def red_at(delta):
        moved = base.copy()
        moved[k[0], k[1], 0] += delta
        params["maps"] = mi.TensorXf(moved)
        params.update()
        return float(np.array(bsdf.eval(ctx, si, wo).x)[0])

    fd = (red_at(1e-3) - red_at(-1e-3)) / 2e-3
    red_at(0.0)
    results["map"] = {"ad": float(grad[k][0]), "fd": fd}
    record(f"baked/gradients/roughness_{roughness:g}", results)
    assert abs(grad[k][0] - fd) <= 0.02 * abs(fd) and abs(fd) > 0, results["map"]


def roughplastic_scene():
    T = mi.ScalarTransform4f
    return mi.load_dict({
        "type": "scene", "integrator": {"type": "path", "max_depth": 3},
        "sensor": {"type": "perspective", "fov": 40.0,
                   "to_world": T().look_at(origin=[0, -0.25, 0.32], target=[0, 0, 0], up=[0, 0, 1]),
                   "film": {"type": "hdrfilm", "width": 16, "height": 12, "pixel_format": "rgb"},
                   "sampler": {"type": "independent", "sample_count": 4}},
        "sun": {"type": "directional", "direction": [-0.3, -0.2, -0.9], "irradiance": 3.0},
        "board": {"type": "rectangle", "to_world": T().scale([0.15, 0.15, 1.0]),
                  "bsdf": {"type": "roughplastic", "alpha": 0.25}},
    })


def test_baked_renders_symbolically_beside_other_scenes(maps):
    """With Dr.Jit's default (symbolic) modes, never switched off, a scene with
    xylem_wood_baked renders, gives the same image as in evaluated (wavefront) mode, and a
    roughplastic scene renders in the same process while the baked BSDF is alive. The
    control: with a per-interaction xylem_wood alive, the same roughplastic render fails."""
    use("llvm_ad_rgb")
    gc.collect()
    assert all(flags().values()), flags()
    scene = board_scene(baked(maps), 4, width=16, height=8)
    img = np.array(mi.render(scene, seed=2))
    with xylem.mitsuba.evaluated():
        wavefront = np.array(mi.render(scene, seed=2))
    assert np.isfinite(img).all() and img.mean() > 1e-3
    np.testing.assert_allclose(img, wavefront, rtol=1e-4, atol=1e-6)
    other = np.array(mi.render(roughplastic_scene(), seed=1))
    assert np.isfinite(other).all() and other.mean() > 1e-3
    assert all(flags().values()) and set(flags()) == set(FLAGS)
    solid = mi.load_dict(SOLID)
    with pytest.raises(Exception):
        mi.render(roughplastic_scene(), seed=1)
    del solid
    gc.collect()
    assert np.isfinite(np.array(mi.render(roughplastic_scene(), seed=1))).all()


def test_baked_scalar_variant_agrees(maps):
    """The scalar variant evaluates the same f and pdf as the LLVM one at 8 texel hits (to
    1e-5 relative) and renders a tiny image; the control, a hit moved to another texel,
    differs."""
    use("llvm_ad_rgb")
    n = 8
    si, wo, _, (wo_l, wi_l), _ = texel_hits(maps, n, seed=9)
    f, pdf = mi.load_dict(baked(maps)).eval_pdf(mi.BSDFContext(), si, wo)
    f, pdf = np.array(f).reshape(3, -1).T, np.array(pdf).ravel()
    uv = np.array(si.uv).reshape(2, -1).T
    frames = [np.array(v).reshape(3, -1).T for v in (si.sh_frame.n, si.dp_du, si.dp_dv)]
    use("scalar_rgb")
    bsdf = mi.load_dict(baked(maps))

    def scalar(k, uv_k):
        s = dr.zeros(mi.SurfaceInteraction3f)
        s.uv = mi.Point2f(*uv_k)
        s.sh_frame = mi.Frame3f(mi.Vector3f(*frames[0][k]))
        s.dp_du, s.dp_dv = mi.Vector3f(*frames[1][k]), mi.Vector3f(*frames[2][k])
        s.wi = mi.Vector3f(*wo_l[k])
        fk, pk = bsdf.eval_pdf(mi.BSDFContext(), s, mi.Vector3f(*wi_l[k]))
        return np.array(fk), float(pk)

    for k in range(n):
        fk, pk = scalar(k, uv[k])
        np.testing.assert_allclose(fk, f[k], rtol=1e-5, atol=1e-9)
        np.testing.assert_allclose(pk, pdf[k], rtol=1e-5, atol=1e-9)
    moved, _ = scalar(0, (uv[0] + 0.37) % 1.0)
    assert not np.allclose(moved, f[0], rtol=1e-3), "another texel gives another f"
    img = np.array(mi.render(board_scene(baked(maps), 2, width=6, height=3)))
    assert img.shape == (3, 6, 3) and np.isfinite(img).all() and img.mean() > 1e-3



def off_centre_hits(maps, u, v, count, rng):
    """`count` interactions at uv (u, v) moved by up to 0.02 texel each (so that the numbers
    hashed from their uv differ), on a flat frame of the board's texel aspect, seen from
    (0.3, 0.2, 0.93); with mip maps on, 2^1.5 texels of level 0 wide (`_mip_level` with
    pixel_angle 1e-3): levels 1 and 2 weigh 1/2 each."""
    h, w = read_maps(maps)["base_color"].shape[:2]
    si = dr.zeros(mi.SurfaceInteraction3f, count)
    jitter = rng.uniform(-0.02, 0.02, (2, count)) / np.array([[w], [h]])
    si.uv = mi.Point2f((np.array([[u], [v]]) + jitter).astype(np.float32))
    si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
    si.dp_du, si.dp_dv = mi.Vector3f(0.3, 0, 0), mi.Vector3f(0, -0.12, 0)
    wi = np.array([0.3, 0.2, 0.93]) / np.linalg.norm([0.3, 0.2, 0.93])
    si.wi = mi.Vector3f(*(float(x) for x in wi))
    si.t = mi.Float(2 ** 1.5 * wi[2] * math.sqrt(0.3 * 0.12) / (1e-3 * math.sqrt(h * w)))
    return si


def between_texels(maps, count, seed):
    """`count` uv points whose texel positions (uv x size - 1/2) in levels 0, 1 and 2 (halved
    sizes, rounded up) are all at least 0.1 texel from a texel centre, so that the jitter of
    `off_centre_hits` stays between the same texel centres."""
    h, w = read_maps(maps)["base_color"].shape[:2]
    rng, points = np.random.default_rng(seed), []
    while len(points) < count:
        uv = rng.uniform(0.05, 0.95, 2)
        frac = [(uv * np.array([-(-w // 2 ** k), -(-h // 2 ** k)]) - 0.5) % 1.0
                for k in range(3)]
        if all(((f > 0.1) & (f < 0.9)).all() for f in frac):
            points.append(tuple(uv))
    return points


@pytest.mark.parametrize("mip", [False, True], ids=["level_0", "mip"])
def test_stochastic_lookup_draws_texels_by_their_filter_weights(maps, mip, monkeypatch):
    """`filter` "stochastic" (the default) draws one texel per interaction with the bilinear
    (trilinear) weights: at 4 uv points between texel centres (`between_texels`), 8192
    interactions each (`off_centre_hits`), every lookup returns one of the 4 (8) neighbouring
    texels' values exactly, and their mean equals `filter` "bilinear"'s lookup to within 4.5
    standard errors in every channel that varies (to 1e-5 in those that vary only by float32
    rounding). The control, the hashed numbers held at 0.5 (always the nearest texel), is
    off."""
    use("llvm_ad_rgb")
    extra = dict(roughness=0.25, pixel_angle=1e-3 if mip else 0.0)
    rng = np.random.default_rng(11)
    n, points = 8192, between_texels(maps, 4, seed=11)
    hits = [off_centre_hits(maps, u, v, n, rng) for u, v in points]

    def lookups(bsdf):
        return [np.array([np.array(c) for c in bsdf._lookup(si, True)]) for si in hits]

    def worst(draws, reference):
        """(largest |z| of the channels that vary by more than float32 rounding, largest
        |difference| of those that do not)"""
        want = reference.mean(1)
        diff = np.abs(draws.mean(1) - want)
        se = draws.std(1, ddof=1) / math.sqrt(draws.shape[1])
        varies = se > 1e-6 * np.abs(want) + 1e-9
        return (float((diff[varies] / se[varies]).max(initial=0.0)),
                float(diff[~varies].max(initial=0.0)))

    bilinear = lookups(mi.load_dict(baked(maps, filter="bilinear", **extra)))
    drawn = lookups(mi.load_dict(baked(maps, **extra)))
    distinct = [len(np.unique(d.T, axis=0)) for d in drawn]
    zs = [worst(d, b) for d, b in zip(drawn, bilinear)]
    monkeypatch.setattr(xylem.mitsuba_baked, "_interaction_numbers",
                        lambda mi_, dr_, uv, count: [mi.Float(0.5)] * count)
    nearest = lookups(mi.load_dict(baked(maps, **extra)))
    control = [worst(d, b) for d, b in zip(nearest, bilinear)]
    record(f"baked/stochastic/{'mip' if mip else 'level_0'}", {
        "interactions": n, "points": len(points), "max_abs_z": max(z for z, _ in zs),
        "distinct_texels_drawn": distinct,
        "control_nearest_max_abs_z": max(z for z, _ in control),
        "control_nearest_max_abs_difference_of_constant_channels": max(e for _, e in control)})
    assert all(2 <= k <= (8 if mip else 4) for k in distinct), distinct
    assert all(z < 4.5 and exact < 1e-5 for z, exact in zs), zs
    assert any(z > 4.5 or exact > 1e-5 for z, exact in control), control


def test_sample_and_eval_pdf_see_one_texel(maps, monkeypatch):
    """`sample` and `eval_pdf` at one interaction draw the same texel: at 4 x 128 interactions
    off the texel centres (rough finish 0.25), the weight `sample` returns equals f cos / pdf
    of `eval_pdf` at the sampled direction to 1e-4 relative. The control, numbers that ignore
    the interaction (a new draw at every call), breaks that at more than a tenth of them."""
    use("llvm_ad_rgb")
    bsdf = mi.load_dict(baked(maps, roughness=0.25))
    rng = np.random.default_rng(12)
    hits = [off_centre_hits(maps, u, v, 128, rng) for u, v in between_texels(maps, 4, seed=12)]
    ctx = mi.BSDFContext()

    def mismatches():
        bad = total = 0
        for si in hits:
            count = dr.width(si.uv)
            s1 = mi.Float(rng.random(count).astype(np.float32))
            s2 = mi.Point2f(rng.random((2, count)).astype(np.float32))
            bs, weight = bsdf.sample(ctx, si, s1, s2)
            f, pdf = bsdf.eval_pdf(ctx, si, bs.wo)
            ok = np.array(bs.pdf) > 0
            weight, f = np.array(weight)[:, ok], np.array(f)[:, ok]
            with np.errstate(divide="ignore", invalid="ignore"):
                again = f / np.array(pdf)[ok]        # a zero pdf here is a mismatch too
            bad += int((~np.isclose(weight, again, rtol=1e-4, atol=1e-7)).any(0).sum())
            total += int(ok.sum())
        return bad, total

    bad, total = mismatches()
    calls = iter(range(1, 1 << 30))
    monkeypatch.setattr(
        xylem.mitsuba_baked, "_interaction_numbers",
        lambda mi_, dr_, uv, count: [mi.Float(np.random.default_rng(next(calls))
                                              .random(dr.width(uv.x)).astype(np.float32))
                                     for _ in range(count)])
    control_bad, control_total = mismatches()
    record("baked/stochastic/sample_and_eval_pdf", {
        "sampled": total, "mismatched": bad, "control_mismatched": control_bad,
        "control_sampled": control_total})
    assert total > 300 and bad == 0, (bad, total)
    assert control_bad > 0.1 * control_total, (control_bad, control_total)


@pytest.mark.parametrize("filt", ["stochastic", "bilinear"])
@pytest.mark.parametrize("pixel_angle", [0.0, 1e-3], ids=["level_0", "mip"])
def test_non_finite_uv_and_distance_give_finite_values(maps, filt, pixel_angle):
    """Interactions whose uv or distance is NaN, infinite or huge (a degenerate mesh's) give
    finite f, pdf and sample weights, the texel (0, 0) standing in for a non-finite uv. Before
    the lookups sanitised them the stochastic lookup read out of its table and the process
    died (SIGSEGV, 2026-12-04), and the bilinear one returned NaN f. So do non-finite views,
    light directions and sample numbers at a finite interaction (f was NaN, 2026-12-04). The
    control: finite lanes in the same batches shade to non-zero values, so the check is not
    passed by zeros."""
    use("llvm_ad_rgb")
    bsdf = mi.load_dict(baked(maps, roughness=0.25, filter=filt, pixel_angle=pixel_angle))
    odd = [math.nan, math.inf, -math.inf, 1e30, -1e30, 0.5, 2.0, -3.0, 0.37]
    si = dr.zeros(mi.SurfaceInteraction3f, len(odd))
    si.uv = mi.Point2f(np.array([odd, odd[::-1][1:] + [0.61]], np.float32))
    si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
    si.dp_du, si.dp_dv = mi.Vector3f(0.3, 0, 0), mi.Vector3f(0, -0.12, 0)
    si.wi = dr.normalize(mi.Vector3f(0.3, 0.2, 0.93))
    si.t = mi.Float(np.array([math.nan, math.inf, 1e30, 0, -1, 0.3, 1e-30, 5, 0.4], np.float32))
    ctx = mi.BSDFContext()
    f, pdf = bsdf.eval_pdf(ctx, si, dr.normalize(mi.Vector3f(-0.2, 0.1, 0.9)))
    bs, weight = bsdf.sample(ctx, si, mi.Float(0.5), mi.Point2f(0.3, 0.6))
    values = [np.array(x) for x in (f, pdf, weight, bs.pdf, bs.wo)]
    assert all(np.isfinite(v).all() for v in values), values
    assert np.array(f)[:, -1].min() > 0 and np.array(pdf)[-1] > 0, values
    # Non-finite directions and sample numbers at a finite interaction: zero, not NaN.
    good = dr.zeros(mi.SurfaceInteraction3f, 3)
    good.uv = mi.Point2f(0.37, 0.61)
    good.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
    good.dp_du, good.dp_dv = mi.Vector3f(0.3, 0, 0), mi.Vector3f(0, -0.12, 0)
    good.t = mi.Float(0.4)
    good.wi = mi.Vector3f(np.array([[math.nan, 0.3, 0.3], [0.2, 0.2, 0.2], [0.93] * 3],
                                   np.float32))
    light = mi.Vector3f(np.array([[-0.2, -math.inf, -0.2], [0.1] * 3, [0.97] * 3], np.float32))
    f, pdf = bsdf.eval_pdf(ctx, good, light)
    bs, weight = bsdf.sample(ctx, good, mi.Float(np.array([0.5, 0.5, math.nan], np.float32)),
                             mi.Point2f(0.3, 0.6))
    values = [np.array(x) for x in (f, pdf, weight, bs.pdf, bs.wo)]
    assert all(np.isfinite(v).all() for v in values), values
    assert np.array(f)[:, 2].min() > 0 and np.array(weight)[:, 1].min() > 0, values


def test_scalar_variant_has_mip_maps_and_both_filters(maps):
    """The scalar variant loads with mip maps on (it raised a TypeError building the level
    boxes until 2026-12-04) and gives the LLVM variant's f and pdf (to 1e-5 relative) with both
    filters, mip-mapped, at 4 interactions between texel centres (`off_centre_hits`: the
    footprint between levels 1 and 2). The control: the same interactions without mip maps
    give other values."""
    use("llvm_ad_rgb")
    rng = np.random.default_rng(13)
    hits = [off_centre_hits(maps, u, v, 1, rng) for u, v in between_texels(maps, 4, seed=13)]
    wo = [float(x) for x in np.array([-0.2, 0.1, 0.9]) / np.linalg.norm([-0.2, 0.1, 0.9])]

    def flat(si):
        """The interaction's fields as Python numbers (uv, t, frame, tangents, wi)."""
        get = lambda v: [float(np.array(c).ravel()[0]) for c in (v.x, v.y, v.z)]
        return ([float(np.array(si.uv.x)[0]), float(np.array(si.uv.y)[0])],
                float(np.array(si.t)[0]), get(si.dp_du), get(si.dp_dv), get(si.wi))

    fields = [flat(si) for si in hits]
    want = {}
    for filt in ("stochastic", "bilinear"):
        for angle in (0.0, 1e-3):
            b = mi.load_dict(baked(maps, roughness=0.25, filter=filt, pixel_angle=angle))
            for k, si in enumerate(hits):
                f, pdf = b.eval_pdf(mi.BSDFContext(), si, mi.Vector3f(*wo))
                want[filt, angle, k] = (np.array(f).ravel(), float(np.array(pdf)[0]))
    use("scalar_rgb")
    for filt in ("stochastic", "bilinear"):
        b = mi.load_dict(baked(maps, roughness=0.25, filter=filt, pixel_angle=1e-3))
        for k, (uv, t, du, dv, wi) in enumerate(fields):
            s = dr.zeros(mi.SurfaceInteraction3f)
            s.uv, s.t = mi.Point2f(*uv), t
            s.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
            s.dp_du, s.dp_dv, s.wi = mi.Vector3f(*du), mi.Vector3f(*dv), mi.Vector3f(*wi)
            f, pdf = b.eval_pdf(mi.BSDFContext(), s, mi.Vector3f(*wo))
            f_want, pdf_want = want[filt, 1e-3, k]
            np.testing.assert_allclose(np.array(f), f_want, rtol=1e-5, atol=1e-9)
            np.testing.assert_allclose(pdf, pdf_want, rtol=1e-5, atol=1e-9)
            f_flat = want[filt, 0.0, k][0]
            assert not np.allclose(f_flat, f_want, rtol=1e-3), (filt, k)


def test_bad_properties_and_maps_are_refused_by_name(maps, tmp_path):
    """Every property out of its range, a missing map and a map holding NaN or infinity are
    refused when the scene loads, with a message that names the property (and its range) or
    the file; none renders NaN. The control: the same folder and properties, valid, load."""
    use("llvm_ad_rgb")
    bad = tmp_path / "bad"
    bad.mkdir()
    for f in maps.iterdir():
        if f.suffix == ".exr":
            (bad / f.name).write_bytes(f.read_bytes())
    colour = np.array(mi.Bitmap(str(bad / "base_color.exr")), np.float32)
    colour[7, 11, 1] = np.nan
    colour[8, 3, 0] = np.inf
    mi.Bitmap(colour).write(str(bad / "base_color.exr"))
    missing = tmp_path / "missing"
    missing.mkdir()
    (missing / "base_color.exr").write_bytes((maps / "base_color.exr").read_bytes())
    cases = [
        (baked(maps, eta=0.5), "`eta` = 0.5: expected 1 to 4"),
        (baked(maps, roughness=1.5), "`roughness` = 1.5: expected 0 (smooth) to 1"),
        (baked(maps, bump=-1.0), "`bump` = -1.0: expected 0 (off) to 100"),
        (baked(maps, pixel_angle=0.5), "`pixel_angle` = 0.5: expected 0 (no mip maps)"),
        (baked(maps, filter="trilinear"), "`filter` = 'trilinear': expected 'stochastic'"),
        ({"type": "xylem_wood_baked"}, "`maps` (a `xylem bake` output folder) is required"),
        (baked(missing), "highlight_width.exr is missing"),
        (baked(bad), "base_color.exr holds 2 non-finite values (the first at row 7, column 11"),
    ]
    for props, message in cases:
        with pytest.raises(Exception) as e:
            mi.load_dict(props)
        assert message in str(e.value), (message, str(e.value)[-400:])
    valid = mi.load_dict(baked(maps, roughness=0.3, filter="bilinear", pixel_angle=1e-3,
                               bump=2.0))
    assert isinstance(valid, mi.BSDF), valid

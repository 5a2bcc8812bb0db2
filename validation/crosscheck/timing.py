"""Timing mode: Mitsuba 3 rendering one scene (xylem depth 8 = Mitsuba depth 9, box filter;
`--case`: `cornell_box`, the Lambertian box of scenes/cornell_box.toml, `cornell_spheres`, the
same walls with a mirror and a glass sphere, or `wood_board`, sweep_board's board under a rect
light, its wood through xylem's `xylem_wood` plugin), its samples/s and its RMSE
against a high-spp reference, and the same figures for a xylem image of the scene if one is
given (`xylem bench render` passes its own). With `--serve` the case is also written as a xylem
scene file (`xylem_<case>.toml` in the work folder, its meshes beside it) whose path ends the
`ready` line, so that xylem renders the very scene Mitsuba renders.

samples/s = width · height · spp / seconds of the render itself: the scene is loaded and rendered
once (Dr.Jit compiles its kernels then), and later renders of the same scene and seed, which
reuse the compiled kernels, are timed. With `--serve` (what `xylem bench render` runs) the process
then times one render per `render` line on stdin, answering each with its seconds, so the caller
can interleave its own renders with Mitsuba's (a change of machine load then falls on both), and
a final `score` line (JSON: the xylem image, its spp and its times) gives medians and ranges. The reference is one Mitsuba render of `--reference-spp`
samples per pixel in chunks of 256 spp, cached in target/crosscheck/; RMSE is over all pixels and
channels. RMSE at equal time is RMSE · sqrt(seconds / Mitsuba's seconds): Monte Carlo error falls
as 1/sqrt(samples), so it is the error each renderer would reach in Mitsuba's time.

Like with like: the timed Mitsuba render starts Russian roulette where xylem does. xylem plays
it after its 3rd BSDF sample (`render::integrator::survival`); Mitsuba 3's `path` after its
`rr_depth`-th (`depth` grows by one per BSDF sample, roulette where `depth >= rr_depth`), so
`rr_depth` = 3. Both discount refraction's η'² (Mitsuba: `throughput · eta²`); Mitsuba caps
survival at 0.95, xylem at 1. The reference keeps Mitsuba's default (5): any unbiased rule
converges to the same image.
"""

import contextlib
import json
import math
import os
import sys
import time

import numpy as np

from . import render, scenes

DEPTH = 8
# Rec. 709 luminance weights (xylem's `math::luminance`).
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
# The cases `--case` names.
CASES = {"cornell_box": scenes.cornell_lambertian, "cornell_spheres": scenes.cornell_spheres,
         "wood_board": scenes.wood_board}
# Mitsuba's `rr_depth` equal to xylem's roulette start (bounce 3), for the timed render.
RR_DEPTH = 3


def add_arguments(ap):
    g = ap.add_argument_group("timing")
    g.add_argument("--case", default="cornell_box", choices=sorted(CASES),
                   help="the scene: the Lambertian Cornell box (default), the box with a "
                        "mirror and a glass sphere, or the wood board (through the plugin)")
    g.add_argument("--spp", type=int, default=64, help="spp of the timed render (64)")
    g.add_argument("--reference-spp", type=int, default=2048)
    g.add_argument("--xylem-image", default=None, help="a xylem EXR of the scene to score")
    g.add_argument("--xylem-seconds", type=float, default=None,
                   help="its render time (s), for samples/s and RMSE at equal time")
    g.add_argument("--xylem-spp", type=int, default=None, help="its spp (default --spp)")
    g.add_argument("--sampler", default="independent",
                   choices=["independent", "multijitter", "orthogonal", "ldsampler", "stratified"],
                   help="Mitsuba's sampler of the timed render (its default: independent)")
    g.add_argument("--serve", action="store_true",
                   help="time one render per `render` line on stdin, then score (see above)")


def uses_plugin(case):
    """Whether the case has wood, which Mitsuba renders through xylem's `xylem_wood` plugin."""
    return any(m["type"] == "wood" for m in case["materials"].values())


def register_plugin(case):
    """xylem's `xylem.mitsuba` module, its plugin registered (before the scene loads), where
    `case` has wood; None where it has not."""
    if not uses_plugin(case):
        return None
    try:
        import xylem.mitsuba
    except ImportError as e:
        raise SystemExit(
            f"--case {case['name']}: Mitsuba renders its wood through xylem's plugin, and the "
            f"xylem Python package is not importable ({e}): `cargo test --release --test python` "
            "stages it in target/python-test/site (`xylem bench render` puts that on "
            "PYTHONPATH), or `pip install ./python`")
    xylem.mitsuba.register()
    return xylem.mitsuba


def mitsuba_mode(case):
    """The Dr.Jit mode Mitsuba renders `case` in: the plugin reads its inputs into numpy, so
    wood renders inside `xylem.mitsuba.evaluated()` (wavefront mode); the boxes in Dr.Jit's
    default (symbolic, one megakernel)."""
    plugin = register_plugin(case)
    return contextlib.nullcontext() if plugin is None else plugin.evaluated()


def reference(mi, folder, case, meshes, spp):
    """The cached high-spp Mitsuba image (H, W, 3) of `case`."""
    w, h = case["res"]
    path = os.path.join(folder, f"reference_{case['name']}_{w}x{h}_d{DEPTH}_{spp}spp.exr")
    if os.path.exists(path):
        return render.read_exr_rgb(mi, path), path
    # Chunks of at most 256 spp (Dr.Jit's wavefront for the plugin's wood grows with spp),
    # the last one the remainder, averaged by their samples.
    chunks = [256] * (spp // 256) + ([spp % 256] if spp % 256 else [])
    register_plugin(case)
    scene = mi.load_dict(scenes.mitsuba_dict(mi, case, meshes, DEPTH, chunks[0], 0))
    acc = np.zeros((h, w, 3))
    for k, n in enumerate(chunks):
        # Progress on stderr (stdout is `xylem bench render`'s protocol): a first reference of
        # the wood takes minutes.
        print(f"Mitsuba reference of {case['name']}: chunk {k + 1} of {len(chunks)} ({n} spp)",
              file=sys.stderr, flush=True)
        with mitsuba_mode(case):
            img = mi.render(scene, seed=100_000 + k, spp=n)
        acc += n * np.array(img, dtype=np.float64)[..., :3]
    img = acc / spp
    bmp = mi.Bitmap(img.astype(np.float32), mi.Bitmap.PixelFormat.RGB)
    # Written whole under a name of this process's own, then renamed: a concurrent run never
    # reads half a reference.
    tmp = f"{path[: -len('.exr')]}.{os.getpid()}.partial.exr"
    bmp.write(tmp)
    os.replace(tmp, path)
    return img, path


def rmse(a, b):
    return float(np.sqrt(np.mean((a - b) ** 2)))


# Pixels whose reference luminance is above every lit surface's (the brightest wall is ≈ 0.4):
# the light itself and the few dozen pixels its edge crosses. Their samples see either the light
# (radiance ≈ 14) or a wall, so their error is heavy-tailed and, being ≈ 0.4 % of the pixels,
# they decide the all-pixel RMSE: two seeds of the same renderer differ by 6 % there
# (notes/render.md). The RMSE over the other pixels measures the path tracer's noise.
SURFACE_MAX_LUMINANCE = 0.5


def rmse_surfaces(a, ref):
    """RMSE over the pixels off the light and its edge (reference luminance ≤ 0.5)."""
    lum = ref @ LUMINANCE
    keep = lum <= SURFACE_MAX_LUMINANCE
    return float(np.sqrt(np.mean((a[keep] - ref[keep]) ** 2)))


def mean_ratio(a, ref):
    """The image's mean luminance over the reference's: 1 within noise when both render one
    scene (a quick like-with-like check; the cross-check proper is `--small`/`--full`)."""
    return float((a @ LUMINANCE).mean() / (ref @ LUMINANCE).mean())


def run(mi, args):
    import drjit as dr

    if not (1 <= args.reference_spp <= 1_000_000 and 1 <= args.spp <= 1_000_000):
        raise SystemExit(f"--spp {args.spp}, --reference-spp {args.reference_spp}: allowed 1 to "
                         "1000000")
    os.makedirs(args.work, exist_ok=True)
    case = CASES[args.case]()
    meshes = scenes.write_meshes(case, os.path.join(args.work, "meshes"))
    ref, ref_path = reference(mi, args.work, case, meshes, args.reference_spp)
    t0 = time.perf_counter()
    register_plugin(case)
    scene = mi.load_dict(scenes.mitsuba_dict(mi, case, meshes, DEPTH, args.spp, 1,
                                             rr_depth=RR_DEPTH, sampler=args.sampler))
    load_s = time.perf_counter() - t0
    def timed():
        t0 = time.perf_counter()
        with mitsuba_mode(case):
            img = mi.render(scene, seed=1, spp=args.spp)
            dr.eval(img)
            dr.sync_thread()
        return img, time.perf_counter() - t0

    img, first = timed()  # JIT compilation
    times, xylem = [], None
    if args.serve:
        # The same case for xylem (seed 1, as Mitsuba's), written whole under a temporary name
        # first: a concurrent run never reads half a file.
        toml = os.path.join(args.work, f"xylem_{case['name']}.toml")
        tmp = f"{toml}.{os.getpid()}.partial"
        with open(tmp, "w") as f:
            f.write(scenes.xylem_toml(case, meshes, DEPTH, args.spp, 1))
        os.replace(tmp, toml)
        print(f"ready {os.path.abspath(toml)}", flush=True)
        for line in sys.stdin:
            word, _, rest = line.strip().partition(" ")
            if word == "render":
                img, t = timed()
                times.append(t)
                print(f"{t:.6f}", flush=True)
            elif word == "score":
                xylem = json.loads(rest)
                break
    else:
        img, t = timed()
        times.append(t)
        if args.xylem_image:
            xylem = {"image": args.xylem_image, "spp": args.xylem_spp or args.spp,
                     "seconds": [args.xylem_seconds] if args.xylem_seconds else []}
    if not times:
        raise SystemExit("--serve: no `render` line before `score`")
    img = np.array(img, dtype=np.float64)[..., :3]
    samples = case["res"][0] * case["res"][1] * args.spp
    sec = float(np.median(times))
    m = {"renderer": f"Mitsuba {mi.__version__} {mi.variant()}", "sampler": args.sampler,
         "threads": args.threads,
         "spp": args.spp, "seconds": sec, "seconds_range": [min(times), max(times)],
         "repeats": len(times), "first_render_s": first, "load_s": load_s,
         "samples_per_s": samples / sec, "rmse": rmse(img, ref),
         "rmse_surfaces": rmse_surfaces(img, ref)}
    m["rmse_equal_time"] = m["rmse"]
    m["rmse_surfaces_equal_time"] = m["rmse_surfaces"]
    out = {"case": case["name"], "res": list(case["res"]), "xylem_depth": DEPTH, "mitsuba_depth": DEPTH + 1,
           "mitsuba_rr_depth": RR_DEPTH,
           "reference": os.path.relpath(ref_path), "reference_spp": args.reference_spp,
           "reference_mean": ref.mean(axis=(0, 1)).tolist(), "mitsuba": m,
           "load_average": list(os.getloadavg())}
    if xylem:
        x = render.read_exr_rgb(mi, xylem["image"])
        xs = {"renderer": "xylem", "image": xylem["image"], "rmse": rmse(x, ref),
              "rmse_surfaces": rmse_surfaces(x, ref), "spp": xylem["spp"],
              "mean_ratio": mean_ratio(x, ref)}
        if xylem["seconds"]:
            xsec = float(np.median(xylem["seconds"]))
            xs["seconds"] = xsec
            xs["seconds_range"] = [min(xylem["seconds"]), max(xylem["seconds"])]
            xs["repeats"] = len(xylem["seconds"])
            xs["samples_per_s"] = case["res"][0] * case["res"][1] * xs["spp"] / xsec
            scale = math.sqrt(xsec / m["seconds"])
            xs["rmse_equal_time"] = xs["rmse"] * scale
            xs["rmse_surfaces_equal_time"] = xs["rmse_surfaces"] * scale
            # The ratio's spread: each interleaved pair's xylem / Mitsuba samples/s.
            pairs = [(xylem["spp"] / a) / (args.spp / b) for a, b in zip(xylem["seconds"], times)]
            xs["ratio_range"] = [min(pairs), max(pairs)]
            # And of the error at equal time: each pair's xylem / Mitsuba seconds, on the two
            # images' error ratio (one image each, so only the times spread).
            for key in ("rmse", "rmse_surfaces"):
                eq = [xs[key] / m[key] * math.sqrt(a / b)
                      for a, b in zip(xylem["seconds"], times)]
                xs[f"{key}_equal_time_ratio_range"] = [min(eq), max(eq)]
        out["xylem"] = xs
    return out


def table(out):
    lines = [f"{out.get('case', 'cornell_box')} {out['res'][0]}x{out['res'][1]}, xylem depth {out['xylem_depth']} "
             f"(Mitsuba {out['mitsuba_depth']}, rr_depth {out['mitsuba_rr_depth']} = xylem's "
             f"roulette start), Mitsuba sampler {out['mitsuba'].get('sampler', 'independent')}, "
             f"reference {out['reference']} "
             f"({out['reference_spp']} spp Mitsuba)",
             f"{'renderer':<28} {'spp':>5} {'seconds (min-max)':>20} {'Msamples/s':>11} {'RMSE':>9} "
             f"{'RMSE@equal time':>16} {'RMSE surfaces':>14} {'@equal time':>12}"]
    rows = [out["mitsuba"]] + ([out["xylem"]] if "xylem" in out else [])
    for r in rows:
        sec = (f"{r['seconds']:.3f} ({r['seconds_range'][0]:.3f}-{r['seconds_range'][1]:.3f})"
               if "seconds_range" in r else "-")
        sps = f"{r['samples_per_s'] / 1e6:.3f}" if "samples_per_s" in r else "-"
        eq = f"{r['rmse_equal_time']:.5f}" if "rmse_equal_time" in r else "-"
        eqs = f"{r['rmse_surfaces_equal_time']:.5f}" if "rmse_surfaces_equal_time" in r else "-"
        lines.append(f"{r['renderer']:<28} {r['spp']:>5} {sec:>20} {sps:>11} {r['rmse']:>9.5f} "
                     f"{eq:>16} {r['rmse_surfaces']:>14.5f} {eqs:>12}")
    m = out["mitsuba"]
    lines.append(f"Mitsuba: first render (with JIT compilation) {m['first_render_s']:.2f} s, "
                 f"scene load {m['load_s']:.2f} s")
    x = out.get("xylem")
    if x and "samples_per_s" in x:
        lines.append(f"xylem / Mitsuba: samples/s {x['samples_per_s'] / m['samples_per_s']:.3f}, "
                     f"RMSE {x['rmse'] / m['rmse']:.3f}, RMSE at equal time "
                     f"{x['rmse_equal_time'] / m['rmse_equal_time']:.3f}; off the light: RMSE "
                     f"{x['rmse_surfaces'] / m['rmse_surfaces']:.3f}, at equal time "
                     f"{x['rmse_surfaces_equal_time'] / m['rmse_surfaces_equal_time']:.3f}")
        lines.append(f"xylem's mean luminance / the reference's: {x['mean_ratio']:.4f}")
        if "ratio_range" in x:
            lo, hi = x["ratio_range"]
            lines.append(f"samples/s ratio over {x['repeats']} interleaved pairs: "
                         f"{lo:.3f}-{hi:.3f} (the medians' ratio above)")
            (a, b), (c, d) = (x["rmse_equal_time_ratio_range"],
                              x["rmse_surfaces_equal_time_ratio_range"])
            lines.append(f"RMSE at equal time ratio over the pairs: {a:.3f}-{b:.3f}; off the "
                         f"light {c:.3f}-{d:.3f}")
    lines.append(f"load average {out['load_average'][0]:.2f}")
    return "\n".join(lines)

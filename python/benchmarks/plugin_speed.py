"""Times the Mitsuba 3 plugin ``xylem_wood`` against Mitsuba's own ``roughplastic`` on the same
scene (issue 30: goal <= 2x roughplastic in ``llvm_ad_rgb``), interleaved, several repeats, and
prints medians and spreads.

    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \\
    PYTHONPATH=target/python-test/site target/python-venv/bin/python \\
        python/benchmarks/plugin_speed.py [--res 128 96] [--spp 8] [--repeats 5] [--profile]

The scene: a 0.3 m board (a rectangle, scene units metres) seen from 0.4 m under one
directional light and a dim constant environment, Mitsuba's ``path`` integrator (max depth 4).
Three renders per repeat, in turn:

- ``roughplastic``: the board with Mitsuba's ``roughplastic`` (GGX, alpha 0.25, eta 1.5), Dr.Jit's
  default (symbolic) modes, i.e. one megakernel per render;
- ``roughplastic_evaluated``: the same inside ``xylem.mitsuba.evaluated()`` (wavefront mode,
  what the plugin needs), which separates the plugin's own cost from the mode's;
- ``xylem_wood``: the board with the plugin (mahogany, eta 1.5, roughness 0.25) inside
  ``evaluated()``.

Each render is timed from ``mi.render`` to ``dr.eval`` + ``dr.sync_thread`` of the image, after
one untimed warm-up render of each (Dr.Jit's kernel cache). ``--profile`` adds a cProfile of
one plugin render: where the time goes (the wood's preparation, the BSDF calls, the numpy and
Dr.Jit conversions, the integrator).
"""

import argparse
import cProfile
import io
import json
import os
import platform
import pstats
import statistics
import time

import drjit as dr
import mitsuba as mi

mi.set_variant(os.environ.get("XYLEM_BENCH_VARIANT", "llvm_ad_rgb"))

import xylem  # noqa: E402
import xylem.mitsuba  # noqa: E402

xylem.mitsuba.register()

BSDFS = {
    "roughplastic": {"type": "roughplastic", "distribution": "ggx", "alpha": 0.25,
                     "int_ior": 1.5, "diffuse_reflectance": {"type": "rgb",
                                                             "value": [0.45, 0.2, 0.1]}},
    "xylem_wood": {"type": "xylem_wood", "preset": "african_mahogany", "seed": 7, "eta": 1.5,
                   "roughness": 0.25, "origin": "0, 120, 0", "axis": "1, 0, 0",
                   "rotation_deg": 20.0},
}


def scene(bsdf, res, spp):
    T = mi.ScalarTransform4f
    return mi.load_dict({
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 4},
        "sensor": {
            "type": "perspective", "fov": 40.0,
            "to_world": T().look_at(origin=[0, -0.25, 0.32], target=[0, 0, 0], up=[0, 0, 1]),
            "film": {"type": "hdrfilm", "width": res[0], "height": res[1],
                     "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "sun": {"type": "directional", "direction": [-0.3, -0.2, -0.9],
                "irradiance": {"type": "rgb", "value": [3.0, 3.0, 3.0]}},
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": [0.2, 0.2, 0.25]}},
        "board": {"type": "rectangle", "to_world": T().scale([0.15, 0.15, 1.0]),
                  "bsdf": dict(BSDFS[bsdf])},
    })


def render(sc, seed, evaluated):
    start = time.perf_counter()
    if evaluated:
        with xylem.mitsuba.evaluated():
            img = mi.render(sc, seed=seed)
            dr.eval(img)
    else:
        img = mi.render(sc, seed=seed)
        dr.eval(img)
    dr.sync_thread()
    return time.perf_counter() - start


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--res", type=int, nargs=2, default=(128, 96))
    ap.add_argument("--spp", type=int, default=8)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--profile", action="store_true")
    ap.add_argument("--json", help="write the figures to this file")
    args = ap.parse_args()

    cases = [("roughplastic", "roughplastic", False),
             ("roughplastic_evaluated", "roughplastic", True),
             ("xylem_wood", "xylem_wood", True)]
    scenes = {b: scene(b, args.res, args.spp) for b in BSDFS}
    for _, b, ev in cases:                       # warm-up: kernel cache, first-call costs
        render(scenes[b], 0, ev)
    times = {name: [] for name, _, _ in cases}
    for r in range(args.repeats):                # interleaved, so load changes hit all alike
        for name, b, ev in cases:
            times[name].append(render(scenes[b], r + 1, ev))

    def summary(ts):
        return {"median_s": statistics.median(ts), "min_s": min(ts), "max_s": max(ts),
                "times_s": ts}

    out = {"variant": mi.variant(), "res": list(args.res), "spp": args.spp,
           "repeats": args.repeats, "machine": platform.processor() or platform.machine(),
           "cpus": os.cpu_count(), "load_avg": os.getloadavg(),
           "cases": {k: summary(v) for k, v in times.items()}}
    base = statistics.median(times["roughplastic"])
    base_ev = statistics.median(times["roughplastic_evaluated"])
    wood = statistics.median(times["xylem_wood"])
    # Ratios of medians, and their spread over the repeats (ratio of each repeat's pair).
    pairs = [w / b for w, b in zip(times["xylem_wood"], times["roughplastic"])]
    pairs_ev = [w / b for w, b in zip(times["xylem_wood"], times["roughplastic_evaluated"])]
    out["ratio_vs_roughplastic"] = wood / base
    out["ratio_vs_roughplastic_range"] = [min(pairs), max(pairs)]
    out["ratio_vs_roughplastic_evaluated"] = wood / base_ev
    out["ratio_vs_roughplastic_evaluated_range"] = [min(pairs_ev), max(pairs_ev)]

    for name, s in out["cases"].items():
        print(f"{name:24s} median {s['median_s']:.3f} s  (min {s['min_s']:.3f}, "
              f"max {s['max_s']:.3f}, {args.repeats} repeats)")
    print(f"xylem_wood / roughplastic            {out['ratio_vs_roughplastic']:.2f}x "
          f"(per repeat {min(pairs):.2f}-{max(pairs):.2f})")
    print(f"xylem_wood / roughplastic evaluated  {out['ratio_vs_roughplastic_evaluated']:.2f}x "
          f"(per repeat {min(pairs_ev):.2f}-{max(pairs_ev):.2f})")
    print(f"load average {out['load_avg']}, {out['cpus']} CPUs, {mi.variant()}, "
          f"{args.res[0]}x{args.res[1]}, {args.spp} spp")

    if args.profile:
        sc = scenes["xylem_wood"]
        prof = cProfile.Profile()
        prof.enable()
        t = render(sc, 99, True)
        prof.disable()
        buf = io.StringIO()
        pstats.Stats(prof, stream=buf).sort_stats("tottime").print_stats(14)
        print(f"\nprofile of one xylem_wood render ({t:.3f} s under cProfile):")
        print(buf.getvalue())
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()

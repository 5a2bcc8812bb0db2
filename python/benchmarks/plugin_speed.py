"""Times the Mitsuba 3 plugin ``xylem_wood`` against Mitsuba's own ``roughplastic`` on the same
scene (issue 30: goal <= 2x roughplastic in ``llvm_ad_rgb``), interleaved, several repeats, and
prints medians and spreads.

    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \\
    PYTHONPATH=target/python-test/site target/python-venv/bin/python \\
        python/benchmarks/plugin_speed.py [--res 128 96] [--spp 8] [--repeats 5] [--profile]
        [--before DIR] [--json FILE] [--frozen] [--renders N]

The scene: a 0.3 m board (a rectangle, scene units metres) seen from 0.4 m under one
directional light and a dim constant environment, Mitsuba's ``path`` integrator (max depth 4).
Three renders per repeat, in turn:

- ``roughplastic``: the board with Mitsuba's ``roughplastic`` (GGX, alpha 0.25, eta 1.5), Dr.Jit's
  default (symbolic) modes, i.e. one megakernel per render;
- ``roughplastic_evaluated``: the same inside ``xylem.mitsuba.evaluated()`` (wavefront mode,
  what the plugin needs), which separates the plugin's own cost from the mode's;
- ``xylem_wood``: the board with the plugin (mahogany, eta 1.5, roughness 0.25) inside
  ``evaluated()``;
- ``xylem_wood_baked``: the board with the Dr.Jit-native plugin on maps of the same preset
  baked by ``xylem bake`` (a 300 x 300 mm board at ``--bake-res`` texels, smooth finish, eta
  1.5), in Dr.Jit's default symbolic modes like ``roughplastic``. ``--maps DIR`` gives a bake
  folder; otherwise the script bakes one with ``$XYLEM_BIN`` or target/release/xylem;
- ``xylem_wood_baked_rough``: the same with a rough finish (roughness 0.25, as
  ``roughplastic``'s alpha): xylem's energy-compensated GGX finish;
- ``xylem_wood_baked_rough_mip``: the same with mip-mapped lookups (``pixel_angle`` from the
  camera, ``xylem.mitsuba_baked.set_pixel_angle``).

``--frozen`` renders every case through ``dr.freeze`` (the symbolic cases only): Dr.Jit
records the render's kernels on the warm-up renders (four, with different seeds) and replays
them when timed, so neither side pays for tracing its Python and C++ into Dr.Jit at every
render (what a loop of renders, as in inverse rendering, would do).

``--cases a,b`` runs only those (and ``roughplastic``, the ratios' base); ``--before DIR`` runs
each plugin case again with the package in DIR (``CASE_before``): the A/B pair of a change.

Both baked cases use the plugin's pore bump at ``--bump`` (default 1, the plugin's default;
0: the normal map is not read) and its texture filter, or ``--filter stochastic|bilinear``.

Each case runs in its own Python process (a ``xylem_wood`` BSDF alive in a process makes every
symbolic render there fail: Dr.Jit traces a symbolic call for every registered BSDF instance,
so the plugin's symbolic-scope error fires even for a scene that does not use it), one process
per case and repeat, interleaved: case A, B, C, A, B, C, ... Each render is timed from
``mi.render`` to ``dr.eval`` + ``dr.sync_thread`` of the image (``--renders N``: the median of
N renders with different seeds, which steadies short renders), after one untimed warm-up
render in the same process (Dr.Jit's kernel cache, first-call costs). ``--profile`` adds a cProfile of
one plugin render: where the time goes (the wood's preparation, the BSDF calls, the numpy and
Dr.Jit conversions, the integrator).
"""

import argparse
import contextlib
import cProfile
import io
import json
import os
import platform
import pstats
import statistics
import subprocess
import sys
import tempfile
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
    # scale 1000 (tree mm per scene unit) is units "m", the default, spelt so that the plugin
    # of before issue 30 (no `units`) reads the same wood: PYTHONPATH at an older package
    # compares the two.
    "xylem_wood": {"type": "xylem_wood", "preset": "african_mahogany", "seed": 7, "eta": 1.5,
                   "roughness": 0.25, "origin": "0, 120, 0", "axis": "1, 0, 0",
                   "rotation_deg": 20.0, "scale": 1000.0},
}


def bake(exe, res, out):
    """Bakes the board's maps (the preset of BSDFS["xylem_wood"]) into `out`."""
    subprocess.run([exe, "bake", "african_mahogany", "--board", "300x300x20", "--res", str(res),
                    "--out", out], check=True, capture_output=True)
    return out


def scene(bsdf, res, spp, maps=None, bump=1.0, filter=None):
    T = mi.ScalarTransform4f
    sc = mi.load_dict({
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
                  "bsdf": ({"type": "xylem_wood_baked", "maps": maps, "eta": 1.5,
                            "roughness": 0.25 if "_rough" in bsdf else 0.0,
                            "bump": bump, **({"filter": filter} if filter else {})}
                           if bsdf.startswith("xylem_wood_baked") else dict(BSDFS[bsdf]))},
    })
    if bsdf.endswith("_mip"):
        import xylem.mitsuba_baked

        xylem.mitsuba_baked.set_pixel_angle(sc)
    return sc


@dr.freeze
def frozen_render(sc, seed):
    """`mi.render` as a frozen function (Dr.Jit's `dr.freeze`): its kernels recorded on the
    first calls and replayed after, with no Python tracing; `seed` a `mi.UInt32`, an input
    rather than a constant of the recording."""
    return mi.render(sc, seed=seed)


def render(sc, seed, evaluated, frozen=False):
    """(wall seconds, process CPU seconds: every thread of the process, Dr.Jit's and rayon's)"""
    start, cpu = time.perf_counter(), time.process_time()
    with xylem.mitsuba.evaluated() if evaluated else contextlib.nullcontext():
        img = frozen_render(sc, mi.UInt32(seed)) if frozen else mi.render(sc, seed=seed)
        dr.eval(img)
    dr.sync_thread()
    return time.perf_counter() - start, time.process_time() - cpu


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--res", type=int, nargs=2, default=(128, 96))
    ap.add_argument("--spp", type=int, default=8)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--profile", action="store_true")
    ap.add_argument("--json", help="write the figures to this file")
    ap.add_argument("--before", help="a folder holding an older `xylem` package (each plugin "
                    "case runs again with it, as CASE_before, this folder first on PYTHONPATH)")
    ap.add_argument("--maps", help="a `xylem bake` folder for xylem_wood_baked (default: bake "
                    "one into a temporary folder)")
    ap.add_argument("--bake-res", type=int, default=1024, help="texels along the board when "
                    "baking (default 1024)")
    ap.add_argument("--bump", type=float, default=1.0, help="the baked cases' pore bump "
                    "(default 1; 0 leaves the normal map unread)")
    ap.add_argument("--renders", type=int, default=1,
                    help="timed renders per process, their median reported (default 1)")
    ap.add_argument("--filter", choices=("stochastic", "bilinear"),
                    help="the baked cases' texture filter (default: the plugin's, stochastic)")
    ap.add_argument("--cases", help="comma-separated cases to run (default: all); "
                    "roughplastic is always run, as the ratios' base")
    ap.add_argument("--frozen", action="store_true", help="render every case through "
                    "dr.freeze (recorded on four warm-up renders, replayed when timed), "
                    "which takes the per-render tracing out of both sides")
    ap.add_argument("--one", help=argparse.SUPPRESS)         # child process: this case only
    ap.add_argument("--seed", type=int, default=1, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.renders < 1 or args.repeats < 1:
        ap.error(f"--renders {args.renders}, --repeats {args.repeats}: each must be at least 1")

    cases = [("roughplastic", "roughplastic", False),
             ("roughplastic_evaluated", "roughplastic", True),
             ("xylem_wood", "xylem_wood", True),
             ("xylem_wood_baked", "xylem_wood_baked", False),
             ("xylem_wood_baked_rough", "xylem_wood_baked_rough", False),
             ("xylem_wood_baked_rough_mip", "xylem_wood_baked_rough_mip", False)]
    if args.cases and not args.one:
        keep = set(args.cases.split(",")) | {"roughplastic"}
        unknown = keep - {c[0] for c in cases}
        if unknown:
            ap.error(f"--cases: unknown {sorted(unknown)}")
        cases = [c for c in cases if c[0] in keep]
    if args.frozen:
        # xylem_wood goes through numpy in evaluated() mode, which a frozen function cannot
        # record: only the cases in Dr.Jit's symbolic modes.
        cases = [c for c in cases if not c[2]]
    if args.before or (args.one or "").endswith("_before"):
        # Each plugin case again with the older package: the A/B pair of a change.
        cases += [(name + "_before", b, ev) for name, b, ev in cases
                  if name.startswith("xylem_wood")]
    if args.one:                                 # child: warm-up(s), timed render(s)
        name, b, ev = next(c for c in cases if c[0] == args.one)
        sc = scene(b, args.res, args.spp, args.maps, args.bump, args.filter)
        render(sc, 0, ev, args.frozen)
        if args.frozen:
            # More warm-ups with other seeds: Dr.Jit recorded this scene's render three times
            # (a literal input that changes is made opaque and recorded again), and the first
            # replay is slower than later ones.
            for seed in (1, 2, 3):
                render(sc, seed * 1_000_000, ev, args.frozen)
        if args.profile:
            prof = cProfile.Profile()
            prof.enable()
        # The median of --renders timed renders (seeds seed, seed + 1000, ...): one short render
        # is at the mercy of a thread's wake-up (8-spp `roughplastic`: 9-19 ms wall).
        timed = [render(sc, args.seed + 1000 * k, ev, args.frozen)
                 for k in range(args.renders)]
        t, cpu = (statistics.median(x) for x in zip(*timed))
        if args.profile:
            prof.disable()
            buf = io.StringIO()
            pstats.Stats(prof, stream=buf).sort_stats("tottime").print_stats(16)
            print(f"profile of one {name} render ({t:.3f} s under cProfile):\n{buf.getvalue()}",
                  file=sys.stderr)
        print(json.dumps({"seconds": t, "cpu_seconds": cpu}))
        return

    def child(name, seed, profile=False):
        cmd = [sys.executable, __file__, "--one", name, "--seed", str(seed), "--res",
               *map(str, args.res), "--spp", str(args.spp), "--maps", args.maps,
               "--bump", str(args.bump), "--renders", str(args.renders)] + (
                   ["--filter", args.filter] if args.filter else []) + (
                   ["--profile"] if profile else []) + (["--frozen"] if args.frozen else [])
        env = dict(os.environ)
        if name.endswith("_before"):
            env["PYTHONPATH"] = os.pathsep.join([args.before, env.get("PYTHONPATH", "")])
        out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env)
        if profile:
            print(out.stderr)
        res = json.loads(out.stdout.strip().splitlines()[-1])
        return res["seconds"], res["cpu_seconds"]

    if not args.maps:
        root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
        exe = os.environ.get("XYLEM_BIN") or os.path.join(root, "target/release/xylem")
        args.maps = bake(exe, args.bake_res, os.path.join(tempfile.mkdtemp(), "maps"))
    times = {name: [] for name, _, _ in cases}
    cpu_times = {name: [] for name, _, _ in cases}
    print(f"{mi.variant()}, {args.res[0]}x{args.res[1]}, {args.spp} spp, {args.repeats} repeats, "
          f"{'frozen (dr.freeze), ' if args.frozen else ''}"
          f"load average {os.getloadavg()[0]:.1f} at the start", flush=True)
    for r in range(args.repeats):                # interleaved, so load changes hit all alike
        for name, _, _ in cases:
            t, cpu = child(name, r + 1)
            times[name].append(t)
            cpu_times[name].append(cpu)

    def summary(ts):
        return {"median_s": statistics.median(ts), "min_s": min(ts), "max_s": max(ts),
                "times_s": ts}

    out = {"variant": mi.variant(), "res": list(args.res), "spp": args.spp, "frozen": args.frozen,
           "bake_res": args.bake_res,
           "repeats": args.repeats, "renders": args.renders,
           "machine": platform.processor() or platform.machine(),
           "cpus": os.cpu_count(), "load_avg": os.getloadavg(),
           "cases": {k: summary(v) for k, v in times.items()},
           "cpu": {k: summary(v) for k, v in cpu_times.items()}}
    for name, s in out["cases"].items():
        c = out["cpu"][name]
        print(f"{name:24s} wall median {s['median_s']:.3f} s (min {s['min_s']:.3f}, "
              f"max {s['max_s']:.3f});  CPU median {c['median_s']:.3f} s (min "
              f"{c['min_s']:.3f}, max {c['max_s']:.3f})")

    def ratio(kind, series, case, base):
        """Ratio of medians of `case` over `base`, and its spread over the repeats (the ratio
        of each repeat's pair, the two renders run next to each other)."""
        per = [a / b for a, b in zip(series[case], series[base])]
        med = statistics.median(series[case]) / statistics.median(series[base])
        out.setdefault("ratios", {})[f"{kind} {case} / {base}"] = {
            "ratio_of_medians": med, "median_of_ratios": statistics.median(per),
            "min": min(per), "max": max(per)}
        print(f"{kind}: {case} / {base} {med:.2f}x (per repeat median "
              f"{statistics.median(per):.2f}, {min(per):.2f}-{max(per):.2f})")

    pairs = [(c, "roughplastic") for c in times
             if c != "roughplastic" and not c.endswith("_before")]
    if "xylem_wood" in times and "roughplastic_evaluated" in times:
        pairs.append(("xylem_wood", "roughplastic_evaluated"))
    pairs += [(c[:-len("_before")], c) for c in times if c.endswith("_before")]
    for kind, series in (("CPU", cpu_times), ("wall", times)):
        for case, base in pairs:
            ratio(kind, series, case, base)
    print(f"load average {out['load_avg']}, {out['cpus']} CPUs, {mi.variant()}, "
          f"{args.res[0]}x{args.res[1]}, {args.spp} spp")

    if args.profile:
        child("xylem_wood", 99, profile=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()

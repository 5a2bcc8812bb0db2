"""`python -m validation.crosscheck --small | --full | --timing`: xylem's path tracer against
Mitsuba 3 on the same scenes (validation/CROSSCHECK.md says what is compared and how).

--small   low resolution, few samples, every case at one depth, plus the negative controls;
          exit status 0 only if every case agrees and every negative control is detected
          (crates/xylem-cli/tests/crosscheck.rs runs it in `cargo test --release`).
--full    every case at xylem depths 1, 2 and 8; writes validation/CROSSCHECK.md and the
          pictures in validation/plots/crosscheck/.
--timing  Mitsuba's speed and error on one scene, `--case cornell_box` (the Lambertian Cornell
          box), `cornell_spheres` (the box with a mirror and a glass sphere) or `wood_board`
          (a mahogany board through the xylem_wood plugin); `xylem bench render` runs it
          beside xylem's.
"""

import argparse
import copy
import json
import os
import platform
import sys
import time

import numpy as np

from . import images, render, scenes, stats

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ALPHA = 0.01
BLOCK = 8

# (case, xylem max_depth) per mode; xylem's depth k is Mitsuba's k + 1.
SMALL = {"res": {"cornell": (32, 32), "plane": (32, 24)}, "batches": 8, "spp": 32,
         "configs": [("cornell_box", 8), ("cornell_spheres", 2), ("plane_point", 1),
                     ("plane_rect", 2)]}
FULL = {"res": {"cornell": (128, 128), "plane": (128, 96)}, "batches": 16, "spp": 32,
        "configs": [(c, d) for c in scenes.CASES for d in (1, 2, 8)]}
# The negative control: xylem's white walls 10 % darker (albedo × 0.9) must be told apart.
DARKER_WHITE = 0.9


def resolution(mode, case):
    return mode["res"]["cornell" if case.startswith("cornell") else "plane"]


def darker_white(case):
    c = copy.deepcopy(case)
    c["name"] += "_darker_white"
    c["materials"]["white"]["albedo"] = [a * DARKER_WHITE for a in c["materials"]["white"]["albedo"]]
    return c


def summary(result):
    return {k: {a: b for a, b in v.items() if a not in ("z", "p", "mean_x", "mean_m")}
            for k, v in result.items()}


def passed(result):
    return all(v["pass"] for v in result.values())


def run(mode, args, mi):
    work = os.path.join(args.work, "renders")
    os.makedirs(work, exist_ok=True)
    os.makedirs(args.plots, exist_ok=True)
    n, spp = mode["batches"], mode["spp"]
    xseeds, mseeds = list(range(1, n + 1)), list(range(1001, 1001 + n))
    rows, controls = [], []
    for name, depth in mode["configs"]:
        case = scenes.CASES[name]()
        res = resolution(mode, name)
        t0 = time.perf_counter()
        bx, tx = render.xylem_batches(args.xylem, case, work, depth, spp, xseeds, res,
                                      args.threads, mi)
        bm, tm = render.mitsuba_batches(mi, case, work, depth, spp, mseeds, res)
        r = stats.compare(bx, bm, ALPHA, BLOCK)
        png = os.path.join(args.plots, f"{name}_d{depth}.png")
        images.write_png(mi, png, images.panel(r, BLOCK))
        row = {"case": name, "xylem_depth": depth, "mitsuba_depth": depth + 1, "res": res,
               "batches": n, "spp": spp, "xylem_s": sum(tx), "mitsuba_s": sum(tm),
               "seconds": time.perf_counter() - t0, "png": os.path.relpath(png, ROOT),
               "pass": passed(r), "tests": summary(r)}
        rows.append(row)
        print(f"{name} depth {depth}: {'pass' if row['pass'] else 'FAIL'} "
              + ", ".join(f"{k} max|z| {v['max_abs_z']:.2f} min p {v['min_p']:.2g}"
                          f" (level {v['level']:.2g})" for k, v in row["tests"].items()),
              flush=True)
        if name == "cornell_box" and depth == mode["configs"][0][1]:
            # Negative controls on this case: xylem's image mirrored left-right, and xylem
            # rendering white walls 10 % darker. Both must fail.
            mirrored = stats.compare(bx[:, :, ::-1], bm, ALPHA, BLOCK)
            dark, _ = render.xylem_batches(args.xylem, darker_white(case), work, depth, spp,
                                           xseeds, res, args.threads, mi)
            darker = stats.compare(dark, bm, ALPHA, BLOCK)
            for what, rr in (("xylem image mirrored left-right", mirrored),
                             (f"xylem white albedo × {DARKER_WHITE}", darker)):
                c = {"control": what, "case": name, "xylem_depth": depth, "detected":
                     not passed(rr), "tests": summary(rr)}
                controls.append(c)
                print(f"negative control ({what}): "
                      f"{'detected' if c['detected'] else 'NOT DETECTED'}, "
                      + ", ".join(f"{k} min p {v['min_p']:.2g}" for k, v in c["tests"].items()),
                      flush=True)
    return rows, controls


def markdown(rows, controls, mode, args, wall):
    lines = [
        "# Cross-check of xylem's path tracer against Mitsuba 3",
        "",
        "Made by `target/python-venv/bin/python -m validation.crosscheck --full` (the method: "
        "validation/crosscheck/; the small version runs in `cargo test --release` as "
        "crates/xylem-cli/tests/crosscheck.rs). Do not edit by hand.",
        "",
        f"- Mitsuba {args.mitsuba_version} (`{args.variant}`), Dr.Jit {args.drjit_version}; "
        f"xylem `{os.path.relpath(args.xylem, ROOT)}`; {args.threads} threads each; "
        f"machine: {platform.machine()}, {os.cpu_count()} cores, load average before the run "
        f"{args.load[0]:.2f}, after {os.getloadavg()[0]:.2f}; total {wall / 60:.1f} min.",
        f"- Each renderer renders each case in {mode['batches']} independent batches of "
        f"{mode['spp']} spp (xylem seeds 1–{mode['batches']}, Mitsuba seeds 1001–"
        f"{1000 + mode['batches']}), box filter, linear RGB.",
        "- Per pixel and channel z = (mean_x − mean_m) / sqrt(var_x/n_x + var_m/n_m) over the "
        "batches (Mitsuba 3's own image-test statistic, with both variances), p from Welch's "
        "t-test (Welch–Satterthwaite degrees of freedom); the same on the means of 8×8-pixel "
        f"regions and of the whole image. Each family (pixels, regions, image) passes at "
        f"{ALPHA:.0%} with the Šidák-corrected level 1 − (1 − {ALPHA})^(1/N). A case fails if "
        "any family fails.",
        "- Depth: xylem `max_depth` k (bounces) = Mitsuba `path` `max_depth` k + 1 (vertices): "
        "xylem 1 is direct lighting. Mitsuba's Russian roulette from depth 5, xylem's from "
        "bounce 3: both unbiased, so the means must agree.",
        "- Geometry: every surface one OBJ mesh written once, flat-shaded in both "
        "(xylem `smooth = false`, Mitsuba `face_normals`); spheres are 48 × 24 UV meshes; "
        "rect lights have a black box behind them in both, since xylem's lights block no rays.",
        "- A plane cannot light itself, so the plane cases give the same image at every depth "
        "(same seeds, so their rows repeat); they test the lights and the camera, the Cornell "
        "boxes the transport.",
        "- Mitsuba's `max_depth` 1 (emitters only) has no xylem equivalent: xylem's `max_depth` "
        "is at least 1.",
        "",
    ]
    for name in dict.fromkeys(r["case"] for r in rows):
        doc = scenes.CASES[name].__doc__.strip().splitlines()[0]
        lines += [f"## {name}", "", doc, "",
                  "| xylem depth (Mitsuba) | res | pixel tests | pixel max \\|z\\| | pixel min p "
                  "(level) | region tests | region max \\|z\\| | region min p (level) | image "
                  "min p | result | spp per renderer | xylem s | Mitsuba s |",
                  "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
        for r in (r for r in rows if r["case"] == name):
            t = r["tests"]
            px, rg, im = t["pixels"], t[f"{BLOCK}x{BLOCK} regions"], t["image"]
            lines.append(
                f"| {r['xylem_depth']} ({r['mitsuba_depth']}) | {r['res'][0]}×{r['res'][1]} | "
                f"{px['tests']} | {px['max_abs_z']:.2f} | {px['min_p']:.2g} ({px['level']:.2g}) | "
                f"{rg['tests']} | {rg['max_abs_z']:.2f} | {rg['min_p']:.2g} ({rg['level']:.2g}) | "
                f"{im['min_p']:.2g} | {'pass' if r['pass'] else '**FAIL**'} | "
                f"{r['batches']} × {r['spp']} | {r['xylem_s']:.1f} | {r['mitsuba_s']:.1f} |")
        lines += ["", "Pictures (xylem mean, Mitsuba mean, luminance difference ±10 % of the mean, "
                  "pixel z ±6, region z ±6; blue negative = xylem darker): "
                  + ", ".join(f"`{r['png']}`" for r in rows if r["case"] == name), ""]
        for r in (r for r in rows if r["case"] == name and not r["pass"]):
            for k, v in r["tests"].items():
                if not v["pass"]:
                    w = v["worst"]
                    lines.append(f"- depth {r['xylem_depth']}, {k}: worst at index {w['index']} "
                                 f"(row, column, channel), z {w['z']:.2f}, xylem mean "
                                 f"{w['mean_xylem']:.5g}, Mitsuba mean {w['mean_mitsuba']:.5g}")
        lines.append("")
    lines += ["## Negative controls", "",
              "The same test must reject a wrong image (on cornell_box at the first depth).", "",
              "| control | pixel min p | region min p | image min p | detected |",
              "| --- | --- | --- | --- | --- |"]
    for c in controls:
        t = c["tests"]
        lines.append(f"| {c['control']} | {t['pixels']['min_p']:.2g} | "
                     f"{t[f'{BLOCK}x{BLOCK} regions']['min_p']:.2g} | {t['image']['min_p']:.2g} | "
                     f"{'yes' if c['detected'] else '**no**'} |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m validation.crosscheck", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    m = ap.add_mutually_exclusive_group(required=True)
    m.add_argument("--small", action="store_true")
    m.add_argument("--full", action="store_true")
    m.add_argument("--timing", action="store_true")
    ap.add_argument("--xylem", default=os.path.join(ROOT, "target/release/xylem"),
                    help="the xylem binary (default target/release/xylem)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--variant", default=None,
                    help="Mitsuba variant (default scalar_rgb for --small, llvm_ad_rgb otherwise)")
    ap.add_argument("--work", default=None, help="scratch folder (default target/crosscheck/MODE)")
    ap.add_argument("--plots", default=None,
                    help="pictures (default validation/plots/crosscheck for --full)")
    ap.add_argument("--report", default=os.path.join(ROOT, "validation/CROSSCHECK.md"))
    ap.add_argument("--json", default=None, help="also write the results as JSON here")
    from . import timing
    timing.add_arguments(ap)
    args = ap.parse_args(argv)
    args.load = os.getloadavg()
    name = "small" if args.small else "full" if args.full else "timing"
    args.variant = args.variant or ("scalar_rgb" if args.small else "llvm_ad_rgb")
    args.work = args.work or os.path.join(ROOT, "target/crosscheck", name)
    args.plots = args.plots or (os.path.join(ROOT, "validation/plots/crosscheck") if args.full
                                else os.path.join(args.work, "plots"))
    if not args.timing and not os.path.exists(args.xylem):
        sys.exit(f"{args.xylem} not found: build it with `cargo build --release` or pass --xylem")
    mi = render.mitsuba(args.variant, args.threads)
    import drjit as dr
    args.mitsuba_version, args.drjit_version = mi.__version__, dr.__version__
    if args.timing:
        out = timing.run(mi, args)
        print(json.dumps(out) if args.json == "-" else timing.table(out))
        return 0
    t0 = time.perf_counter()
    rows, controls = run(SMALL if args.small else FULL, args, mi)
    wall = time.perf_counter() - t0
    ok = all(r["pass"] for r in rows) and all(c["detected"] for c in controls)
    if args.full:
        with open(args.report, "w") as f:
            f.write(markdown(rows, controls, FULL, args, wall))
        print(f"wrote {os.path.relpath(args.report, ROOT)}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"rows": rows, "controls": controls, "seconds": wall}, f, indent=1)
    print(f"{'all cases agree and every negative control is detected' if ok else 'FAILED'} "
          f"({wall:.1f} s)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())

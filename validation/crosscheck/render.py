"""Rendering a case in batches: xylem through its command line (EXR read back), Mitsuba 3 through
`mi.load_dict` + `mi.render`."""

import os
import subprocess
import time

import numpy as np

from . import scenes


def mitsuba(variant="scalar_rgb", threads=None):
    """Mitsuba with `variant` set (and Dr.Jit's thread pool at `threads` if given)."""
    import drjit as dr
    import mitsuba as mi

    mi.set_variant(variant)
    if threads:
        dr.set_thread_count(threads)
    return mi


def read_exr_rgb(mi, path):
    """The beauty R, G, B channels of a xylem EXR (H, W, 3), float64."""
    bmp = mi.Bitmap(path)
    names = [bmp.struct_()[i].name for i in range(bmp.channel_count())]
    a = np.array(bmp, dtype=np.float64)
    return a[..., [names.index(c) for c in ("R", "G", "B")]]


def xylem_batches(xylem, case, folder, max_depth, spp, seeds, res, threads, mi):
    """One xylem render per seed, (n, H, W, 3), and the wall time of each run (whole process)."""
    meshes = scenes.write_meshes(case, os.path.join(folder, "meshes"))
    text = scenes.xylem_toml(case, meshes, max_depth, spp, seeds[0], res)
    name = f"{case['name']}_d{max_depth}"
    path = os.path.join(folder, f"{name}.toml")
    with open(path, "w") as f:
        f.write(text)
    out, seconds = [], []
    w, h = res
    for s in seeds:
        # Sampled as Mitsuba is, spp in every pixel, so both sides' batch variances are those
        # of equal sampling. (Adaptive sampling, xylem's default, gives a light's edge pixels
        # many more samples; on the full plane_rect one found a 0.3 % sliver off the light,
        # 1.9941 ± 0.0024 over 16 batches, that Mitsuba's 512 samples there never hit — exactly
        # 2.0, variance 0 — and Welch's z, trusting that 0, read 9.5. Adaptive sampling is
        # checked against uniform in crates/xylem/tests/adaptive_sampling.rs.)
        cmd = [xylem, "render", path, "--out", folder, "--spp", str(spp), "--seed", str(s),
               "--threads", str(threads), "--res", f"{w}x{h}", "--sampling", "uniform"]
        t0 = time.perf_counter()
        run = subprocess.run(cmd, capture_output=True, text=True)
        seconds.append(time.perf_counter() - t0)
        if run.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)} failed:\n{run.stdout}\n{run.stderr}")
        out.append(read_exr_rgb(mi, os.path.join(folder, f"{name}.exr")))
    return np.stack(out), seconds


def mitsuba_batches(mi, case, folder, max_depth, spp, seeds, res):
    """One Mitsuba render per seed of the case's scene, (n, H, W, 3), and each render's time."""
    meshes = scenes.write_meshes(case, os.path.join(folder, "meshes"))
    scene = mi.load_dict(scenes.mitsuba_dict(mi, case, meshes, max_depth, spp, seeds[0], res))
    out, seconds = [], []
    for s in seeds:
        t0 = time.perf_counter()
        img = np.array(mi.render(scene, seed=s, spp=spp), dtype=np.float64)
        seconds.append(time.perf_counter() - t0)
        out.append(img[..., :3])
    return np.stack(out), seconds

"""Error at equal CPU time of two xylem binaries on built-in scenes (notes/render.md, "Stratified
pixel samples"): each scene at half its size and its own spp, 3 seeds per binary, relative MSE
against a reference of the NEW binary at 16x spp made of two halves (their difference estimates
the reference's own noise, which is taken off), times the median CPU seconds of the render.

    python tools/equal_time.py OLD_BINARY NEW_BINARY SCENE... > rows.json

Needs numpy and Mitsuba 3 (to read the EXRs), e.g. target/python-venv/bin/python.
"""
import json, os, re, subprocess, sys, tempfile
import numpy as np, mitsuba as mi
mi.set_variant("scalar_rgb")
def load(p):
    b = mi.Bitmap(p)
    for name, layer in b.split():
        if name in ("", "<root>", "beauty") or name.lower().startswith("beauty"):
            return np.array(layer.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False)).astype(np.float64)
def render(binary, scene, w, h, spp, seed, out):
    t0 = os.times()
    r = subprocess.run([binary, "render", f"scenes/{scene}.toml", "--res", f"{w}x{h}", "--spp", str(spp), "--seed", str(seed), "--threads", "2", "--quiet", "--out", out], capture_output=True, text=True)
    t1 = os.times()
    if r.returncode: print(r.stderr); raise SystemExit(1)
    cpu = (t1.children_user - t0.children_user) + (t1.children_system - t0.children_system)
    return load(f"{out}/{scene}.exr"), cpu
old_bin, new_bin, scenes = sys.argv[1], sys.argv[2], sys.argv[3:]
tmp = tempfile.mkdtemp(prefix="equal_time_")
rows = {}
for s in scenes:
    txt = open(f"scenes/{s}.toml").read()
    w = int(re.search(r"^width = (\d+)", txt, re.M).group(1)) // 2
    h = int(re.search(r"^height = (\d+)", txt, re.M).group(1)) // 2
    spp = int(re.search(r"^spp = (\d+)", txt, re.M).group(1))
    ref_a, _ = render(new_bin, s, w, h, 8 * spp, 101, f"{tmp}/ra")
    ref_b, _ = render(new_bin, s, w, h, 8 * spp, 202, f"{tmp}/rb")
    ref = 0.5 * (ref_a + ref_b)
    ref_noise = np.mean((ref_a - ref_b) ** 2) / 4.0
    norm = np.mean(ref ** 2)
    res = {}
    for name, binary in [("old", old_bin), ("new", new_bin)]:
        mses, cpus = [], []
        for seed in (11, 12, 13):
            img, cpu = render(binary, s, w, h, spp, seed, f"{tmp}/{name}")
            mses.append((np.mean((img - ref) ** 2) - ref_noise) / norm)
            cpus.append(cpu)
        res[name] = (float(np.mean(mses)), float(np.median(cpus)))
    ratio = res["new"][0] * res["new"][1] / (res["old"][0] * res["old"][1])
    rows[s] = dict(w=w, h=h, spp=spp, old_mse=res["old"][0], old_cpu=res["old"][1], new_mse=res["new"][0], new_cpu=res["new"][1], mse_ratio=res["new"][0] / res["old"][0], equal_time_ratio=ratio)
    print(s, json.dumps(rows[s]), file=sys.stderr, flush=True)
json.dump(rows, sys.stdout, indent=1)

"""Renders the built-in teapot and turned bowl in Mitsuba 3 through ``xylem_wood_baked``: each is
baked with ``xylem bake PRESET --mesh NAME`` (the OBJ and the maps) and loaded with Mitsuba's
OBJ loader, under a key light and a dim sky on a grey table, mip-mapped lookups on
(``set_pixel_angle``). Writes ``OUT/mitsuba_teapot.png`` and ``OUT/mitsuba_bowl.png`` (the
README's pictures: ``--out notes/images``).

    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \\
    PYTHONPATH=target/python-test/site XYLEM_BIN=target/release/xylem \\
        target/python-venv/bin/python python/examples/render_baked_meshes.py --out notes/images

The cameras are scenes/teapot.toml's and scenes/turned_bowl.toml's (mm), the presets the
README's bake commands use (walnut, red oak), the finish rough 0.15 with the pore bump.
"""

import argparse
import os
import pathlib
import subprocess
import tempfile
import time

import mitsuba as mi

mi.set_variant("llvm_ad_rgb")

import xylem.mitsuba  # noqa: E402
import xylem.mitsuba_baked  # noqa: E402

xylem.mitsuba.register()

# name: (preset, camera eye, target, key light direction (towards the light), two-sided: the
# teapot's patches are not all oriented alike, and Mitsuba's BSDFs are one-sided; the plugin's
# `two_sided` shades the back of a face as xylem's renderer does)
SUBJECTS = {
    "teapot": ("walnut", [0.0, -330.0, 190.0], [10.0, 0.0, 45.0], [-0.55, -0.45, 0.7], True),
    "bowl": ("red_oak", [0.0, -200.0, 330.0], [0.0, 0.0, 35.0], [0.45, -0.25, 0.86], False),
}


def bake(exe, preset, mesh, res, out):
    subprocess.run([exe, "bake", preset, "--mesh", mesh, "--res", str(res), "--out", str(out)],
                   check=True, capture_output=True)
    return out


def scene(obj, maps, eye, target, light, two_sided, width, height, spp):
    T = mi.ScalarTransform4f
    wood = {"type": "xylem_wood_baked", "maps": str(maps), "eta": 1.5, "roughness": 0.15,
            "two_sided": two_sided}
    return mi.load_dict({
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 5},
        "sensor": {"type": "perspective", "fov": 36.0, "fov_axis": "y",
                   "to_world": T().look_at(origin=eye, target=target, up=[0, 0, 1]),
                   "film": {"type": "hdrfilm", "width": width, "height": height},
                   "sampler": {"type": "independent", "sample_count": spp}},
        "key": {"type": "directional", "direction": [-x for x in light],
                "irradiance": {"type": "rgb", "value": [2.2, 2.1, 2.0]}},
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": [0.12, 0.13, 0.15]}},
        "table": {"type": "rectangle", "to_world": T().scale([1000.0, 1000.0, 1.0]),
                  "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb",
                                                              "value": [0.15, 0.15, 0.16]}}},
        "mesh": {"type": "obj", "filename": str(obj), "bsdf": wood},
    })


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="out")
    ap.add_argument("--res", type=int, nargs=2, default=(420, 320))
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--bake-res", type=int, default=1024)
    args = ap.parse_args()
    root = pathlib.Path(__file__).resolve().parents[2]
    exe = os.environ.get("XYLEM_BIN") or str(root / "target/release/xylem")
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    work = pathlib.Path(tempfile.mkdtemp())
    for name, (preset, eye, target, light, two_sided) in SUBJECTS.items():
        maps = bake(exe, preset, name, args.bake_res, work / name)
        sc = scene(maps / f"{preset}.obj", maps, eye, target, light, two_sided, *args.res,
                   args.spp)
        xylem.mitsuba_baked.set_pixel_angle(sc)
        start = time.perf_counter()
        img = mi.render(sc, seed=1)
        bitmap = mi.Bitmap(img).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, True)
        path = out / f"mitsuba_{name}.png"
        bitmap.write(str(path))
        print(f"{path}: {preset}, {args.res[0]}x{args.res[1]}, {args.spp} spp, "
              f"{time.perf_counter() - start:.1f} s")


if __name__ == "__main__":
    main()

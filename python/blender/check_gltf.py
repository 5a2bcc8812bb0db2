"""Blender 5 (PyPI `bpy`) against xylem: crates/xylem-cli/tests/blender.rs runs this with the
pinned python/requirements-blender.txt (notes/gltf.md, "Blender").

    python check_gltf.py --bake DIR --scene grazing_board.toml --xylem-png XYLEM.png --out OUT

1. Imports DIR/*.glb with Blender's glTF importer and reads how the top face's Principled BSDF
   gets its Anisotropic, Anisotropic Rotation and Tangent inputs.
2. Renders it with Cycles (CPU) under the scene's camera and light (mm → m; Blender's y is
   glTF's −z, and the scene is symmetric about y = 0) and measures the highlight's orientation
   as xylem's render of the same scene gives it: the principal axis of the second moments of
   the bright region (linear luminance at least half its 99.5th percentile), angle in degrees
   from the image's x axis (counter-clockwise, in (−90°, 90°]), and its elongation √(λ₁/λ₂).
3. The same for two negative controls: the .glb with KHR_materials_anisotropy stripped, and
   the imported board turned 90° about the vertical (fibres across the view).
4. The add-on (xylem_import.py) builds its node material from the folder's maps; its node tree
   is read back and it is rendered and measured too.

Writes OUT/report.json and the renders (PNG); exits 0 whatever it measured (the Rust test
judges), non-zero only when something could not be run.
"""

import argparse
import json
import math
import os
import struct
import sys
import time
import tomllib

import bpy
import numpy as np
from mathutils import Vector

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import xylem_import  # noqa: E402

MM = 1e-3


def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def setup_scene(scene_toml, samples, light_w):
    """Camera, light, black world and Cycles settings from xylem's scene file."""
    with open(scene_toml, "rb") as f:
        sc = tomllib.load(f)
    scene = bpy.context.scene
    cam_t = sc["camera"]

    def to_blender(p):
        return Vector((p[0] * MM, -p[1] * MM, p[2] * MM))

    cam = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    scene.collection.objects.link(cam)
    eye, target = to_blender(cam_t["eye"]), to_blender(cam_t["target"])
    cam.location = eye
    cam.rotation_euler = (target - eye).to_track_quat("-Z", "Y").to_euler()
    cam.data.sensor_fit = "VERTICAL"
    cam.data.angle_y = math.radians(cam_t["fov_deg"])
    cam.data.clip_start = 1e-3
    scene.camera = cam

    (lt,) = sc["lights"]
    light = bpy.data.lights.new("key", type="POINT")
    light.energy = light_w
    light.shadow_soft_size = lt["radius"] * MM
    lo = bpy.data.objects.new("key", light)
    lo.location = to_blender(lt["center"])
    scene.collection.objects.link(lo)

    world = bpy.data.worlds.new("black")
    scene.world = world
    world.use_nodes = True
    bg = world.node_tree.nodes.get("Background")
    if bg is not None:
        bg.inputs["Color"].default_value = (0, 0, 0, 1)
        bg.inputs["Strength"].default_value = 0.0

    r = scene.render
    r.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.seed = 1
    scene.cycles.max_bounces = 1
    r.resolution_x = sc["render"]["width"]
    r.resolution_y = sc["render"]["height"]
    r.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    r.image_settings.file_format = "PNG"
    r.image_settings.color_mode = "RGB"


def render(path):
    bpy.context.scene.render.filepath = path
    t = time.time()
    bpy.ops.render.render(write_still=True)
    return time.time() - t


def load_linear(path):
    """A PNG's linear luminance (sRGB decoded), rows from the bottom as Blender stores them."""
    img = bpy.data.images.load(path)
    w, h = img.size
    px = np.array(img.pixels[:], dtype=np.float64).reshape(h, w, img.channels)[..., :3]
    bpy.data.images.remove(img)
    lin = np.where(px <= 0.04045, px / 12.92, ((px + 0.055) / 1.055) ** 2.4)
    return lin @ np.array([0.2126, 0.7152, 0.0722])


def orientation(y):
    """The bright region's principal axis (degrees from +x, counter-clockwise), its elongation
    and size: pixels of luminance ≥ half the 99.5th percentile, second moments unweighted."""
    peak = float(np.percentile(y, 99.5))
    if peak <= 0:
        return {"angle_deg": None, "elongation": 0.0, "pixels": 0, "threshold": peak}
    rows, cols = np.nonzero(y >= 0.5 * peak)
    xs, ys = cols.astype(np.float64), rows.astype(np.float64)
    cxx, cyy = np.var(xs), np.var(ys)
    cxy = np.mean((xs - xs.mean()) * (ys - ys.mean()))
    angle = 0.5 * math.degrees(math.atan2(2 * cxy, cxx - cyy))
    tr, det = cxx + cyy, cxx * cyy - cxy * cxy
    disc = math.sqrt(max(tr * tr / 4 - det, 0.0))
    l1, l2 = tr / 2 + disc, max(tr / 2 - disc, 1e-9)
    return {
        "angle_deg": round(angle, 2),
        "elongation": round(math.sqrt(l1 / l2), 3),
        "pixels": int(xs.size),
        "centroid": [round(float(xs.mean()), 1), round(float(ys.mean()), 1)],
        "threshold": round(0.5 * peak, 5),
    }


def montage(paths, out, scale=2):
    """The PNGs side by side (nearest-neighbour ×scale, 4 px white gaps), for notes/gltf.md."""
    tiles = []
    for p in paths:
        img = bpy.data.images.load(p)
        w, h = img.size
        a = np.array(img.pixels[:]).reshape(h, w, img.channels)[..., :3]
        bpy.data.images.remove(img)
        a = np.repeat(np.repeat(a, scale, 0), scale, 1)
        tiles += [a, np.ones((a.shape[0], 4, 3))]
    m = np.concatenate(tiles[:-1], 1)
    h, w, _ = m.shape
    img = bpy.data.images.new("montage", w, h)
    img.pixels[:] = np.concatenate([m, np.ones((h, w, 1))], 2).ravel()
    img.filepath_raw = out
    img.file_format = "PNG"
    img.save()


def principled(mat):
    for n in mat.node_tree.nodes:
        if n.bl_idname == "ShaderNodeBsdfPrincipled":
            return n
    return None


def socket_state(node, name):
    s = node.inputs[name]
    if s.is_linked:
        link = s.links[0]
        return {"linked": True, "from": f"{link.from_node.bl_idname}.{link.from_socket.name}"}
    v = s.default_value
    return {"linked": False, "value": list(v) if hasattr(v, "__len__") else float(v)}


def material_report(mat):
    p = principled(mat)
    if p is None:
        return {"name": mat.name, "principled": False}
    names = ["Base Color", "Roughness", "Anisotropic", "Anisotropic Rotation", "Tangent",
             "Normal", "Coat Weight", "Coat IOR"]
    return {"name": mat.name, "principled": True,
            "inputs": {k: socket_state(p, k) for k in names if k in p.inputs},
            "images": sorted(n.image.name for n in mat.node_tree.nodes
                             if n.bl_idname == "ShaderNodeTexImage" and n.image)}


def strip_anisotropy(src, dst):
    """The .glb with KHR_materials_anisotropy removed from the JSON chunk (binary unchanged)."""
    with open(src, "rb") as f:
        b = f.read()
    (jlen,) = struct.unpack_from("<I", b, 12)
    doc = json.loads(b[20:20 + jlen])
    for m in doc.get("materials", []):
        m.get("extensions", {}).pop("KHR_materials_anisotropy", None)
        if not m.get("extensions", True):
            del m["extensions"]
    for key in ("extensionsUsed", "extensionsRequired"):
        if key in doc:
            doc[key] = [e for e in doc[key] if e != "KHR_materials_anisotropy"]
            if not doc[key]:
                del doc[key]
    j = json.dumps(doc, separators=(",", ":")).encode()
    j += b" " * (-len(j) % 4)
    rest = b[20 + jlen:]
    out = b"glTF" + struct.pack("<II", 2, 12 + 8 + len(j) + len(rest))
    out += struct.pack("<I", len(j)) + b"JSON" + j + rest
    with open(dst, "wb") as f:
        f.write(out)


def run_case(name, args, build):
    """Reset, build the board (`build` returns the material to report), render, measure."""
    reset()
    t0 = time.time()
    mat = build()
    setup_scene(args.scene, args.samples, args.light_w)
    png = os.path.join(args.out, f"{name}.png")
    took = render(png)
    res = {"material": material_report(mat) if mat else None,
           "render_s": round(took, 2), "case_s": round(time.time() - t0, 2), "png": png}
    res.update(orientation(load_linear(png)))
    print(f"{name}: {res['angle_deg']}°, elongation {res['elongation']}, "
          f"{res['pixels']} px, render {took:.1f} s", flush=True)
    return res


def imported_material():
    for m in bpy.data.materials:
        if "baked face" in m.name:
            return m
    raise SystemExit("the imported .glb has no material named '… (baked face)'")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bake", required=True)
    ap.add_argument("--scene", required=True)
    ap.add_argument("--xylem-png", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--samples", type=int, default=16)
    ap.add_argument("--light-w", type=float, default=1.0)
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    (glb,) = [os.path.join(args.bake, f) for f in os.listdir(args.bake) if f.endswith(".glb")]
    stripped = os.path.join(args.out, "stripped.glb")
    strip_anisotropy(glb, stripped)

    def gltf(path, turn=False):
        def build():
            bpy.ops.import_scene.gltf(filepath=path)
            if turn:
                for o in bpy.data.objects:
                    if o.type == "MESH":
                        o.rotation_mode = "XYZ"
                        o.rotation_euler.z += math.pi / 2
            return imported_material()
        return build

    started = time.time()
    report = {"blender": bpy.app.version_string,
              "xylem": orientation(load_linear(args.xylem_png)),
              "cases": {}}
    cases = report["cases"]
    cases["gltf"] = run_case("blender_gltf", args, gltf(glb))
    cases["stripped"] = run_case("blender_stripped", args, gltf(stripped))
    cases["turned"] = run_case("blender_turned", args, gltf(glb, turn=True))
    cases["addon"] = run_case(
        "blender_addon", args,
        lambda: xylem_import.import_bake(args.bake).active_material)
    montage([args.xylem_png] + [cases[k]["png"] for k in ("gltf", "addon", "stripped", "turned")],
            os.path.join(args.out, "side_by_side.png"))
    report["total_s"] = round(time.time() - started, 2)
    with open(os.path.join(args.out, "report.json"), "w", encoding="utf-8") as f:
        json.dump(report, f, indent=1)
    print(f"xylem: {report['xylem']['angle_deg']}°, elongation {report['xylem']['elongation']}")


if __name__ == "__main__":
    main()

"""The cross-check cases: one description per case, written out as a xylem scene (TOML) and as a
Mitsuba 3 scene dictionary with the same geometry, camera, lights and materials.

Identical geometry: every surface is a triangle mesh built here once, in world millimetres, and
written as one OBJ file without normals; xylem loads it as `shape = "mesh"` with
`smooth = false`, Mitsuba as `obj` with `face_normals = True`, so both shade with the same flat
face normals (spheres are faceted, 48 × 24 UV spheres, in both). Transforms follow xylem's
convention (scenes/README.md): scale, then rotate about x, y, z in that order, then translate.

Lights: xylem's lights are not geometry (they block nothing), Mitsuba's rectangle emitter is a
surface. So each rect light gets a black box (albedo 0) just behind its emitting face in both
scenes, and the Mitsuba emitter's own BSDF is black: a ray reaching the light from the front
ends there in both (xylem adds the emission and stops), a ray reaching it from behind meets a
black surface in both.

Depth: xylem's `max_depth` k (bounces; notes in validation/CROSSCHECK.md) is Mitsuba's `path`
`max_depth` k + 1 (path vertices counting the camera's first hit): xylem's depth 1 is direct
lighting, Mitsuba's depth 2.
"""

import math
import os

import numpy as np

# The classic Cornell box (the numbers of scenes/cornell_box.toml).
WHITE = [0.725, 0.71, 0.68]
RED = [0.63, 0.065, 0.05]
GREEN = [0.14, 0.45, 0.091]
CORNELL_LIGHT = {
    "type": "rect",
    "corner": [-65.0, 222.5, 549.0],
    "edge_u": [0.0, 105.0, 0.0],
    "edge_v": [130.0, 0.0, 0.0],
    "radiance": 1.0,
    "color": [18.387, 13.9873, 6.75357],
}
CORNELL_CAMERA = {"eye": [0.0, -1050.0, 275.0], "target": [0.0, 0.0, 275.0], "up": [0.0, 0.0, 1.0],
                  "fov_deg": 37.0}


def rotation(deg):
    """xylem's `rotate_deg`: about x, then y, then z (R = Rz Ry Rx)."""
    ax, ay, az = (math.radians(d) for d in deg)
    rx = np.array([[1, 0, 0], [0, math.cos(ax), -math.sin(ax)], [0, math.sin(ax), math.cos(ax)]])
    ry = np.array([[math.cos(ay), 0, math.sin(ay)], [0, 1, 0], [-math.sin(ay), 0, math.cos(ay)]])
    rz = np.array([[math.cos(az), -math.sin(az), 0], [math.sin(az), math.cos(az), 0], [0, 0, 1]])
    return rz @ ry @ rx


def place(v, rotate=(0, 0, 0), translate=(0, 0, 0), scale=1.0):
    return (np.asarray(v, float) * scale) @ rotation(rotate).T + np.asarray(translate, float)


def quad(size, rotate=(0, 0, 0), translate=(0, 0, 0)):
    """xylem's `quad`: size [x, y] in the xy plane, centred, facing +z (counter-clockwise)."""
    hx, hy = size[0] / 2, size[1] / 2
    v = [[-hx, -hy, 0], [hx, -hy, 0], [hx, hy, 0], [-hx, hy, 0]]
    return place(v, rotate, translate), np.array([[0, 1, 2], [0, 2, 3]])


def box(size, rotate=(0, 0, 0), translate=(0, 0, 0)):
    """xylem's `box`: size [x, y, z], centred, faces wound outwards."""
    h = np.asarray(size, float) / 2
    v = np.array([[sx, sy, sz] for sz in (-1, 1) for sy in (-1, 1) for sx in (-1, 1)]) * h
    return outward(place(v, rotate, translate))


BOX_FACES = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]


def outward(v):
    """The 12 triangles of a box whose vertex k has bit 0, 1, 2 of k along its three edges,
    each wound so its normal points away from the centre."""
    centre = v.mean(axis=0)
    tri = []
    for a, b, c, d in BOX_FACES:
        for t in ([a, b, c], [a, c, d]):
            p, q, r = v[t]
            if np.dot(np.cross(q - p, r - p), p - centre) < 0:
                t = [t[0], t[2], t[1]]
            tri.append(t)
    return v, np.array(tri)


def sphere(radius, center, segments=48, rings=24):
    """A UV sphere: `rings` bands in θ, `segments` in φ, wound outwards (flat-shaded in both)."""
    v = [[0, 0, radius]]
    for i in range(1, rings):
        th = math.pi * i / rings
        for j in range(segments):
            ph = 2 * math.pi * j / segments
            v.append([radius * math.sin(th) * math.cos(ph), radius * math.sin(th) * math.sin(ph),
                      radius * math.cos(th)])
    v.append([0, 0, -radius])
    bottom = len(v) - 1
    ring = lambda i, j: 1 + (i - 1) * segments + j % segments
    tri = [[0, ring(1, j), ring(1, j + 1)] for j in range(segments)]
    for i in range(1, rings - 1):
        for j in range(segments):
            a, b, c, d = ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), ring(i, j + 1)
            tri += [[a, b, c], [a, c, d]]
    tri += [[ring(rings - 1, j), bottom, ring(rings - 1, j + 1)] for j in range(segments)]
    return np.asarray(v, float) + np.asarray(center, float), np.array(tri)


def housing(light, depth_mm=0.9, gap_mm=0.05):
    """A black box just behind a rect light's emitting face (see the module doc)."""
    c, u, v = (np.asarray(light[k], float) for k in ("corner", "edge_u", "edge_v"))
    n = np.cross(u, v)
    n /= np.linalg.norm(n)
    back = -n
    corners = [c + a * u + b * v + back * d for d in (gap_mm, gap_mm + depth_mm)
               for b in (0, 1) for a in (0, 1)]
    return outward(np.array(corners))


def cornell_walls():
    return [
        ("floor", quad([550, 550], translate=[0, 275, 0]), "white"),
        ("ceiling", quad([550, 550], [180, 0, 0], [0, 275, 550]), "white"),
        ("back", quad([550, 550], [90, 0, 0], [0, 550, 275]), "white"),
        ("left", quad([550, 550], [0, 90, 0], [-275, 275, 275]), "red"),
        ("right", quad([550, 550], [0, -90, 0], [275, 275, 275]), "green"),
        ("light_housing", housing(CORNELL_LIGHT), "black"),
    ]


CORNELL_MATERIALS = {
    "white": {"type": "lambertian", "albedo": WHITE},
    "red": {"type": "lambertian", "albedo": RED},
    "green": {"type": "lambertian", "albedo": GREEN},
    "black": {"type": "lambertian", "albedo": [0.0, 0.0, 0.0]},
}


def cornell_lambertian():
    """(a) The all-Lambertian Cornell box of scenes/cornell_box.toml."""
    return {
        "name": "cornell_box", "res": (256, 256), "camera": CORNELL_CAMERA,
        "materials": CORNELL_MATERIALS, "lights": [CORNELL_LIGHT],
        "shapes": cornell_walls() + [
            ("short_box", box([165, 165, 165], [0, 0, -17], [90, 180, 82.5]), "white"),
            ("tall_box", box([165, 165, 330], [0, 0, 17], [-90, 370, 165]), "white"),
        ],
    }


def cornell_spheres():
    """(b) The same box with a mirror sphere and a glass sphere (eta 1.5) for the boxes."""
    materials = dict(CORNELL_MATERIALS)
    materials["mirror"] = {"type": "mirror", "reflectance": [0.9, 0.9, 0.9]}
    materials["glass"] = {"type": "glass", "eta": 1.5}
    return {
        "name": "cornell_spheres", "res": (256, 256), "camera": CORNELL_CAMERA,
        "materials": materials, "lights": [CORNELL_LIGHT],
        "shapes": cornell_walls() + [
            ("mirror_sphere", sphere(100.0, [-120, 360, 100]), "mirror"),
            ("glass_sphere", sphere(100.0, [110, 180, 100]), "glass"),
        ],
    }


def wood_board():
    """(f) sweep_board's finished board under a rect light, path traced: the mahogany board
    (260 × 110 × 18 mm on a dark table; the tree axis along x, the pith 120 mm from the board's
    centre line at the top face's height, so the top face is quartersawn, as sweep_board's) with
    a rough finish (roughness 0.25) under a 120 mm square light above and to the side. Mitsuba
    renders it through the `xylem_wood` plugin (the same wood and BSDF, point-sampled: xylem's
    footprint filter is off, and the plugin has no pore bump, so neither has one). For the speed
    benchmark (`xylem bench render --case wood_board`), not the cross-check's cases."""
    # edge_u × edge_v points down: the light faces the board.
    light = {"type": "rect", "corner": [90.0, -60.0, 400.0], "edge_u": [0.0, 120.0, 0.0],
             "edge_v": [120.0, 0.0, 0.0], "radiance": 50.0}
    return {
        "name": "wood_board", "res": (256, 192),
        "camera": {"eye": [0.0, -250.0, 190.0], "target": [0.0, 0.0, 5.0],
                   "up": [0.0, 0.0, 1.0], "fov_deg": 38.0},
        "render": {"footprint_filter": False},
        "materials": {
            "table": {"type": "lambertian", "albedo": [0.03, 0.03, 0.035]},
            "board": {"type": "wood", "preset": "african_mahogany", "seed": 7, "eta": 1.5,
                      "roughness": 0.25, "bump": 0.0},
            "black": {"type": "lambertian", "albedo": [0.0, 0.0, 0.0]},
        },
        "lights": [light],
        "shapes": [
            ("table", box([900, 900, 20], translate=[0, 0, -10]), "table"),
            ("board", box([260, 110, 18], translate=[0, 0, 9]), "board"),
            ("light_housing", housing(light), "black"),
        ],
        "trees": {"board": {"origin": [0.0, 120.0, 18.0], "axis": [1.0, 0.0, 0.0],
                            "rotation_deg": 0.0}},
    }


PLANE_CAMERA = {"eye": [0.0, -420.0, 260.0], "target": [0.0, 0.0, 0.0], "up": [0.0, 0.0, 1.0],
                "fov_deg": 50.0}


def plane_point():
    """(c) A plane under a point light (off-centre, so the image has a gradient and a peak)."""
    return {
        "name": "plane_point", "res": (256, 192), "camera": PLANE_CAMERA,
        "materials": {"grey": {"type": "lambertian", "albedo": [0.8, 0.6, 0.4]}},
        "lights": [{"type": "point", "position": [60.0, 40.0, 150.0], "intensity": 20000.0,
                    "color": [1.0, 0.9, 0.8]}],
        "shapes": [("plane", quad([600, 600]), "grey")],
    }


RECT_LIGHT = {
    "type": "rect",
    # A 120 × 80 mm light 120–171 mm up, its normal (u × v) tilted 40° from straight down
    # towards the camera, so the camera sees its emitting face.
    "corner": [-60.0, 30.0, 120.0],
    "edge_u": [120.0, 0.0, 0.0],
    "edge_v": [0.0, -80.0 * math.cos(math.radians(40)), 80.0 * math.sin(math.radians(40))],
    "radiance": 1.0,
    "color": [2.0, 2.0, 1.6],
}


def plane_rect():
    """(d) A plane under a rect light, the light's emitting face in view."""
    return {
        "name": "plane_rect", "res": (256, 192), "camera": PLANE_CAMERA,
        "materials": {"grey": {"type": "lambertian", "albedo": [0.5, 0.7, 0.8]},
                      "black": {"type": "lambertian", "albedo": [0.0, 0.0, 0.0]}},
        "lights": [RECT_LIGHT],
        "shapes": [("plane", quad([600, 600]), "grey"),
                   ("light_housing", housing(RECT_LIGHT), "black")],
    }


CASES = {c()["name"]: c for c in (cornell_lambertian, cornell_spheres, plane_point, plane_rect)}


def write_obj(path, mesh):
    """The mesh as an OBJ file, written whole under a temporary name first (a concurrent run
    writing the same file never leaves a reader half of it)."""
    v, f = mesh
    tmp = f"{path}.{os.getpid()}.partial"
    with open(tmp, "w") as out:
        out.write("# written by validation/crosscheck/scenes.py\n")
        for p in v:
            out.write(f"v {p[0]:.9g} {p[1]:.9g} {p[2]:.9g}\n")
        for t in f:
            out.write(f"f {t[0] + 1} {t[1] + 1} {t[2] + 1}\n")
    os.replace(tmp, path)


def write_meshes(case, folder):
    """The case's meshes as OBJ files in `folder`; {shape name: path}."""
    os.makedirs(folder, exist_ok=True)
    paths = {}
    for name, mesh, _ in case["shapes"]:
        paths[name] = os.path.join(folder, f"{case['name']}_{name}.obj")
        write_obj(paths[name], mesh)
    return paths


def toml_value(x):
    if isinstance(x, bool):
        return "true" if x else "false"
    if isinstance(x, int):
        return str(x)
    if isinstance(x, str):
        return f'"{x}"'
    if isinstance(x, (list, tuple, np.ndarray)):
        return "[" + ", ".join(toml_value(v) for v in x) + "]"
    return repr(float(x))


def xylem_toml(case, meshes, max_depth, spp, seed, res=None):
    """The case as a xylem scene file (text); `max_depth` in xylem's counting."""
    w, h = res or case["res"]
    cam = case["camera"]
    lines = ["[render]", f"width = {w}", f"height = {h}", f"spp = {spp}", 'integrator = "path"',
             f"max_depth = {max_depth}", f"seed = {seed}", 'filter = "box"']
    lines += [f"{k} = {toml_value(v)}" for k, v in case.get("render", {}).items()]
    lines += ["", "[camera]"]
    lines += [f"{k} = {toml_value(cam[k])}" for k in ("eye", "target", "up", "fov_deg")]
    for light in case["lights"]:
        lines += ["", "[[lights]]"] + [f"{k} = {toml_value(v)}" for k, v in light.items()]
    for name, m in case["materials"].items():
        lines += ["", f"[materials.{name}]"] + [f"{k} = {toml_value(v)}" for k, v in m.items()]
    for name, _, material in case["shapes"]:
        lines += ["", "[[objects]]", f'name = "{name}"', 'shape = "mesh"',
                  f"file = {toml_value(os.path.abspath(meshes[name]))}", "smooth = false",
                  f'material = "{material}"']
        tree = case.get("trees", {}).get(name)
        if tree:
            fields = ", ".join(f"{k} = {toml_value(v)}" for k, v in tree.items())
            lines.append(f'tree = {{ {fields}, space = "world" }}')
    return "\n".join(lines) + "\n"


def rgb(v):
    return {"type": "rgb", "value": [float(x) for x in v]}


def mitsuba_bsdf(m, tree=None):
    """xylem's material as Mitsuba's: opaque ones two-sided, as xylem shades them; wood as the
    `xylem_wood` plugin (scene units mm) with the object's `tree` placement (world space)."""
    if m["type"] == "wood":
        tree = tree or {}
        vec = lambda v: ", ".join(f"{float(x):g}" for x in v)
        return {"type": "xylem_wood", "preset": m["preset"], "seed": int(m["seed"]),
                "eta": float(m["eta"]), "roughness": float(m["roughness"]), "units": "mm",
                "origin": vec(tree.get("origin", [0, 0, 0])),
                "axis": vec(tree.get("axis", [0, 0, 1])),
                "rotation_deg": float(tree.get("rotation_deg", 0.0))}
    if m["type"] == "lambertian":
        return {"type": "twosided", "b": {"type": "diffuse", "reflectance": rgb(m["albedo"])}}
    if m["type"] == "mirror":
        # Mitsuba's `conductor` with material "none" reflects everything (Fresnel 1) times
        # specular_reflectance: xylem's mirror.
        return {"type": "twosided", "b": {"type": "conductor", "material": "none",
                                          "specular_reflectance": rgb(m["reflectance"])}}
    if m["type"] == "glass":
        return {"type": "dielectric", "int_ior": float(m["eta"]), "ext_ior": 1.0}
    raise ValueError(f"no Mitsuba equivalent for material type {m['type']!r}")


def mitsuba_dict(mi, case, meshes, max_depth, spp, seed, res=None, rr_depth=5,
                 sampler="independent"):
    """The case as a Mitsuba 3 scene dictionary; `max_depth` in xylem's counting (+1 here),
    `sampler` the name of Mitsuba's sampler plugin."""
    w, h = res or case["res"]
    cam = case["camera"]
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": max_depth + 1, "rr_depth": rr_depth},
        "sensor": {
            "type": "perspective", "fov": float(cam["fov_deg"]), "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(origin=cam["eye"], target=cam["target"],
                                                       up=cam["up"]),
            "film": {"type": "hdrfilm", "width": w, "height": h, "pixel_format": "rgb",
                     "component_format": "float32", "rfilter": {"type": "box"}},
            "sampler": {"type": sampler, "sample_count": spp, "seed": seed},
        },
    }
    for i, light in enumerate(case["lights"]):
        colour = np.asarray(light.get("color", [1, 1, 1]), float)
        if light["type"] == "point":
            scene[f"light{i}"] = {"type": "point", "position": light["position"],
                                  "intensity": rgb(colour * light["intensity"])}
        elif light["type"] == "rect":
            c, u, v = (np.asarray(light[k], float) for k in ("corner", "edge_u", "edge_v"))
            # Mitsuba's rectangle is [-1, 1]² in xy facing +z; columns u/2, v/2, n map it onto
            # the light (the normal follows u × v, the side xylem's rect light emits to).
            n = np.cross(u, v)
            n /= np.linalg.norm(n)
            m = np.eye(4)
            m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = u / 2, v / 2, n, c + (u + v) / 2
            scene[f"light{i}"] = {
                "type": "rectangle", "to_world": mi.ScalarTransform4f(m.tolist()),
                "bsdf": {"type": "diffuse", "reflectance": rgb([0, 0, 0])},
                "emitter": {"type": "area", "radiance": rgb(colour * light["radiance"])},
            }
        else:
            raise ValueError(f"no Mitsuba equivalent for light type {light['type']!r}")
    for name, _, material in case["shapes"]:
        scene[name] = {"type": "obj", "filename": os.path.abspath(meshes[name]),
                       "face_normals": True,
                       "bsdf": mitsuba_bsdf(case["materials"][material],
                                            case.get("trees", {}).get(name))}
    return scene

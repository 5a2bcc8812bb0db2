"""Blender add-on: a board with xylem's node material from a `xylem bake` folder.

Blender's glTF importer reads `KHR_materials_anisotropy` from Blender 4.0 on; older importers
(Debian's Blender 3.4, for one) load the .glb without it and the highlight loses its grain.
This add-on builds the material from the folder's maps instead, in any Blender whose
Principled BSDF has the Anisotropic and Tangent inputs and Separate Color (3.3 on; the coat
needs 4.0 and is left out before):

- Base Color: base_color.png (sRGB);
- Normal: normal.png (tangent space, non-colour);
- Roughness and Anisotropic from metallic_roughness.png (G: glTF roughness r, α = r²) and
  anisotropy.png (B: strength s), converted so that Cycles' anisotropic GGX has the
  extension's two roughnesses: α_t = mix(α, 1, s²) across the fibre and α_b = α along it.
  Cycles' Principled BSDF takes α_x = r_B²/√(1 − 0.9 a) along the tangent and α_y =
  r_B²·√(1 − 0.9 a) across it, so r_B = (α_t α_b)^¼ and a = (1 − α_b/α_t)/0.9 (clamped to 1);
- Tangent: anisotropy.png's direction (R, G mapped to [−1, 1]: the direction, in the face's
  tangent frame, in which the highlight stretches — across the fibre) as the world vector
  d_x T + d_y (N × T), T the UV map's tangent (+u, along the board), N × T the image's up;
  Anisotropic Rotation stays 0;
- Coat: the finish (weight 1, roughness 0, IOR 1.5, xylem's default smooth finish).

File > Import > xylem bake folder (bake.json) places the board as `xylem bake` wrote it
(metres, length along x, width along y, top face at z = +T/2); headless, call
`import_bake(folder)`. notes/gltf.md has the test that renders it.
"""

import json
import os

import bpy

bl_info = {
    "name": "xylem bake folder",
    "author": "xylem",
    "version": (0, 1, 0),
    "blender": (3, 3, 0),
    "location": "File > Import > xylem bake folder (bake.json)",
    "description": "A board with a Principled BSDF built from xylem's baked maps "
    "(base colour, roughness, anisotropy and tangent from the fibre map, coat)",
    "category": "Import-Export",
}

MAPS = ("base_color.png", "normal.png", "metallic_roughness.png", "anisotropy.png")


class BakeFolderError(Exception):
    """The folder is not a `xylem bake` output Blender can use."""


def read_bake(folder):
    """bake.json of a `xylem bake` folder, after checking the maps it needs are there."""
    path = os.path.join(folder, "bake.json")
    try:
        with open(path, encoding="utf-8") as f:
            meta = json.load(f)
    except OSError as e:
        raise BakeFolderError(f"{path}: cannot read ({e}); is {folder} a `xylem bake` folder?")
    except json.JSONDecodeError as e:
        raise BakeFolderError(f"{path}: not JSON ({e})")
    missing = [m for m in MAPS if not os.path.isfile(os.path.join(folder, m))]
    if missing:
        raise BakeFolderError(f"{folder}: missing {', '.join(missing)} (written by `xylem bake`)")
    board = meta.get("board_mm")
    if not (isinstance(board, list) and len(board) == 3 and all(
            isinstance(v, (int, float)) and v > 0 for v in board)):
        raise BakeFolderError(f"{path}: board_mm must be three positive sizes, got {board!r}")
    return meta


def _image(nodes, folder, name, colour, loc):
    node = nodes.new("ShaderNodeTexImage")
    node.image = bpy.data.images.load(os.path.join(folder, name), check_existing=True)
    node.image.colorspace_settings.name = "sRGB" if colour else "Non-Color"
    node.interpolation = "Linear"
    node.label = name
    node.location = loc
    return node


def _math(nodes, links, op, a, b=None, loc=(0, 0), label=None):
    node = nodes.new("ShaderNodeMath")
    node.operation = op
    node.location = loc
    if label:
        node.label = label
    for k, v in enumerate((a, b)):
        if v is None:
            continue
        if isinstance(v, (int, float)):
            node.inputs[k].default_value = v
        else:
            links.new(v, node.inputs[k])
    return node.outputs[0]


def _vmath(nodes, links, op, a, b=None, loc=(0, 0), scale=None):
    node = nodes.new("ShaderNodeVectorMath")
    node.operation = op
    node.location = loc
    links.new(a, node.inputs[0])
    if b is not None:
        links.new(b, node.inputs[1])
    if scale is not None:
        links.new(scale, node.inputs["Scale"])
    return node.outputs[0]


def build_material(folder, name=None, coat=True):
    """The board's top-face material from the maps of a `xylem bake` folder."""
    meta = read_bake(folder)
    mat = bpy.data.materials.new(name or f"xylem {meta.get('preset', 'board')} (baked maps)")
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    out.location = (400, 0)
    bsdf = nodes.new("ShaderNodeBsdfPrincipled")
    bsdf.location = (100, 0)
    links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])

    base = _image(nodes, folder, "base_color.png", True, (-900, 400))
    links.new(base.outputs["Color"], bsdf.inputs["Base Color"])

    normal = _image(nodes, folder, "normal.png", False, (-900, -700))
    nmap = nodes.new("ShaderNodeNormalMap")
    nmap.location = (-300, -700)
    links.new(normal.outputs["Color"], nmap.inputs["Color"])
    links.new(nmap.outputs["Normal"], bsdf.inputs["Normal"])

    # Roughness and strength → (r_B, a) of Cycles' anisotropic GGX (module docstring).
    mr = _image(nodes, folder, "metallic_roughness.png", False, (-1500, 150))
    an = _image(nodes, folder, "anisotropy.png", False, (-1500, -250))
    sep_r = nodes.new("ShaderNodeSeparateColor")
    sep_r.location = (-1200, 150)
    links.new(mr.outputs["Color"], sep_r.inputs[0])
    sep_a = nodes.new("ShaderNodeSeparateColor")
    sep_a.location = (-1200, -250)
    links.new(an.outputs["Color"], sep_a.inputs[0])
    r, s = sep_r.outputs["Green"], sep_a.outputs["Blue"]
    alpha = _math(nodes, links, "MULTIPLY", r, r, (-1000, 200), "α = r²")
    s2 = _math(nodes, links, "MULTIPLY", s, s, (-1000, 0), "s²")
    one_minus = _math(nodes, links, "SUBTRACT", 1.0, alpha, (-850, 100))
    alpha_t = _math(nodes, links, "MULTIPLY_ADD", one_minus, s2, (-700, 100), "α_t")
    links.new(alpha, alpha_t.node.inputs[2])
    prod = _math(nodes, links, "MULTIPLY", alpha, alpha_t, (-550, 200))
    r_b = _math(nodes, links, "POWER", prod, 0.25, (-400, 200), "r_B = (α α_t)^¼")
    links.new(r_b, bsdf.inputs["Roughness"])
    ratio = _math(nodes, links, "DIVIDE", alpha, alpha_t, (-550, 0))
    gap = _math(nodes, links, "SUBTRACT", 1.0, ratio, (-400, 0))
    aniso = _math(nodes, links, "DIVIDE", gap, 0.9, (-250, 0), "a = (1 − α/α_t)/0.9")
    aniso.node.use_clamp = True
    links.new(aniso, bsdf.inputs["Anisotropic"])

    # Tangent: d_x T + d_y (N × T), d = 2 (R, G) − 1.
    tan = nodes.new("ShaderNodeTangent")
    tan.direction_type = "UV_MAP"
    tan.location = (-1000, -450)
    geo = nodes.new("ShaderNodeNewGeometry")
    geo.location = (-1000, -600)
    dx = _math(nodes, links, "MULTIPLY_ADD", sep_a.outputs["Red"], 2.0, (-1000, -300), "d_x")
    dx.node.inputs[2].default_value = -1.0
    dy = _math(nodes, links, "MULTIPLY_ADD", sep_a.outputs["Green"], 2.0, (-850, -300), "d_y")
    dy.node.inputs[2].default_value = -1.0
    bit = _vmath(nodes, links, "CROSS_PRODUCT", geo.outputs["Normal"], tan.outputs["Tangent"],
                 (-800, -550))
    tx = _vmath(nodes, links, "SCALE", tan.outputs["Tangent"], loc=(-600, -400), scale=dx)
    ty = _vmath(nodes, links, "SCALE", bit, loc=(-600, -550), scale=dy)
    t = _vmath(nodes, links, "ADD", tx, ty, (-400, -450))
    links.new(t, bsdf.inputs["Tangent"])
    bsdf.inputs["Anisotropic Rotation"].default_value = 0.0

    if coat and "Coat Weight" in bsdf.inputs:
        bsdf.inputs["Coat Weight"].default_value = 1.0
        bsdf.inputs["Coat Roughness"].default_value = 0.0
        bsdf.inputs["Coat IOR"].default_value = 1.5
        # Cycles divides the base layer's IOR by the coat's under a coat: 1.5 would leave the
        # base (the fibre highlight) no specular at all; 2.25 keeps 1.5 relative to the finish.
        bsdf.inputs["IOR"].default_value = 2.25
    return mat


def import_bake(folder, coat=True):
    """A box of the baked board (metres) whose top face carries `build_material`'s material,
    the other faces a plain Principled BSDF; linked to the scene and returned."""
    import bmesh

    meta = read_bake(folder)
    w, h, t = (v / 1000.0 for v in meta["board_mm"])
    mesh = bpy.data.meshes.new(f"xylem {meta.get('preset', 'board')}")
    bm = bmesh.new()
    bmesh.ops.create_cube(bm, size=1.0)
    bmesh.ops.scale(bm, vec=(w, h, t), verts=bm.verts)
    uv = bm.loops.layers.uv.new("UVMap")
    for face in bm.faces:
        top = face.normal.z > 0.5
        face.material_index = 0 if top else 1
        for loop in face.loops:
            p = loop.vert.co
            # u along +x, v along +y: the image's right and up (Blender's v is up).
            loop[uv].uv = (p.x / w + 0.5, p.y / h + 0.5) if top else (0.0, 0.0)
    bm.to_mesh(mesh)
    bm.free()
    mesh.materials.append(build_material(folder, coat=coat))
    side = bpy.data.materials.new(f"xylem {meta.get('preset', 'board')} (sides)")
    side.use_nodes = True
    mesh.materials.append(side)
    obj = bpy.data.objects.new(mesh.name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


class IMPORT_OT_xylem_bake(bpy.types.Operator):
    """Import a `xylem bake` folder as a board with xylem's node material"""

    bl_idname = "import_scene.xylem_bake"
    bl_label = "xylem bake folder (bake.json)"
    bl_options = {"REGISTER", "UNDO"}

    filepath: bpy.props.StringProperty(subtype="FILE_PATH")
    filter_glob: bpy.props.StringProperty(default="bake.json", options={"HIDDEN"})
    coat: bpy.props.BoolProperty(name="Finish (coat)", default=True)

    def execute(self, context):
        try:
            import_bake(os.path.dirname(self.filepath), coat=self.coat)
        except BakeFolderError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        return {"FINISHED"}

    def invoke(self, context, event):
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}


def _menu(self, context):
    self.layout.operator(IMPORT_OT_xylem_bake.bl_idname, text=IMPORT_OT_xylem_bake.bl_label)


def register():
    bpy.utils.register_class(IMPORT_OT_xylem_bake)
    bpy.types.TOPBAR_MT_file_import.append(_menu)


def unregister():
    bpy.types.TOPBAR_MT_file_import.remove(_menu)
    bpy.utils.unregister_class(IMPORT_OT_xylem_bake)

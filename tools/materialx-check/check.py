"""Checks a `xylem bake --materialx` folder with the MaterialX and OpenUSD Python packages.

    python tools/materialx-check/check.py DIR PRESET --coat-ior 1.5

Prints one JSON report and exits 0 when every check passes, 1 otherwise (the report's
`failures` names each). Checks (notes/gltf.md, "MaterialX / OpenPBR"):

- DIR/PRESET.mtlx: MaterialX's `Document.validate()` passes with the standard data libraries
  (stdlib, pbrlib, bxdf with OpenPBR) loaded by `mx.loadLibraries`; every node has a node
  definition and every input the type its definition gives; exactly one material, `M_PRESET`,
  whose surface shader is an `open_pbr_surface` (ND_open_pbr_surface_surfaceshader);
  every `image` file exists beside the document and MaterialX's own image loader reads it at
  one size; `coat_weight` 1 and `coat_ior` the given value; specular roughness anisotropy read
  from its texture has a mean above 0.1 (a board's fibres lie in its face); the geometry tangent
  and normal come from the node graph; MaterialX's GLSL generator generates the shader.
- DIR/PRESET.usda: OpenUSD opens it; `/Board/top` is a Mesh with `primvars:st`, bound
  (UsdShade.MaterialBindingAPI) to a Material that references the `.mtlx` beside it at
  `/MaterialX/Materials/M_PRESET`, the document's material. (usd-core has no usdMtlx plugin, so
  the reference is checked as authored, not composed.)
"""

from __future__ import annotations

import argparse
import json
import os
import sys

import MaterialX as mx


def library() -> mx.Document:
    lib = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)
    return lib


def image_size(path: str) -> tuple[int, int, list[float]] | None:
    """Width, height and mean of the first channel, read by MaterialX's stb loader."""
    from MaterialX import PyMaterialXRender as mx_render

    handler = mx_render.ImageHandler.create(mx_render.StbImageLoader.create())
    img = handler.acquireImage(mx.FilePath(path))
    if img is None or img.getWidth() == 0:
        return None
    w, h = img.getWidth(), img.getHeight()
    total = 0.0
    for y in range(h):
        for x in range(w):
            total += img.getTexelColor(x, y)[0]
    return w, h, total / (w * h)


def check_mtlx(path: str, preset: str, coat_ior: float, fail: list[str], report: dict) -> None:
    if not os.path.isfile(path):
        fail.append(f"{path}: missing")
        return
    doc = mx.createDocument()
    try:
        mx.readFromXmlFile(doc, path)
    except Exception as e:  # noqa: BLE001 (any parse error is a failure to report)
        fail.append(f"{path}: not readable as MaterialX: {e}")
        return
    doc.setDataLibrary(library())
    ok, msg = doc.validate()
    report["validate"] = ok
    if not ok:
        fail.append(f"validate(): {msg.strip()}")
    folder = os.path.dirname(os.path.abspath(path))
    # Every node has a definition and every input its definition's type.
    for elem in doc.traverseTree():
        if not elem.isA(mx.Node):
            continue
        nd = elem.getNodeDef()
        if nd is None:
            fail.append(f"node {elem.getNamePath()} ({elem.getCategory()}): no node definition")
            continue
        for inp in elem.getInputs():
            want = nd.getActiveInput(inp.getName())
            if want is None:
                fail.append(f"{inp.getNamePath()}: not an input of {nd.getName()}")
            elif want.getType() != inp.getType():
                fail.append(
                    f"{inp.getNamePath()}: type {inp.getType()}, {nd.getName()} wants {want.getType()}"
                )
    materials = doc.getMaterialNodes()
    report["materials"] = [m.getName() for m in materials]
    want_name = f"M_{preset}"
    if [m.getName() for m in materials] != [want_name]:
        fail.append(f"materials {report['materials']}: expected exactly [{want_name}]")
        return
    shaders = mx.getShaderNodes(materials[0])
    if len(shaders) != 1:
        fail.append(f"{want_name}: {len(shaders)} surface shaders, expected 1")
        return
    sh = shaders[0]
    nd = sh.getNodeDef()
    report["shader"] = {"category": sh.getCategory(), "nodedef": nd.getName() if nd else None}
    if sh.getCategory() != "open_pbr_surface" or nd is None or nd.getName() != "ND_open_pbr_surface_surfaceshader":
        fail.append(f"surface shader {sh.getName()}: {report['shader']}, expected open_pbr_surface")
        return

    def value(name: str) -> float | None:
        i = sh.getInput(name)
        return None if i is None or i.getValue() is None else float(i.getValue())

    report["coat_weight"], report["coat_ior"] = value("coat_weight"), value("coat_ior")
    if report["coat_weight"] != 1.0:
        fail.append(f"coat_weight {report['coat_weight']}: expected 1")
    if report["coat_ior"] is None or abs(report["coat_ior"] - coat_ior) > 1e-6:
        fail.append(f"coat_ior {report['coat_ior']}: expected {coat_ior}")
    # Images: each file beside the document, readable by MaterialX, all one size.
    sizes = {}
    for elem in doc.traverseTree():
        if elem.isA(mx.Node) and elem.getCategory() == "image":
            f = elem.getInput("file")
            name = f.getResolvedValueString() if f is not None else ""
            full = os.path.join(folder, name)
            if not name or not os.path.isfile(full):
                fail.append(f"{elem.getNamePath()}: file `{name}` missing")
                continue
            got = image_size(full)
            if got is None:
                fail.append(f"{elem.getNamePath()}: `{name}` unreadable by MaterialX")
                continue
            sizes[elem.getName()] = got
    report["images"] = {k: {"size": [v[0], v[1]], "mean": round(v[2], 4)} for k, v in sizes.items()}
    if len({v[:2] for v in sizes.values()}) > 1:
        fail.append(f"images of different sizes: {report['images']}")
    # The anisotropy and the geometry come from the graph.
    for name in ["base_color", "specular_roughness", "specular_roughness_anisotropy", "geometry_normal", "geometry_tangent"]:
        i = sh.getInput(name)
        if i is None or not (i.getNodeGraphString() or i.getNodeName()):
            fail.append(f"{sh.getName()}.{name}: not connected to the baked maps")
    aniso = sh.getInput("specular_roughness_anisotropy")
    if aniso is not None and aniso.getNodeGraphString():
        graph = doc.getNodeGraph(aniso.getNodeGraphString())
        out = graph.getOutput(aniso.getOutputString()) if graph else None
        node = out.getConnectedNode() if out else None
        mean = sizes.get(node.getName())[2] if node is not None and node.getName() in sizes else None
        report["anisotropy_mean"] = mean
        if mean is None or mean <= 0.1:
            fail.append(f"specular_roughness_anisotropy mean {mean}: expected > 0.1")
    if not fail:
        try:
            from MaterialX import PyMaterialXGenGlsl as mx_glsl
            from MaterialX import PyMaterialXGenShader as mx_gen

            gen = mx_glsl.GlslShaderGenerator.create()
            ctx = mx_gen.GenContext(gen)
            ctx.registerSourceCodeSearchPath(mx.getDefaultDataSearchPath())
            shader = gen.generate(sh.getName(), sh, ctx)
            report["glsl_pixel_chars"] = len(shader.getSourceCode(mx_gen.PIXEL_STAGE))
        except Exception as e:  # noqa: BLE001
            fail.append(f"GLSL generation: {e}")


def check_usda(path: str, mtlx: str, preset: str, prim: str, fail: list[str],
               report: dict) -> None:
    from pxr import Usd, UsdGeom, UsdShade

    if not os.path.isfile(path):
        fail.append(f"{path}: missing")
        return
    stage = Usd.Stage.Open(path)
    if stage is None:
        fail.append(f"{path}: USD cannot open it")
        return
    report["up_axis"] = UsdGeom.GetStageUpAxis(stage)
    report["meters_per_unit"] = UsdGeom.GetStageMetersPerUnit(stage)
    top = stage.GetPrimAtPath(prim)
    if not top or top.GetTypeName() != "Mesh":
        fail.append(f"{prim}: no Mesh")
        return
    if not UsdGeom.PrimvarsAPI(top).GetPrimvar("st").HasValue():
        fail.append(f"{prim}: no primvars:st")
    bound, _ = UsdShade.MaterialBindingAPI(top).ComputeBoundMaterial()
    if not bound:
        fail.append(f"{prim}: no material binding")
        return
    report["binding"] = str(bound.GetPath())
    refs = []
    for spec in bound.GetPrim().GetPrimStack():
        for r in spec.referenceList.GetAddedOrExplicitItems():
            refs.append((spec.layer.ComputeAbsolutePath(r.assetPath), str(r.primPath)))
    report["references"] = [[os.path.basename(a), p] for a, p in refs]
    want = (os.path.abspath(mtlx), f"/MaterialX/Materials/M_{preset}")
    if want not in [(os.path.abspath(a), p) for a, p in refs]:
        fail.append(f"{bound.GetPath()}: references {report['references']}, expected {os.path.basename(want[0])} at {want[1]}")
    elif not os.path.isfile(want[0]):
        fail.append(f"{bound.GetPath()}: referenced {want[0]} missing")


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("preset")
    ap.add_argument("--coat-ior", type=float, required=True)
    ap.add_argument("--prim", default="/Board/top",
                    help="the baked Mesh prim (/Board/top; /Object/mesh for a mesh bake)")
    a = ap.parse_args()
    fail: list[str] = []
    report: dict = {"materialx": mx.getVersionString()}
    mtlx = os.path.join(a.dir, f"{a.preset}.mtlx")
    check_mtlx(mtlx, a.preset, a.coat_ior, fail, report)
    try:
        from pxr import Usd

        report["usd"] = ".".join(map(str, Usd.GetVersion()))
        check_usda(os.path.join(a.dir, f"{a.preset}.usda"), mtlx, a.preset, a.prim, fail, report)
    except ImportError as e:
        fail.append(f"pxr (usd-core) not importable: {e}")
    report["failures"] = fail
    print(json.dumps(report))
    return 1 if fail else 0


if __name__ == "__main__":
    sys.exit(main())

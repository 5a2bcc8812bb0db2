"""A Mitsuba 3 BSDF plugin, ``xylem_wood_baked``: xylem's finished-wood BSDF written in Dr.Jit,
shading the maps that ``xylem bake`` writes, so that it runs inside Mitsuba's symbolic
megakernel and is differentiable.

    import mitsuba as mi
    mi.set_variant("llvm_ad_rgb")
    import xylem.mitsuba
    xylem.mitsuba.register()           # registers xylem_wood and xylem_wood_baked
    bsdf = mi.load_dict({"type": "xylem_wood_baked", "maps": "out/walnut", "eta": 1.5})

``maps`` is the folder of a ``xylem bake PRESET --out DIR``, of a board or of a ``--mesh``
(an OBJ with ``vt`` whose same file Mitsuba loads: its OBJ loader flips v as xylem's reader
does, so si.uv is the bake's uv): the plugin reads ``base_color.exr``, ``fiber_color.exr``,
``fiber_direction.exr`` and ``ray_direction.exr`` (the signed tangent-space fibre and ray
axes), ``highlight_width.exr`` (beta, radians) and ``ray_mask.exr``, derives from them once
per texel what the BSDF needs (``_shading_maps``: the bounded diffuse, clamped values, unit
axes and bumped normal) into one 14- or 17-channel table (clamped at the edges, texel
centres at (i + 1/2)/W as xylem's own ``BakedMaps::lookup``; one table, so a lookup finds its
texels once; a ``mi.Texture2f`` of it for the bilinear ``filter``) and looks it up at
``si.uv`` (texel (0, 0) is the image's
top-left, v runs down the rows, as glTF and the bake write them). ``eta`` is the finish's
index (1-4, default 1.5) and ``roughness`` its GGX roughness (0-1, default 0; below 1e-3 the
finish is smooth, as in ``WoodBsdf``). ``bump`` (0-100, default 1) scales the slope of the
baked normal map (``normal.exr``, the pore bump at the strength xylem's ``bump = 1``; 0 leaves
it unread): the BSDF is evaluated in a frame about the tilted normal, as xylem's solid wood
is.
``two_sided`` (default false) shades a hit seen from behind as xylem's renderer does, the
frame turned half round the fibre's projection into the face (Mitsuba's ``twosided`` mirrors
the directions instead, which differs for the ray axis's in-face part).
``pixel_angle`` (radians, default 0: none) turns on mip-mapped lookups: the ray-cone angle of a
camera sample, which ``set_pixel_angle(scene)`` computes from the scene's camera and sets on
every ``xylem_wood_baked`` there (Mitsuba's integrators give a BSDF no uv footprint); the
lookups are then trilinear between the mip levels about the footprint (``_halve``,
``_lookup``).
``filter`` (default ``"stochastic"``) is how a lookup filters the texels: ``"stochastic"``
draws one texel (and one mip level) per interaction with the bilinear (trilinear) weights, by
numbers hashed from si.uv, so that ``eval_pdf`` and ``sample`` at one interaction see the same
texel (stochastic texture filtering, Pharr et al. 2024): the BSDFs of the texels are averaged
over the pixel's samples rather than their parameters, for a quarter of the gathers (an
eighth with mip maps), and uv gets no derivative; ``"bilinear"`` interpolates the parameters
and is differentiable in uv.

The BSDF at a texel is xylem's ``WoodBsdf`` (crates/xylem/src/bsdf/wood.rs) for the parameters
xylem's own baked-map material builds there (``material/face.rs`` ``face_shading``): the
Lambertian substrate with its internal reflections under the finish, scaled so the fibre lobes
fit (notes/bsdf.md §1.3, §2.3), plus the energy-bounded Marschner et al. 2005 fibre lobe of the
fibre axis and of the ray axis (in the face, across the fibre), blended by the ray mask, all
seen through the finish. A smooth finish is Fresnel's, its mirror a delta component
(component 1). A rough finish is xylem's energy-compensated GGX interface (notes/bsdf.md §4):
its single- and multiple-scattering reflection, the substrate seen through 1 - R(mu), and the
fibre lobes convolved with the spreads of the light it transmits, with xylem's own tables
(``xylem._xylem.rough_finish_nodes``: R, R_ms and the spreads on the sqrt(mu) nodes for this
roughness and index) in a Dr.Jit texture. Sampling is xylem's: a lobe by its estimated albedo,
the fibre lobes by their Gaussian in psi and a uniform azimuth on the cone's arc above the
critical angle (notes/bsdf.md §3), a rough finish's reflection by its visible normals; pdf is
the mixture's density.

Tangent space: x along dp/du, y along -dp/dv (up the image), z the shading normal, as the bake
defines it; where ``dp/du`` is unset (a zero-initialised interaction, as
``mitsuba.chi2.BSDFAdapter`` makes) x is the shading frame's s.

Unlike ``xylem_wood`` it needs no ``evaluated()`` mode, leaves other scenes renderable, and
is differentiable by Dr.Jit's AD (directions, the maps, which ``mi.traverse`` lists as
``maps``: an (H, W, 14) tensor of base colour, beta, fibre colour, ray mask, fibre direction
and ray direction, and the tangent-space normal when ``bump`` > 0: (H, W, 17); and uv with
``filter`` ``"bilinear"``).

Every ``mi.render`` traces the plugin's Python into Dr.Jit again (about 8 ms of a short
render's time). A loop of renders (an optimisation, a parameter study) avoids that by freezing
the render, which records its kernels and replays them, and follows changes made through
``mi.traverse`` (python/tests/test_mitsuba_baked.py ``test_baked_render_freezes``)::

    @dr.freeze
    def render(scene, seed):
        return mi.render(scene, seed=seed)

    image = render(scene, mi.UInt32(seed))   # a Python int seed would be recorded as a constant

What it approximates compared with the solid wood of ``xylem_wood``: the wood is sampled at the
texel centres and filtered between them (at ``--res 1024`` on a 300 mm board, 0.29 mm
texels; pores and ray flecks narrower than that blur); the tangent frame is Mitsuba's per
triangle (dp/du, dp/dv) where the bake interpolated vertex tangents; a bake without
``ray_direction.exr`` gets the ray axis in the face across the fibre; the pore bump is the
baked normal map's, filtered between texel centres (pores are about a texel wide at
``--res 1024``); a mip level's texels average the BSDF's parameters over the texels below
(colours, axes with beta widened by their spread, the normal), not the BSDF.
``BSDFContext`` masks are honoured per component (0: the diffuse and fibre lobes and a rough
finish's reflection, 1: a smooth finish's mirror), with the lobe probabilities renormalised
over what is enabled.
"""

import math
import pathlib

import numpy as np

from . import _xylem
from .mitsuba import _has

# Below this cos psi a direction lies on the fibre axis (fiber.rs MIN_COS_PSI).
MIN_COS_PSI = 1e-5
# Smallest half-width of the sampled azimuth arc (fiber.rs MIN_ARC).
MIN_ARC = math.pi / 8
# Nodes per axis of the tabulated lobe-albedo bound: a refinement (120 = 4 x 30) of xylem's
# 31-node bilinear table (fiber_albedo_table.rs), so bilinear lookup here reproduces it exactly.
ALBEDO_NODES = 121
# Rec. 709 luminance (crates/xylem/src/math/mod.rs `luminance`).
LUMINANCE = (0.2126, 0.7152, 0.0722)
# 12-point Gauss-Legendre on [0, 1] (fresnel.rs GL_X / GL_W; Abramowitz & Stegun 25.4.29).
_GL_X, _GL_W = np.polynomial.legendre.leggauss(12)


def _maps(folder, normal):
    """The bake's maps (float32 EXRs) as one (H, W, 14) array: base colour, beta, fibre colour,
    ray mask, fibre direction, ray direction (zeros where the bake has no ``ray_direction.exr``,
    as bakes before it had none: the in-face axis is used then); with `normal`, 17 channels, the
    tangent-space normal last."""
    import mitsuba as mi

    folder = pathlib.Path(folder)

    def read(name, channels, optional=False):
        path = folder / f"{name}.exr"
        if optional and not path.exists():
            return None
        if not path.exists():
            raise FileNotFoundError(
                f"xylem_wood_baked: {path} is missing (`maps` must be a `xylem bake` folder)"
            )
        a = np.array(mi.Bitmap(str(path)), dtype=np.float32)
        a = a.reshape(a.shape[0], a.shape[1], -1)
        if a.shape[2] != channels:
            raise ValueError(f"xylem_wood_baked: {path} has {a.shape[2]} channels, not {channels}")
        bad = ~np.isfinite(a)
        if bad.any():
            row, col, ch = (int(i[0]) for i in np.nonzero(bad))
            raise ValueError(f"xylem_wood_baked: {path} holds {int(bad.sum())} non-finite values "
                             f"(the first at row {row}, column {col}, channel {ch}): a bake "
                             "writes finite maps")
        return a

    layers = [read("base_color", 3), read("highlight_width", 1), read("fiber_color", 3),
              read("ray_mask", 1), read("fiber_direction", 3)]
    ray = read("ray_direction", 3, optional=True)
    layers.append(np.zeros_like(layers[0]) if ray is None else ray)
    if normal:
        layers.append(read("normal", 3))
    shapes = {m.shape[:2] for m in layers}
    if len(shapes) != 1:
        raise ValueError(f"xylem_wood_baked: the maps in {folder} differ in size: {sorted(shapes)}")
    return np.concatenate(layers, 2)


def _albedo_table():
    """xylem's bound on the fibre lobe's albedo (``max_lobe_albedo``, with its margin) at
    ALBEDO_NODES x ALBEDO_NODES nodes, rows the dip, columns beta, both over [0, pi/2]."""
    nodes = np.linspace(0.0, 0.5 * math.pi, ALBEDO_NODES)
    return np.array([[_xylem.max_lobe_albedo(b, d) for b in nodes] for d in nodes],
                    dtype=np.float32)


class _Jit:
    """The Dr.Jit types that derive the shading maps and their mip levels: the variant's own in
    JIT variants (so that AD flows), Dr.Jit's LLVM backend's in the scalar variant; and
    `out`, which makes a tensor of them the variant's."""

    def __init__(self, mi, dr):
        if dr.is_jit_v(mi.Float):
            self.Float, self.UInt, self.Vec, self.Tensor, self.Tex, self.Point2f = (
                mi.Float, mi.UInt32, mi.Vector3f, mi.TensorXf, mi.Texture2f, mi.Point2f)
            self.out = lambda t: t
        else:
            import drjit.llvm as jit
            self.Float, self.UInt, self.Vec, self.Tensor, self.Tex, self.Point2f = (
                jit.Float, jit.UInt32, jit.Array3f, jit.TensorXf, jit.Texture2f, jit.Array2f)
            self.out = lambda t: mi.TensorXf(np.array(t, dtype=np.float32))

    def tensor(self, dr, channels, h, w):
        """An (h, w, len(channels)) tensor of per-texel Floats."""
        c = len(channels)
        flat = dr.zeros(self.Float, h * w * c)
        idx = dr.arange(self.UInt, h * w)
        dr.make_opaque(flat)
        for k, x in enumerate(channels):
            dr.scatter(flat, x, idx * c + k)
        return self.Tensor(flat, (h, w, c))


def _shading_maps(mi, dr, jit, maps, bump, f_int):
    """The texture the BSDF looks up, derived once per texel from the bake's maps (an (H, W,
    14 or 17) tensor, `_maps`) as `Texel` used to derive it at every lookup: the bounded
    diffuse rho'' (3, wood.rs `bounded_diffuse`; notes/bsdf.md §1.3, §2.3), beta, the fibre
    colour (3) and the ray mask, clamped as material/baked.rs `BakedWoodMaterial::shade` clamps
    them, the unit tangent-space fibre and ray axes (3 + 3; a zero fibre axis is x, a zero ray
    axis in the face across the fibre, face.rs: xylem's frame.t = n x s) and, with `bump` > 0,
    the unit bumped normal (3; the baked normal's slope times `bump`, Blinn 1978). (H, W, 14),
    or 17 with the normal.

    Only the axes' dips below the bumped normal enter rho''s bound (its lobe albedos), and the
    tangent-space axes and normal hold them, so nothing here depends on the hit's frame. At
    texel centres the BSDF is what deriving these at the lookup gave; between them rho'' is
    interpolated instead of its inputs. Computed with Dr.Jit ops, so in AD variants the
    gradients of `maps` (what ``mi.traverse`` lists) flow through it; the scalar variant
    derives them with Dr.Jit's LLVM backend (`_Jit`; the result is in its types)."""
    Float, UInt, Vec, Tex, Point2f = jit.Float, jit.UInt, jit.Vec, jit.Tex, jit.Point2f
    src = maps if dr.is_jit_v(mi.Float) else jit.Tensor(np.array(maps))
    h, w, c = src.shape
    idx = dr.arange(UInt, h * w)
    ch = [dr.gather(Float, src.array, idx * c + k) for k in range(c)]

    def unit(v, fallback):
        return dr.select(dr.squared_norm(v) < 1e-12, fallback, dr.normalize(v))

    diffuse = Vec(*(dr.clip(x, 0.0, 1.0) for x in ch[0:3]))
    beta = dr.clip(ch[3], 1e-3, 0.5 * math.pi)
    fiber = Vec(*(dr.clip(x, 0.0, 1.0) for x in ch[4:7]))
    m = dr.clip(ch[7], 0.0, 1.0)
    u = unit(Vec(ch[8], ch[9], ch[10]), Vec(1.0, 0.0, 0.0))
    s = unit(Vec(u.x, u.y, 0.0), Vec(1.0, 0.0, 0.0))
    r = unit(Vec(ch[11], ch[12], ch[13]), Vec(-s.y, s.x, 0.0))
    out = [*diffuse, beta, *fiber, m, *u, *r]
    nb = Vec(0.0, 0.0, 1.0)
    if bump > 0:
        nb = unit(Vec(bump * ch[14], bump * ch[15], ch[16]), nb)
        out += [*nb]
    albedo = Tex(jit.Tensor(_albedo_table()[..., None]), filter_mode=dr.FilterMode.Linear,
                 wrap_mode=dr.WrapMode.Clamp)

    def bound(axis):
        """The lobe albedo bound of `axis` at the texel's beta and the axis's dip below the
        bumped normal (the 121-node table, bilinear: xylem's own)."""
        dip = dr.asin(dr.minimum(dr.abs(dr.dot(axis, nb)), 1.0))
        scale = 2.0 / math.pi * (ALBEDO_NODES - 1) / ALBEDO_NODES
        pos = Point2f(beta * scale + 0.5 / ALBEDO_NODES, dip * scale + 0.5 / ALBEDO_NODES)
        return albedo.eval(pos)[0]

    # rho'' = rho' / (1 - rho' F_int), rho' = s rho, s = min(1, min_c room_c / rho_c), room =
    # 1 - k_f A, A the ray-mask blend of the lobes' albedo bounds.
    room = 1.0 - fiber * ((1.0 - m) * bound(u) + m * bound(r))
    ratio = dr.select(diffuse > room, room / dr.maximum(diffuse, 1e-30), 1.0)
    rho = diffuse * dr.minimum(dr.minimum(ratio.x, ratio.y), dr.minimum(ratio.z, 1.0))
    out[0:3] = rho / (1.0 - rho * f_int)
    return jit.tensor(dr, out, h, w)


def _halve(dr, jit, t):
    """The next mip level of shading maps `t` (`_shading_maps`' channels): each texel the box
    average of its 2 x 2 parents (the last row or column counted twice where a size is odd).
    Colours and the ray mask are averaged; the axes are averaged and renormalised (each parent
    first turned to the side of the first, as a fibre axis and its opposite are the same lobe),
    and the normal too, so that the pore bump fades to its mean; beta is widened by the spread
    of the fibre axes, beta^2 = mean(beta^2) + (1 - L) / L with L the length of their mean
    (Toksvig 2005), so that fibre wander finer than a texel widens the highlight."""
    h, w, c = t.shape
    h2, w2 = (h + 1) // 2, (w + 1) // 2
    idx = dr.arange(jit.UInt, h2 * w2)
    # The sizes as opaque variables: one kernel for every level, not one compiled for each.
    w_, w2_ = dr.opaque(jit.UInt, w), dr.opaque(jit.UInt, w2)
    i, j = idx // w2_, idx % w2_
    rows = (2 * i, dr.minimum(2 * i + 1, dr.opaque(jit.UInt, h - 1)))
    cols = (2 * j, dr.minimum(2 * j + 1, w_ - 1))
    taps = [(r * w_ + q) * c for r in rows for q in cols]

    def channel(k):
        return [dr.gather(jit.Float, t.array, tap + k) for tap in taps]

    def mean(xs):
        return (xs[0] + xs[1] + xs[2] + xs[3]) * 0.25

    def axis(k, aligned):
        vs = [jit.Vec(*x) for x in zip(*(channel(k + d) for d in range(3)))]
        if aligned:
            vs = [vs[0]] + [dr.select(dr.dot(v, vs[0]) < 0, -v, v) for v in vs[1:]]
        m = mean(vs)
        length = dr.norm(m)
        return dr.select(length > 1e-6, m / dr.maximum(length, 1e-6), vs[0]), length

    out = [mean(channel(k)) for k in range(c)]
    u, length = axis(8, True)
    r, _ = axis(11, True)
    spread = (1.0 - dr.minimum(length, 1.0)) / dr.maximum(length, 1e-3)
    beta2 = mean([b * b for b in channel(3)])
    out[3] = dr.minimum(dr.sqrt(beta2 + spread), 0.5 * math.pi)
    out[8:14] = [*u, *r]
    if c > 14:
        out[14:17] = [*axis(14, False)[0]]
    return jit.tensor(dr, out, h2, w2)


def _atlas(dr, jit, levels):
    """The mip levels side by side in one (H, W0 + W1, C) tensor: level 0 at the left, the
    others in a column right of it, top to bottom; and each level's (width, height, x offset,
    y offset) in texels. A lookup clamped to within a level's texel centres reads its
    neighbours only with weight 0, so levels do not bleed into each other."""
    h0, w0, c = levels[0].shape
    boxes, y = [(w0, h0, 0, 0)], 0
    for lv in levels[1:]:
        boxes.append((lv.shape[1], lv.shape[0], w0, y))
        y += lv.shape[0]
    height, width = max(h0, y), w0 + (levels[1].shape[1] if len(levels) > 1 else 0)
    flat = dr.zeros(jit.Float, height * width * c)
    for lv, (w, h, ox, oy) in zip(levels, boxes):
        idx = dr.arange(jit.UInt, h * w * c)
        texel, k = idx // c, idx % c
        # Opaque sizes: one kernel for every level.
        w_, ox_, oy_ = (dr.opaque(jit.UInt, x) for x in (w, ox, oy))
        row, col = texel // w_, texel % w_
        dr.scatter(flat, lv.array, ((row + oy_) * width + col + ox_) * c + k)
    return jit.Tensor(flat, (height, width, c)), boxes


def _hash(dr, h, wrap):
    """Chris Wellons's `lowbias32` integer hash (hash-prospector), on 32-bit unsigned h; `wrap`
    keeps the scalar variant's Python ints to 32 bits (identity for Dr.Jit's UInt32)."""
    h = h ^ (h >> 16)
    h = wrap(h * 0x7FEB352D)
    h = h ^ (h >> 15)
    h = wrap(h * 0x846CA68B)
    return h ^ (h >> 16)


def _interaction_numbers(mi, dr, uv, count):
    """`count` numbers in [0, 1) that are a hash of the interaction's uv bits: the same for every
    call at one interaction (`eval_pdf` and `sample` see one texel), uncorrelated between
    interactions (uv is continuous; two paths that meet one uv exactly have measure zero)."""
    if dr.is_jit_v(mi.Float):
        bits = [dr.reinterpret_array(mi.UInt32, c) for c in (uv.x, uv.y)]
        wrap = lambda h: h
    else:
        import struct

        bits = [struct.unpack("<I", struct.pack("<f", float(c)))[0] for c in (uv.x, uv.y)]
        wrap = lambda h: h & 0xFFFFFFFF
    h = _hash(dr, bits[0] ^ _hash(dr, bits[1] ^ 0x9E3779B9, wrap), wrap)
    out = []
    for _ in range(count):
        h = _hash(dr, h ^ 0x85EBCA6B, wrap)
        out.append(mi.Float(h >> 8) * (1.0 / (1 << 24)))
    return out


def _frame_axes(mi, dr, si):
    """Tangent-space x ("right") and y ("up") in the shading frame's coordinates: x = dp/du
    projected into the surface (the shading frame's s where dp/du is unset), y = n x right,
    turned to the side of -dp/dv (the bake's up, bake/mod.rs `TexelFrame`)."""
    du, dv = si.sh_frame.to_local(si.dp_du), si.sh_frame.to_local(si.dp_dv)
    right = mi.Vector3f(du.x, du.y, 0.0)
    unset = dr.squared_norm(right) < 1e-12
    right = dr.select(unset, mi.Vector3f(1, 0, 0), dr.normalize(right))
    up = mi.Vector3f(-right.y, right.x, 0.0)
    up = dr.select(dr.dot(up, dv) > 0, -up, up)
    return right, up


def _refract_in(mi, dr, w, eta):
    """The interior direction that refracts into exterior w (Snell; fresnel.rs refract_in)."""
    e2 = eta * eta
    return mi.Vector3f(w.x / eta, w.y / eta, dr.safe_sqrt((e2 - 1.0 + w.z * w.z) / e2))


def _refract_out(mi, dr, w, eta):
    """Exterior direction of interior w and whether it leaves (fresnel.rs refract_out)."""
    e2 = eta * eta
    z2 = (1.0 - e2) + e2 * w.z * w.z
    return mi.Vector3f(w.x * eta, w.y * eta, dr.safe_sqrt(z2)), (z2 > 0) & (w.z > 0)


def _fresnel(mi, dr, cos, eta):
    """Unpolarised Fresnel reflectance from outside (Born & Wolf §1.5.2; Mitsuba's mi.fresnel)."""
    return mi.fresnel(dr.clip(cos, 0.0, 1.0), eta)[0]


def _gaussian(dr, inv_beta, x):
    """g(beta, x) = exp(-x^2 / 2 beta^2) / (beta sqrt(2 pi)) (Marschner et al. 2005 §4.2), of
    1 / beta (a division per width, shared by its Gaussians)."""
    return dr.exp(-0.5 * dr.square(x * inv_beta)) * (inv_beta / math.sqrt(2.0 * math.pi))


class _Angles:
    """A direction's longitudinal angle about a fibre u: sin psi = w . u (clamped), psi (Marschner
    et al. 2005 eq. 2) and cos psi = sqrt(1 - sin^2 psi)."""

    def __init__(self, dr, w, u):
        self.sin = dr.clip(dr.dot(w, u), -1.0, 1.0)
        self.psi = dr.asin(self.sin)
        self.cos = dr.safe_sqrt(1.0 - self.sin * self.sin)


def _lobe(dr, o, i, inv_beta):
    """The energy-bounded fibre lobe g(beta, psi_i + psi_o) / (2 pi max(cos psi_i, cos psi_o))
    (fiber.rs lobe_value; notes/bsdf.md §2), without its colour; o, i: `_Angles`."""
    c = dr.maximum(dr.maximum(i.cos, o.cos), MIN_COS_PSI)
    return _gaussian(dr, inv_beta, i.psi + o.psi) / (2.0 * math.pi * c)


def _arc(dr, u, sin_psi, cos_psi, z_min):
    """Half-width Delta of the azimuth arc of the cone at psi above z_min: z(phi) = sin psi u_z
    + cos psi h cos(phi - phi0), h = sqrt(1 - u_z^2) (fiber.rs half_width_argument and
    arc_from_argument)."""
    a, b = sin_psi * u.z, cos_psi * dr.safe_sqrt(1.0 - u.z * u.z)
    t = dr.select(b < 1e-7, dr.select(a > z_min, -1.0, 1.0), (z_min - a) / dr.maximum(b, 1e-7))
    return dr.select(t <= -1.0, math.pi, dr.select(t >= 1.0, 0.0, dr.acos(dr.clip(t, -1.0, 1.0))))


def _lobe_pdf(dr, u, psi_o, i, wi_z, inv_beta, z_min):
    """Density of `_lobe_sample` about psi_o per interior solid angle at the interior direction
    with angles i and z = wi_z: g(beta, psi_i + psi_o) / (2 max(Delta, MIN_ARC) cos psi_i)
    (fiber.rs pdf_about; notes/bsdf.md §3)."""
    delta = _arc(dr, u, i.sin, i.cos, z_min)
    ok = (wi_z > z_min) & (i.cos >= MIN_COS_PSI) & (delta > 0)
    g = _gaussian(dr, inv_beta, i.psi + psi_o)
    width = 2.0 * dr.maximum(delta, MIN_ARC) * dr.maximum(i.cos, MIN_COS_PSI)
    return dr.select(ok, g / width, 0.0)


def _lobe_sample(mi, dr, u, psi_o, u2, beta, z_min):
    """An interior direction about the fibre u: psi_i from the Gaussian about -psi_o (inverse
    CDF), phi uniform on the arc above z_min widened to MIN_ARC, off-arc samples rejected
    (fiber.rs sample_about); and whether it is valid."""
    x = dr.clip(2.0 * u2.x - 1.0, -0.9999999, 0.9999999)
    psi_i = -psi_o + beta * math.sqrt(2.0) * dr.erfinv(x)
    s, c = dr.sincos(psi_i)
    v, w = mi.coordinate_system(u)
    delta = _arc(dr, u, s, c, z_min)
    offset = dr.maximum(delta, MIN_ARC) * (2.0 * u2.y - 1.0)
    sp, cp = dr.sincos(dr.atan2(w.z, v.z) + offset)
    wi_in = s * u + c * (cp * v + sp * w)
    ok = ((dr.abs(psi_i) < 0.5 * math.pi) & (c >= MIN_COS_PSI) & (delta > 0)
          & (dr.abs(offset) < delta) & (wi_in.z > z_min))
    return wi_in, ok


def _ggx_d(dr, alpha, h):
    """GGX D(h) = alpha^2 / (pi (cos^2 theta_h (alpha^2 - 1) + 1)^2), 0 for h.z <= 0 (Walter et
    al. 2007 eq. 33; ggx.rs `Ggx::d`)."""
    a2 = alpha * alpha
    t = h.z * h.z * (a2 - 1.0) + 1.0
    return dr.select(h.z > 0, a2 / (math.pi * t * t), 0.0)


def _ggx_lambda(dr, alpha, w):
    """Smith Lambda(w) = (-1 + sqrt(1 + alpha^2 tan^2 theta)) / 2 (Heitz 2014 eq. 72; ggx.rs
    `Ggx::lambda`); infinite at or below the horizon."""
    c2 = w.z * w.z
    tan2 = dr.maximum(1.0 - c2, 0.0) / dr.maximum(c2, 1e-30)
    return dr.select(c2 > 0, 0.5 * (-1.0 + dr.sqrt(1.0 + alpha * alpha * tan2)), math.inf)


class _Spread:
    """How a fibre u sees one part of the light a rough finish transmits from exterior w: its
    share, mean longitudinal angle psi = asin E[t.u], cos psi, and var psi = var(t.u) / (1 -
    E[t.u]^2) (fiber.rs `FiberAxis::spread`); E and var of t.u from the part's mean and
    covariance turned to w's azimuth (rough_transmission.rs `TransmittedPart::along`). `part`:
    (share, mean x, mean z, cov xx, cov yy, cov xz). Also 1 / max(cos psi, MIN_COS_PSI), for
    the lobe's 1 / max(cos_a, cos_b) = min(1 / max(cos_a, .), 1 / max(cos_b, .))."""

    def __init__(self, dr, w, part, u):
        share, mx, mz, cxx, cyy, cxz = part
        r2 = w.x * w.x + w.y * w.y
        inv_r = dr.rsqrt(dr.maximum(r2, 1e-12))
        c, s = dr.select(r2 > 1e-12, w.x * inv_r, 1.0), dr.select(r2 > 1e-12, w.y * inv_r, 0.0)
        ux, uy = c * u.x + s * u.y, c * u.y - s * u.x
        czz = dr.maximum(1.0 - cxx - cyy - mx * mx - mz * mz, 0.0)
        mean = dr.clip(mx * ux + mz * u.z, -0.9999, 0.9999)
        var = dr.maximum(cxx * ux * ux + cyy * uy * uy + czz * u.z * u.z + 2.0 * cxz * ux * u.z,
                         0.0)
        cos2 = 1.0 - mean * mean
        self.share, self.psi, self.var = share, dr.asin(mean), var / cos2
        self.inv_cos = 1.0 / dr.maximum(dr.sqrt(cos2), MIN_COS_PSI)


def _lobe_spread(dr, o, i, beta):
    """The energy-bounded fibre lobe seen through a rough finish (notes/bsdf.md §4.6; fiber.rs
    `FiberAxis::eval_spread`): sum over the parts a of wo's and b of wi's `_Spread`s of
    share_a share_b g(sqrt(beta^2 + var_a + var_b), psi_a + psi_b) / (2 pi max(cos_a, cos_b)),
    the constant factors 1 / (2 pi sqrt(2 pi)) taken out of the sum."""
    f = 0.0
    for a in o:
        for b in i:
            inv_var = 1.0 / (beta * beta + a.var + b.var)
            g = dr.exp(-0.5 * dr.square(a.psi + b.psi) * inv_var) * dr.sqrt(inv_var)
            f += (a.share * b.share) * g * dr.minimum(a.inv_cos, b.inv_cos)
    return f * (1.0 / (2.0 * math.pi * math.sqrt(2.0 * math.pi)))


def _sampling_about(dr, spread, beta):
    """(psi, width, 1 / width) a fibre lobe's samples are drawn with under a rough finish: the
    single scattering part's mean angle, beta widened by twice the mean variance (wood.rs
    `sampling_about`)."""
    var = spread[0].share * spread[0].var + spread[1].share * spread[1].var
    width = dr.minimum(dr.sqrt(beta * beta + 2.0 * var), 0.5 * math.pi)
    return spread[0].psi, width, 1.0 / width


def _axis_view(dr, wo, wo_in, parts, axis, beta, inv_beta):
    """How the view sees one axis (fibre or ray), shared by every wi: under a smooth finish
    (`parts` None) the refracted view's `_Angles`, under a rough one the `_Spread`s of the
    transmitted `parts`; and the (psi, width, 1 / width) its lobe's samples are drawn about."""
    if parts is None:
        a = _Angles(dr, wo_in, axis)
        return a, (a.psi, beta, inv_beta)
    spread = [_Spread(dr, wo, p, axis) for p in parts]
    return spread, _sampling_about(dr, spread, beta)


def _axis_terms(dr, seen, about, axis, wi, wi_in, parts_i, beta, inv_beta, z_min):
    """One axis's lobe at wi (no colour; `_lobe`, or `_lobe_spread` under a rough finish) and
    its sampling density per interior solid angle (`_lobe_pdf`); `seen`, `about`: `_axis_view`."""
    angles = _Angles(dr, wi_in, axis)
    if parts_i is None:
        lobe = _lobe(dr, seen, angles, inv_beta)
    else:
        lobe = _lobe_spread(dr, seen, [_Spread(dr, wi, p, axis) for p in parts_i], beta)
    return lobe, _lobe_pdf(dr, axis, about[0], angles, wi_in.z, about[2], z_min)


_CLASSES = {}


def bsdf_class(mi, dr):
    """The ``xylem_wood_baked`` class for the current variant."""
    key = mi.variant()
    if key in _CLASSES:
        return _CLASSES[key]

    def luminance(c):
        return LUMINANCE[0] * c.x + LUMINANCE[1] * c.y + LUMINANCE[2] * c.z

    class Texel:
        """The BSDF's parameters at the interaction (wood.rs `WoodBsdf::new` for the texel's
        values; `_shading_maps` derived them per texel) and its frame: the tangent frame (x
        along dp/du, y against dp/dv, z the shading normal; `_frame_axes`) or, with the bump, a
        frame about the bumped normal in it. `local` / `world` map Mitsuba's shading-frame
        directions to and from it; the lobes depend only on dot products with the normal and
        the axes, so any frame about the normal will do."""

        def __init__(self, bsdf, si, active):
            v = bsdf._lookup(si, active)
            self.diffuse_eff = mi.Color3f(v[0], v[1], v[2])
            self.beta, self.m = v[3], v[7]
            self.inv_beta = 1.0 / self.beta
            self.fiber_color = mi.Color3f(v[4], v[5], v[6])
            self.right, self.up = _frame_axes(mi, dr, si)

            def unit(a, b, c, fallback):
                """An interpolated unit vector renormalised."""
                x = mi.Vector3f(a, b, c)
                return dr.select(dr.squared_norm(x) < 1e-12, fallback, dr.normalize(x))

            self.u = unit(v[8], v[9], v[10], mi.Vector3f(1, 0, 0))
            self.r = unit(v[11], v[12], v[13], mi.Vector3f(0, 1, 0))
            self.frame = None
            if bsdf.bump > 0:
                self.frame = mi.Frame3f(unit(v[14], v[15], v[16], mi.Vector3f(0, 0, 1)))
                self.u, self.r = self.frame.to_local(self.u), self.frame.to_local(self.r)
            self.back = None
            if bsdf.two_sided:
                # Seen from behind (si.wi below the shading frame, Mitsuba's `twosided` test),
                # the frame turns half round the fibre's projection into the face, s: (s, t, n)
                # -> (s, -t, -n), as xylem's renderer faces an opaque surface to its viewer
                # (render/integrator.rs; its frame's s is that projection).
                self.back = si.wi.z < 0.0
                self.s = unit(self.u.x, self.u.y, 0.0, mi.Vector3f(1, 0, 0))

        def _turn(self, w):
            """w turned half round s where the hit is seen from behind (an involution)."""
            if self.back is None:
                return w
            return dr.select(self.back, 2.0 * dr.dot(self.s, w) * self.s - w, w)

        def local(self, w):
            """A shading-frame direction in the BSDF's frame."""
            w = mi.Vector3f(dr.dot(w, self.right), dr.dot(w, self.up), w.z)
            return self._turn(w if self.frame is None else self.frame.to_local(w))

        def world(self, w):
            w = self._turn(w)
            w = w if self.frame is None else self.frame.to_world(w)
            return self.right * w.x + self.up * w.y + mi.Vector3f(0, 0, w.z)

    class View:
        """What the BSDF needs of the view wo (Mitsuba's si.wi) alone, shared by every wi: the
        finish's transmittance T(wo); smooth: wo refracted into the finish; rough: R(wo),
        R_ms(wo) and the transmitted light's parts (wood.rs `RoughView`); and how the fibre
        axis sees it (`_axis_view`). The ray axis's view is computed where it is used, in
        `rays` branches."""

        def __init__(self, bsdf, t, wo):
            self.wo, self.wo_in, self.parts = wo, None, None
            if bsdf._rough is None:
                self.trans = bsdf._transmittance(wo.z)
                self.wo_in = _refract_in(mi, dr, wo, bsdf.eta)
            else:
                self.reflectance, self.multiple, self.parts = bsdf._finish_at(wo.z)
                self.trans = 1.0 - self.reflectance
            self.fiber = _axis_view(dr, wo, self.wo_in, self.parts, t.u, t.beta, t.inv_beta)

        def ray_args(self, t):
            """What the ray axis's view is made of (`_axis_view`'s arguments)."""
            return (self.wo, self.wo_in, self.parts, t.r, t.beta, t.inv_beta)

    class XylemWoodBaked(mi.BSDF):
        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            if not _has(props, "maps"):
                raise ValueError(
                    "xylem_wood_baked: `maps` (a `xylem bake` output folder) is required")
            self.maps = str(props.get("maps"))
            self.eta = float(props.get("eta", 1.5))
            self.roughness = float(props.get("roughness", 0.0))
            self.bump = float(props.get("bump", 1.0))
            self.two_sided = bool(props.get("two_sided", False))
            if not 0.0 <= self.bump <= 100.0:
                raise ValueError(f"xylem_wood_baked: `bump` = {self.bump}: expected 0 (off) to "
                                 "100 (1: the baked normal map as it is)")
            if not 1.0 <= self.eta <= 4.0:
                raise ValueError(f"xylem_wood_baked: `eta` = {self.eta}: expected 1 to 4")
            if not 0.0 <= self.roughness <= 1.0:
                raise ValueError(
                    f"xylem_wood_baked: `roughness` = {self.roughness}: expected 0 (smooth) to 1")
            self.pixel_angle = float(props.get("pixel_angle", 0.0))
            if not 0.0 <= self.pixel_angle <= 0.1:
                raise ValueError(f"xylem_wood_baked: `pixel_angle` = {self.pixel_angle}: "
                                 "expected 0 (no mip maps) to 0.1 rad (`pixel_angle(scene)`)")
            self._pixel_angle = mi.Float(self.pixel_angle)
            self.filter = str(props.get("filter", "stochastic"))
            if self.filter not in ("stochastic", "bilinear"):
                raise ValueError(f"xylem_wood_baked: `filter` = {self.filter!r}: expected "
                                 "'stochastic' (one texel per interaction) or 'bilinear'")
            linear = dict(filter_mode=dr.FilterMode.Linear, wrap_mode=dr.WrapMode.Clamp)
            self._linear = linear
            self._tensor = mi.TensorXf(_maps(self.maps, normal=self.bump > 0))
            eta = self.eta
            # As WoodBsdf: below roughness 1e-3 the finish is smooth (wood.rs MIN_ROUGHNESS).
            self._rough = None
            if self.roughness >= 1e-3:
                nodes = _xylem.rough_finish_nodes(self.roughness, eta)
                table = np.concatenate([nodes["reflectance"][:, None], nodes["multiple"][:, None],
                                        nodes["transmission"]], 1).astype(np.float32)
                # A 1D texture, the mu nodes at its texel centres: linear filtering is the
                # tables' interpolation in sqrt(mu).
                self._rough = mi.Texture1f(mi.TensorXf(table), **linear)
                self._ggx = mi.MicrofacetDistribution(mi.MicrofacetType.GGX, self.roughness,
                                                      True)
                self._mu_nodes = table.shape[0]
                self._ms_norm = float(nodes["ms_norm"])
                avg_reflectance = float(nodes["avg_reflectance"])
            else:
                # F_ext = 2 int_0^1 F(mu) mu dmu (fresnel.rs fresnel_diffuse_reflectance), 0 at
                # eta 1.
                mu = (_GL_X + 1.0) / 2.0
                fresnel = np.array([np.ravel(_fresnel(mi, dr, mi.Float(float(x)), eta))[0]
                                    for x in mu])
                avg_reflectance = (0.0 if eta <= 1.0
                                   else float(np.sum(_GL_W / 2.0 * 2.0 * mu * fresnel)))
            # 1 - R_int = (1 - R_avg) / eta^2 (wood.rs `escape`; notes/bsdf.md §1.3, §4.3).
            self._escape = (1.0 - avg_reflectance) / (eta * eta)
            self._f_int = 1.0 - self._escape
            self._build()
            self._z_crit = math.sqrt(max(0.0, 1.0 - 1.0 / (eta * eta)))
            self._delta = eta > 1.0 and self._rough is None
            lobes = (mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.GlossyReflection
                     | mi.BSDFFlags.FrontSide | mi.BSDFFlags.SpatiallyVarying
                     | mi.BSDFFlags.Anisotropic)
            delta = mi.BSDFFlags.DeltaReflection | mi.BSDFFlags.FrontSide
            if self.two_sided:
                lobes, delta = lobes | mi.BSDFFlags.BackSide, delta | mi.BSDFFlags.BackSide
            # Component 0: everything but a smooth finish's mirror (a rough finish's reflection
            # included); component 1: the mirror.
            self.m_components = [lobes, delta] if self._delta else [lobes]
            self.m_flags = (lobes | delta) if self._delta else lobes

        def _transmittance(self, cos):
            """1 - F of the smooth finish (Fresnel)."""
            return 1.0 - _fresnel(mi, dr, cos, self.eta)

        def _finish_at(self, mu):
            """The rough finish at exterior cosine mu: R(mu), R_ms(mu) and the transmitted
            light's two parts (share, mean x, mean z, cov xx, yy, xz), the means the smooth
            refraction plus the table's offsets (rough_transmission.rs `parts`); all linear in
            sqrt(mu) between the tables' nodes (rough_finish.rs `locate`)."""
            n = self._mu_nodes
            x = dr.sqrt(dr.clip(mu, 0.0, 1.0)) * (n - 1)
            v = self._rough.eval(mi.Point1f((x + 0.5) / n))
            mu = dr.clip(mu, 0.0, 1.0)
            refr = _refract_in(mi, dr, mi.Vector3f(dr.safe_sqrt(1.0 - mu * mu), 0.0, mu),
                               self.eta)
            single = dr.clip(v[2], 0.0, 1.0)
            parts = [(single, refr.x + v[3], refr.z + v[4], v[5], v[6], v[7]),
                     (1.0 - single, refr.x + v[8], refr.z + v[9], v[10], v[11], v[12])]
            return v[0], v[1], parts

        def _reflection(self, wo, wi, multiple_o, multiple_i):
            """The rough finish's reflection (no cosine), F(wo.h) D G2 / (4 mu_o mu_i) (Walter
            et al. 2007 eq. 20; Heitz 2014 eq. 99) plus the multiple-scattering lobe R_ms(mu_o)
            R_ms(mu_i) / (pi avg R_ms) (Kulla & Conty 2017; rough_finish.rs `reflection`); and
            the half vector."""
            a = self.roughness
            h = dr.normalize(wo + wi)
            g2 = 1.0 / (1.0 + _ggx_lambda(dr, a, wo) + _ggx_lambda(dr, a, wi))
            single = (_fresnel(mi, dr, dr.dot(wo, h), self.eta) * _ggx_d(dr, a, h) * g2
                      / (4.0 * wo.z * wi.z))
            f = single + multiple_o * multiple_i * self._ms_norm
            return dr.select(h.z > 0, f, 0.0), h

        def _reflection_pdf(self, wo, h):
            """Density of wi = reflect(wo, h) for h drawn from the visible normals: G1(wo) D(h)
            / (4 wo.z) (Heitz 2018; ggx.rs `reflection_pdf`)."""
            a = self.roughness
            p = _ggx_d(dr, a, h) / ((1.0 + _ggx_lambda(dr, a, wo)) * 4.0 * wo.z)
            return dr.select((wo.z > 0) & (dr.dot(wo, h) > 0), p, 0.0)

        def _enabled(self, ctx):
            """(the mirror, the other lobes) as `ctx` asks for them (component 1 / 0)."""
            return (self._delta and ctx.is_enabled(mi.BSDFFlags.DeltaReflection, 1),
                    ctx.is_enabled(mi.BSDFFlags.GlossyReflection, 0))

        def _probs(self, t, view, ctx):
            """Lobe probabilities for wo, proportional to each lobe's estimated albedo
            (wood.rs `lobe_probs`): the finish's reflection (smooth: F; rough: R - R_ms),
            diffuse T lum(rho'') (1 - R_int) (+ R_ms, drawn with the diffuse), fibre and ray
            T lum(k_f) / pi (1 - m) and m; a lobe `ctx` leaves out gets 0."""
            mirror, rest = self._enabled(ctx)
            zero = mi.Float(0.0)
            ms = zero
            if self._rough is None:
                spec = _fresnel(mi, dr, view.wo.z, self.eta) if mirror else zero
            elif rest:
                spec = dr.maximum(view.reflectance - view.multiple, 0.0)
                ms = view.multiple
            else:
                spec = zero
            tr = view.trans if rest else zero
            diff = tr * luminance(t.diffuse_eff) * self._escape + ms
            kf = tr * luminance(t.fiber_color) / math.pi
            fib, ray = kf * (1.0 - t.m), kf * t.m
            total = spec + diff + fib + ray
            inv = dr.select(total > 0, 1.0 / total, 0.0)
            return spec * inv, diff * inv, fib * inv, ray * inv

        def _rays(self, t, fn, args):
            """fn(*args), two Floats, where the texel has rays (ray mask m > 0), zeros where it
            has none (m multiplies the ray lobe and its probability). Under a rough finish a
            symbolic branch, which a packet of lanes with no rays skips (86 % of a mahogany
            board's texels have m = 0): 0.93x the render's time. The smooth finish's ray lobe
            is cheap (no spreads), and there the branch saved nothing measurable (0.98x,
            0.93-1.14) while tracing it cost every render 3.5 ms more, so it is computed
            everywhere."""
            if self._rough is None:
                return fn(*args)
            return dr.if_stmt(args, t.m > 0.0, fn, lambda *_: (mi.Float(0.0), mi.Float(0.0)))

        def _eval_pdf(self, t, view, probs, wi):
            """xylem's f (no cosine) and the sampling density, sharing the refracted directions
            and the longitudinal angles. f = T(wo) T(wi) / eta^2 (rho''/pi + k_f ((1 - m)
            f_fib + m f_ray)) (notes/bsdf.md eq. 1.4), the fibre lobes of the directions
            refracted into a smooth finish or seen through a rough one (`_lobe_spread`), plus a
            rough finish's reflection; the density of the non-delta lobes' mixture (wood.rs
            `density`): diffuse cos/pi, the fibre lobes' interior densities times d w_int /
            d w_ext = cos theta_i / (eta^2 cos theta_i') (notes/bsdf.md §1.1), a rough
            finish's visible-normal density. Zero where either cosine is <= 0 or where not
            finite."""
            eta, wo, z_crit = self.eta, view.wo, self._z_crit
            wi_in = _refract_in(mi, dr, wi, eta)
            parts = None
            if self._rough is None:
                trans_i = self._transmittance(wi.z)
            else:
                reflectance_i, multiple_i, parts = self._finish_at(wi.z)
                trans_i = 1.0 - reflectance_i
            fiber = _axis_terms(dr, *view.fiber, t.u, wi, wi_in, parts, t.beta, t.inv_beta,
                                z_crit)

            def ray(wo, wo_in, parts_o, r, beta, inv_beta, wi, wi_in, parts):
                seen, about = _axis_view(dr, wo, wo_in, parts_o, r, beta, inv_beta)
                return _axis_terms(dr, seen, about, r, wi, wi_in, parts, beta, inv_beta, z_crit)

            ray = self._rays(t, ray, view.ray_args(t) + (wi, wi_in, parts))
            lobes, dens = (fiber[0], ray[0]), (fiber[1], ray[1])
            substrate = t.diffuse_eff / math.pi + t.fiber_color * (
                (1.0 - t.m) * lobes[0] + t.m * lobes[1])
            f = substrate * (view.trans * trans_i / (eta * eta))
            jac = wi.z / (eta * eta) / dr.maximum(wi_in.z, 1e-7)
            pdf = probs[1] * wi.z / math.pi + (probs[2] * dens[0] + probs[3] * dens[1]) * jac
            if self._rough is not None:
                reflection, h = self._reflection(wo, wi, view.multiple, multiple_i)
                f += reflection
                pdf += probs[0] * self._reflection_pdf(wo, h)
            ok = (wo.z > 0) & (wi.z > 0)
            f = dr.select(ok & dr.isfinite(f.x + f.y + f.z), dr.maximum(f, 0.0), 0.0)
            return f, dr.select(ok & dr.isfinite(pdf), pdf, 0.0)

        # Mitsuba's si.wi (towards the viewer) is xylem's wo; its `wo` (towards the light) is
        # xylem's wi. Mitsuba's eval carries the cosine of its wo.
        def eval(self, ctx, si, wo, active=True):
            return self.eval_pdf(ctx, si, wo, active)[0]

        def pdf(self, ctx, si, wo, active=True):
            return self.eval_pdf(ctx, si, wo, active)[1]

        def eval_pdf(self, ctx, si, wo, active=True):
            t = Texel(self, si, active)
            view = View(self, t, t.local(si.wi))
            wi = t.local(wo)
            f, pdf = self._eval_pdf(t, view, self._probs(t, view, ctx), wi)
            # (wi.z > 0: f is 0 elsewhere already, and a NaN direction's f * wi.z is NaN.)
            active = active & self._enabled(ctx)[1] & (wi.z > 0)
            return dr.select(active, f * wi.z, 0.0), dr.select(active, pdf, 0.0)

        def sample(self, ctx, si, sample1, sample2, active=True):
            """A lobe by `sample1` over the cumulative probabilities (finish, diffuse, fibre,
            ray; wood.rs `pick`), a direction from it by `sample2` (wood.rs `sample`): the
            smooth finish's mirror, or a visible GGX normal (Mitsuba's sampler of D_vis, the
            density `_reflection_pdf` states), cosine-weighted, or about the fibre or ray
            axis."""
            t = Texel(self, si, active)
            wo = t.local(si.wi)
            view = View(self, t, wo)
            probs = self._probs(t, view, ctx)
            # (Comparisons, not `~`: the scalar variant's masks are Python bools.)
            c1, c2 = probs[0] + probs[1], probs[0] + probs[1] + probs[2]
            spec = sample1 < probs[0]
            diff = (sample1 >= probs[0]) & (sample1 < c1)
            # (A ray lobe of probability 0 is never picked, also where c2 rounds below 1.)
            fib = (sample1 >= c1) & ((sample1 < c2) | (probs[3] <= 0))
            axis = dr.select(fib, t.u, t.r)
            ray_about = self._rays(t, lambda *args: _axis_view(dr, *args)[1][:2],
                                   view.ray_args(t))
            psi, width = (dr.select(fib, a, b) for a, b in zip(view.fiber[1], ray_about))
            wi_in, lobe_ok = _lobe_sample(mi, dr, axis, psi, sample2, width, self._z_crit)
            wi_lobe, leaves = _refract_out(mi, dr, wi_in, self.eta)
            if self._rough is None:
                wi_spec = mi.Vector3f(-wo.x, -wo.y, wo.z)
            else:
                h = self._ggx.sample(wo, sample2)[0]
                wi_spec = 2.0 * dr.dot(wo, h) * h - wo
            wi = dr.select(spec, wi_spec,
                           dr.select(diff, mi.warp.square_to_cosine_hemisphere(sample2), wi_lobe))
            f, pdf = self._eval_pdf(t, view, probs, wi)
            ok = active & (wo.z > 0) & (wi.z > 0) & (spec | diff | (lobe_ok & leaves))
            bs = dr.zeros(mi.BSDFSample3f, dr.width(sample1))
            # A direction made of non-finite inputs (pdf 0 there) is the normal instead.
            world = t.world(wi)
            bs.wo = dr.select(dr.isfinite(world.x + world.y + world.z), world,
                              mi.Vector3f(0, 0, 1))
            bs.eta = 1.0
            if self._rough is None:
                ok &= spec | (pdf > 0)
                bs.pdf = dr.select(ok, dr.select(spec, probs[0], pdf), 0.0)
                bs.sampled_type = dr.select(spec, mi.UInt32(+mi.BSDFFlags.DeltaReflection),
                                            mi.UInt32(+mi.BSDFFlags.GlossyReflection))
                bs.sampled_component = dr.select(spec, mi.UInt32(1), mi.UInt32(0))
                # The mirror's weight F / P(specular) (f = F / cos); the rest f cos / pdf.
                mirror = _fresnel(mi, dr, wo.z, self.eta) / dr.maximum(probs[0], 1e-30)
                weight = f * wi.z / dr.select(pdf > 0, pdf, 1.0)
                weight = dr.select(spec, mi.Color3f(mirror), weight)
            else:
                ok &= pdf > 0
                bs.pdf = dr.select(ok, pdf, 0.0)
                bs.sampled_type = dr.select(diff, mi.UInt32(+mi.BSDFFlags.DiffuseReflection),
                                            mi.UInt32(+mi.BSDFFlags.GlossyReflection))
                bs.sampled_component = mi.UInt32(0)
                weight = f * wi.z / dr.select(pdf > 0, pdf, 1.0)
            return bs, dr.select(ok, weight, 0.0)

        def traverse(self, callback):
            callback.put("maps", self._tensor, mi.ParamFlags.Differentiable)
            callback.put("pixel_angle", self._pixel_angle, mi.ParamFlags.NonDifferentiable)

        def _build(self):
            """What the BSDF looks up (`_shading_maps`), one texture a level, so that a lookup
            computes its taps and weights once; with a `pixel_angle`, its mip levels down to
            one texel (`_halve`)."""
            jit = _Jit(mi, dr)
            level = _shading_maps(mi, dr, jit, self._tensor, self.bump, self._f_int)
            levels = [level]
            while self.pixel_angle > 0 and max(level.shape[:2]) > 1:
                level = _halve(dr, jit, level)
                levels.append(level)
            self._levels = len(levels)
            if len(levels) > 1:
                level, boxes = _atlas(dr, jit, levels)
                # Per level (width, height, x offset, y offset); the scalar variant indexes a
                # numpy array where the JIT variants gather.
                wrap = mi.Float if dr.is_jit_v(mi.Float) else (lambda a: a)
                self._boxes = [wrap(np.array(b, np.float32)) for b in zip(*boxes)]
            table = jit.out(level)
            # Evaluated here: the stochastic lookups gather from it inside Mitsuba's kernel.
            dr.make_opaque(table)
            self._table = table
            # Only the bilinear filter reads it through a texture.
            self._texture = (mi.Texture2f(table, **self._linear) if self.filter == "bilinear"
                             else None)

        def parameters_changed(self, keys=None):
            angle = self._pixel_angle
            self.pixel_angle = float(angle if isinstance(angle, float) else angle[0])
            self._build()

        def _lookup(self, si, active):
            """The shading maps at si.uv: one texel drawn by its bilinear weight (`filter`
            "stochastic", `_stochastic_lookup`), or bilinear in level 0; with a `pixel_angle`,
            in the mip level about log2 of the footprint's width in texels (`_mip_level`),
            drawn by its weight or trilinear between the two (each level looked up in the
            atlas, `_atlas`, clamped to its texels)."""
            # A non-finite uv (a degenerate mesh's) reads texel (0, 0), and a huge one the edge
            # as Clamp does, rather than NaNs (Dr.Jit's texture overflows its index) or, drawn
            # stochastically, an index out of the table.
            finite = dr.isfinite(si.uv.x) & dr.isfinite(si.uv.y)
            uv = mi.Point2f(*(dr.clip(dr.select(finite, c, 0.0), -1.0, 2.0)
                              for c in (si.uv.x, si.uv.y)))
            if self.filter == "stochastic":
                return self._stochastic_lookup(si, uv, active)
            if self._levels == 1:
                return self._texture.eval(uv, active)
            lower, frac = self._mip_level(si)
            atlas = self._table.shape

            def at(level, uv, active):
                x, y, _ = self._in_level(level, uv, active)
                return self._texture.eval(mi.Point2f(x / atlas[1], y / atlas[0]), active)

            def upper(lower, uv, frac, active):
                return tuple(x * frac for x in at(lower + 1, uv, active & (frac > 0.0)))

            def none(lower, uv, frac, active):
                return tuple(mi.Float(0.0) for _ in range(atlas[2]))

            top = dr.if_stmt((lower, uv, frac, active), frac > 0.0, upper, none)
            return [a * (1.0 - frac) + b for a, b in zip(at(lower, uv, active), top)]

        def _mip_level(self, si):
            """The mip level below the footprint and the weight of the one above: log2 of the
            footprint's width in texels, a ray cone's (Amanatides 1984; Akenine-Moeller et al.
            2019): width pixel_angle * si.t across the ray, 1 / cos theta longer along the
            surface, in texels by the texels per unit area, W H / |dp/du x dp/dv|. At a camera
            hit si.t is the distance from the camera; at later bounces the segment from the
            last vertex, which underestimates the cone (sharper, never blurrier)."""
            h, w = self._tensor.shape[:2]
            area = dr.norm(dr.cross(si.dp_du, si.dp_dv))
            per_length = dr.select(area > 1e-20, dr.rsqrt(dr.maximum(area, 1e-20)), 0.0)
            texels = (self._pixel_angle * si.t * math.sqrt(h * w) * per_length
                      / dr.maximum(dr.abs(si.wi.z), 1e-3))
            texels = dr.select(dr.isfinite(texels) & (texels > 1.0), texels, 1.0)
            lam = dr.clip(dr.log2(texels), 0.0, self._levels - 1.0)
            lower = dr.minimum(mi.UInt32(dr.floor(lam)), self._levels - 1)
            return lower, lam - mi.Float(lower)

        def _in_level(self, level, uv, active):
            """uv in mip level `level`'s texels in the atlas, clamped to its texel centres (so
            that no other level bleeds in), and the level's box: (x, y, (x0, y0, x1, y1)) with
            its first and last texels."""
            if dr.is_jit_v(mi.Float):
                w, h, ox, oy = (dr.gather(mi.Float, b, level, active) for b in self._boxes)
            else:
                w, h, ox, oy = (float(b[int(level)]) for b in self._boxes)
            x = dr.clip(uv.x * w, 0.5, w - 0.5) + ox
            y = dr.clip(uv.y * h, 0.5, h - 0.5) + oy
            return x, y, (ox, oy, ox + w - 1.0, oy + h - 1.0)

        def _stochastic_lookup(self, si, uv, active):
            """Stochastic texture filtering (Pharr, Wronski, Salvi & Fajardo 2024, "Filtering
            after shading with stochastic texture filtering"): one texel, drawn with the
            bilinear weights (and, with mip maps, one level drawn with the trilinear weight),
            by numbers hashed from the interaction (`_interaction_numbers`), so that eval_pdf
            and sample at one interaction see the same texel. The BSDF is then filtered after
            shading: its expectation is the bilinear (trilinear) average of the texels' BSDFs
            rather than the BSDF of the averaged parameters, for a quarter (an eighth) of the
            gathers. At texel centres it is the texel's value exactly."""
            xi = _interaction_numbers(mi, dr, uv, 3 if self._levels > 1 else 2)
            height, width, channels = self._table.shape
            if self._levels == 1:
                x, y = uv.x * width, uv.y * height
                lo_x, lo_y, hi_x, hi_y = 0.0, 0.0, width - 1.0, height - 1.0
            else:
                lower, frac = self._mip_level(si)
                level = lower + dr.select(xi[2] < frac, mi.UInt32(1), mi.UInt32(0))
                x, y, (lo_x, lo_y, hi_x, hi_y) = self._in_level(level, uv, active)

            def pick(t, u, lo, hi):
                """Texel index along one axis: the lower neighbour of t - 1/2, or the upper
                with probability its bilinear weight; clamped as Dr.Jit's Clamp wrap mode."""
                t = t - 0.5
                i = dr.floor(t)
                i = dr.select(u < t - i, i + 1.0, i)
                return dr.minimum(mi.UInt32(dr.clip(i, lo, hi)), mi.UInt32(hi))

            texel = pick(y, xi[1], lo_y, hi_y) * width + pick(x, xi[0], lo_x, hi_x)
            index = texel * channels
            if not dr.is_jit_v(mi.Float):
                return [mi.Float(self._table.array[index + k]) for k in range(channels)]
            return [dr.gather(mi.Float, self._table.array, index + k, active)
                    for k in range(channels)]

        def to_string(self):
            return (f"XylemWoodBaked[maps={self.maps}, eta={self.eta}, "
                    f"roughness={self.roughness}, bump={self.bump}, "
                    f"pixel_angle={self.pixel_angle}, filter={self.filter}, "
                    f"two_sided={self.two_sided}]")

    _CLASSES[key] = XylemWoodBaked
    return XylemWoodBaked


def pixel_angle(scene, sensor=0):
    """The ray-cone angle of one camera sample of `scene`'s sensor (radians): for a
    ``perspective`` camera 2 tan(fov_x / 2) / width, the angle a pixel subtends at the image
    centre, divided by sqrt(spp) (each sample's share of the pixel, as Mitsuba scales ray
    differentials). Give it to ``xylem_wood_baked`` as ``pixel_angle`` for mip-mapped lookups
    (`set_pixel_angle` does so for every one in the scene)."""
    import mitsuba as mi

    cam = scene.sensors()[sensor]
    params = mi.traverse(cam)
    fov = next(float(params[k][0] if hasattr(params[k], "__len__") else params[k])
               for k in params.keys() if k.endswith("x_fov"))
    width = cam.film().crop_size()[0]
    spp = cam.sampler().sample_count()
    return 2.0 * math.tan(math.radians(fov) / 2.0) / width / math.sqrt(spp)


def set_pixel_angle(scene, angle=None):
    """Sets ``pixel_angle`` (default `pixel_angle(scene)`) on every ``xylem_wood_baked`` in
    `scene` and updates them; returns the angle."""
    import mitsuba as mi

    angle = pixel_angle(scene) if angle is None else float(angle)
    params = mi.traverse(scene)
    keys = [k for k in params.keys() if k.endswith(".pixel_angle") or k == "pixel_angle"]
    for k in keys:
        params[k] = mi.Float(angle)
    params.update()
    return angle

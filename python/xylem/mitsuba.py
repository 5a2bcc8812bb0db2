"""A Mitsuba 3 BSDF plugin, ``xylem_wood``: xylem's wood volume under a finish, shaded by
xylem's finished-wood BSDF at every hit point.

    import mitsuba as mi
    mi.set_variant("llvm_ad_rgb")          # or "scalar_rgb"
    import xylem.mitsuba
    xylem.mitsuba.register()
    bsdf = mi.load_dict({"type": "xylem_wood", "preset": "african_mahogany", "seed": 7,
                         "eta": 1.5, "roughness": 0.0, "units": "mm",
                         "origin": "0, 120, 0", "axis": "1, 0, 0", "rotation_deg": 0.0})

Parameters: ``preset`` (a built-in name) or ``preset_file`` (a preset TOML), ``seed`` (the tree),
the finish ``eta`` (1-4) and ``roughness`` (0-1), and the tree placement of xylem's solid cutting
in world space, ``p_tree = origin + scale * Rz(rotation_deg) * A * p`` with ``A`` turning
``axis`` onto the pith: ``origin`` (tree mm), ``axis`` (3-vectors, as a "x, y, z" string or a
sequence) and ``rotation_deg``.

Units: ``units`` is the length of one scene unit, one of ``"m"`` (the default: Mitsuba scenes are
usually modelled in metres), ``"cm"``, ``"mm"`` (xylem's own scenes), ``"in"``, ``"ft"``; or give
``scale``, tree millimetres per scene unit (``units="m"`` is ``scale=1000``; not both). xylem's
tree is in millimetres (growth rings a few mm apart), so a scene in metres read as millimetres
would show a 0.3 m board as 0.3 mm of wood: one ring, no grain. ``origin`` is in tree mm
whatever the units.

Cost: the wood (tree point, texel, BSDF parameters) is evaluated once per surface interaction
and shared by ``eval_pdf``, ``eval``, ``pdf`` and ``sample`` at that interaction (Mitsuba's
path integrator calls ``eval_pdf`` for emitter sampling and ``sample`` at every bounce's ``si``):
the plugin keeps the last interaction's prepared wood (``WoodSurface.prepare``), keyed by the
Dr.Jit variables of ``si.p`` and ``si.sh_frame`` and, failing that, by their values, until
``sample`` (the last call at an interaction) releases it. ``share_wood`` (default true) is a
debug switch: false evaluates the wood again in every call, as before (the tests' control).

Contexts: ``BSDFContext`` masks select Mitsuba's components, 0 (the diffuse and fibre lobes, and
a rough finish's reflection) and 1 (a smooth finish's mirror), as ``xylem_wood_baked``'s do.
Every mask of whole components is honoured: none gives zeros; the mirror alone is sampled
exactly (the mirror direction with probability 1, Fresnel's reflectance as its weight); the
other lobes alone are drawn with the mirror's share of ``uc`` skipped (xylem picks the mirror
first, for ``uc`` below ``WoodHits.mirror_probability``) and their density divided by the
share left. A mask that keeps part of component 0 (its diffuse lobe but not its glossy fibre
lobes, or the reverse) raises ``NotImplementedError``: xylem draws those together. The
transport mode is not read (xylem's BSDF has no adjoint form).

Frames: Mitsuba hands the BSDF directions in the hit's shading frame ``si.sh_frame``. xylem
shades the world point with the frame it builds itself (z = the same shading normal, x along the
fibre), exactly as xylem's renderer does; ``WoodSurface.prepare`` composes the two into one
rotation per hit (Mitsuba's local -> world -> xylem's local), so cosines are the same in both
frames. Mitsuba's ``si.wi`` is xylem's ``wo`` (towards the
viewer) and Mitsuba's ``wo`` is xylem's ``wi`` (towards the light). Mitsuba's ``eval`` includes
the cosine foreshortening, xylem's does not; ``sample`` returns the weight f cos / pdf.

In the LLVM (JIT) variants the plugin reads its inputs into numpy, so Dr.Jit's symbolic loops,
calls and conditionals must be off while it renders: render inside ``with
xylem.mitsuba.evaluated():``, which turns them off for the block and restores them after
(rendering then runs in evaluated, wavefront mode). ``register()`` changes no global state; a
plugin call in a symbolic scope raises an error saying so instead. Dr.Jit traces a symbolic
call for every registered BSDF, so while a ``xylem_wood`` BSDF is alive, symbolic renders of
other scenes in the same process raise that error too: render them inside ``evaluated()`` as
well, or in another process.

The plugin is not differentiable (its inputs go through numpy): a call whose inputs carry
gradients (``dr.grad_enabled``) raises ``NotImplementedError`` rather than returning values
whose derivatives would be silently wrong. ``mi.traverse`` shows ``eta``, ``roughness`` and
``seed`` (non-differentiable); changing them and calling ``params.update()`` rebuilds the wood.
"""

import contextlib
import threading

import numpy as np

from . import WoodSurface

_REGISTERED = False


def _has(props, name):
    try:
        return name in props
    except TypeError:  # Mitsuba before 3.6
        return props.has_property(name)


def _vector(props, name, default):
    if not _has(props, name):
        return tuple(float(x) for x in default)
    value = props.get(name)
    if isinstance(value, str):
        parts = [p for p in value.replace(",", " ").split() if p]
    else:
        parts = list(value)
    if len(parts) != 3:
        raise ValueError(f"xylem_wood: `{name}` = {value!r}: expected three numbers x, y, z")
    return tuple(float(x) for x in parts)


# Tree millimetres per scene unit for `units` (xylem's tree is in mm).
UNITS = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4, "ft": 304.8}
DEFAULT_UNITS = "m"


def _units(props):
    """(units, tree mm per scene unit) from `units` (a name in UNITS, default metres) or
    `scale` (a number; the two together are an error)."""
    has_units, has_scale = _has(props, "units"), _has(props, "scale")
    if has_units and has_scale:
        raise ValueError("xylem_wood: give `units` or `scale` (tree mm per scene unit), not both")
    if has_scale:
        scale = float(props.get("scale"))
        return f"{scale:g} mm", scale
    units = props.get("units") if has_units else DEFAULT_UNITS
    if units not in UNITS:
        raise ValueError(
            f"xylem_wood: `units` = {units!r}: expected one of {', '.join(UNITS)} "
            "(or `scale`, tree mm per scene unit)"
        )
    return units, UNITS[units]


_SYMBOLIC = ("SymbolicLoops", "SymbolicCalls", "SymbolicConditionals")


@contextlib.contextmanager
def evaluated():
    """Dr.Jit's symbolic loops, calls and conditionals off inside the block, as the plugin
    needs in JIT variants (``with xylem.mitsuba.evaluated(): image = mi.render(scene)``); the
    flags are restored when the block ends, also on an exception."""
    import drjit as dr

    with contextlib.ExitStack() as stack:
        for name in _SYMBOLIC:
            stack.enter_context(dr.scoped_set_flag(getattr(dr.JitFlag, name), False))
        yield


def register():
    """Registers the ``xylem_wood`` BSDF (render JIT variants inside ``evaluated()``) and the
    Dr.Jit-native ``xylem_wood_baked`` (``xylem.mitsuba_baked``: baked maps, symbolic modes,
    differentiable) with Mitsuba 3 (a variant must be set first). Changes no Dr.Jit flag."""
    global _REGISTERED
    import drjit as dr
    import mitsuba as mi

    if mi.variant() is None:
        raise RuntimeError("xylem.mitsuba.register(): call mitsuba.set_variant(...) first")
    mi.register_bsdf("xylem_wood", lambda props: _make(mi, dr, props))
    from . import mitsuba_baked

    mi.register_bsdf("xylem_wood_baked", lambda props: mitsuba_baked.bsdf_class(mi, dr)(props))
    _REGISTERED = True


def _make(mi, dr, props):
    return _bsdf_class(mi, dr)(props)


_CLASSES = {}


def _bsdf_class(mi, dr):
    """The BSDF class for the current variant (Mitsuba's types differ per variant)."""
    key = mi.variant()
    if key in _CLASSES:
        return _CLASSES[key]
    scalar = key.startswith("scalar")

    def to_np3(v):
        """A Mitsuba 3-vector (scalar or wide) as an (N, 3) float32 array (a transposed view of
        Dr.Jit's (3, N) copy; the bindings read strided arrays, so no second copy is made)."""
        return np.asarray(v, dtype=np.float32).reshape(3, -1).T

    def to_np2(v):
        return np.asarray(v, dtype=np.float32).reshape(2, -1).T

    def to_np1(v):
        return np.asarray(v, dtype=np.float32).reshape(-1)

    def from_np3(cls, a):
        return cls(a[0]) if scalar else cls(a.T)

    def from_np1(a):
        return mi.Float(float(a[0])) if scalar else mi.Float(a)

    def from_bool(a):
        return mi.Bool(bool(a[0])) if scalar else mi.Bool(a)

    def frame_np(frame):
        """A Mitsuba frame (scalar or wide) as (N, 3, 3) rows s, t, n (a strided view)."""
        rows = [np.asarray(v, dtype=np.float32).reshape(3, -1) for v in (frame.s, frame.t, frame.n)]
        return np.stack(rows).transpose(2, 0, 1)

    def jit_key(si):
        """The Dr.Jit variables of the interaction's point and shading frame: their indices
        (the cache key) and the arrays themselves (held with the cache entry, so that no index
        can be freed and reused while it is a key: Dr.Jit variables are immutable and an
        in-place update of a held one gets a new index)."""
        fr = si.sh_frame
        held = [type(c)(c) for v in (si.p, fr.s, fr.t, fr.n) for c in (v.x, v.y, v.z)]
        return (dr.width(si.p),) + tuple(c.index for c in held), held

    class XylemWood(mi.BSDF):
        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            preset = props.get("preset") if _has(props, "preset") else None
            preset_file = (
                props.get("preset_file") if _has(props, "preset_file") else None
            )
            self.eta = float(props.get("eta", 1.5))
            self.roughness = float(props.get("roughness", 0.0))
            self.seed = int(props.get("seed", 0))
            self.units, scale = _units(props)
            self._wood = dict(
                preset_file=preset_file,
                origin=_vector(props, "origin", (0, 0, 0)),
                axis=_vector(props, "axis", (0, 0, 1)),
                rotation_deg=float(props.get("rotation_deg", 0.0)),
                scale=scale,
            )
            # Debug switch for the tests' negative control: False evaluates the wood again in
            # every call (the behaviour before issue 30's shared evaluation).
            self.share_wood = bool(props.get("share_wood", True))
            self._preset = preset
            self._build()
            self.name = preset if preset is not None else preset_file

        def _build(self):
            """The WoodSurface and the lobes of the current eta, roughness and seed."""
            self.surface = WoodSurface(self._preset, seed=self.seed, eta=self.eta,
                                       roughness=self.roughness, **self._wood)
            # One cache entry per calling thread, keyed by its OS thread id: the scalar variant
            # calls from Mitsuba's render threads, whose eval_pdf and sample at one interaction
            # must not meet another thread's entry. (Not `threading.local`: a foreign thread's
            # Python state, and what it holds, may be dropped between two calls.)
            self._entries = {}
            smooth = self.eta > 1.0 and self.roughness < 1e-3
            lobes = (
                mi.BSDFFlags.DiffuseReflection
                | mi.BSDFFlags.GlossyReflection
                | mi.BSDFFlags.FrontSide
                | mi.BSDFFlags.SpatiallyVarying
                | mi.BSDFFlags.Anisotropic
            )
            delta = mi.BSDFFlags.DeltaReflection | mi.BSDFFlags.FrontSide
            # Component 0: everything but the smooth finish's mirror; component 1: the mirror.
            self.m_components = [lobes, delta] if smooth else [lobes]
            self.m_flags = (lobes | delta) if smooth else lobes

        def _frame(self, si):
            """Mitsuba's shading frame, or the identity where it is unset (a zero-initialised
            interaction, as `mitsuba.chi2.BSDFAdapter` makes)."""
            n = si.sh_frame.n
            unset = dr.squared_norm(n) < 0.5
            s = dr.select(unset, mi.Vector3f(1, 0, 0), si.sh_frame.s)
            t = dr.select(unset, mi.Vector3f(0, 1, 0), si.sh_frame.t)
            n = dr.select(unset, mi.Vector3f(0, 0, 1), n)
            return mi.Frame3f(s, t, n)

        @staticmethod
        def _finite(bad, *arrays):
            """`bad` (numpy, per lane) or'ed with the lanes where any of the (N, k) `arrays`
            holds NaN or infinity, and the arrays with such lanes made harmless (points 0,
            directions and numbers the normal's and 1/2's). A lane masked off with garbage in
            it, or a degenerate mesh's, then shades to zero rather than the bindings refusing
            the whole batch for one non-finite number; done in numpy, where the inputs are
            anyway (Dr.Jit masks cost a kernel each in `evaluated()` mode: 1.27x the render)."""
            for a in arrays:
                bad = bad | ~np.isfinite(a).reshape(len(a), -1).all(1)
            if not bad.any():
                return (bad,) + arrays
            clean = []
            for a in arrays:
                fill = np.full(a.shape[1:], 0.5, np.float32)
                if a.shape[1:] == (3,):
                    fill = np.array([0, 0, 1], np.float32)
                clean.append(np.where(bad.reshape((-1,) + (1,) * (a.ndim - 1)), fill, a)
                             .astype(np.float32))
            return (bad,) + tuple(clean)

        def _check(self, *values):
            """Refuses what the plugin cannot do right: a symbolic scope (it reads its inputs
            into numpy) and inputs that carry gradients (it is not differentiable)."""
            if not scalar and dr.flag(dr.JitFlag.SymbolicScope):
                raise RuntimeError(
                    "xylem_wood reads its inputs into numpy and cannot run in a symbolic "
                    "Dr.Jit scope: render inside `with xylem.mitsuba.evaluated():`"
                )
            if any(dr.grad_enabled(v) for v in values):
                raise NotImplementedError(
                    "xylem_wood is not differentiable (its inputs go through numpy, so "
                    "derivatives would be wrong): use it in primal renders only, with no "
                    "gradients enabled on the geometry, the sensor or the directions"
                )

        def _enabled(self, ctx):
            """(the mirror, the other lobes) as `ctx` asks for them (component 1 / 0, as
            `xylem_wood_baked`'s): True, False, or None where `ctx` keeps part of component
            0's lobes (its diffuse but not its glossy ones, or the reverse), which this plugin
            cannot split."""
            flags = mi.BSDFFlags
            diffuse = ctx.is_enabled(flags.DiffuseReflection, 0)
            glossy = ctx.is_enabled(flags.GlossyReflection, 0)
            rest = diffuse if diffuse == glossy else None
            mirror = len(self.m_components) == 2 and ctx.is_enabled(flags.DeltaReflection, 1)
            return mirror, rest

        def _mask(self, ctx):
            """What `ctx` leaves of the BSDF: "all", "none", "mirror" (a smooth finish's
            mirror alone, sampled here exactly) or "rest" (a smooth finish's other lobes:
            drawn with the mirror's share of `uc` skipped and their density divided by what
            is left, `WoodHits.mirror_probability`). A mask that keeps part of component 0's
            lobes (its diffuse but not its glossy ones) is refused: the plugin draws those
            together; `xylem_wood_baked` cannot split them either."""
            mirror, rest = self._enabled(ctx)
            smooth = len(self.m_components) == 2
            if rest is True:
                return "all" if mirror or not smooth else "rest"
            if rest is False:
                return "mirror" if mirror else "none"
            raise NotImplementedError(
                f"xylem_wood cannot honour this BSDFContext (component {ctx.component}, type "
                f"mask {ctx.type_mask:#x}): it keeps part of the diffuse and fibre lobes, "
                "which the plugin draws together")

        def _kept(self, hits, wi):
            """(p, 1 - p) at `wi` (numpy): the mirror's probability and the share of
            `sample`'s draws the smooth finish's other lobes take."""
            p = hits.mirror_probability(wi)
            return p, (1.0 - p).astype(np.float32)

        def _hits(self, si):
            """The wood at the interaction's points, shaded once (`WoodSurface.prepare`) and
            shared by every call at the same interaction: the path integrator calls
            `eval_pdf` (emitter sampling) and `sample` at each bounce's `si`. Cached by the
            Dr.Jit variables of `si.p` and `si.sh_frame` (held while cached) and, when they
            differ, by their values (an interaction gathered again holds the same numbers in
            new variables); the scalar variant keys by value only. One entry per thread: a new
            interaction replaces the old one, and `sample` releases it. Returns the `WoodHits`
            and, as numpy, the lanes whose point or frame is not finite (shaded at the origin
            in the identity frame; their BSDF values are set to zero, `_finite`)."""
            thread = threading.get_ident()
            cached = self._entries.get(thread)
            key = held = None
            if not scalar:
                key, held = jit_key(si)
                if cached is not None and cached[0] == key:
                    return cached[1]
            p, frame = to_np3(si.p), frame_np(self._frame(si))
            bad = ~(np.isfinite(p).all(1) & np.isfinite(frame).reshape(len(frame), -1).all(1))
            if bad.any():
                p = np.where(bad[:, None], 0.0, p).astype(np.float32)
                frame = np.where(bad[:, None, None], np.eye(3, dtype=np.float32), frame)
            if cached is not None:
                _, hits, p0, frame0, _ = cached
                if np.array_equal(p, p0) and np.array_equal(frame, frame0):
                    self._entries[thread] = (key, hits, p0, frame0, held)
                    return hits
            hits = (self.surface.prepare(p, frame), bad)
            if self.share_wood:
                self._entries[thread] = (key, hits, p, frame, held)
            return hits

        def eval(self, ctx, si, wo, active=True):
            return self.eval_pdf(ctx, si, wo, active)[0]

        def pdf(self, ctx, si, wo, active=True):
            self._check(si.p, si.wi, si.sh_frame.n, wo)
            mask = self._mask(ctx)
            if mask in ("none", "mirror"):  # nothing, or a delta lobe alone: no density
                return dr.zeros(mi.Float, dr.width(wo))
            hits, bad = self._hits(si)
            bad, wi, wo_np = self._finite(bad, to_np3(si.wi), to_np3(wo))
            pdf = hits.pdf(wi, wo_np)
            if mask == "rest":
                pdf = renormalised(pdf, self._kept(hits, wi)[1])
            pdf = from_np1(pdf)
            ok = (active & from_bool(~bad) & (mi.Frame3f.cos_theta(si.wi) > 0)
                  & (mi.Frame3f.cos_theta(wo) > 0))
            return dr.select(ok, pdf, 0.0)

        def eval_pdf(self, ctx, si, wo, active=True):
            """f cos(theta_o) and the pdf of `wo`: one pass over the shared wood."""
            self._check(si.p, si.wi, si.sh_frame.n, wo)
            mask = self._mask(ctx)
            if mask in ("none", "mirror"):  # nothing, or a delta lobe alone: no value, density
                n = dr.width(wo)
                return dr.zeros(mi.Color3f, n), dr.zeros(mi.Float, n)
            hits, bad = self._hits(si)
            bad, wi, wo_np = self._finite(bad, to_np3(si.wi), to_np3(wo))
            f, pdf = hits.eval_pdf(wi, wo_np)
            if mask == "rest":
                pdf = renormalised(pdf, self._kept(hits, wi)[1])
            cos_o = mi.Frame3f.cos_theta(wo)
            ok = active & from_bool(~bad) & (mi.Frame3f.cos_theta(si.wi) > 0) & (cos_o > 0)
            f = from_np3(mi.Color3f, f)
            return dr.select(ok, f * cos_o, 0.0), dr.select(ok, from_np1(pdf), 0.0)

        def sample(self, ctx, si, sample1, sample2, active=True):
            self._check(si.p, si.wi, si.sh_frame.n)
            mask = self._mask(ctx)
            if mask in ("none", "mirror"):
                return self._sample_masked(mask, si, dr.width(sample1), active)
            hits, bad = self._hits(si)
            bad, wi, uc, u = self._finite(bad, to_np3(si.wi), to_np1(sample1)[:, None],
                                          to_np2(sample2))
            uc = uc[:, 0]
            kept = None
            if mask == "rest":
                # The mirror is picked for uc below its probability p (lobes in order, mirror
                # first: wood.rs `pick`): uc mapped into [p, 1) draws only the others (p + a
                # non-negative number rounds to p or above, never below).
                p, kept = self._kept(hits, wi)
                uc = (p + uc * kept).astype(np.float32)
            s = hits.sample(wi, uc, u)
            if kept is not None:
                s["pdf"] = renormalised(s["pdf"], kept)
                s["valid"] = s["valid"] & ~s["is_delta"]
            # `sample` is the last call Mitsuba's integrators make at an interaction (after
            # eval_pdf for emitter sampling): the entry (0.5 KB per lane) is released here
            # rather than held until the next call.
            self._entries.pop(threading.get_ident(), None)
            bs = dr.zeros(mi.BSDFSample3f, dr.width(sample1))
            wo = from_np3(mi.Vector3f, s["wi"])
            pdf = from_np1(s["pdf"])
            delta = from_bool(s["is_delta"])
            valid = from_bool(s["valid"]) & (pdf > 0)
            ok = (active & valid & from_bool(~bad) & (mi.Frame3f.cos_theta(si.wi) > 0)
                  & (mi.Frame3f.cos_theta(wo) > 0))
            bs.wo = wo
            bs.pdf = dr.select(ok, pdf, 0.0)
            bs.eta = 1.0
            bs.sampled_type = dr.select(
                delta,
                mi.UInt32(+mi.BSDFFlags.DeltaReflection),
                mi.UInt32(+mi.BSDFFlags.GlossyReflection),
            )
            bs.sampled_component = dr.select(delta, mi.UInt32(1), mi.UInt32(0))
            f = from_np3(mi.Color3f, s["f"])
            weight = f * mi.Frame3f.cos_theta(wo) / dr.select(ok, pdf, 1.0)
            return bs, dr.select(ok, weight, 0.0)

        def _sample_masked(self, mask, si, n, active):
            """`sample` where `ctx` keeps nothing (an invalid sample) or a smooth finish's
            mirror alone: the mirror direction, chosen with probability 1, weight Fresnel's
            reflectance (Mitsuba's `fresnel`, the formula of xylem's `fresnel_dielectric`)."""
            bs = dr.zeros(mi.BSDFSample3f, n)
            if mask == "none":
                return bs, dr.zeros(mi.Color3f, n)
            cos_o = mi.Frame3f.cos_theta(si.wi)
            ok = active & (cos_o > 0)
            bs.wo = mi.Vector3f(-si.wi.x, -si.wi.y, si.wi.z)
            bs.pdf = dr.select(ok, 1.0, 0.0)
            bs.eta = 1.0
            bs.sampled_type = mi.UInt32(+mi.BSDFFlags.DeltaReflection)
            bs.sampled_component = mi.UInt32(1)
            f = mi.fresnel(dr.maximum(cos_o, 0.0), self.eta)[0]
            return bs, dr.select(ok, mi.Color3f(f), 0.0)

        def traverse(self, callback):
            # Dr.Jit values (params.update() assigns them in place); none is differentiable
            # (see the module). The scalar variant's are plain numbers: listed, not settable.
            self._params = {"eta": mi.Float(self.eta), "roughness": mi.Float(self.roughness),
                            "seed": mi.UInt32(self.seed)}
            for name, value in self._params.items():
                callback.put(name, value, mi.ParamFlags.NonDifferentiable)

        def parameters_changed(self, keys=None):
            if not hasattr(self, "_params"):  # never traversed: nothing can have changed
                return
            first = lambda v: np.array(v).ravel()[0]
            self.eta = float(first(self._params["eta"]))
            self.roughness = float(first(self._params["roughness"]))
            self.seed = int(first(self._params["seed"]))
            self._build()

        def to_string(self):
            return (
                f"XylemWood[preset={self.name}, eta={self.eta}, roughness={self.roughness}, "
                f"units={self.units}]"
            )

    def renormalised(pdf, kept):
        """A density over the lobes `kept` of the draws take (numpy): pdf / kept, 0 where
        nothing is kept."""
        return np.where(kept > 0, pdf / np.where(kept > 0, kept, 1.0), 0.0).astype(np.float32)

    _CLASSES[key] = XylemWood
    return XylemWood

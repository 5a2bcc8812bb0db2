"""The bindings give the Rust library's numbers: every value is compared with what
crates/xylem-cli/tests/python.rs computed by calling the library directly (float32, bit for bit)."""

import numpy as np
import pytest

import xylem


def f32(x):
    return np.asarray(x, dtype=np.float32)


def same(a, b):
    """Bit-for-bit equal float32 arrays (NaN nowhere)."""
    a, b = f32(a), f32(b)
    assert a.shape == b.shape, (a.shape, b.shape)
    assert np.isfinite(a).all()
    bad = np.argwhere(a != b)
    assert bad.size == 0, f"{len(bad)} values differ, first at {bad[0]}: {a[tuple(bad[0])]} vs {b[tuple(bad[0])]}"


@pytest.mark.parametrize("case", range(3))
def test_wood_bsdf_matches_rust(reference, case):
    c = reference["bsdf"][case]
    b = xylem.WoodBsdf(c["params"])
    same(b.eval(c["wo"], c["wi"]), c["f"])
    same(b.pdf(c["wo"], c["wi"]), c["pdf"])
    s = b.sample(c["wo"], c["uc"], c["u"])
    same(s["wi"], c["sample_wi"])
    same(s["f"], c["sample_f"])
    same(s["pdf"], c["sample_pdf"])
    assert (s["is_delta"] == np.array(c["sample_delta"])).all()
    assert (s["valid"] == np.array(c["sample_valid"])).all()
    # The smooth finish's mirror is sampled sometimes and flagged as a delta lobe.
    if c["name"] == "smooth_finish":
        assert s["is_delta"].any() and not s["is_delta"].all()


def test_wood_bsdf_batch_of_shading_points(reference):
    """N shading points in one WoodBsdf give, row by row, the single-point numbers."""
    cases = reference["bsdf"]
    fields = cases[0]["params"].keys()
    n = len(cases[0]["wo"])
    params = {k: np.array([cases[i % 3]["params"][k] for i in range(n)]) for k in fields}
    b = xylem.WoodBsdf(params)
    assert len(b) == n
    wo = np.array([cases[i % 3]["wo"][i] for i in range(n)])
    wi = np.array([cases[i % 3]["wi"][i] for i in range(n)])
    want = np.array([cases[i % 3]["f"][i] for i in range(n)])
    same(b.eval(wo, wi), want)
    assert b.has_delta().tolist() == [i % 3 == 0 for i in range(n)]


def test_wood_volume_matches_rust(reference):
    v = reference["volume"]
    vol = xylem.WoodVolume(v["preset"], seed=v["seed"])
    got = vol.eval(np.array(v["points"]), "all")
    for key in ["diffuse", "fiber_color", "fiber_dir", "ray_dir", "bump_grad", "ray_mask",
                "pore_mask", "bump", "highlight_width", "growth_time"]:
        same(got[key], v[key])
    # Asking for less returns only those arrays, with the same values.
    colour = vol.eval(np.array(v["points"]), needs="color")
    assert "fiber_dir" not in colour and "bump" not in colour
    same(colour["diffuse"], v["diffuse"])


def test_wood_surface_matches_rust(reference):
    s = reference["surface"]
    surf = xylem.WoodSurface(s["preset"], seed=s["seed"], eta=s["eta"], roughness=s["roughness"],
                             origin=s["origin"], axis=s["axis"], rotation_deg=s["rotation_deg"])
    same(surf.eval(s["p"], s["n"], s["wo"], s["wi"]), s["f"])
    same(surf.pdf(s["p"], s["n"], s["wo"], s["wi"]), s["pdf"])
    shaded = surf.shade(s["p"], s["n"])
    frames = shaded["frame"]
    # xylem's shading frame: orthonormal rows, z = the given normal.
    assert np.allclose(np.einsum("nij,nkj->nik", frames, frames), np.eye(3), atol=1e-5)
    n = np.array(s["n"], dtype=np.float32)
    assert np.allclose(frames[:, 2], n / np.linalg.norm(n, axis=1, keepdims=True), atol=1e-6)
    # A WoodBsdf built from the shaded parameters gives the same f in the local frame.
    local = lambda d: np.einsum("nij,nj->ni", frames, np.array(d, dtype=np.float32))
    b = xylem.WoodBsdf({k: shaded[k] for k in shaded if k != "frame"})
    np.testing.assert_allclose(b.eval(local(s["wo"]), local(s["wi"])), s["f"], rtol=2e-4, atol=1e-6)


def test_render_and_sweep_match_rust(reference):
    r = reference["render"]
    w, h = r["res"]
    img = xylem.render(r["scene"], spp=r["spp"], res=(w, h))
    assert img["beauty"].shape == (h, w, 3)
    same(img["beauty"].reshape(-1, 3), r["beauty"])
    same(img["std_error"].reshape(-1), r["std_error"])
    same(img["albedo"].reshape(-1, 3), r["albedo"])
    # The image does not depend on the thread count.
    same(xylem.render(r["scene"], spp=r["spp"], res=(w, h), threads=1)["beauty"], img["beauty"])
    sw = xylem.sweep(r["scene"], frames=r["sweep_frames"], arc=tuple(r["sweep_arc"]),
                     spp=r["spp"], res=(w, h))
    assert sw["frames"].shape == (r["sweep_frames"], h, w, 3)
    for k in range(r["sweep_frames"]):
        same(sw["frames"][k].reshape(-1, 3), r["sweep"][k])
    same(sw["light_deg"], r["sweep_light_deg"])


def test_errors_name_the_field(root):
    with pytest.raises(ValueError, match=r"roughness = 2: must be a finite value in \[0, 1\]"):
        xylem.WoodBsdf(roughness=2.0)
    with pytest.raises(ValueError, match=r"fiber_dir.*unit vector"):
        xylem.WoodBsdf(fiber_dir=[1.0, 1.0, 0.0])
    with pytest.raises(ValueError, match=r"highlight_width.*\(shading point 1\)"):
        xylem.WoodBsdf(highlight_width=[0.1, 3.0])
    with pytest.raises(ValueError, match=r"unknown field `colour`"):
        xylem.WoodBsdf(colour=1.0)
    with pytest.raises(ValueError, match=r"wi: leading shape \(3,\) does not broadcast with the "
                                         r"other arguments' \(bsdf: \(\), wo: \(2,\), wi: \(3,\)\)"):
        xylem.WoodBsdf().eval(np.ones((2, 3)), np.ones((3, 3)))
    with pytest.raises(ValueError, match=r"wi: shape \(4,\), expected \(\.\.\., 3\)"):
        xylem.WoodBsdf().eval([0, 0, 1], [0, 0, 1, 0])
    with pytest.raises(ValueError, match=r"unknown wood preset `oak`; valid presets: african_mahogany"):
        xylem.WoodVolume("oak")
    with pytest.raises(ValueError, match=r"needs: unknown `colour`"):
        xylem.WoodVolume("walnut").eval([[100.0, 0.0, 0.0]], needs="colour")
    with pytest.raises(OSError, match=r"no_such_preset.toml"):
        xylem.WoodVolume(preset_file="no_such_preset.toml")
    with pytest.raises(ValueError, match=r"eta = 5: must be a finite index in \[1, 4\]"):
        xylem.WoodSurface("walnut", eta=5.0)
    scene = str(root / "scenes" / "sweep_board.toml")
    with pytest.raises(ValueError, match=r"spp = 0"):
        xylem.render(scene, spp=0)
    with pytest.raises(ValueError, match=r"res width = 0: must be a whole number in 1..=16384"):
        xylem.render(scene, res=(0, 10))
    with pytest.raises(OSError, match=r"missing.toml"):
        xylem.render(str(root / "missing.toml"))
    with pytest.raises(ValueError, match=r"spp = 1000001: out of range \(allowed 1 to 1000000"):
        xylem.render(scene, spp=1000001)
    with pytest.raises(ValueError, match=r"threads = 99999: out of range \(allowed 0 = all cores"):
        xylem.render(scene, threads=99999)
    with pytest.raises(ValueError, match=r"no \[sweep\] table"):
        xylem.sweep(str(root / "scenes" / "teapot.toml"), spp=1, res=(4, 4))


def test_render_releases_the_gil(root):
    """A render on one thread lets another Python thread run meanwhile."""
    import threading
    import time

    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.005)

    # A daemon stopped in `finally`: a render that raises must not leave pytest waiting on it.
    t = threading.Thread(target=tick, daemon=True)
    t.start()
    try:
        start = time.perf_counter()
        out = xylem.render(
            str(root / "scenes" / "sweep_board.toml"), spp=16, res=(96, 72), threads=1
        )
        end = time.perf_counter()
    finally:
        done.set()
        t.join()
    assert out["seconds"] > 0.05, "render too short to tell"
    during = [x for x in ticks if start < x < end]
    assert len(during) >= 5, f"only {len(during)} ticks during a {end - start:.2f} s render"


def test_builtin_scenes_render_by_bare_name_from_an_empty_folder(tmp_path, monkeypatch):
    """Built-in scenes, their meshes and measured maps come from the module (issue 26)."""
    monkeypatch.chdir(tmp_path)
    for name in ["sweep_board", "cornell_bunny", "measured_maple_sweep"]:
        img = xylem.render(name, spp=1, res=(8, 6))
        assert img["beauty"].shape == (6, 8, 3), name
    sw = xylem.sweep("sweep_board", frames=2, spp=1, res=(8, 6))
    assert sw["frames"].shape == (2, 6, 8, 3)


def test_render_takes_a_quality_preset_and_restores_a_scene(root):
    """`quality=` is `--quality`: the draft preset renders at its 4 spp (with the exact
    distortion Jacobian) where the scene asks for 16, `spp=` overrides the preset's, and a loaded
    `Scene` renders as before afterwards (the preset's rebuilt materials are restored, like its
    settings)."""
    scene = xylem.load_file(str(root / "scenes" / "sweep_board.toml"))
    small = dict(res=(24, 18), threads=1)

    def noise(**kw):
        """The mean standard error of a render: it falls as 1/sqrt(spp)."""
        return float(xylem.render(scene, **small, **kw)["std_error"].mean())

    before = xylem.render(scene, **small)["beauty"]
    # 4 spp against the scene's 16: twice the standard error (1.5-2.5 allowed for the estimate).
    assert 1.5 < noise(quality="draft") / noise() < 2.5
    assert 0.8 < noise(quality="draft", spp=16) / noise() < 1.25, "spp= overrides the preset's"
    after = xylem.render(scene, **small)["beauty"]
    assert np.array_equal(before, after), "the Scene must come back as it was"
    with pytest.raises(ValueError, match=r"quality: `best` is not a quality \(allowed: draft"):
        xylem.render(scene, quality="best")
    out = xylem.sweep(scene, frames=2, quality="final", **small)
    assert out["frames"].shape == (2, 18, 24, 3)


def random_frames(rng, n):
    """n orthonormal frames (rows s, t, n) with tilted normals, and unit local directions."""
    normal = rng.normal(size=(n, 3)) * 0.3 + np.array([0, 0, 1.0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    s = np.cross(normal, rng.normal(size=(n, 3)))
    s /= np.linalg.norm(s, axis=1, keepdims=True)
    t = np.cross(normal, s)
    return np.stack([s, t, normal], axis=1).astype(np.float32)


def local_dirs(rng, n):
    z = rng.uniform(0.05, 1.0, n)
    phi = rng.uniform(0, 2 * np.pi, n)
    r = np.sqrt(1 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1).astype(np.float32)


def test_prepared_wood_matches_the_surface():
    """WoodSurface.prepare(p, frame) shades the wood once (shade_count moves by the point count
    and not again); its eval / pdf / eval_pdf / sample with directions in the caller's frames
    equal the surface's own world-space calls (to float rounding of the frame change)."""
    rng = np.random.default_rng(8)
    n = 40
    surf = xylem.WoodSurface("african_mahogany", seed=7, eta=1.5, roughness=0.25,
                             origin=(0, 120, 0), axis=(1, 0, 0), rotation_deg=20.0)
    p = np.stack([rng.uniform(-80, 80, n), rng.uniform(-40, 40, n), rng.uniform(0, 5, n)], 1)
    frame = random_frames(rng, n)
    wo, wi = local_dirs(rng, n), local_dirs(rng, n)
    uc, u = rng.random(n), rng.random((n, 2))
    world = lambda d: np.einsum("nij,ni->nj", frame, d)  # local (s, t, n) -> world
    assert surf.shade_count == 0
    hits = surf.prepare(p, frame)
    assert len(hits) == n and hits.shape == (n,) and surf.shade_count == n
    assert repr(hits) == f"<WoodHits of shape ({n},): {n} hit points>"
    f, pdf = hits.eval(wo, wi), hits.pdf(wo, wi)
    f2, pdf2 = hits.eval_pdf(wo, wi)
    s = hits.sample(wo, uc, u)
    assert surf.shade_count == n, "the prepared calls evaluated the wood again"
    np.testing.assert_array_equal(f, f2)
    np.testing.assert_array_equal(pdf, pdf2)
    normal = frame[:, 2]
    np.testing.assert_allclose(f, surf.eval(p, normal, world(wo), world(wi)), rtol=1e-4, atol=1e-6)
    np.testing.assert_allclose(pdf, surf.pdf(p, normal, world(wo), world(wi)), rtol=1e-4, atol=1e-6)
    want = surf.sample(p, normal, world(wo), uc, u)
    np.testing.assert_array_equal(s["valid"], want["valid"])
    np.testing.assert_allclose(world(s["wi"]), want["wi"], atol=1e-5)
    np.testing.assert_allclose(s["pdf"], want["pdf"], rtol=1e-4, atol=1e-6)
    assert f.max() > 0 and s["valid"].any()
    assert surf.shade_count == 4 * n          # the three surface calls above: one per point each
    # Broadcasting: one direction pair against every hit.
    assert hits.eval(wo[0], wi[0]).shape == (n, 3)


def test_prepare_errors():
    surf = xylem.WoodSurface("walnut")
    frame = np.eye(3, dtype=np.float32)
    with pytest.raises(ValueError, match=r"frame: shape \(4, 3\), expected \(\.\.\., 3, 3\)"):
        surf.prepare([0, 0, 0], np.zeros((4, 3)))
    with pytest.raises(ValueError, match=r"frame: element 1 is not orthonormal"):
        surf.prepare([0, 0, 0], np.stack([frame, 2 * frame]))
    with pytest.raises(ValueError, match="does not broadcast"):
        surf.prepare(np.zeros((3, 3)), np.stack([frame, frame]))
    assert surf.shade_count == 0, "refused before shading"
    hits = surf.prepare([0, 0, 0], frame)
    with pytest.raises(ValueError, match="wo: element"):
        hits.eval([0, 0, np.nan], [0, 0, 1])

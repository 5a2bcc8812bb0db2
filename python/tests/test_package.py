"""The package as a user meets it (issue 30): its version, type stubs, docstrings and reprs,
numpy broadcasting over leading dimensions, errors on non-finite input, and scenes from dicts."""

import inspect
import os
import pathlib
import shutil
import subprocess
import sys
import tomllib

import numpy as np
import pytest

import xylem


def unit(v):
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def upper(rng, shape):
    d = unit(rng.normal(size=shape + (3,)))
    d[..., 2] = np.abs(d[..., 2]) + 0.05
    return unit(d).astype(np.float32)


def test_version_is_the_workspace_version(root):
    cargo = tomllib.loads((root / "Cargo.toml").read_text())
    assert xylem.__version__ == cargo["workspace"]["package"]["version"]
    py = tomllib.loads((root / "python" / "Cargo.toml").read_text())
    assert py["package"]["version"] == {"workspace": True}
    project = tomllib.loads((root / "python" / "pyproject.toml").read_text())
    # The wheel's version comes from Cargo.toml, and its name is free on PyPI ("xylem" is not).
    assert "version" in project["project"]["dynamic"]
    assert project["project"]["name"] == "xylem-wood"
    assert project["tool"]["maturin"]["strip"] is True


def _site():
    return pathlib.Path(xylem.__file__).resolve().parent


@pytest.fixture(scope="module")
def mypy_cache(tmp_path_factory):
    """One mypy cache for the module's runs (numpy's stubs are analysed once)."""
    return tmp_path_factory.mktemp("mypy_cache")


def _stubtest(path, cache):
    env = dict(os.environ, PYTHONPATH=str(path), MYPY_CACHE_DIR=str(cache))
    return subprocess.run([sys.executable, "-m", "mypy.stubtest", "xylem._xylem"],
                          capture_output=True, text=True, env=env)


def test_type_stubs_match_the_module(tmp_path, mypy_cache):
    pkg = _site()
    assert (pkg / "py.typed").exists() and (pkg / "_xylem.pyi").exists()
    ok = _stubtest(pkg.parent, mypy_cache)
    assert ok.returncode == 0, ok.stdout + ok.stderr
    # Negative control: a stub whose parameter name differs from the module's is caught.
    bad = tmp_path / "xylem"
    shutil.copytree(pkg, bad)
    stub = (bad / "_xylem.pyi").read_text()
    assert "def eval(self, wo: _ArrayLike, wi: _ArrayLike)" in stub
    (bad / "_xylem.pyi").write_text(
        stub.replace("def eval(self, wo: _ArrayLike, wi: _ArrayLike)",
                     "def eval(self, w_out: _ArrayLike, wi: _ArrayLike)"))
    wrong = _stubtest(tmp_path, mypy_cache)
    assert wrong.returncode != 0 and "WoodBsdf.eval" in wrong.stdout, wrong.stdout


def test_mypy_uses_the_stubs(tmp_path, mypy_cache):
    prog = tmp_path / "prog.py"
    prog.write_text("import xylem\nf = xylem.WoodBsdf(roughness=0.2).eval([0, 0, 1], [0, 0, 1])\n"
                    "reveal_type(f)\nx: int = xylem.render('sweep_board')\n")
    env = dict(os.environ, PYTHONPATH=str(_site().parent))
    r = subprocess.run([sys.executable, "-m", "mypy", "--cache-dir", str(mypy_cache), str(prog)],
                       capture_output=True, text=True, env=env)
    # The array type comes from the stub; assigning a render (a dict) to an int is an error.
    assert "ndarray" in r.stdout and "float" in r.stdout, r.stdout
    assert 'has type "dict[str, Any]", variable has type "int"' in r.stdout, r.stdout


def test_docstrings_list_every_constructor_field(reference):
    # WoodBsdf's fields are WoodBsdfParams' (the Rust side wrote them into the reference).
    assert sorted(xylem.WoodBsdf.FIELDS) == sorted(reference["bsdf"][0]["params"].keys())
    for cls, fields in [(xylem.WoodBsdf, xylem.WoodBsdf.FIELDS),
                        (xylem.WoodVolume, inspect.signature(xylem.WoodVolume).parameters),
                        (xylem.WoodSurface, inspect.signature(xylem.WoodSurface).parameters)]:
        doc = cls.__doc__
        missing = [f for f in fields if f"`{f}`" not in doc]
        assert not missing, (cls.__name__, missing)
        assert len(list(fields)) >= 3
    # No default reads as `...` (issue 30: `origin=Ellipsis`).
    for f in [xylem.WoodSurface, xylem.WoodVolume, xylem.WoodBsdf, xylem.render, xylem.sweep,
              xylem.load_dict, xylem.load_file]:
        for p in inspect.signature(f).parameters.values():
            assert p.default is not Ellipsis, (f, p)


def test_reprs_rebuild_the_object():
    b = xylem.WoodBsdf(roughness=0.2, eta=1.3, fiber_dir=[0.6, 0.8, 0.0], ray_mask=0.25)
    again = eval(repr(b), {"WoodBsdf": xylem.WoodBsdf})
    wo, wi = upper(np.random.default_rng(3), (16,)), upper(np.random.default_rng(4), (16,))
    assert np.array_equal(again.eval(wo, wi), b.eval(wo, wi))
    assert "shape (2, 3)" in repr(xylem.WoodBsdf(roughness=np.full((2, 3), 0.1)))
    s = xylem.WoodSurface("walnut", seed=4, roughness=0.1, origin=(1, 2, 3), rotation_deg=30)
    assert repr(s) == ("WoodSurface('walnut', seed=4, eta=1.5, roughness=0.1, "
                       "origin=(1.0, 2.0, 3.0), axis=(0.0, 0.0, 1.0), rotation_deg=30.0, scale=1.0)")
    s2 = eval(repr(s), {"WoodSurface": xylem.WoodSurface})
    p, n = np.array([[10.0, 5.0, 0.0]]), np.array([[0, 0, 1.0]])
    assert np.array_equal(s2.eval(p, n, wo[:1], wi[:1]), s.eval(p, n, wo[:1], wi[:1]))
    assert repr(xylem.WoodVolume("red_oak", seed=3)) == "WoodVolume('red_oak', seed=3)"
    assert "Ellipsis" not in repr(s) + repr(b)


def test_broadcasting_over_leading_dimensions():
    rng = np.random.default_rng(7)
    b = xylem.WoodBsdf(roughness=0.3, fiber_dir=[0.8, 0.0, 0.6])
    grid = upper(rng, (6, 5))           # an (H, W, 3) grid of directions
    light = upper(rng, ())              # one direction
    f = b.eval(grid, light)
    assert f.shape == (6, 5, 3) and b.pdf(grid, light).shape == (6, 5)
    # Each element equals the flat (N, 3) call's row, which equals the single-pair call.
    flat = b.eval(grid.reshape(-1, 3), light)
    assert np.array_equal(f.reshape(-1, 3), flat)
    assert np.array_equal(f[2, 3], b.eval(grid[2, 3], light))
    assert b.eval(grid[2, 3], light).shape == (3,)
    # numpy's rules: (6, 1, 3) against (5, 3) gives (6, 5).
    col, row = grid[:, :1], grid[0]
    both = b.eval(col, row)
    assert both.shape == (6, 5, 3)
    assert np.array_equal(both[4, 2], b.eval(col[4, 0], row[2]))
    # Shading points with a shape broadcast against the directions too.
    rough = xylem.WoodBsdf(roughness=np.linspace(0.1, 0.5, 5), fiber_dir=[0.8, 0.0, 0.6])
    assert rough.shape == (5,) and len(rough) == 5
    many = rough.eval(grid, light)
    assert many.shape == (6, 5, 3)
    assert np.array_equal(many[1, 4], xylem.WoodBsdf(roughness=0.5, fiber_dir=[0.8, 0, 0.6])
                          .eval(grid[1, 4], light))
    s = b.sample(grid, rng.random((6, 5)), rng.random(2))
    assert s["wi"].shape == (6, 5, 3) and s["valid"].shape == (6, 5) and s["valid"].any()
    # Volumes and surfaces take grids of points.
    pts = rng.uniform(-40, 40, (3, 4, 3))
    tex = xylem.WoodVolume("walnut", seed=2).eval(pts)
    assert tex["diffuse"].shape == (3, 4, 3) and tex["growth_time"].shape == (3, 4)
    surf = xylem.WoodSurface("walnut", roughness=0.2)
    sh = surf.shade(pts, [0, 0, 1])
    assert sh["frame"].shape == (3, 4, 3, 3) and sh["eta"].shape == (3, 4)
    assert surf.eval(pts, [0, 0, 1], light, grid[:3, :4]).shape == (3, 4, 3)
    # Shapes that do not broadcast are refused, naming the argument and the shapes.
    with pytest.raises(ValueError, match=r"wi: leading shape \(4,\) does not broadcast.*"
                                         r"wo: \(6, 5\), wi: \(4,\)"):
        b.eval(grid, grid[0, :4])


def test_empty_batches_give_empty_results():
    b = xylem.WoodBsdf(roughness=0.2)
    none = np.zeros((0, 3))
    assert b.eval(none, [0, 0, 1]).shape == (0, 3)
    assert b.pdf(none, none).shape == (0,)
    s = b.sample(none, np.zeros(0), np.zeros((0, 2)))
    assert s["wi"].shape == (0, 3) and s["pdf"].shape == (0,)
    assert b.eval(np.zeros((4, 0, 3)), [0, 0, 1]).shape == (4, 0, 3)
    assert xylem.WoodVolume("walnut").eval(none)["diffuse"].shape == (0, 3)
    assert xylem.WoodSurface("walnut").eval(none, [0, 0, 1], [0, 0, 1], [0, 0, 1]).shape == (0, 3)
    assert len(xylem.WoodBsdf(roughness=np.zeros(0))) == 0
    # An empty batch against a batch of two does not broadcast.
    with pytest.raises(ValueError, match="does not broadcast"):
        b.eval(none, np.ones((2, 3)))


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_inputs_are_errors(bad):
    b = xylem.WoodBsdf(roughness=0.2)
    wo = np.array([[0, 0, 1.0], [0.6, 0, 0.8], [0, 0.6, 0.8]])
    wo[1, 2] = bad
    with pytest.raises(ValueError, match=r"wo: element \(1, 2\) is (NaN|inf|-inf); every input must be finite"):
        b.eval(wo, [0, 0, 1])
    with pytest.raises(ValueError, match=r"wi: element \(1, 2\)"):
        b.pdf([0, 0, 1], wo)
    with pytest.raises(ValueError, match=r"uc: element 0"):
        b.sample([0, 0, 1], [bad], [0.5, 0.5])
    with pytest.raises(ValueError, match=r"points: element \(1, 2\)"):
        xylem.WoodVolume("walnut").eval(wo)
    with pytest.raises(ValueError, match=r"WoodBsdfParams.diffuse: element 1"):
        xylem.WoodBsdf(diffuse=[0.5, bad, 0.5])
    with pytest.raises(ValueError, match=r"p: element \(1, 2\)"):
        xylem.WoodSurface("walnut").eval(wo, [0, 0, 1], [0, 0, 1], [0, 0, 1])
    # The same call with finite values works (the control).
    wo[1, 2] = 0.8
    assert np.isfinite(b.eval(wo, [0, 0, 1])).all()


def test_scene_from_a_dict_renders_as_its_file(root):
    path = root / "scenes" / "sweep_board.toml"
    d = tomllib.loads(path.read_text())
    # numpy values are taken as their Python equivalents.
    d["camera"]["eye"] = np.array(d["camera"]["eye"])
    d["render"]["spp"] = np.int64(2)
    scene = xylem.load_dict(d, name="board")
    assert scene.name == "board" and scene.spp == 2 and scene.res == (512, 384)
    assert "from <dict>" in repr(scene) and "[sweep]" in repr(scene)
    from_dict = xylem.render(scene, res=(24, 18))
    from_file = xylem.render(str(path), spp=2, res=(24, 18))
    assert np.array_equal(from_dict["beauty"], from_file["beauty"])
    # A plain dict renders directly, and the Scene's own settings stay after an override.
    assert np.array_equal(xylem.render(d, res=(24, 18))["beauty"], from_dict["beauty"])
    assert scene.res == (512, 384) and scene.spp == 2
    sw = xylem.sweep(scene, frames=2, res=(8, 6))
    assert sw["frames"].shape == (2, 6, 8, 3)
    # A changed dict renders differently (the control): the light moved.
    d["lights"][0]["center"] = [-250.0, 0.0, 433.0]
    assert not np.array_equal(xylem.render(d, res=(24, 18))["beauty"], from_dict["beauty"])
    loaded = xylem.load_file(path)
    assert np.array_equal(xylem.render(loaded, spp=2, res=(24, 18))["beauty"], from_file["beauty"])


def test_scene_dict_errors_name_the_field(root):
    d = tomllib.loads((root / "scenes" / "sweep_board.toml").read_text())
    d["objects"][1]["size"] = [260.0, -1.0, 18.0]
    with pytest.raises(ValueError, match=r"scene <dict>: field `objects\[1\]\.size`"):
        xylem.load_dict(d)
    d = tomllib.loads((root / "scenes" / "sweep_board.toml").read_text())
    d["render"]["spp"] = None
    with pytest.raises(ValueError, match=r"`render.spp` = None: a NoneType is not a scene value"):
        xylem.load_dict(d)
    d["render"]["spp"] = float("nan")
    with pytest.raises(ValueError, match=r"`render.spp` = NaN: must be finite"):
        xylem.load_dict(d)
    with pytest.raises(TypeError, match="expected a file path, a built-in scene name, a dict"):
        xylem.render(42)


def test_hand_written_scene_dict(tmp_path, monkeypatch):
    """The dict of notes/python.md renders: wood lit from one side is brighter on that side."""
    monkeypatch.chdir(tmp_path)
    scene = {
        "render": {"width": 64, "height": 48, "spp": 4, "integrator": "direct"},
        "camera": {"eye": [0, -250, 190], "target": [0, 0, 5], "up": [0, 0, 1], "fov_deg": 38},
        "lights": [{"name": "key", "type": "sphere", "center": [250, 0, 433], "radius": 8,
                    "radiance": 4000}],
        "materials": {"board": {"type": "wood", "preset": "walnut", "seed": 3,
                                "eta": 1.5, "roughness": 0.2}},
        "objects": [{"shape": "box", "size": [260, 110, 18], "translate": [0, 0, 9],
                     "material": "board"}],
    }
    img = xylem.render(xylem.load_dict(scene), seed=1)["beauty"]
    assert img.shape == (48, 64, 3) and np.isfinite(img).all() and img.mean() > 0
    lum = img.mean(axis=2)
    # Negative control: the same board lit from the other side reverses the comparison.
    scene["lights"][0]["center"] = [-250, 0, 433]
    mirrored = xylem.render(scene, seed=1)["beauty"].mean(axis=2)
    left, right = slice(0, 32), slice(32, 64)
    assert lum[:, right].mean() > lum[:, left].mean()
    assert mirrored[:, left].mean() > mirrored[:, right].mean()

"""Many boards fitted in parallel on a local Dask cluster (python/examples/fit_boards_dask.py)
give the same maps as fitting each alone."""

import os
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "python" / "examples"))


@pytest.fixture(scope="module")
def captures(tmp_path_factory):
    """Three small captures of the built-in fit scene (3, 4 and 5 frames per arc, 1 spp)."""
    exe = os.environ.get("XYLEM_BIN")
    if not exe:
        pytest.skip("XYLEM_BIN not set: run through `cargo test --release --test python`")
    d = tmp_path_factory.mktemp("captures")
    caps = []
    for frames in (3, 4, 5):
        out = d / f"board_{frames}"
        subprocess.run([exe, "sweep", "fit_maple_sweep", "--frames", str(frames), "--spp", "1",
                        "--out", str(out), "--quiet"], check=True, capture_output=True)
        caps.append(out)
    return caps


def test_boards_fit_in_parallel_on_a_local_dask_cluster(captures, tmp_path):
    import xylem
    from fit_boards_dask import fit_boards

    reports = fit_boards(captures, tmp_path / "dask", workers=2, texels=8)
    assert sorted(reports) == sorted(str(c) for c in captures)
    # Fitted in worker processes, not here.
    assert all(r["worker_pid"] != os.getpid() for r in reports.values())
    for c in captures:
        alone = xylem.fit(c, tmp_path / "alone" / c.name, texels=(8, 8), threads=1)
        assert reports[str(c)]["frames"] == alone["frames"] == 3 * int(c.name.split("_")[1])
        for name in ("maps.exr", "diffuse.png", "residual.png"):
            a = (tmp_path / "dask" / c.name / name).read_bytes()
            b = (tmp_path / "alone" / c.name / name).read_bytes()
            assert a == b, f"{c.name}/{name} differs between the Dask fit and one alone"


def test_a_missing_capture_is_an_os_error_naming_it(tmp_path):
    import xylem

    with pytest.raises(OSError, match="manifest.json"):
        xylem.fit(tmp_path / "nope", tmp_path / "out")

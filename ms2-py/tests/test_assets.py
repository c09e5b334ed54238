"""The asset store and the real Panda: each source, the fallback warning, bad files.

The real Panda's files (asset group ``franka_description``) are fetched, never committed; the
tests that need them take them from wherever this machine has them (``./scripts/setup.sh``
fetches them) and skip otherwise. No test uses the network: the wheel source is exercised with
a wheel built here and served from a local ``--find-links`` folder.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import ms2.assets as assets
import pytest

GROUP = "franka_description"


def _run(code: str, env_extra: dict[str, str], cwd: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    env.pop("MS2_PANDA_DESCRIPTION", None)
    env.update(env_extra)
    return subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=cwd
    )


# Makes PickCube twice, records warnings, prints which Panda was built as JSON.
PROBE = """
import json, warnings
import gymnasium as gym
import ms2
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    for _ in range(2):
        env = gym.make("PickCube-v0", obs_mode="state")
        env.reset(seed=0)
        for _ in range(3):
            env.step(env.action_space.sample() * 0)
        env.close()
info = ms2.assets.panda_description()
info["warnings"] = [str(w.message) for w in caught if "real Panda" in str(w.message)]
print(json.dumps(info))
"""


def _probe(env_extra: dict[str, str], cwd: Path) -> dict:
    proc = _run(PROBE, env_extra, cwd)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


@pytest.fixture(scope="module")
def real_files() -> Path:
    """A folder in the asset-directory layout holding the real files (verified)."""
    st = assets.status(GROUP)
    if not st.present:
        pytest.skip("franka_description not fetched on this machine (ms2 assets fetch)")
    g = assets.group(GROUP)
    if st.source == "asset directory":
        return st.root
    # A package source: copy its files into the asset-directory layout.
    out = Path(os.environ.get("TMPDIR", "/tmp")) / f"ms2-test-assets-{os.getpid()}"
    source = next(s for s in g["sources"] if st.source.endswith(s.get("module", "-")))
    for f in g["files"]:
        dst = out / f["path"]
        dst.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(st.root / assets._file_in_source(source, f["path"]), dst)
    return out


def _copy_group(src_root: Path, dst_root: Path) -> None:
    for f in assets.group(GROUP)["files"]:
        dst = dst_root / f["path"]
        dst.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(src_root / f["path"], dst)


def test_group_data_names_files_checksums_and_sources():
    g = assets.group(GROUP)
    assert g["entry"] == "descriptions/panda_v2.urdf"
    assert len(g["files"]) == 22
    assert all(len(f["sha256"]) == 64 for f in g["files"])
    kinds = [s["kind"] for s in g["sources"]]
    assert kinds == ["asset_dir", "python_package", "python_package", "pypi_wheel"]
    with pytest.raises(ValueError, match="franka_description"):
        assets.group("no_such_group")


def test_missing_asset_gives_one_warning_and_the_primitive_panda(tmp_path):
    info = _probe({"MS2_ASSET_DIR": str(tmp_path / "empty")}, tmp_path)
    assert info["real"] is False
    assert info["source"] == "primitive"
    assert len(info["warnings"]) == 1, info["warnings"]
    assert "ms2 assets fetch franka_description" in info["warnings"][0]
    assert info["visual_triangles"] == 0


def test_forcing_the_primitive_panda_gives_no_warning(tmp_path, real_files):
    info = _probe(
        {"MS2_ASSET_DIR": str(real_files), "MS2_PANDA_DESCRIPTION": "primitive"}, tmp_path
    )
    assert info["real"] is False
    assert info["warnings"] == []


def test_real_panda_from_the_asset_dir(tmp_path, real_files):
    store = tmp_path / "store"
    _copy_group(real_files, store)
    info = _probe({"MS2_ASSET_DIR": str(store)}, tmp_path)
    assert info["real"] is True, info
    assert info["source"] == "asset directory"
    assert info["urdf"] == str(store / "descriptions" / "panda_v2.urdf")
    assert info["visual_triangles"] == 134924
    assert info["warnings"] == []


def _fake_site_packages(root: Path, real_files: Path) -> Path:
    site = root / "site"
    pkg = site / "mani_skill2"
    pkg.mkdir(parents=True)
    (pkg / "__init__.py").write_text("raise ImportError('ms2 must not import mani_skill2')\n")
    _copy_group(real_files, pkg / "assets")
    return site


def test_real_panda_from_an_installed_mani_skill2_package(tmp_path, real_files):
    site = _fake_site_packages(tmp_path, real_files)
    extra = {"MS2_ASSET_DIR": str(tmp_path / "empty"), "PYTHONPATH": str(site)}
    info = _probe(extra, tmp_path)
    assert info["real"] is True, info
    assert info["source"] == "Python package mani_skill2"
    assert info["urdf"] == str(site / "mani_skill2" / "assets" / "descriptions" / "panda_v2.urdf")
    # `ms2 assets fetch` copies them into the asset directory, which then serves them.
    proc = _run(
        "import ms2.cli; raise SystemExit(ms2.cli.main(['assets', 'fetch', 'franka_description']))",
        extra,
        tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    assert "Python package mani_skill2" in proc.stdout
    assert not list((tmp_path / "empty").glob(".ms2-staging-*"))
    info = _probe({"MS2_ASSET_DIR": str(tmp_path / "empty")}, tmp_path)
    assert info["source"] == "asset directory"


def _build_wheel(folder: Path, real_files: Path) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    wheel = folder / "mani_skill2-0.5.3-py3-none-any.whl"
    dist = "mani_skill2-0.5.3.dist-info"
    with zipfile.ZipFile(wheel, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("mani_skill2/__init__.py", "")
        for f in assets.group(GROUP)["files"]:
            z.write(real_files / f["path"], f"mani_skill2/assets/{f['path']}")
        z.writestr(f"{dist}/METADATA", "Metadata-Version: 2.1\nName: mani-skill2\nVersion: 0.5.3\n")
        z.writestr(
            f"{dist}/WHEEL",
            "Wheel-Version: 1.0\nGenerator: ms2-tests\nRoot-Is-Purelib: true\nTag: py3-none-any\n",
        )
        z.writestr(f"{dist}/RECORD", "")
    return wheel


def test_real_panda_from_the_wheel_served_locally(tmp_path, real_files):
    links = tmp_path / "links"
    wheel = _build_wheel(links, real_files)
    sha = hashlib.sha256(wheel.read_bytes()).hexdigest()
    store = tmp_path / "store"
    source = assets.fetch(
        GROUP, target=store, use_packages=False, find_links=str(links), wheel_sha256=sha, quiet=True
    )
    assert source == "PyPI wheel mani-skill2==0.5.3"
    assert sorted(p.name for p in store.iterdir()) == ["descriptions"]  # no staging left
    assert (
        store / "descriptions" / "franka_description" / "meshes" / "visual" / "link0.dae"
    ).is_file()
    info = _probe({"MS2_ASSET_DIR": str(store)}, tmp_path)
    assert info["real"] is True and info["source"] == "asset directory"
    # Present and valid: a second fetch does nothing.
    assert assets.fetch(GROUP, target=store, use_packages=False, find_links=str(links)) == (
        "already present"
    )


def test_a_wheel_with_the_wrong_checksum_is_refused_naming_it(tmp_path, real_files):
    links = tmp_path / "links"
    _build_wheel(links, real_files)  # not the published wheel: its sha256 differs
    store = tmp_path / "store"
    with pytest.raises(
        assets.FetchError, match=r"mani_skill2-0\.5\.3-py3-none-any\.whl has sha256"
    ):
        assets.fetch(GROUP, target=store, use_packages=False, find_links=str(links), quiet=True)
    assert not (store / "descriptions").exists()
    assert not list(store.glob(".ms2-*"))


def test_a_wheel_with_a_corrupt_member_is_refused_naming_the_file(tmp_path, real_files):
    bad = tmp_path / "bad"
    _copy_group(real_files, bad)
    mesh = bad / "descriptions/franka_description/meshes/collision/link3.stl"
    data = bytearray(mesh.read_bytes())
    data[100] ^= 0xFF
    mesh.write_bytes(bytes(data))
    links = tmp_path / "links"
    wheel = _build_wheel(links, bad)
    sha = hashlib.sha256(wheel.read_bytes()).hexdigest()
    store = tmp_path / "store"
    with pytest.raises(assets.FetchError, match=r"link3\.stl has sha256"):
        assets.fetch(
            GROUP, target=store, use_packages=False, find_links=str(links), wheel_sha256=sha
        )
    assert not (store / "descriptions").exists()


def test_a_corrupt_file_in_the_asset_dir_is_an_error_naming_it(tmp_path, real_files):
    store = tmp_path / "store"
    _copy_group(real_files, store)
    mesh = store / "descriptions/franka_description/meshes/visual/link3.dae"
    data = bytearray(mesh.read_bytes())
    data[1000] ^= 0x01
    mesh.write_bytes(bytes(data))
    proc = _run(PROBE, {"MS2_ASSET_DIR": str(store)}, tmp_path)
    assert proc.returncode != 0
    assert "RuntimeError" in proc.stderr and "link3.dae has sha256" in proc.stderr, proc.stderr
    proc = _run(
        "import ms2.cli; raise SystemExit(ms2.cli.main(['assets', 'verify']))",
        {"MS2_ASSET_DIR": str(store)},
        tmp_path,
    )
    assert proc.returncode == 1
    assert "FAILED" in proc.stdout and "link3.dae" in proc.stdout
    # A truncated file too.
    mesh.write_bytes(bytes(data[:500]))
    proc = _run(PROBE, {"MS2_ASSET_DIR": str(store)}, tmp_path)
    assert proc.returncode != 0 and "link3.dae has 500 bytes" in proc.stderr, proc.stderr


def test_assets_list_reports_the_asset_dir_and_groups(tmp_path):
    proc = _run(
        "import ms2.cli; raise SystemExit(ms2.cli.main(['assets', 'list']))",
        {"MS2_ASSET_DIR": str(tmp_path / "empty")},
        tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    assert str(tmp_path / "empty") in proc.stdout
    assert "franka_description: 22 files" in proc.stdout
    assert "Apache-2.0" in proc.stdout

"""The asset store: ``ms2 assets list / fetch / verify`` and the sources of fetched assets.

Assets that ms2 does not write itself (Franka's ``franka_description`` meshes of the real Panda)
are fetched, never part of ms2's repository. They live in the asset directory, ``$MS2_ASSET_DIR``
(the variable ManiSkill2 reads) or ``~/.ms2/data`` when it is unset, in ManiSkill2's layout.
Each asset group (files, sizes, sha256 checksums, sources) is data compiled into the native
module (``ms2-assets/groups/*.json``). A group's sources are tried in order:

1. the asset directory itself;
2. an installed ``mani_skill2`` (or ``mani_skill``) Python package, which ships the files
   (read in place at run time; ``ms2 assets fetch`` copies them into the asset directory);
3. the ``mani-skill2==0.5.3`` wheel from the Python package index, downloaded with
   ``pip download --no-deps`` and checked against its sha256 (only the group's files are
   extracted).

Every file is checked against its size and sha256 before use. ``fetch`` writes into a staging
folder inside the asset directory, verifies every file there, then moves the files into place
(``os.replace``), so an interrupted fetch leaves no half-written file at a group path.
"""

from __future__ import annotations

import argparse
import hashlib
import importlib.util
import json
import os
import shutil
import subprocess
import sys
import tempfile
import warnings
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from . import _native

ASSET_DIR_ENV = "MS2_ASSET_DIR"

_packages_registered = False
_panda_warned = False


def asset_dir() -> Path:
    """The asset directory: ``$MS2_ASSET_DIR``, else ``~/.ms2/data``."""
    return Path(_native.asset_dir())


def group_names() -> list[str]:
    """Names of the known asset groups."""
    return list(_native.asset_group_names())


def group(name: str) -> dict[str, Any]:
    """The asset group ``name`` (``ValueError`` naming the known ones if unknown)."""
    return json.loads(_native.asset_group_json(name))


def _package_dir(module: str) -> Path | None:
    """Folder of an installed package, found without importing it."""
    try:
        spec = importlib.util.find_spec(module)
    except (ImportError, ValueError):
        return None
    if spec is None or not spec.submodule_search_locations:
        return None
    return Path(next(iter(spec.submodule_search_locations)))


def register_installed_packages() -> None:
    """Tells the native store where installed asset packages (``mani_skill2``, ...) live."""
    global _packages_registered
    if _packages_registered:
        return
    _packages_registered = True
    modules = {
        s["module"]
        for name in group_names()
        for s in group(name)["sources"]
        if s["kind"] == "python_package"
    }
    for module in sorted(modules):
        path = _package_dir(module)
        if path is not None:
            _native.register_asset_package_dir(module, str(path))


def panda_description() -> dict[str, Any]:
    """Which Panda the envs of this process build: ``{"real": bool, "source", "urdf" or
    "reason", "visual_triangles"}``."""
    register_installed_packages()
    return dict(_native.panda_description())


def warn_if_primitive_panda() -> None:
    """Warns once per process when the real Panda's files are not available."""
    global _panda_warned
    if _panda_warned:
        return
    _panda_warned = True
    info = panda_description()
    if not info["real"] and "MS2_PANDA_DESCRIPTION" not in info.get("reason", ""):
        warnings.warn(
            "ms2: the real Panda's meshes (asset group franka_description) were not found, "
            "so the primitive Panda is used. Fetch them with `ms2 assets fetch "
            f"franka_description` (into {asset_dir()}). Details: {info.get('reason', '')}",
            stacklevel=3,
        )


@dataclass
class GroupStatus:
    """Where a group is available, and any problem found."""

    name: str
    present: bool
    source: str | None
    root: Path | None
    problem: str | None


def _source_label(source: dict[str, Any]) -> str:
    if source["kind"] == "asset_dir":
        return "asset directory"
    if source["kind"] == "python_package":
        return f"Python package {source['module']}"
    return f"PyPI wheel {source['requirement']}"


def status(name: str, root: Path | None = None) -> GroupStatus:
    """Checks the directory sources of group ``name`` in order (checksums included)."""
    register_installed_packages()
    g = group(name)
    problems = []
    for index, source in enumerate(g["sources"]):
        if source["kind"] == "asset_dir":
            base = root if root is not None else asset_dir()
        elif source["kind"] == "python_package":
            base = _package_dir(source["module"])
            if base is None:
                continue
        else:
            continue
        try:
            _native.verify_asset_group(name, str(base), index)
        except ValueError as err:
            problems.append(f"{_source_label(source)}: {err}")
            continue
        return GroupStatus(name, True, _source_label(source), base, None)
    return GroupStatus(name, False, None, None, "; ".join(problems) or None)


class FetchError(RuntimeError):
    """A fetch failed; the message names the file or source at fault."""


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 16), b""):
            h.update(chunk)
    return h.hexdigest()


def _file_in_source(source: dict[str, Any], group_path: str) -> str:
    """Path of a group file inside a package source's folder."""
    rel = group_path
    strip = source.get("strip")
    if strip and rel.startswith(strip + "/"):
        rel = rel[len(strip) + 1 :]
    return f"{source['prefix'].rstrip('/')}/{rel}"


def _install(g: dict[str, Any], staging: Path, target: Path) -> None:
    """Verifies the staged files, then moves them to their group paths under ``target``."""
    try:
        _native.verify_asset_group(g["name"], str(staging), 0)
    except ValueError as err:
        raise FetchError(str(err)) from None
    for f in g["files"]:
        dst = target / f["path"]
        dst.parent.mkdir(parents=True, exist_ok=True)
        os.replace(staging / f["path"], dst)


def _stage_from_package(
    g: dict[str, Any], source: dict[str, Any], pkg: Path, staging: Path
) -> None:
    for f in g["files"]:
        dst = staging / f["path"]
        dst.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(pkg / _file_in_source(source, f["path"]), dst)


def _download_wheel(
    source: dict[str, Any],
    dest: Path,
    find_links: str | None,
    index_url: str | None,
    quiet: bool,
) -> Path:
    cmd = [sys.executable, "-m", "pip", "download", "--no-deps", "--only-binary=:all:"]
    cmd += ["--dest", str(dest), "--disable-pip-version-check"]
    if find_links is not None:
        cmd += ["--no-index", "--find-links", find_links]
    if index_url is not None:
        cmd += ["--index-url", index_url]
    if quiet:
        cmd.append("--quiet")
    cmd.append(source["requirement"])
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise FetchError(
            f"pip download {source['requirement']} failed (exit {proc.returncode}): "
            f"{proc.stderr.strip()[-800:]}"
        )
    wheel = dest / source["filename"]
    if not wheel.is_file():
        raise FetchError(f"pip download {source['requirement']} did not produce {wheel}")
    return wheel


def _stage_from_wheel(
    g: dict[str, Any], source: dict[str, Any], wheel: Path, staging: Path, wheel_sha256: str
) -> None:
    found = _sha256(wheel)
    if found != wheel_sha256:
        raise FetchError(
            f"wheel {wheel} has sha256 {found}, expected {wheel_sha256}: refusing to use it"
        )
    try:
        with zipfile.ZipFile(wheel) as z:
            for f in g["files"]:
                member = f"{source['prefix'].rstrip('/')}/{f['path']}"
                dst = staging / f["path"]
                dst.parent.mkdir(parents=True, exist_ok=True)
                try:
                    with z.open(member) as src, open(dst, "wb") as out:
                        shutil.copyfileobj(src, out)
                except KeyError:
                    raise FetchError(f"wheel {wheel} has no member {member}") from None
    except zipfile.BadZipFile as err:
        raise FetchError(f"wheel {wheel} is not a valid zip file: {err}") from None


def fetch(
    name: str,
    *,
    target: Path | None = None,
    force: bool = False,
    use_packages: bool = True,
    use_wheel: bool = True,
    find_links: str | None = None,
    index_url: str | None = None,
    wheel_sha256: str | None = None,
    quiet: bool = False,
) -> str:
    """Puts group ``name`` into the asset directory (``target``); returns the source used.

    Already present and verified: nothing is done unless ``force``. Otherwise the sources are
    tried in order (installed packages, then the wheel). ``find_links`` makes pip read wheels
    from that folder or URL only (offline use); ``wheel_sha256`` replaces the group's recorded
    checksum of the wheel (for wheels built locally). Raises ``FetchError`` naming the file or
    source at fault; ``ValueError`` for an unknown group.
    """
    g = group(name)
    target = Path(target) if target is not None else asset_dir()
    if not force:
        try:
            _native.verify_asset_group(name, str(target), 0)
            return "already present"
        except ValueError:
            pass
    target.mkdir(parents=True, exist_ok=True)
    errors = []
    for source in g["sources"]:
        kind = source["kind"]
        if kind == "asset_dir" or (kind == "python_package" and not use_packages):
            continue
        if kind == "pypi_wheel" and not use_wheel:
            continue
        staging = Path(tempfile.mkdtemp(prefix=".ms2-staging-", dir=target))
        try:
            if kind == "python_package":
                pkg = _package_dir(source["module"])
                if pkg is None:
                    continue
                try:
                    _stage_from_package(g, source, pkg, staging)
                    _install(g, staging, target)
                except (OSError, FetchError) as err:
                    errors.append(f"{_source_label(source)} at {pkg}: {err}")
                    continue
            else:
                with tempfile.TemporaryDirectory(prefix=".ms2-wheel-", dir=target) as dl:
                    try:
                        wheel = _download_wheel(source, Path(dl), find_links, index_url, quiet)
                        _stage_from_wheel(
                            g, source, wheel, staging, wheel_sha256 or source["sha256"]
                        )
                        _install(g, staging, target)
                    except (OSError, FetchError) as err:
                        errors.append(f"{_source_label(source)}: {err}")
                        continue
            return _source_label(source)
        finally:
            shutil.rmtree(staging, ignore_errors=True)
    raise FetchError(f"could not fetch asset group {name!r}: " + "; ".join(errors or ["no source"]))


def _human(n: int) -> str:
    return f"{n / 1e6:.1f} MB"


def _cmd_list(_args: argparse.Namespace) -> int:
    print(f"asset directory: {asset_dir()}  (${ASSET_DIR_ENV}, default ~/.ms2/data)")
    for name in group_names():
        g = group(name)
        st = status(name)
        where = f"available ({st.source}: {st.root})" if st.present else "not fetched"
        size = _human(sum(f["size"] for f in g["files"]))
        print(f"{name}: {len(g['files'])} files, {size}, {g['license']}")
        print(f"    {where}")
        if st.problem:
            print(f"    problem: {st.problem}")
        print(f"    sources: {', '.join(_source_label(s) for s in g['sources'])}")
    return 0


def _cmd_fetch(args: argparse.Namespace) -> int:
    names = group_names() if args.group == "all" else [args.group]
    for name in names:
        source = fetch(
            name,
            force=args.force,
            use_packages=not args.no_packages,
            find_links=args.find_links,
            quiet=args.quiet,
        )
        print(f"{name}: {source} -> {asset_dir()}")
    return 0


def _cmd_verify(args: argparse.Namespace) -> int:
    names = group_names() if args.group == "all" else [args.group]
    bad = 0
    for name in names:
        try:
            _native.verify_asset_group(name, str(asset_dir()), 0)
            print(f"{name}: ok ({len(group(name)['files'])} files in {asset_dir()})")
        except ValueError as err:
            print(f"{name}: FAILED: {err}")
            bad += 1
    return 1 if bad else 0


def _cmd_download(args: argparse.Namespace) -> int:
    from . import download as dl

    root = asset_dir()
    names = dl.resolve(args.what, asset_dir=root)
    for name in names:
        last = [-1]

        def progress(got: int, total: int | None, last: list[int] = last, name: str = name) -> None:
            step = got >> 24  # a line every 16 MiB
            if not args.quiet and step != last[0]:
                last[0] = step
                of = f" of {_human(total)}" if total else ""
                print(f"  {name}: {_human(got)}{of}", flush=True)

        path = dl.download_archive(
            name, root, base=args.base_url, force=args.force, progress=progress
        )
        print(f"{name}: {path}")
    return 0


def add_parser(sub: Any) -> None:
    """Adds ``ms2 assets ...`` to the command line."""
    p = sub.add_parser(
        "assets",
        help="list, fetch, download and verify fetched assets (real Panda meshes, ManiSkill2 data)",
    )
    a = p.add_subparsers(dest="assets_command", required=True)
    lp = a.add_parser("list", help="asset groups, where they are found, sizes and licences")
    lp.set_defaults(func=_cmd_list)
    fp = a.add_parser("fetch", help="put an asset group into the asset directory")
    fp.add_argument("group", help="asset group name, or 'all'")
    fp.add_argument("--force", action="store_true", help="fetch even if present and valid")
    fp.add_argument(
        "--no-packages",
        action="store_true",
        help="do not copy from installed mani_skill2 / mani_skill packages",
    )
    fp.add_argument(
        "--find-links",
        default=None,
        help="read wheels from this folder or URL only (pip --no-index --find-links)",
    )
    fp.add_argument("-q", "--quiet", action="store_true", help="no pip output")
    fp.set_defaults(func=_cmd_fetch)
    dp = a.add_parser(
        "download",
        help="download ManiSkill2's published data archives (YCB, EGAD, clutter episodes, "
        "PartNet-Mobility models, ...)",
    )
    dp.add_argument(
        "what",
        help="env id (e.g. PickSingleYCB-v0, TurnFaucet-v0), archive name (ycb, egad), "
        "partnet_mobility/<model id>, or 'all'",
    )
    dp.add_argument(
        "--base-url",
        default=None,
        help="download from this base URL instead of ManiSkill2's (also $MS2_DOWNLOAD_BASE_URL)",
    )
    dp.add_argument("--force", action="store_true", help="download even if the data is present")
    dp.add_argument("-q", "--quiet", action="store_true", help="no progress lines")
    dp.set_defaults(func=_cmd_download)
    vp = a.add_parser("verify", help="check sizes and sha256 of an asset group's files")
    vp.add_argument("group", nargs="?", default="all", help="asset group name (default: all)")
    vp.set_defaults(func=_cmd_verify)


__all__ = [
    "ASSET_DIR_ENV",
    "FetchError",
    "GroupStatus",
    "add_parser",
    "asset_dir",
    "fetch",
    "group",
    "group_names",
    "panda_description",
    "register_installed_packages",
    "status",
    "warn_if_primitive_panda",
]

"""``ms2 assets download``: ManiSkill2's published asset archives, fetched over HTTP.

The archives, their checksums and the env ids that need them are ManiSkill2 0.5.3's
(``mani_skill2/utils/download_asset.py``): ``ycb`` (``mani_skill2_ycb/``), ``egad``
(``mani_skill2_egad/``), ``pick_clutter_ycb`` (``pick_clutter/ycb_train_5k.json.gz``),
``assembling_kits``, ``panda_avoid_obstacles``, ``pinch``, ``write``, and one zip per
PartNet-Mobility model (``partnet_mobility/<model id>``; ``TurnFaucet-v0`` and the mobile env ids
download the models ManiSkill2's info files list). ManiSkill2 publishes checksums (none for the
PartNet-Mobility models) but no sizes: a download is checked against the server's
``Content-Length`` (a short body is an interrupted download) and then against the sha256.

Safety: bytes go to ``<asset dir>/.ms2_downloads/<name>.part``; an interrupted download keeps
that file and the next run resumes it with an HTTP ``Range`` request. A zip archive is checked
(no member outside its folder) and extracted into a temporary folder that is renamed into
place, so the asset directory never holds a half-written data set. The base URL can be
replaced (``--base-url`` or ``$MS2_DOWNLOAD_BASE_URL``), e.g. by a mirror.
"""

from __future__ import annotations

import hashlib
import http.client
import os
import shutil
import tempfile
import urllib.error
import urllib.request
import zipfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

#: Where ManiSkill2 0.5.3 publishes its asset archives.
DEFAULT_BASE_URL = "https://storage1.ucsd.edu/datasets/ManiSkill2022-assets"
#: Environment variable replacing :data:`DEFAULT_BASE_URL`.
BASE_URL_ENV = "MS2_DOWNLOAD_BASE_URL"
#: Folder under the asset directory holding partial downloads.
STAGING_DIR = ".ms2_downloads"

_CHUNK = 1 << 16


@dataclass(frozen=True)
class Archive:
    """One published archive: its path under the base URL, sha256 and where it goes."""

    path: str
    sha256: str | None
    """``None`` where ManiSkill2 publishes none (the PartNet-Mobility models): then only the
    server's ``Content-Length`` and the zip's own CRCs check the bytes."""
    target: str
    """Folder (zip archives: the archive's top folder) or file path under ``parent``."""
    parent: str = ""
    """Folder under the asset dir that receives ``target`` (default: the asset dir itself)."""

    @property
    def is_zip(self) -> bool:
        return self.path.endswith(".zip")


#: ManiSkill2 0.5.3's archives (facts from its download_asset.py).
ARCHIVES: dict[str, Archive] = {
    "ycb": Archive(
        "mani_skill2_ycb_v2.zip",
        "b83afbe9c38a780f5625f2c97afad712db49fcb533d4814ac0c827b0514a504b",
        "mani_skill2_ycb",
    ),
    "egad": Archive(
        "mani_skill2_egad_v1.zip",
        "4b5d841256e0151c2a615a98d4e92afa12ad6d795e2565b364586e3940d3aa36",
        "mani_skill2_egad",
    ),
    "pick_clutter_ycb": Archive(
        "pick_clutter/ycb_train_5k.json.gz",
        "70ec176c7036f326ea7813b77f8c03bea9db5960198498957a49b2895a9ec338",
        "pick_clutter/ycb_train_5k.json.gz",
    ),
    "assembling_kits": Archive(
        "assembling_kits_v1.zip",
        "e3371f17a07a012edaa3a0b3604fb1577f3fb921876c3d5ed59733dd75a6b4a0",
        "assembling_kits",
    ),
    "panda_avoid_obstacles": Archive(
        "avoid_obstacles/panda_train_2k.json.gz",
        "44dae9a0804172515c290c1f49a1e7e72d76e40201a2c5c7d4a3ccd43b4d5be4",
        "avoid_obstacles/panda_train_2k.json.gz",
    ),
    "pinch": Archive(
        "pinch.zip",
        "3281d2d777fad42e6d37371b2d3ee16fb1c39984907176718ca2e4f447326fe7",
        "pinch",
    ),
    "write": Archive(
        "write.zip",
        "c5b49e581bfed9cfb2107a607faf52795f840e93f5a7ad389290314513b4b634",
        "write",
    ),
}

#: Env ids (ManiSkill2's data groups) to the archives they need.
GROUPS: dict[str, list[str]] = {
    "PickSingleYCB-v0": ["ycb"],
    "PickSingleEGAD-v0": ["egad"],
    "PickClutterYCB-v0": ["ycb", "pick_clutter_ycb"],
    "AssemblingKits-v0": ["assembling_kits"],
    "PandaAvoidObstacles-v0": ["panda_avoid_obstacles"],
    "Pinch-v0": ["pinch"],
    "Write-v0": ["write"],
}


#: Env ids to the PartNet-Mobility categories whose models they need (ManiSkill2 0.5.3's data
#: groups); the model ids are the keys of ``partnet_mobility/meta/info_<category>_train.json``.
PARTNET_GROUPS: dict[str, list[str]] = {
    "TurnFaucet-v0": ["faucet"],
    "OpenCabinetDrawer-v1": ["cabinet_drawer"],
    "OpenCabinetDoor-v1": ["cabinet_door"],
    "PushChair-v1": ["chair"],
    "MoveBucket-v1": ["bucket"],
}
#: Prefix of a single PartNet-Mobility model's name (``partnet_mobility/<model id>``).
PARTNET_PREFIX = "partnet_mobility/"


def partnet_archive(model_id: str) -> Archive:
    """The published zip of PartNet-Mobility model ``model_id`` (a number), which unpacks to
    ``partnet_mobility/dataset/<model_id>/``."""
    if not model_id.isdigit():
        raise ValueError(f"PartNet-Mobility model ids are numbers, got {model_id!r}")
    return Archive(
        f"partnet_mobility/dataset/{model_id}.zip", None, model_id, "partnet_mobility/dataset"
    )


def partnet_model_ids(category: str, asset_dir: Path) -> list[str]:
    """The model ids ManiSkill2 lists for ``category`` (its train info file in ``asset_dir``)."""
    import json

    info = asset_dir / "partnet_mobility" / "meta" / f"info_{category}_train.json"
    try:
        ids = list(json.loads(info.read_text()))
    except FileNotFoundError:
        raise DownloadError(
            f"{info} is missing: it lists the {category} models to download; get it with "
            "`ms2 assets fetch partnet_mobility_meta`"
        ) from None
    except (OSError, ValueError) as err:
        raise DownloadError(f"{info}: not a JSON object of model ids ({err})") from None
    return ids


class DownloadError(RuntimeError):
    """A download failed; the message names the URL or file and what was expected."""


def base_url() -> str:
    """``$MS2_DOWNLOAD_BASE_URL`` when set, else ManiSkill2's :data:`DEFAULT_BASE_URL`."""
    return os.environ.get(BASE_URL_ENV) or DEFAULT_BASE_URL


def resolve(
    name: str, archives: dict[str, Archive] | None = None, asset_dir: Path | None = None
) -> list[str]:
    """Archive names for an env id, an archive name, ``partnet_mobility/<model id>`` or ``all``
    (``ValueError`` otherwise). The PartNet-Mobility env ids (:data:`PARTNET_GROUPS`) read
    their model ids from the info files in ``asset_dir``."""
    archives = ARCHIVES if archives is None else archives
    if name == "all":
        return list(archives)
    if name in archives:
        return [name]
    if name in GROUPS:
        return list(GROUPS[name])
    if name.startswith(PARTNET_PREFIX):
        partnet_archive(name[len(PARTNET_PREFIX) :])  # checks the id
        return [name]
    if name in PARTNET_GROUPS and asset_dir is not None:
        return [
            PARTNET_PREFIX + model_id
            for category in PARTNET_GROUPS[name]
            for model_id in partnet_model_ids(category, asset_dir)
        ]
    raise ValueError(
        f"unknown asset {name!r}: expected an env id ({', '.join([*GROUPS, *PARTNET_GROUPS])}), "
        f"an archive ({', '.join(archives)}), partnet_mobility/<model id> or 'all'"
    )


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(_CHUNK), b""):
            h.update(block)
    return h.hexdigest()


def _fetch_to(url: str, part: Path, progress: Callable[[int, int | None], None] | None) -> None:
    """Downloads ``url`` into ``part``, resuming from its current size with a Range request."""
    have = part.stat().st_size if part.exists() else 0
    req = urllib.request.Request(url, headers={"User-Agent": "ms2-assets"})
    if have:
        req.add_header("Range", f"bytes={have}-")
    try:
        resp = urllib.request.urlopen(req, timeout=60)
    except urllib.error.HTTPError as err:
        if err.code == 416 and have:
            return  # The partial file already holds every byte: the checksum decides.
        raise DownloadError(f"{url}: HTTP {err.code} {err.reason}") from None
    except (urllib.error.URLError, OSError) as err:
        raise DownloadError(f"{url}: cannot connect ({err})") from None
    with resp:
        if have and resp.status == 206:
            total = None
            rng = resp.headers.get("Content-Range", "")
            if "/" in rng and rng.rsplit("/", 1)[1].strip().isdigit():
                total = int(rng.rsplit("/", 1)[1])
            mode = "ab"
        else:
            have, mode = 0, "wb"  # The server ignored the range: start over.
            length = resp.headers.get("Content-Length")
            total = int(length) if length and length.isdigit() else None
        got = have
        with open(part, mode) as f:
            try:
                while True:
                    block = resp.read(_CHUNK)
                    if not block:
                        break
                    f.write(block)
                    got += len(block)
                    if progress:
                        progress(got, total)
            except (OSError, ValueError, http.client.HTTPException) as err:
                raise DownloadError(
                    f"{url}: interrupted after {got} bytes ({err}); run the command again to resume"
                ) from None
    if total is not None and got < total:
        raise DownloadError(
            f"{url}: interrupted after {got} of {total} bytes; run the command again to resume"
        )
    if total is not None and got > total:
        part.unlink(missing_ok=True)
        raise DownloadError(f"{url}: received {got} bytes, more than the announced {total}")


def _extract_zip(archive: Path, name: str, target: str, asset_dir: Path, tmp: Path) -> None:
    try:
        with zipfile.ZipFile(archive) as z:
            bad = z.testzip()
            if bad is not None:
                raise DownloadError(f"archive {name}: member {bad!r} is corrupt")
            for m in z.namelist():
                p = PurePosixPath(m)
                if p.is_absolute() or ".." in p.parts:
                    raise DownloadError(f"archive {name}: member {m!r} points outside its folder")
                if p.parts and p.parts[0] != target:
                    raise DownloadError(
                        f"archive {name}: member {m!r} is not under {target}/ as expected"
                    )
            z.extractall(tmp)
    except zipfile.BadZipFile as err:
        raise DownloadError(f"archive {name} ({archive}) is not a valid zip file: {err}") from None
    src = tmp / target
    if not src.is_dir():
        raise DownloadError(f"archive {name}: holds no {target}/ folder")
    dest = asset_dir / target
    old = None
    if dest.exists():
        old = tmp / ".old"
        os.replace(dest, old)
    os.replace(src, dest)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)


def download_archive(
    name: str,
    asset_dir: Path,
    base: str | None = None,
    archives: dict[str, Archive] | None = None,
    force: bool = False,
    progress: Callable[[int, int | None], None] | None = None,
) -> Path:
    """Downloads one archive into ``asset_dir`` (checksum-checked, resumable, atomic) and
    returns the installed folder or file. Present data is kept unless ``force``."""
    archives = ARCHIVES if archives is None else archives
    if name.startswith(PARTNET_PREFIX) and name not in archives:
        a = partnet_archive(name[len(PARTNET_PREFIX) :])
    elif name in archives:
        a = archives[name]
    else:
        raise ValueError(f"unknown archive {name!r}: expected one of {', '.join(archives)}")
    dest = asset_dir / a.parent / a.target
    if dest.exists() and not force:
        return dest
    url = f"{(base or base_url()).rstrip('/')}/{a.path}"
    staging = asset_dir / STAGING_DIR
    staging.mkdir(parents=True, exist_ok=True)
    stem = name.replace("/", "_")
    part = staging / f"{stem}.{(a.sha256 or 'unchecked')[:12]}.part"
    _fetch_to(url, part, progress)
    found = _sha256(part)
    if a.sha256 is not None and found != a.sha256:
        part.unlink(missing_ok=True)
        raise DownloadError(
            f"{url}: sha256 {found} does not match the published {a.sha256} "
            "(corrupt or another file); the partial download was removed"
        )
    if a.is_zip:
        tmp = Path(tempfile.mkdtemp(prefix=f"{stem}.", dir=staging))
        try:
            (asset_dir / a.parent).mkdir(parents=True, exist_ok=True)
            _extract_zip(part, name, a.target, asset_dir / a.parent, tmp)
        except DownloadError:
            part.unlink(missing_ok=True)  # complete but unusable: the next run fetches anew
            raise
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
        part.unlink(missing_ok=True)
    else:
        dest.parent.mkdir(parents=True, exist_ok=True)
        os.replace(part, dest)
    return dest


def download(
    what: str,
    asset_dir: Path,
    base: str | None = None,
    archives: dict[str, Archive] | None = None,
    force: bool = False,
    progress: Callable[[int, int | None], None] | None = None,
) -> list[Path]:
    """Downloads what an env id, archive name or ``all`` needs; returns the installed paths."""
    return [
        download_archive(n, asset_dir, base, archives, force, progress)
        for n in resolve(what, archives, asset_dir)
    ]


__all__ = [
    "ARCHIVES",
    "Archive",
    "BASE_URL_ENV",
    "DEFAULT_BASE_URL",
    "DownloadError",
    "GROUPS",
    "PARTNET_GROUPS",
    "PARTNET_PREFIX",
    "base_url",
    "download",
    "download_archive",
    "partnet_archive",
    "partnet_model_ids",
    "resolve",
]

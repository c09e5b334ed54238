"""``ms2 assets download`` against a local HTTP server serving generated archives.

No test uses the network: a server on 127.0.0.1 serves archives built here, in ManiSkill2's
layout, whole, truncated, corrupt, missing (404), or cut once and then resumable (Range).
"""

from __future__ import annotations

import gzip
import hashlib
import io
import json
import os
import subprocess
import sys
import threading
import zipfile
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import pytest
from ms2 import download as dl


def _zip(members: dict[str, bytes]) -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        for name, data in members.items():
            z.writestr(name, data)
    return buf.getvalue()


# A ManiSkill2-layout YCB archive with one model, padded so downloads take several chunks.
YCB_ZIP = _zip(
    {
        "mani_skill2_ycb/info_pick_v0.json": json.dumps(
            {"002_master_chef_can": {"bbox": {"min": [0, 0, 0], "max": [1, 1, 1]}}}
        ).encode(),
        "mani_skill2_ycb/models/002_master_chef_can/collision.obj": b"v 0 0 0\n",
        "mani_skill2_ycb/models/002_master_chef_can/noise.bin": os.urandom(300_000),
    }
)
CLUTTER = gzip.compress(json.dumps([{"episode_id": 0, "actors": []}]).encode())


def _sha(b: bytes) -> str:
    return hashlib.sha256(b).hexdigest()


class _Server:
    """Serves ``files`` (path → bytes) with Range support, in modes chosen by path prefix:
    ``/ok/``, ``/trunc/`` (always cut at half), ``/flaky/`` (the first request cut at half),
    ``/corrupt/`` (one byte flipped). Records each request's Range header."""

    def __init__(self, files: dict[str, bytes]):
        self.files = files
        self.ranges: list[str | None] = []
        self.flaky_done: set[str] = set()
        server = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, *args):
                pass

            def do_GET(self):
                mode, _, rel = self.path.lstrip("/").partition("/")
                data = server.files.get(rel)
                server.ranges.append(self.headers.get("Range"))
                if data is None:
                    self.send_error(404, "Not Found")
                    return
                if mode == "corrupt":
                    data = data[:100] + bytes([data[100] ^ 0xFF]) + data[101:]
                start = 0
                rng = self.headers.get("Range")
                if rng and rng.startswith("bytes="):
                    start = int(rng[6:].split("-")[0])
                    if start >= len(data):
                        self.send_response(416)
                        self.send_header("Content-Range", f"bytes */{len(data)}")
                        self.end_headers()
                        return
                    self.send_response(206)
                    self.send_header("Content-Range", f"bytes {start}-{len(data) - 1}/{len(data)}")
                else:
                    self.send_response(200)
                body = data[start:]
                self.send_header("Content-Length", str(len(body)))
                self.end_headers()
                cut = mode == "trunc" or (mode == "flaky" and rel not in server.flaky_done)
                if cut:
                    server.flaky_done.add(rel)
                    self.wfile.write(body[: len(body) // 2])
                    self.wfile.flush()
                    self.close_connection = True
                    return
                self.wfile.write(body)

        self.httpd = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.thread = threading.Thread(target=self.httpd.serve_forever, daemon=True)
        self.thread.start()

    def url(self, mode: str) -> str:
        return f"http://127.0.0.1:{self.httpd.server_address[1]}/{mode}"

    def close(self):
        self.httpd.shutdown()
        self.httpd.server_close()


ARCHIVES = {
    "ycb": dl.Archive("mani_skill2_ycb_v2.zip", _sha(YCB_ZIP), "mani_skill2_ycb"),
    "pick_clutter_ycb": dl.Archive(
        "pick_clutter/ycb_train_5k.json.gz", _sha(CLUTTER), "pick_clutter/ycb_train_5k.json.gz"
    ),
}


@pytest.fixture()
def server():
    s = _Server({"mani_skill2_ycb_v2.zip": YCB_ZIP, "pick_clutter/ycb_train_5k.json.gz": CLUTTER})
    yield s
    s.close()


def _nothing_half_written(root: Path) -> None:
    assert not (root / "mani_skill2_ycb").exists()
    staging = root / dl.STAGING_DIR
    leftovers = [p for p in staging.iterdir() if p.is_dir()] if staging.exists() else []
    assert leftovers == []


def test_an_env_id_downloads_its_archives_into_maniskill2_layout(server, tmp_path):
    paths = dl.download("PickClutterYCB-v0", tmp_path, server.url("ok"), ARCHIVES)
    assert paths == [tmp_path / "mani_skill2_ycb", tmp_path / "pick_clutter/ycb_train_5k.json.gz"]
    info = json.loads((tmp_path / "mani_skill2_ycb/info_pick_v0.json").read_text())
    assert list(info) == ["002_master_chef_can"]
    assert (tmp_path / "pick_clutter/ycb_train_5k.json.gz").read_bytes() == CLUTTER
    assert list((tmp_path / dl.STAGING_DIR).iterdir()) == []
    # Present data is kept; --force downloads again and replaces it.
    (tmp_path / "mani_skill2_ycb/marker").write_text("x")
    dl.download("PickSingleYCB-v0", tmp_path, server.url("ok"), ARCHIVES)
    assert (tmp_path / "mani_skill2_ycb/marker").exists()
    dl.download("ycb", tmp_path, server.url("ok"), ARCHIVES, force=True)
    assert not (tmp_path / "mani_skill2_ycb/marker").exists()
    assert (tmp_path / "mani_skill2_ycb/info_pick_v0.json").exists()


def test_a_truncated_download_is_an_error_and_installs_nothing(server, tmp_path):
    with pytest.raises(dl.DownloadError, match=r"interrupted after \d+ of \d+ bytes"):
        dl.download("ycb", tmp_path, server.url("trunc"), ARCHIVES)
    _nothing_half_written(tmp_path)


def test_an_interrupted_download_resumes_with_a_range_request(server, tmp_path):
    with pytest.raises(dl.DownloadError, match="run the command again to resume"):
        dl.download("ycb", tmp_path, server.url("flaky"), ARCHIVES)
    _nothing_half_written(tmp_path)
    part = next((tmp_path / dl.STAGING_DIR).glob("ycb.*.part"))
    have = part.stat().st_size
    assert 0 < have < len(YCB_ZIP)
    dl.download("ycb", tmp_path, server.url("flaky"), ARCHIVES)
    assert server.ranges[-1] == f"bytes={have}-"
    assert (tmp_path / "mani_skill2_ycb/models/002_master_chef_can/collision.obj").exists()
    assert not part.exists()


def test_corrupt_bytes_and_a_wrong_checksum_are_rejected(server, tmp_path):
    with pytest.raises(dl.DownloadError, match="sha256 .* does not match the published"):
        dl.download("ycb", tmp_path, server.url("corrupt"), ARCHIVES)
    _nothing_half_written(tmp_path)
    assert list((tmp_path / dl.STAGING_DIR).glob("*.part")) == []
    wrong = {"ycb": dl.Archive("mani_skill2_ycb_v2.zip", "0" * 64, "mani_skill2_ycb")}
    with pytest.raises(dl.DownloadError, match="0{64}"):
        dl.download("ycb", tmp_path, server.url("ok"), wrong)
    _nothing_half_written(tmp_path)


def test_a_missing_archive_is_a_404_naming_the_url(server, tmp_path):
    missing = {"egad": dl.Archive("mani_skill2_egad_v1.zip", "0" * 64, "mani_skill2_egad")}
    with pytest.raises(dl.DownloadError, match=r"/ok/mani_skill2_egad_v1.zip: HTTP 404"):
        dl.download("egad", tmp_path, server.url("ok"), missing)
    assert not (tmp_path / "mani_skill2_egad").exists()


def test_bad_archives_with_the_right_checksum_install_nothing(server, tmp_path):
    garbage = b"not a zip at all" * 100
    evil = _zip({"mani_skill2_ycb/a.txt": b"a", "mani_skill2_ycb/../../evil.txt": b"x"})
    other = _zip({"something_else/a.txt": b"a"})
    for data, message in [
        (garbage, "not a valid zip file"),
        (evil, "points outside its folder"),
        (other, "is not under mani_skill2_ycb/"),
    ]:
        server.files["bad.zip"] = data
        table = {"ycb": dl.Archive("bad.zip", _sha(data), "mani_skill2_ycb")}
        with pytest.raises(dl.DownloadError, match=message):
            dl.download("ycb", tmp_path, server.url("ok"), table)
        _nothing_half_written(tmp_path)
        assert not (tmp_path.parent / "evil.txt").exists()


def test_unknown_names_are_value_errors():
    with pytest.raises(ValueError, match="unknown asset 'PickBanana-v0': expected an env id"):
        dl.resolve("PickBanana-v0")
    assert dl.resolve("PickClutterYCB-v0") == ["ycb", "pick_clutter_ycb"]
    assert set(dl.resolve("all")) == set(dl.ARCHIVES)


def test_the_cli_downloads_from_a_base_url(server, tmp_path):
    env = dict(os.environ, MS2_ASSET_DIR=str(tmp_path))
    # The CLI uses the published table: serve our archive under the published name and check
    # the command reports the checksum mismatch (our test archive is not ManiSkill2's).
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "ms2",
            "assets",
            "download",
            "PickSingleYCB-v0",
            "-q",
            "--base-url",
            server.url("ok"),
        ],
        capture_output=True,
        text=True,
        env=env,
    )
    assert r.returncode != 0
    assert "does not match the published b83afbe9" in r.stderr + r.stdout
    assert not (tmp_path / "mani_skill2_ycb").exists()
    r = subprocess.run(
        [sys.executable, "-m", "ms2", "assets", "download", "nothing-v0"],
        capture_output=True,
        text=True,
        env=env,
    )
    assert r.returncode != 0 and "unknown asset 'nothing-v0'" in r.stderr + r.stdout


def _partnet_server(models: dict[str, bytes]) -> _Server:
    return _Server({f"partnet_mobility/dataset/{m}.zip": z for m, z in models.items()})


def _write_info(root: Path, category: str, ids: list[str]) -> None:
    meta = root / "partnet_mobility" / "meta"
    meta.mkdir(parents=True, exist_ok=True)
    (meta / f"info_{category}_train.json").write_text(json.dumps({i: {} for i in ids}))


def test_turn_faucet_downloads_the_partnet_models_its_info_file_lists(tmp_path):
    """ManiSkill2's layout: partnet_mobility/dataset/<id>/ for every faucet of the info file;
    an id's zip with a member outside <id>/ installs nothing; a missing info file names it."""
    root = tmp_path / "data"
    with pytest.raises(dl.DownloadError, match="info_faucet_train.json is missing"):
        dl.download("TurnFaucet-v0", root, base="http://127.0.0.1:9")
    _write_info(root, "faucet", ["148", "149"])
    good = {
        m: _zip({f"{m}/mobility.urdf": b"<robot/>", f"{m}/meta.json": b"{}"})
        for m in ("148", "149")
    }
    s = _partnet_server(good)
    try:
        paths = dl.download("TurnFaucet-v0", root, base=s.url("ok"))
        assert sorted(p.name for p in paths) == ["148", "149"]
        for m in ("148", "149"):
            urdf = root / "partnet_mobility" / "dataset" / m / "mobility.urdf"
            assert urdf.read_bytes() == b"<robot/>"
        # A single model by name; present data is kept, --force downloads again.
        one = dl.download("partnet_mobility/148", root, base=s.url("ok"), force=True)
        assert one == [root / "partnet_mobility" / "dataset" / "148"]
    finally:
        s.close()
    bad = _partnet_server(
        {"150": _zip({"other/mobility.urdf": b"x"}), "152": _zip({"152/mobility.urdf": b"y"})}
    )
    try:
        with pytest.raises(dl.DownloadError, match="not under 150/"):
            dl.download("partnet_mobility/150", root, base=bad.url("ok"))
        assert not (root / "partnet_mobility" / "dataset" / "150").exists()
        with pytest.raises(dl.DownloadError, match="HTTP 404"):
            dl.download("partnet_mobility/151", root, base=bad.url("ok"))
        with pytest.raises(dl.DownloadError, match="interrupted"):
            dl.download("partnet_mobility/152", root, base=bad.url("trunc"))
        assert not (root / "partnet_mobility" / "dataset" / "152").exists()
        # The next run resumes the partial file and installs the model.
        dl.download("partnet_mobility/152", root, base=bad.url("ok"))
        assert (
            root / "partnet_mobility" / "dataset" / "152" / "mobility.urdf"
        ).read_bytes() == b"y"
    finally:
        bad.close()
    with pytest.raises(ValueError, match="model ids are numbers, got 'abc'"):
        dl.resolve("partnet_mobility/abc")

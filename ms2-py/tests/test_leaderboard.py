"""ms2 leaderboard: several results.json rendered into one static HTML table, checked as HTML
and as Debian's headless Chromium draws it (a screenshot)."""

from __future__ import annotations

import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest
from ms2.cli import main
from ms2.evaluation.leaderboard import COLUMNS, HEADER_BACKGROUND, ROW_BACKGROUNDS
from ms2.evaluation.results import EpisodeResult, write_results
from PIL import Image

#: (task, solution, [(success, failure kind or None, episode length)]) of the fake runs.
RUNS = [
    ("PickCube-v0", "alpha", [(1, None, 40), (0, None, 200), (1, None, 50), (0, None, 200)]),
    ("PickCube-v0", "beta", [(1, None, 30)] * 4),
    ("PickCube-v0", "gamma", [(1, None, 40), (0, "timeout", 3), (1, None, 50), (0, None, 200)]),
    ("StackCube-v0", "<script>x</script>", [(0, "exception", 1), (1, None, 90)]),
]
#: The rows expected, in order: (rank, task, solution, success rate, failed episodes).
EXPECTED_ROWS = [
    ("1", "PickCube-v0", "beta", "100.0 %", "0"),
    ("2", "PickCube-v0", "alpha", "50.0 %", "0"),
    ("3", "PickCube-v0", "gamma", "50.0 %", "1"),
    ("1", "StackCube-v0", "<script>x</script>", "50.0 %", "1"),
]


def make_results(root: Path) -> list[Path]:
    """One ``ms2 evaluate``-style output directory per run of :data:`RUNS`."""
    dirs = []
    for i, (env_id, solution, episodes) in enumerate(RUNS):
        results = [
            EpisodeResult(
                episode_id=j,
                seed=j,
                metrics={"elapsed_steps": float(steps), "success": float(success)},
                seconds=0.1,
                failure_kind=kind,
                failure_reason=None if kind is None else "test",
                failure_step=None if kind is None else steps,
            )
            for j, (success, kind, steps) in enumerate(episodes)
        ]
        header = {
            "env_id": env_id,
            "solution": solution,
            "obs_mode": "state",
            "control_mode": "pd_ee_delta_pose",
        }
        out = root / f"run{i}"
        write_results(out, results, header)
        dirs.append(out)
    return dirs


class _TableParser(HTMLParser):
    """Collects the header cells, and each body row's class and cell texts."""

    def __init__(self) -> None:
        super().__init__()
        self.headers: list[str] = []
        self.rows: list[tuple[str, list[str]]] = []
        self._cell: list[str] | None = None
        self._in_body = False

    def handle_starttag(self, tag, attrs):
        if tag == "tbody":
            self._in_body = True
        elif tag == "tr" and self._in_body:
            self.rows.append((dict(attrs).get("class", ""), []))
        elif tag in ("td", "th"):
            self._cell = []

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None:
            text = "".join(self._cell).strip()
            (self.rows[-1][1] if tag == "td" else self.headers).append(text)
            self._cell = None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)


def render(tmp_path: Path, capsys) -> Path:
    board = tmp_path / "board.html"
    assert main(["leaderboard", *map(str, make_results(tmp_path)), "-o", str(board)]) == 0
    assert f"wrote {board}" in capsys.readouterr().out
    return board


def test_leaderboard_html_table(tmp_path, capsys):
    board = render(tmp_path, capsys)
    text = board.read_text()
    assert "<script>" not in text  # names are escaped
    parser = _TableParser()
    parser.feed(text)
    assert parser.headers == [header for header, _ in COLUMNS]
    assert [row_class for row_class, _ in parser.rows] == ["band0", "band1", "band0", "band1"]
    shown = [(c[0], c[1], c[2], c[3], c[5]) for _, c in parser.rows]
    assert shown == EXPECTED_ROWS
    lengths = [c[4] for _, c in parser.rows]
    assert lengths == ["30.0", "122.5", "73.2", "45.5"]
    assert 'title="timeout: 1"' in text  # failure kinds on hover


def test_leaderboard_errors(tmp_path, capsys):
    missing = tmp_path / "nothing_here"
    code = main(["leaderboard", str(missing), "-o", str(tmp_path / "b.html")])
    assert code == 2
    assert f"no evaluation results at {missing / 'results.json'}" in capsys.readouterr().err
    (tmp_path / "bad").mkdir()
    (tmp_path / "bad" / "results.json").write_text('{"env_id": "PickCube-v0"}')
    assert main(["leaderboard", str(tmp_path / "bad"), "-o", str(tmp_path / "b.html")]) == 2
    assert "is not an ms2 results.json" in capsys.readouterr().err
    assert not (tmp_path / "b.html").exists()


def _hex_rgb(colour: str) -> np.ndarray:
    return np.array([int(colour[i : i + 2], 16) for i in (1, 3, 5)])


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(start, end) of the runs of True in a 1-D mask."""
    padded = np.concatenate([[False], mask, [False]]).astype(np.int8)
    edges = np.flatnonzero(np.diff(padded))
    return list(zip(edges[::2], edges[1::2], strict=True))


def test_leaderboard_screenshot_in_headless_chromium(tmp_path, capsys):
    chromium = shutil.which("chromium")
    if chromium is None:
        pytest.fail("Debian's chromium is not installed (scripts/test.sh installs it)")
    board = render(tmp_path, capsys)
    png = tmp_path / "board.png"
    width, height = 1400, 500
    done = subprocess.run(
        [
            chromium,
            "--headless",
            "--no-sandbox",  # the tests may run as root
            "--disable-gpu",
            "--hide-scrollbars",
            f"--user-data-dir={tmp_path / 'profile'}",
            f"--screenshot={png}",
            f"--window-size={width},{height}",
            board.as_uri(),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0 and png.exists(), done.stderr[-2000:]
    image = np.asarray(Image.open(png).convert("RGB")).astype(int)
    assert image.shape == (height, width, 3)

    def near(colour: str) -> np.ndarray:
        return np.abs(image - _hex_rgb(colour)).max(axis=2) <= 4

    header = near(HEADER_BACKGROUND)
    ys, xs = np.nonzero(header)
    assert ys.size > 5000, "no table header drawn"
    top, bottom, left, right = ys.min(), ys.max(), xs.min(), xs.max()
    assert right - left > width / 2  # a wide table
    # White header text on the header colour.
    head = image[top : bottom + 1, left : right + 1]
    assert (head.min(axis=2) > 200).sum() > 200
    # The body rows: band colours alternate below the header, one band per row.
    column = left + 3
    band1_runs = [r for r in _runs(near(ROW_BACKGROUNDS[1])[:, column]) if r[0] > bottom]
    assert len(band1_runs) == 2, band1_runs  # rows 2 and 4 of 4
    row_height = band1_runs[0][1] - band1_runs[0][0]
    assert row_height > 15
    body_bottom = band1_runs[-1][1]
    assert body_bottom - bottom == pytest.approx(4 * row_height, abs=8)
    # Dark text in every row.
    for row in range(4):
        y0 = bottom + 1 + row * (body_bottom - bottom) // 4
        cells = image[y0 : y0 + row_height, left : right + 1]
        assert (cells.max(axis=2) < 100).sum() > 100, f"no text in row {row}"
    # Nothing drawn below the table.
    assert (image[body_bottom + 20 :].min(axis=2) < 250).sum() == 0

"""A leaderboard page: the ``results.json`` of several ``ms2 evaluate`` runs as one static
HTML table (no scripts, no external files: open it in any browser or publish it as is).

One row per solution × task: rank within the task, task, solution, success rate, mean episode
length, failed episodes (with their kinds), episodes, obs / control mode. Rows are sorted by
task, then success rate (highest first), then failed episodes (fewest first), then mean episode
length (shortest first), then solution name.
"""

from __future__ import annotations

import html
import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from .results import read_results, write_text_atomic

#: Colours of the table (the tests look for them in a screenshot).
HEADER_BACKGROUND = "#1f3b63"
ROW_BACKGROUNDS = ("#ffffff", "#e3ecfa")

_STYLE = f"""
body {{ font-family: sans-serif; margin: 24px; color: #111; background: #fff; }}
h1 {{ font-size: 22px; margin: 0 0 12px 0; }}
p.note {{ color: #444; font-size: 13px; margin: 0 0 16px 0; }}
table.leaderboard {{ border-collapse: collapse; font-size: 15px; }}
table.leaderboard th {{ background: {HEADER_BACKGROUND}; color: #fff; text-align: left;
  padding: 8px 14px; white-space: nowrap; }}
table.leaderboard td {{ padding: 8px 14px; border-bottom: 1px solid #c8d3e6; white-space: nowrap; }}
table.leaderboard tr.band0 td {{ background: {ROW_BACKGROUNDS[0]}; }}
table.leaderboard tr.band1 td {{ background: {ROW_BACKGROUNDS[1]}; }}
td.num {{ text-align: right; font-variant-numeric: tabular-nums; }}
"""

#: The table's columns: header and the row key shown.
COLUMNS = (
    ("#", "rank"),
    ("Task", "env_id"),
    ("Solution", "solution"),
    ("Success rate", "success_rate"),
    ("Mean episode length", "mean_episode_length"),
    ("Failed episodes", "num_failed"),
    ("Episodes", "num_episodes"),
    ("Obs mode", "obs_mode"),
    ("Control mode", "control_mode"),
)


def collect_rows(results: Iterable[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """Leaderboard rows from ``results.json`` contents, sorted and ranked within each task."""
    rows = []
    for r in results:
        rows.append(
            {
                "env_id": str(r["env_id"]),
                "solution": str(r["solution"]),
                "success_rate": float(r["success_rate"]),
                "mean_episode_length": float(r["mean_episode_length"]),
                "num_failed": int(r.get("num_failed", 0)),
                "failures_by_kind": dict(r.get("failures_by_kind") or {}),
                "num_episodes": int(r["num_episodes"]),
                "obs_mode": str(r.get("obs_mode")),
                "control_mode": str(r.get("control_mode")),
            }
        )
    rows.sort(
        key=lambda row: (
            row["env_id"],
            -row["success_rate"],
            row["num_failed"],
            row["mean_episode_length"],
            row["solution"],
        )
    )
    rank = 0
    for i, row in enumerate(rows):
        rank = rank + 1 if i and rows[i - 1]["env_id"] == row["env_id"] else 1
        row["rank"] = rank
    return rows


def _cell(row: Mapping[str, Any], key: str) -> str:
    value = row[key]
    if key == "success_rate":
        return f'<td class="num">{100.0 * value:.1f} %</td>'
    if key == "mean_episode_length":
        return f'<td class="num">{value:.1f}</td>'
    if key == "num_failed":
        kinds = ", ".join(f"{k}: {n}" for k, n in sorted(row["failures_by_kind"].items()))
        title = f' title="{html.escape(kinds)}"' if kinds else ""
        return f'<td class="num"{title}>{value}</td>'
    if isinstance(value, int):
        return f'<td class="num">{value}</td>'
    return f"<td>{html.escape(str(value))}</td>"


def render_html(rows: Sequence[Mapping[str, Any]], title: str = "ms2 leaderboard") -> str:
    """The leaderboard page of ``rows`` (from :func:`collect_rows`)."""
    head = "".join(f"<th>{html.escape(h)}</th>" for h, _ in COLUMNS)
    body = []
    for i, row in enumerate(rows):
        cells = "".join(_cell(row, key) for _, key in COLUMNS)
        body.append(f'<tr class="band{i % 2}">{cells}</tr>')
    tasks = len({row["env_id"] for row in rows})
    note = (
        f"{len(rows)} evaluation(s) of {tasks} task(s), from <code>ms2 evaluate</code> results. "
        "Failed episodes: the solution raised, returned a NaN or malformed action, or exceeded "
        "the per-step time limit (hover for the kinds)."
    )
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        f"<title>{html.escape(title)}</title>\n<style>{_STYLE}</style>\n</head>\n<body>\n"
        f'<h1>{html.escape(title)}</h1>\n<p class="note">{note}</p>\n'
        '<table class="leaderboard">\n'
        f"<thead><tr>{head}</tr></thead>\n<tbody>\n" + "\n".join(body) + "\n</tbody>\n</table>\n"
        "</body>\n</html>\n"
    )


def write_leaderboard(
    result_dirs: Sequence[str | os.PathLike[str]],
    output: str | os.PathLike[str],
    title: str = "ms2 leaderboard",
) -> Path:
    """Reads each directory's (or file's) ``results.json`` and writes the page to ``output``
    (atomically). ``ValueError`` naming the first unreadable results; none given is an error."""
    if not result_dirs:
        raise ValueError("no results given: pass one or more `ms2 evaluate -o` directories")
    rows = collect_rows(read_results(d) for d in result_dirs)
    return write_text_atomic(output, render_html(rows, title))


__all__ = ["COLUMNS", "collect_rows", "render_html", "write_leaderboard"]

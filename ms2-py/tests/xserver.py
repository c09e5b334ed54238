"""A virtual X server (Xvfb) for the viewer tests, with synthetic input (xdotool) and
screenshots (Pillow's X grabber). scripts/test.sh installs the Debian packages `xvfb` and
`xdotool`."""

from __future__ import annotations

import os
import shutil
import subprocess
import time

import numpy as np

TOOLS = ("Xvfb", "xdotool")


def missing_tools() -> list[str]:
    return [t for t in TOOLS if shutil.which(t) is None]


class XServer:
    """An Xvfb server on a free display number (``-displayfd``), 1024x768x24, without key
    auto-repeat: under load xdotool's release of a key can come later than the server's
    repeat delay (660 ms), and a repeated key would be a second press the test did not send."""

    def __init__(self) -> None:
        missing = missing_tools()
        if missing:
            raise RuntimeError(
                f"the viewer tests need {missing} (Debian packages xvfb, xdotool; "
                "scripts/test.sh installs them)"
            )
        read_fd, write_fd = os.pipe()
        self.proc = subprocess.Popen(
            [
                "Xvfb",
                "-displayfd",
                str(write_fd),
                "-screen",
                "0",
                "1024x768x24",
                "-nolisten",
                "tcp",
                "-r",
            ],
            pass_fds=(write_fd,),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        os.close(write_fd)
        with os.fdopen(read_fd) as f:
            number = f.readline().strip()
        if not number:
            self.proc.kill()
            raise RuntimeError("Xvfb did not report its display number")
        self.display = f":{number}"

    def env(self) -> dict[str, str]:
        """``os.environ`` with ``DISPLAY`` set to this server."""
        return {**os.environ, "DISPLAY": self.display}

    def xdotool(self, *args: str) -> str:
        out = subprocess.run(
            ["xdotool", *args], env=self.env(), capture_output=True, text=True, timeout=30
        )
        if out.returncode != 0:
            raise RuntimeError(f"xdotool {' '.join(args)} failed: {out.stderr.strip()}")
        return out.stdout

    def find_window(self, name: str, timeout_s: float = 30.0) -> int:
        """The id of the first window whose title contains ``name``."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            out = subprocess.run(
                ["xdotool", "search", "--name", name],
                env=self.env(),
                capture_output=True,
                text=True,
            )
            ids = out.stdout.split()
            if ids:
                return int(ids[0])
            time.sleep(0.1)
        raise TimeoutError(f"no window titled {name!r} appeared on {self.display}")

    def geometry(self, window: int) -> tuple[int, int, int, int]:
        """``(x, y, width, height)`` of a window on the screen."""
        values = dict(
            line.split("=", 1)
            for line in self.xdotool("getwindowgeometry", "--shell", str(window)).split()
        )
        return int(values["X"]), int(values["Y"]), int(values["WIDTH"]), int(values["HEIGHT"])

    def focus(self, window: int) -> None:
        self.xdotool("windowfocus", "--sync", str(window))

    def keys(self, window: int, keys: list[str], delay_ms: int = 20) -> None:
        """Types ``keys`` (X keysym names: ``"i"``, ``"space"``, ``"Escape"``) into ``window``
        as real key presses (XTEST), after giving it the focus."""
        self.focus(window)
        for start in range(0, len(keys), 50):
            self.xdotool("key", "--delay", str(delay_ms), *keys[start : start + 50])

    def screenshot(self) -> np.ndarray:
        """The whole screen, uint8 [H, W, 3]."""
        from PIL import ImageGrab

        return np.asarray(ImageGrab.grab(xdisplay=self.display).convert("RGB"))

    def close(self) -> None:
        self.proc.terminate()
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()

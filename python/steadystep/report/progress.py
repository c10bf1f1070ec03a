"""Progress of the comparison as plain lines, for a run whose standard error is not a terminal (a log file, CI).

tqdm draws nothing off a terminal, and a bar redrawn in place is unreadable in a log. Here every phase says when it
starts and ends, and while it works a line is written at least every interval (default 10 s; the environment variable
STEADYSTEP_PROGRESS_S changes it): the phase, units done of all, the time elapsed, an estimate of the time left
(elapsed per unit so far times the units left) and the last unit finished. A ticker thread writes the line again when
nothing finished within the interval, so that a unit longer than the interval (a reference run, a probe) still
shows the job alive:

    steadystep compare [runs] 120/480 units (25%), 1 min 02 s elapsed, about 3 min 06 s left; last: chain fixed:30 naive
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
import time

DEFAULT_INTERVAL_S = 10.0


def interval_s() -> float:
    """The longest silence between two lines: STEADYSTEP_PROGRESS_S if set to a positive number, else 10 s."""
    try:
        value = float(os.environ.get("STEADYSTEP_PROGRESS_S", DEFAULT_INTERVAL_S))
    except ValueError:
        return DEFAULT_INTERVAL_S
    return value if 0 < value < float("inf") else DEFAULT_INTERVAL_S


def duration(seconds: float) -> str:
    """A duration as a person reads it: "42 s", "3 min 05 s", "1 h 02 min"."""
    seconds = max(0, round(seconds))
    if seconds < 60:
        return f"{seconds} s"
    if seconds < 3600:
        return f"{seconds // 60} min {seconds % 60:02d} s"
    return f"{seconds // 3600} h {seconds % 3600 // 60:02d} min"


class Lines:
    """The interface of the tqdm bar the phases use (update, set_postfix_str, set_description_str), as lines."""

    def __init__(self, total: int, desc: str, unit: str = "unit", stream=None, every_s: float | None = None):
        self.total, self.desc, self.unit, self.done, self.last = total, desc, unit, 0, ""
        self.stream = stream if stream is not None else sys.stderr
        self.every_s = interval_s() if every_s is None else every_s
        self.started = self.said = time.monotonic()
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._say(f"{self.desc} started" + ("" if unit == "step" else f": {total} {self._units(total)}"))
        self._ticker = threading.Thread(target=self._tick, name="steadystep progress", daemon=True)
        self._ticker.start()

    def _units(self, n: int) -> str:
        return self.unit if n == 1 else f"{self.unit}s"

    def _say(self, line: str) -> None:
        self.said = time.monotonic()
        try:
            print(line, file=self.stream, flush=True)
        except (OSError, ValueError):  # a closed or full log: progress is not worth failing the job for
            pass

    def _state(self) -> str:
        elapsed = time.monotonic() - self.started
        if self.unit == "step":  # a phase of no countable units
            return f"{self.desc} working, {duration(elapsed)} elapsed"
        share = f" ({100 * self.done // self.total}%)" if self.total else ""
        if self.done and self.done < self.total:
            left = f", about {duration(elapsed / self.done * (self.total - self.done))} left"
        elif self.done < self.total:
            left = ", estimate after the first unit"
        else:
            left = ""
        last = f"; last: {self.last}" if self.last else ""
        return (f"{self.desc} {self.done}/{self.total} {self._units(self.total)}{share}, {duration(elapsed)} "
                f"elapsed{left}{last}")

    def _tick(self) -> None:
        while not self._stop.wait(max(0.05, self.every_s / 4)):
            with self._lock:
                if time.monotonic() - self.said >= self.every_s:
                    self._say(self._state())

    def update(self, n: int = 1) -> None:
        with self._lock:
            self.done += n
            if time.monotonic() - self.said >= self.every_s:
                self._say(self._state())

    def set_postfix_str(self, text: str = "", refresh: bool = True) -> None:
        with self._lock:
            self.last = text

    def set_description_str(self, text: str = "", refresh: bool = True) -> None:
        with self._lock:  # said with the next line (phases that alternate would otherwise fill the log)
            self.desc = text

    def close(self) -> None:
        self._stop.set()
        self._ticker.join()
        with self._lock:
            counted = "" if self.unit == "step" else f" {self.done} {self._units(self.done)}"
            self._say(f"{self.desc} done:{counted} in {duration(time.monotonic() - self.started)}")


def off_terminal(progress) -> bool:
    """Whether progress is to be written as lines: asked for ("lines"), or left to the default (None) while
    standard error is not a terminal."""
    if progress == "lines":
        return True
    if progress is not None:
        return False
    try:
        return not sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


@contextlib.contextmanager
def bar(total: int, progress, desc: str, unit: str = "unit"):
    """The phase's progress: lines off a terminal (off_terminal), else study.progress_bar (tqdm on a terminal,
    nothing for progress=False)."""
    if off_terminal(progress) and sys.stderr is not None:
        lines = Lines(total, desc, unit)
        try:
            yield lines
        finally:
            lines.close()
        return
    from steadystep.lab import study

    with study.progress_bar(total, None if progress == "lines" else progress, desc, unit) as made:
        yield made


@contextlib.contextmanager
def step(desc: str, progress=None):
    """A short phase of no countable units (the article's figure, the page): a line when it starts and when it
    ends, off a terminal, and the ticker's line while it lasts longer than the interval."""
    if not (off_terminal(progress) and sys.stderr is not None):
        yield
        return
    lines = Lines(1, desc, "step")
    try:
        yield
        lines.update()
    finally:
        lines.close()

"""Progress of long loops: the one place that makes CraftSuite's progress bars.

On a terminal, a tqdm bar redrawn in place. Where the bar's stream is not a terminal (a
log file, a pipe, CI), a plain line every tenth of the way or every ``LINE_EVERY``
seconds instead: a redrawn bar's carriage returns turn a log into one endless line. Either
way the rate counts only the work done in this session (``initial``: what a resumed run or
a reused one had done before), and ``bar.write`` prints a message on a line of its own.
"""

from __future__ import annotations

import sys
import time

LINE_EVERY = 30.0  # seconds between two plain lines, at most (a tenth of a long run can take an hour)


def progress_bar(total: int, desc: str, unit: str = "step", initial: int = 0, enabled: bool = True, stream=None):
    """A progress bar over ``total`` units, ``initial`` of them done before it starts.

    Args:
        total: the units of the whole loop, e.g. transitions.
        desc: what the loop is, the first words of every line.
        unit: the name of one unit.
        initial: units done before this session (a resumed run's): in the count, not the rate.
        enabled: False for no output at all (a worker's loop, a caller that reports itself).
        stream: where it is drawn (default: stderr, as tqdm's).

    Returns:
        A tqdm bar on a terminal, else a ``LineProgress``; both take ``update``,
        ``set_postfix``, ``write`` and ``close``, and count in ``n``.
    """
    from tqdm import tqdm

    stream = stream or sys.stderr
    if enabled and not _is_terminal(stream):
        return LineProgress(total, desc, unit, initial, stream)
    return tqdm(total=total, initial=initial, desc=desc, unit=unit, disable=not enabled, file=stream,
                dynamic_ncols=True, mininterval=1.0)


def progress_iter(items, desc: str, unit: str = "it", enabled: bool = True):
    """Yield ``items`` (a sized collection) while a ``progress_bar`` counts them."""
    items = list(items)
    with progress_bar(len(items), desc, unit, enabled=enabled) as bar:
        for item in items:
            yield item
            bar.update(1)


def _is_terminal(stream) -> bool:
    try:
        return stream.isatty()
    except (AttributeError, ValueError):  # no isatty, or a closed stream
        return False


class LineProgress:
    """A progress bar for logs: a plain line whenever another tenth of ``total`` is done or
    ``every`` seconds have passed since the last line, and one at the end; never a carriage
    return. ``clock`` is injectable for tests."""

    def __init__(self, total: int, desc: str, unit: str, initial: int, stream, every: float = LINE_EVERY,
                 clock=time.monotonic):
        self.total, self.desc, self.unit, self.initial, self.n = total, desc, unit, initial, initial
        self.stream, self.every, self.clock = stream, every, clock
        self.start = self.last = clock()
        self.shown = initial  # the count of the last line
        self.postfix = ""

    def __enter__(self) -> LineProgress:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def update(self, n: int = 1) -> None:
        self.n += n
        now = self.clock()
        if self._tenth(self.n) > self._tenth(self.shown) or now - self.last >= self.every:
            self._line(now)

    def set_postfix(self, **values) -> None:
        self.postfix = ", ".join(f"{k} {v}" for k, v in values.items())

    def write(self, text: str) -> None:
        """A message on a line of its own (to stdout, as ``tqdm.write``)."""
        print(text, flush=True)

    def close(self) -> None:
        if self.n != self.shown:
            self._line(self.clock())

    def _tenth(self, n: int) -> int:
        return int(10 * n / self.total) if self.total else 0

    def _line(self, now: float) -> None:
        self.shown, self.last = self.n, now
        elapsed = now - self.start
        rate = (self.n - self.initial) / elapsed if elapsed > 0 else 0.0  # this session's work only
        share = f"{100 * self.n / self.total:.0f}% " if self.total else ""
        total = f"/{self.total:,}" if self.total else ""
        more = f", {self.postfix}" if self.postfix else ""
        print(f"{self.desc}: {share}({self.n:,}{total} {self.unit}s, {rate:,.0f} {self.unit}s/s, "
              f"{_clock(elapsed)} elapsed{more})", file=self.stream, flush=True)


def _clock(seconds: float) -> str:
    minutes, seconds = divmod(int(seconds), 60)
    hours, minutes = divmod(minutes, 60)
    return f"{hours}:{minutes:02d}:{seconds:02d}" if hours else f"{minutes:02d}:{seconds:02d}"

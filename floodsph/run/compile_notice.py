"""Say on screen when numba compiles floodsph's kernels, and how long it took.

The kernels are compiled on their first use and cached on disk (``@njit(cache=True)``), so a
first run spends most of a minute compiling before its first step (``benchmarks/compile_time.py``
measures it) and later runs load them in seconds.
:class:`CompileNotice` listens to numba's ``"numba:compile"`` event, which numba raises only
when a kernel is actually compiled (not when it is loaded from the cache), and calls
``notify`` once with :data:`START_MESSAGE` at the first compilation and once at the end with
the time compiling took.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

START_MESSAGE = "compiling the numerical kernels (first run only; they are cached afterwards)"


class CompileNotice:
    """Context manager: ``notify(message)`` when compiling starts, and its total time at exit."""

    def __init__(self, notify: Callable[[str], None]):
        self.notify = notify
        self.seconds = 0.0
        self.kernels = 0
        self._depth = 0
        self._started = 0.0
        self._listener: Any = None  # numba's event listener while compiling

    def __enter__(self) -> CompileNotice:
        from numba.core import event

        notice = self

        class _Listener(event.Listener):
            def on_start(self, ev):
                notice._on_start()

            def on_end(self, ev):
                notice._on_end()

        self._listener = _Listener()
        event.register("numba:compile", self._listener)
        return self

    def _on_start(self) -> None:
        if self._depth == 0:
            if self.kernels == 0:
                self.notify(START_MESSAGE)
            self._started = time.perf_counter()
            self.kernels += 1
        self._depth += 1

    def _on_end(self) -> None:
        self._depth -= 1
        if self._depth == 0:
            self.seconds += time.perf_counter() - self._started

    def __exit__(self, *exc) -> None:
        from numba.core import event

        event.unregister("numba:compile", self._listener)
        if self.kernels:
            plural = "s" if self.kernels != 1 else ""
            self.notify(f"compiled {self.kernels} numerical kernel{plural} in "
                        f"{self.seconds:.0f} s")

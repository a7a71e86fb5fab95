"""SIGINT, SIGTERM and SIGHUP as a request to stop a run cleanly.

Batch schedulers send SIGTERM at the time limit (SLURM, PBS), a closed terminal sends SIGHUP,
Ctrl-C sends SIGINT. While :class:`StopSignals` is active each of them is caught:

* before the time loop is armed (set-up), the run stops at once with :class:`RunInterrupted`;
* once armed, the signal only sets :attr:`StopSignals.requested`; the simulation finishes the
  step it is in, the run writes a checkpoint and ``run.json`` with status ``"interrupted"``;
  a second signal while it does so is ignored, so the checkpoint is never cut short.

Handlers can only be installed from the main thread; elsewhere (a dask worker, say) the
class does nothing and the process's own handling applies. An ensemble (never armed) uses it
to turn each of the three signals into the :class:`RunInterrupted` of its own ending.
"""

from __future__ import annotations

import signal
import threading

SIGNALS = tuple(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP")
                if hasattr(signal, name))


class RunInterrupted(KeyboardInterrupt):
    """A stop signal arrived while the run was being set up."""


class StopSignals:
    """Context manager: catch the stop signals for the length of a run."""

    def __init__(self, during: str = "during set-up", external=None):
        self.during = during
        self.external = external
        self.requested: str | None = None
        self.armed = False
        self._previous: dict = {}

    def __enter__(self) -> StopSignals:
        if threading.current_thread() is threading.main_thread():
            for sig in SIGNALS:
                self._previous[sig] = signal.signal(sig, self._handle)
        return self

    def __exit__(self, *exc) -> None:
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)
        self._previous.clear()

    def _handle(self, signum, frame) -> None:
        if self.requested is not None:
            return
        self.requested = signal.Signals(signum).name
        if not self.armed:
            raise RunInterrupted(" ".join(filter(None, ("interrupted by", self.requested,
                                                        self.during))))

    def __call__(self) -> bool:
        """True once a stop was requested (the simulation's ``should_stop``): by a signal, or
        by ``external() -> reason or None`` (an ensemble stopping its members on workers,
        where no signal handler can be installed)."""
        if self.requested is None and self.external is not None:
            self.requested = self.external()
        return self.requested is not None

"""What a run will cost before it starts, and its progress while it runs.

A run that would take hours is more often a user's slip than their intent: a
modulus in GPa typed as Pa, a time step of 1e-9 s, an end time of 1e9 s, a pulse
of 1e-6 rad/s that lasts two months. Every engine therefore estimates its cost from
its inputs before it starts (`RunCost`), refuses a run whose estimate exceeds a
budget (default `DEFAULT_BUDGET_S`, one hour; raise it with the engine's
``max_hours`` argument) or whose output would not fit in memory, with a message
that names the cause and the fix, and shows a progress bar on stderr (`Progress`)
for any run estimated at more than `PROGRESS_AFTER_S` seconds.

Estimates are rough (a factor of ~3, calibrated on this machine kind, see each
engine); they guard against slips of orders of magnitude, not seconds.
"""

from __future__ import annotations

import math
import os
import sys
from dataclasses import dataclass

from .errors import InputError
from .validation import positive

__all__ = [
    "RunCost",
    "Progress",
    "DEFAULT_BUDGET_S",
    "PROGRESS_AFTER_S",
    "memory_limit",
    "budget_seconds",
    "format_duration",
    "format_bytes",
]

#: Longest estimated wall time a single run may take unless the caller raises it (s).
DEFAULT_BUDGET_S = 3600.0
#: Runs estimated above this many seconds show a progress bar (when progress is automatic).
PROGRESS_AFTER_S = 3.0


def memory_limit() -> float:
    """Half of this machine's physical memory (bytes); 8 GiB where it cannot be read."""
    try:
        return 0.5 * os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        return 8.0 * 2**30


def format_duration(seconds: float) -> str:
    """'42 s', '12 min', '3.4 h', '5.1 days' or '2.3e+04 years'."""
    if not math.isfinite(seconds):
        return "forever"
    for unit, size in (("years", 3.156e7), ("days", 86400.0), ("h", 3600.0), ("min", 60.0)):
        if seconds >= size:
            return f"{seconds / size:.2g} {unit}"
    return f"{seconds:.2g} s"


def format_bytes(n: float) -> str:
    """'512 B', '3.2 GiB', '7.3 TiB'."""
    for unit in ("PiB", "TiB", "GiB", "MiB", "KiB"):
        size = 2.0 ** {"KiB": 10, "MiB": 20, "GiB": 30, "TiB": 40, "PiB": 50}[unit]
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{n:.0f} B"


def budget_seconds(max_hours) -> float:
    """The budget in seconds from a ``max_hours`` argument (None: the default)."""
    if max_hours is None:
        return DEFAULT_BUDGET_S

    return 3600.0 * positive(
        "max_hours", max_hours, "the longest run allowed, in hours", allow_inf=True
    )


@dataclass(frozen=True)
class RunCost:
    """The estimated cost of one run.

    Attributes
    ----------
    steps : float
        Time steps (or right-hand-side evaluations) the run needs.
    seconds : float
        Estimated wall time on this machine kind (s).
    memory : float
        Memory its output needs (bytes).
    basis : str
        How the estimate was made, in words a user can act on (e.g. "step ≤ 1.2e-7 s,
        set by the highest frequency 1.3e+06 Hz of the column").
    """

    steps: float
    seconds: float
    memory: float
    basis: str

    def check(
        self,
        what: str,
        fix: str,
        *,
        max_seconds: float = DEFAULT_BUDGET_S,
        max_memory: float | None = None,
    ) -> RunCost:
        """Raise `InputError` if the run would exceed the time budget or the memory.

        Parameters
        ----------
        what : str
            The run, as the user named it (e.g. "simulate(S1, t_end=1e9 s)").
        fix : str
            What to change (e.g. "shorten t_end or raise output_dt").
        max_seconds : float
            The time budget (s).
        max_memory : float, optional
            Bytes; default `memory_limit`.
        """
        limit = memory_limit() if max_memory is None else max_memory
        problems = []
        if not self.seconds <= max_seconds:
            problems.append(
                f"estimated {format_duration(self.seconds)} of computing "
                f"({self.steps:.3g} steps), over the budget of "
                f"{format_duration(max_seconds)}"
            )
        if not self.memory <= limit:
            problems.append(
                f"its output would need {format_bytes(self.memory)}, more than the "
                f"{format_bytes(limit)} a run may use"
            )
        if problems:
            raise InputError(
                f"{what}: {' and '.join(problems)} ({self.basis}); {fix}"
                + (
                    " — or, if you mean it, raise the budget (max_hours, --max-hours)"
                    if not self.seconds <= max_seconds
                    else ""
                )
            )
        return self


class Progress:
    """A progress bar over a run's own clock (simulated seconds), on stderr.

    Parameters
    ----------
    total : float
        The end of the run's clock (e.g. t_end in s).
    desc : str
        The bar's label.
    show : bool or None
        True: always; False: never; None: when `estimate` ≥ `PROGRESS_AFTER_S`.
    estimate : float, optional
        The estimated wall time (s), shown before the bar starts.
    unit : str
        The unit of `total` (default "s", simulated seconds).
    note : str
        Shown on a line of its own under the estimate, when the bar is shown (e.g. a
        faster way to run it).

    Use as a context manager; call `update(t)` with the run's clock as often as
    convenient (cheap: the bar redraws at most ten times a second).
    """

    def __init__(
        self,
        total: float,
        desc: str,
        *,
        show: bool | None = None,
        estimate: float | None = None,
        unit: str = "s",
        note: str = "",
    ):
        if show is None:
            show = estimate is not None and estimate >= PROGRESS_AFTER_S
        self.total = float(total)
        self._bar = None
        if show:
            from tqdm.auto import tqdm

            if estimate is not None:
                print(f"{desc}: estimated {format_duration(estimate)}", file=sys.stderr)
            if note:
                print(f"{desc}: {note}", file=sys.stderr)
            self._bar = tqdm(
                total=self.total,
                desc=desc,
                unit=unit,
                file=sys.stderr,
                leave=False,
                mininterval=0.5,
                bar_format="{l_bar}{bar}| {n:.3g}/{total:.3g} " + unit + " [{elapsed}<{remaining}]",
            )

    @property
    def shown(self) -> bool:
        return self._bar is not None

    def update(self, t: float) -> None:
        """Move the bar to `t` on the run's clock."""
        bar = self._bar
        if bar is not None and t > bar.n:
            bar.update(min(t, self.total) - bar.n)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

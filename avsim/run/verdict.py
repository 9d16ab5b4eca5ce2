"""How a run ended: its verdict (the result file's ``verdict``) and, for a run that ended in
error, what was raised and when.

- `RunVerdict.PASS`: the run went to its end and no criterion failed;
- `RunVerdict.FAIL`: it went to its end and a criterion failed;
- `RunVerdict.ERROR`: an exception ended it (a bug in a stage: perception, the planner,
  control, the storyboard, a criterion, the recorder, the world); the criteria are those
  judged until then (`avsim.criteria.base.judged_so_far`);
- `RunVerdict.INTERRUPTED`: a signal ended it early (`avsim.run.interrupts`); the criteria
  are those judged until then.

An error outranks an interruption (the bug is the news); only `PASS` passes.
"""

from __future__ import annotations

import traceback
from dataclasses import dataclass
from enum import Enum


class RunVerdict(Enum):
    """A run's verdict, as the result file words it."""

    PASS = "pass"
    FAIL = "fail"
    ERROR = "error"
    INTERRUPTED = "interrupted"


@dataclass(frozen=True, slots=True)
class RunError:
    """The exception that ended a run."""

    type: str  # the exception's class name (`ValueError`)
    message: str  # its text (may hold several lines)
    traceback: str  # the whole formatted traceback
    sim_time: float  # [s] simulated time when it was raised

    @classmethod
    def of(cls, exc: BaseException, sim_time: float) -> RunError:
        """The error `exc`, raised at `sim_time` [s]."""
        return cls(type(exc).__name__, str(exc),
                   "".join(traceback.format_exception(exc)), sim_time)

    def line(self) -> str:
        """One line for the log: ``run ended in error at t = T s: <type>: <message>``
        (the message's lines joined by spaces)."""
        message = " ".join(self.message.split())
        said = f"{self.type}: {message}" if message else self.type
        return f"run ended in error at t = {self.sim_time:.3f} s: {said}"

    def as_json(self) -> dict[str, object]:
        """The result file's ``error`` (sim time [s] to 4 decimals)."""
        return {"type": self.type, "message": self.message, "traceback": self.traceback,
                "sim_time": round(self.sim_time, 4)}

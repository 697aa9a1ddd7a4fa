"""fovea — errors: the library's status codes and the one exception every refusal becomes.

Every fallible libfovea call returns an ``fv_status`` and fills an ``fv_error`` with one line for
the user (include/fovea/status.h); the package turns a failed call into :class:`FoveaError`
carrying that line and the status, and checks what Python can get wrong before it reaches C
(a gaze outside [0, 1], a buffer of the wrong shape) with the same exception and the same kind of
line. A Python type the API does not take at all (an int where a scene name goes) is a
:class:`TypeError`, as anywhere in Python.

Warnings the library sends to its ``fv_log`` sink (a default light added, triangles dropped) are
emitted as :class:`FoveaWarning` once the call returns.
"""
import enum
import warnings


class Status(enum.IntEnum):
    """fv_status (include/fovea/status.h), same values."""

    OK = 0
    INVALID = 1    # bad input from the user: value, name, size, file contents
    IO = 2         # file missing, unreadable or unwritable
    NOMEM = 3      # an allocation failed or a requested size overflows
    INTERNAL = 4   # a bug or an unexpected failure of a library we use
    CANCELLED = 5  # the caller's progress callback asked to stop


class FoveaError(Exception):
    """A refusal or failure of libfovea: ``message`` is fovea's one line, ``status`` its code."""

    def __init__(self, message, status=Status.INVALID):
        super().__init__(message)
        self.message = message
        try:
            self.status = Status(int(status))
        except ValueError:
            self.status = Status.INTERNAL

    @property
    def exit_code(self):
        """What the fovea tools exit with for this status: 2 for bad input, 1 otherwise."""
        return 2 if self.status in (Status.INVALID, Status.IO) else 1

    def __repr__(self):
        return f"FoveaError({self.message!r}, {self.status.name})"


class FoveaWarning(UserWarning):
    """A warning libfovea sent to its log (e.g. "no light in the scene: added a default one")."""


def emit_warnings(messages):
    """Re-emits the warnings a call's log collected, in order, then forgets them."""
    for m in messages:
        warnings.warn(m, FoveaWarning, stacklevel=3)
    messages.clear()


class Closing:
    """What every handle-owning object shares: close() at the end of a ``with`` block and when
    collected (quietly at interpreter shutdown, when the library may already be gone). Subclasses
    define close(), safe to call twice."""

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass

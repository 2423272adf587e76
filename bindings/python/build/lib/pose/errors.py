# SPDX-License-Identifier: Apache-2.0
"""Status codes and the exception that carries pose_last_error()."""
import enum

from ._lib import libpose


class Status(enum.IntEnum):
    OK = 0
    CLAMPED = 1
    INVALID_ARGUMENT = -1
    OUT_OF_MEMORY = -2
    IO = -3
    FORMAT = -4
    VERSION = -5
    CHECKSUM = -6
    INVALID_DATA = -7
    UNSUPPORTED = -8
    NOT_FOUND = -9
    THREAD = -10


class PoseError(Exception):
    """A pose call failed: `status` (a Status, or the raw int for a code this
    module does not know) and `message`, pose_last_error() at the failure."""

    def __init__(self, status, message):
        try:
            status = Status(status)
        except ValueError:
            pass
        self.status, self.message = status, message
        name = libpose.pose_status_string(int(status)).decode()
        super().__init__("%s: %s" % (name, message) if message else name)


def check(status):
    """Raise PoseError for a failure; True when a joint limit clamped the request."""
    if status < 0:
        raise PoseError(status, libpose.pose_last_error().decode(errors="replace"))
    return status == Status.CLAMPED


def last_error():
    """This thread's message for the last failure or clamp ("" when none)."""
    return libpose.pose_last_error().decode(errors="replace")

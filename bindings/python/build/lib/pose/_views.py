# SPDX-License-Identifier: Apache-2.0
"""Read-only views of float/uint32 arrays the library owns: numpy arrays
without a copy when numpy is importable, else memoryviews of the same bytes.
Each view keeps its owner (the Rig or State) alive; the bytes stay valid
until that owner is closed, and a state's are rewritten by each apply()."""
import ctypes

try:
    import numpy
except ImportError:  # the bindings work without numpy, with memoryviews
    numpy = None

_FORMATS = {ctypes.c_float: ("f", "float32"), ctypes.c_uint32: ("I", "uint32"), ctypes.c_uint16: ("H", "uint16")}


def view(pointer, rows, columns, ctype, owner):
    """rows x columns elements of ctype at pointer, read-only, tied to owner."""
    count = rows * columns
    if not pointer or count == 0:
        data = (ctype * 0)()
    else:
        data = (ctype * count).from_address(ctypes.addressof(pointer.contents))
    data._owner = owner  # the Rig or State whose memory this is
    code, dtype = _FORMATS[ctype]
    if numpy is not None:
        array = numpy.frombuffer(data, dtype=dtype).reshape(rows, columns)
        array.flags.writeable = False
        return array
    return memoryview(data).cast("B").cast(code, (rows, columns)).toreadonly()

"""JSON blocks of short numbers parsed straight into arrays, without Python objects.

A block of the MCAP form is ``{"t_ns": [...], "<field>": [...], ...}``. :func:`parse_blocks`
reads a topic's blocks byte by byte (numba) into one float64 and one int64 array and a table
of the fields it met, and gives up (-1) at anything beyond plain JSON objects of number
lists: strings other than keys, escapes or non-ASCII bytes in keys, literals other than
``null``, nested values, and numbers outside the fast path below. The caller then decodes
the topic as before (``ingest.mcap_reader``), so what is refused here is read as it always
was.

Numbers: a decimal ``m 10^e`` whose significand ``m`` (all its digits, leading zeros
dropped) is at most 2^53 and ``|e| <= 22`` is one correctly rounded multiplication or
division of two exact doubles (Clinger 1990, "How to read floating point numbers
accurately", PLDI '90, the fast path), so it is the double every correct decimal reader
(orjson, ``float()``) returns. An integer (no point, no exponent) is read as the Python
int it is and then converted, as ``array('d', ...)`` converts orjson's ints: ``-0`` is
``+0.0``; ``-0.0`` is ``-0.0``. ``null`` is NaN.
"""

from __future__ import annotations

import numba
import numpy as np

#: 10^0 .. 10^22, each exact in a double
_POW10 = np.array([float(10**k) for k in range(23)])
_TWO53 = 2**53
#: significant digits beyond which a significand may pass 2^53 (checked exactly after)
_MAX_DIGITS = 18
#: columns of the field table: block, key start, key stop, first value, value stop, integers
FIELD_COLUMNS = 6


@numba.njit(cache=True, nogil=True)
def _space(buf, i, stop):
    while i < stop and (buf[i] == 32 or buf[i] == 9 or buf[i] == 10 or buf[i] == 13):
        i += 1
    return i


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _number(buf, i, stop, values, ints, k):
    """The number at ``buf[i]`` into ``values[k]`` (and ``ints[k]`` when it is an
    integer); (index after it, 1 integer / 0 not, or -1 refused)."""
    negative = False
    if i < stop and buf[i] == 45:  # -
        negative = True
        i += 1
    if i >= stop:
        return i, -1
    if buf[i] == 110:  # null
        if negative or i + 4 > stop or buf[i + 1] != 117 or buf[i + 2] != 108 \
                or buf[i + 3] != 108:
            return i, -1
        values[k] = np.nan
        return i + 4, 0
    m = 0
    digits = 0
    if buf[i] == 48:  # 0: no further integer digits
        i += 1
    elif 49 <= buf[i] <= 57:
        while i < stop and 48 <= buf[i] <= 57:
            m = m * 10 + (buf[i] - 48)
            digits += 1
            i += 1
            if digits > _MAX_DIGITS:
                return i, -1
    else:
        return i, -1
    integer = True
    scale = 0
    if i < stop and buf[i] == 46:  # .
        integer = False
        i += 1
        start = i
        while i < stop and 48 <= buf[i] <= 57:
            if m > 0 or buf[i] != 48:
                digits += 1
                if digits > _MAX_DIGITS:
                    return i, -1
            m = m * 10 + (buf[i] - 48)
            scale -= 1
            i += 1
        if i == start:
            return i, -1
    if i < stop and (buf[i] == 101 or buf[i] == 69):  # e E
        integer = False
        i += 1
        sign = 1
        if i < stop and (buf[i] == 43 or buf[i] == 45):
            if buf[i] == 45:
                sign = -1
            i += 1
        start = i
        exponent = 0
        while i < stop and 48 <= buf[i] <= 57:
            if exponent < 1000:
                exponent = exponent * 10 + (buf[i] - 48)
            i += 1
        if i == start:
            return i, -1
        scale += sign * exponent
    if integer:
        ints[k] = -m if negative else m
        value = float(m)
        values[k] = -value if negative and m > 0 else value
        return i, 1
    if m > _TWO53 or scale > 22 or scale < -22:
        if m != 0 or scale > 400 or scale < -400:
            return i, -1
    if m == 0:
        value = 0.0
    elif scale >= 0:
        value = float(m) * _POW10[scale]
    else:
        value = float(m) / _POW10[-scale]
    values[k] = -value if negative else value
    return i, 0


@numba.njit(cache=True, nogil=True, error_model="numpy")
def parse_blocks(buf, starts, stops, values, ints, fields):
    """Blocks ``buf[starts[b]:stops[b]]`` into ``values``/``ints`` and one row of ``fields``
    per field (:data:`FIELD_COLUMNS`); the number of rows, or -1 where a block is more than
    an object of number lists (or a table is full)."""
    k = 0
    row = 0
    for b in range(starts.size):
        stop = stops[b]
        i = _space(buf, starts[b], stop)
        if i >= stop or buf[i] != 123:  # {
            return -1
        i = _space(buf, i + 1, stop)
        if i < stop and buf[i] == 125:  # } an empty object: not a block
            return -1
        while True:
            if i >= stop or buf[i] != 34:  # "
                return -1
            key = i + 1
            i += 1
            while i < stop and buf[i] != 34:
                if buf[i] == 92 or buf[i] < 32 or buf[i] > 126:  # escapes, control, non-ASCII
                    return -1
                i += 1
            if i >= stop or row >= fields.shape[0]:
                return -1
            fields[row, 0] = b
            fields[row, 1] = key
            fields[row, 2] = i
            fields[row, 3] = k
            i = _space(buf, i + 1, stop)
            if i >= stop or buf[i] != 58:  # :
                return -1
            i = _space(buf, i + 1, stop)
            if i >= stop or buf[i] != 91:  # [
                return -1
            i = _space(buf, i + 1, stop)
            whole = 1
            if i < stop and buf[i] == 93:  # ] empty list
                i += 1
            else:
                while True:
                    if k >= values.size:
                        return -1
                    i, kind = _number(buf, i, stop, values, ints, k)
                    if kind < 0:
                        return -1
                    whole &= kind
                    k += 1
                    i = _space(buf, i, stop)
                    if i < stop and buf[i] == 44:  # ,
                        i = _space(buf, i + 1, stop)
                    elif i < stop and buf[i] == 93:  # ]
                        i += 1
                        break
                    else:
                        return -1
            fields[row, 4] = k
            fields[row, 5] = whole
            row += 1
            i = _space(buf, i, stop)
            if i < stop and buf[i] == 44:  # ,
                i = _space(buf, i + 1, stop)
            elif i < stop and buf[i] == 125:  # }
                if _space(buf, i + 1, stop) != stop:
                    return -1
                break
            else:
                return -1
    return row

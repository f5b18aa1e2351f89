"""Numbers as metrologists write them (GUM, JCGM 100:2008, 7.2.6): an uncertainty to two
significant digits, and the value it qualifies to the same decimal, so that ``0.0001211``
beside ``u 0.0068`` reads ``0.0001`` and ``0.0068``. For every table a person reads (the
report, ``swtlab results``, the gap page); files (CSV, JSON, the database) keep full
precision."""

from __future__ import annotations

import math

#: significant digits of a shown uncertainty (GUM 7.2.6: "at most two")
U_DIGITS = 2
#: significant digits of a value shown without a usable uncertainty
PLAIN_DIGITS = 4


def _usable(u: float | None) -> bool:
    return u is not None and math.isfinite(u) and u > 0


def decimals(u: float) -> int:
    """Decimal places that show ``u`` (> 0) to :data:`U_DIGITS` significant digits, after
    rounding it there (``0.0995`` -> ``0.10``: 2); negative for tens, hundreds (``340``: -1)."""
    rounded = float(f"{u:.{U_DIGITS}g}")
    return U_DIGITS - 1 - math.floor(math.log10(rounded))


def at_decimals(x: float, places: int) -> str:
    """``x`` rounded to ``places`` decimals (negative: to tens, hundreds), without a sign on
    a zero (``-0.00004`` at 4 decimals: ``0.0000``)."""
    if places >= 0:
        text = f"{x:.{places}f}"
    else:
        step = 10 ** -places
        text = f"{round(x / step) * step:.0f}"
    return text[1:] if text.startswith("-") and not text.strip("-0.") else text


def plain(x: float | None, digits: int = PLAIN_DIGITS) -> str:
    """A value shown without an uncertainty: ``digits`` significant digits ('' for None or
    NaN)."""
    if x is None or not math.isfinite(x):
        return ""
    return f"{x:.{digits}g}"


def value_and_u(value: float | None, u: float | None, scale: float = 1.0
                ) -> tuple[str, str]:
    """``value`` and its uncertainty ``u`` (both times ``scale``: the display unit) as text:
    ``u`` to two significant digits, ``value`` to the same decimal. Without a usable ``u``
    (None, NaN, 0) the value gets :data:`PLAIN_DIGITS` significant digits and ``u`` shows
    as given ('' when None or NaN)."""
    if value is not None and math.isfinite(value):
        value = value * scale
    if u is None or not _usable(u):
        return plain(value), "" if u is None or not math.isfinite(u) else plain(u * scale)
    u = u * scale
    places = decimals(u)
    shown_u = at_decimals(float(f"{u:.{U_DIGITS}g}"), places)
    if value is None or not math.isfinite(value):
        return "", shown_u
    return at_decimals(value, places), shown_u


def to_decimal_of(value: float | None, u: float | None, scale: float = 1.0) -> str:
    """``value`` (times ``scale``) to the decimal its uncertainty ``u`` supports
    (:func:`value_and_u`'s first part)."""
    return value_and_u(value, u, scale)[0]

"""Numbers as CSV text, compiled: the same characters as Python's ``repr`` (floats) and ``str`` (ints).

A result file's floats are written in their shortest round-trip form, the one ``repr(float)`` gives
(docs/results-format.md: "floats with every digit"), so a reader gets back the very doubles. Python
finds it with David Gay's ``dtoa`` at ~0.3-0.45 µs a value, numpy's Dragon4 (``arr.astype(str)``,
the same strings) at ~0.8-1 µs: at 10 km a steady run writes ~750 000 values, 0.3 s of CPU time.
This module finds the same digits with Ryu (Ulf Adams, "Ryū: fast float-to-string conversion",
PLDI 2018, and the reference implementation's ``d2s.c``: the shortest decimal in the double's
rounding interval, the closest one when several are as short, ties to even), compiled with numba, at
about a fifth of that (75-90 ns a value); the layout of ``repr`` around those digits
(:func:`_put_double`) is Python's ``float_repr_style = 'short'``: positional when −4 < decpt ≤ 16,
else ``d.ddde±XX``.
``tests/test_numbers_text.py`` checks the strings against ``repr`` on random bit patterns, every
binade's ends, subnormals, integers, ±0, ±inf and NaN.
"""

from __future__ import annotations

import functools

import numpy as np

from ..contact.jitcache import jit_cache_available, njit
from ..io import repr_rows

__all__ = ["csv_rows", "rows_text", "FLOAT_WIDTH", "COMPILED_FROM_VALUES"]

#: The most characters ``repr`` takes for a double ("-2.2250738585072014e-308") or ``str`` for an int64.
FLOAT_WIDTH = 24

#: Tables of at least this many values go through the compiled :func:`rows_text`, smaller ones
#: through ``repr``: loading the compiled code from numba's cache costs ~8 ms CPU once a process (with
#: numba loaded; ~0.3 s more without), what ``repr`` takes for ~20 000 values.
COMPILED_FROM_VALUES = 20_000

_POW5_INV_BITCOUNT = 125
_POW5_BITCOUNT = 125


@functools.cache
def _pow5_tables() -> tuple[np.ndarray, np.ndarray]:
    """Ryu's tables (``d2s_full_table.h``) as (n, 2) uint64 [low, high] words of 128-bit integers:
    ⌊2^(⌈log2 5^q⌉ − 1 + 125) / 5^q⌋ + 1 for q < 342 (positive binary exponents) and 5^i scaled to
    125 bits, ⌊5^i / 2^(⌈log2 5^i⌉ − 125)⌋, for i < 326 (negative ones); exact Python integers."""
    mask = (1 << 64) - 1
    inv = np.empty((342, 2), dtype=np.uint64)
    for q in range(342):
        p = 5 ** q
        v = (1 << (p.bit_length() - 1 + _POW5_INV_BITCOUNT)) // p + 1
        inv[q] = (v & mask, v >> 64)
    split = np.empty((326, 2), dtype=np.uint64)
    for i in range(326):
        p = 5 ** i
        shift = p.bit_length() - _POW5_BITCOUNT
        v = p >> shift if shift >= 0 else p << -shift
        split[i] = (v & mask, v >> 64)
    return inv, split


# numba types a Python int literal as int64, and uint64 mixed with int64 as float64: every integer of
# the digit search below is a uint64 of these
_U0, _U1, _U2, _U4, _U5, _U10, _U100 = (np.uint64(v) for v in (0, 1, 2, 4, 5, 10, 100))
_U32, _U52, _U63, _U64 = np.uint64(32), np.uint64(52), np.uint64(63), np.uint64(64)
_MASK32 = np.uint64(0xFFFFFFFF)
_MANTISSA_MASK = np.uint64((1 << 52) - 1)
_EXPONENT_MASK = np.uint64(0x7FF)
_HIDDEN_BIT = np.uint64(1 << 52)


@njit(inline="always")
def _umul128(a, b):
    """(high, low) 64-bit words of the 128-bit product of uint64 ``a`` and ``b``."""
    a_lo, a_hi = a & _MASK32, a >> _U32
    b_lo, b_hi = b & _MASK32, b >> _U32
    b00 = a_lo * b_lo
    mid1 = a_hi * b_lo + (b00 >> _U32)
    mid2 = a_lo * b_hi + (mid1 & _MASK32)
    high = a_hi * b_hi + (mid1 >> _U32) + (mid2 >> _U32)
    low = (mid2 << _U32) | (b00 & _MASK32)
    return high, low


@njit(inline="always")
def _mul_shift(m, mul_lo, mul_hi, j):
    """⌊m · mul / 2^j⌋ for a 128-bit ``mul`` and 64 < j < 128 (``d2s.c: mulShift64``)."""
    b0_hi, _ = _umul128(m, mul_lo)
    b2_hi, b2_lo = _umul128(m, mul_hi)
    low = b2_lo + b0_hi
    high = b2_hi + (_U1 if low < b0_hi else _U0)
    s = np.uint64(j - 64)
    if s == _U0:
        return low
    return (high << (_U64 - s)) | (low >> s)


@njit(inline="always")
def _pow5_factor(value):
    count = 0
    while value % _U5 == _U0:
        value //= _U5
        count += 1
    return count


@njit
def _shortest(mantissa, exponent, inv_table, split_table):
    """Ryu's ``d2d``: the shortest decimal ``digits · 10^e10`` that reads back as the finite nonzero
    double of IEEE ``mantissa`` (52 bits) and biased ``exponent``; returns (digits, e10)."""
    if exponent == 0:
        e2 = 1 - 1023 - 52 - 2
        m2 = mantissa
    else:
        e2 = exponent - 1023 - 52 - 2
        m2 = _HIDDEN_BIT | mantissa
    accept_bounds = (m2 & _U1) == _U0
    mv = _U4 * m2
    mm_shift = _U1 if (mantissa != _U0 or exponent <= 1) else _U0
    vm_trailing_zeros = False
    vr_trailing_zeros = False
    if e2 >= 0:
        q = ((e2 * 78913) >> 18) - (1 if e2 > 3 else 0)          # log10(2^e2), one less above 3
        e10 = q
        k = _POW5_INV_BITCOUNT + (((q * 1217359) >> 19) + 1) - 1
        j = -e2 + q + k
        mul_lo, mul_hi = inv_table[q, 0], inv_table[q, 1]
        vr = _mul_shift(_U4 * m2, mul_lo, mul_hi, j)
        vp = _mul_shift(_U4 * m2 + _U2, mul_lo, mul_hi, j)
        vm = _mul_shift(_U4 * m2 - _U1 - mm_shift, mul_lo, mul_hi, j)
        if q <= 21:
            if mv % _U5 == _U0:
                vr_trailing_zeros = _pow5_factor(mv) >= q
            elif accept_bounds:
                vm_trailing_zeros = _pow5_factor(mv - _U1 - mm_shift) >= q
            elif _pow5_factor(mv + _U2) >= q:
                vp -= _U1
    else:
        q = (((-e2) * 732923) >> 20) - (1 if -e2 > 1 else 0)     # log10(5^-e2), one less above 1
        e10 = q + e2
        i = -e2 - q
        k = (((i * 1217359) >> 19) + 1) - _POW5_BITCOUNT
        j = q - k
        mul_lo, mul_hi = split_table[i, 0], split_table[i, 1]
        vr = _mul_shift(_U4 * m2, mul_lo, mul_hi, j)
        vp = _mul_shift(_U4 * m2 + _U2, mul_lo, mul_hi, j)
        vm = _mul_shift(_U4 * m2 - _U1 - mm_shift, mul_lo, mul_hi, j)
        if q <= 1:
            vr_trailing_zeros = True
            if accept_bounds:
                vm_trailing_zeros = mm_shift == _U1
            else:
                vp -= _U1
        elif q < 63:
            vr_trailing_zeros = (mv & ((_U1 << np.uint64(q)) - _U1)) == _U0
    removed = 0
    last_removed = _U0
    if vm_trailing_zeros or vr_trailing_zeros:
        # the rare case: an end of the interval or the value itself is a short decimal. Digits go
        # while the interval holds a shorter decimal, then (d2s.c's second loop) while the lower end,
        # exact, ends in a zero; once vp and vm agree but for their last digit they stay agreeing
        while True:
            if vp // _U10 > vm // _U10:
                vm_trailing_zeros = vm_trailing_zeros and vm % _U10 == _U0
            elif not (vm_trailing_zeros and vm % _U10 == _U0):
                break
            vr_trailing_zeros = vr_trailing_zeros and last_removed == _U0
            last_removed = vr % _U10
            vr //= _U10
            vp //= _U10
            vm //= _U10
            removed += 1
        if vr_trailing_zeros and last_removed == _U5 and vr % _U2 == _U0:
            last_removed = _U4                      # exactly halfway: round to even
        up = (vr == vm and (not accept_bounds or not vm_trailing_zeros)) or last_removed >= _U5
        output = vr + (_U1 if up else _U0)
    else:
        round_up = False
        if vp // _U100 > vm // _U100:
            round_up = vr % _U100 >= np.uint64(50)
            vr //= _U100
            vp //= _U100
            vm //= _U100
            removed += 2
        while vp // _U10 > vm // _U10:
            round_up = vr % _U10 >= _U5
            vr //= _U10
            vp //= _U10
            vm //= _U10
            removed += 1
        output = vr + (_U1 if (vr == vm or round_up) else _U0)
    return output, e10 + removed


@njit(inline="always")
def _put(out, pos, text):
    for c in text:
        out[pos] = ord(c)
        pos += 1
    return pos


@njit(inline="always")
def _put_uint(out, pos, value, digits):
    """The decimal digits of uint64 ``value`` at ``pos``; ``digits`` a scratch array of 20."""
    n = 0
    while True:
        digits[n] = np.uint8(48 + np.int64(value % _U10))
        value //= _U10
        n += 1
        if value == _U0:
            break
    for i in range(n):
        out[pos + i] = digits[n - 1 - i]
    return pos + n


@njit
def _put_double(out, pos, bits, inv_table, split_table, digits):
    """``repr`` of the double of IEEE ``bits`` written at ``pos``; returns the position after it."""
    negative = (bits >> _U63) != _U0
    exponent = np.int64((bits >> _U52) & _EXPONENT_MASK)
    mantissa = bits & _MANTISSA_MASK
    if exponent == 0x7FF:
        if mantissa != _U0:
            return _put(out, pos, "nan")            # repr drops a NaN's sign
        if negative:
            out[pos] = 45
            pos += 1
        return _put(out, pos, "inf")
    if negative:
        out[pos] = 45                               # "-"
        pos += 1
    if exponent == 0 and mantissa == _U0:
        return _put(out, pos, "0.0")
    value, e10 = _shortest(mantissa, exponent, inv_table, split_table)
    n = 0
    while value != _U0:
        digits[n] = np.uint8(48 + np.int64(value % _U10))
        value //= _U10
        n += 1
    # digits[n-1] … digits[0] most significant first; the value is 0.d1d2… × 10^decpt
    decpt = n + e10
    if -4 < decpt <= 16:
        if decpt <= 0:
            pos = _put(out, pos, "0.")
            for _ in range(-decpt):
                out[pos] = 48
                pos += 1
            for i in range(n):
                out[pos + i] = digits[n - 1 - i]
            return pos + n
        if decpt >= n:
            for i in range(n):
                out[pos + i] = digits[n - 1 - i]
            pos += n
            for _ in range(decpt - n):
                out[pos] = 48
                pos += 1
            return _put(out, pos, ".0")
        for i in range(decpt):
            out[pos + i] = digits[n - 1 - i]
        pos += decpt
        out[pos] = 46                               # "."
        pos += 1
        for i in range(decpt, n):
            out[pos] = digits[n - 1 - i]
            pos += 1
        return pos
    out[pos] = digits[n - 1]
    pos += 1
    if n > 1:
        out[pos] = 46
        pos += 1
        for i in range(1, n):
            out[pos] = digits[n - 1 - i]
            pos += 1
    e = decpt - 1
    out[pos] = 101                                  # "e"
    out[pos + 1] = 45 if e < 0 else 43              # "-" / "+"
    pos += 2
    e = -e if e < 0 else e
    if e < 10:
        out[pos] = 48
        pos += 1
    return _put_uint(out, pos, np.uint64(e), digits)


@njit
def _rows(bits, integer, inv_table, split_table, out):
    """Rows of ``bits`` (n, m: doubles' IEEE bits, or int64 two's complement where ``integer``),
    comma-separated, each ended by a newline, into ``out``; returns the bytes written."""
    digits = np.empty(24, dtype=np.uint8)
    pos = 0
    for r in range(bits.shape[0]):
        for c in range(bits.shape[1]):
            if c:
                out[pos] = 44                       # ","
                pos += 1
            b = bits[r, c]
            if integer[c]:
                if (b >> _U63) != _U0:
                    out[pos] = 45
                    pos += 1
                    b = (~b) + _U1                  # the magnitude of a negative int64
                pos = _put_uint(out, pos, b, digits)
            else:
                pos = _put_double(out, pos, b, inv_table, split_table, digits)
        out[pos] = 10                               # "\n"
        pos += 1
    return pos


def rows_text(arrays) -> str:
    """Equal-length columns as CSV rows, each ended by a newline ("" for none): integer arrays as
    ``str(int)``, every other as ``repr(float)`` of its float64 values, character for character.

    Parameters
    ----------
    arrays : sequence of array_like (n,)
        The columns, in order; integer dtypes are written as integers, everything else as float64.
    """
    columns = [np.asarray(a) for a in arrays]
    if not columns or not len(columns[0]):
        return ""
    integer = np.array([np.issubdtype(a.dtype, np.integer) for a in columns], dtype=np.bool_)
    bits = np.empty((len(columns[0]), len(columns)), dtype=np.uint64)
    for c, a in enumerate(columns):
        bits[:, c] = (a.astype(np.int64) if integer[c] else a.astype(np.float64)).view(np.uint64)
    out = np.empty(bits.size * (FLOAT_WIDTH + 1), dtype=np.uint8)
    n = _rows(bits, integer, *_pow5_tables(), out)
    return out[:n].tobytes().decode("ascii")


def csv_rows(arrays) -> str:
    """:func:`rows_text` of the columns ``arrays`` for tables of :data:`COMPILED_FROM_VALUES` values
    or more where numba can cache its machine code on disk, else :func:`exucable.io.repr_rows`: the
    same characters either way (for :func:`exucable.io.csv_text`'s ``rows``)."""
    arrays = [np.asarray(a) for a in arrays]
    values = len(arrays) * (len(arrays[0]) if arrays else 0)
    # without a disk cache numba would compile it in every process (seconds): repr is cheaper
    if values < COMPILED_FROM_VALUES or not jit_cache_available(_rows.py_func):
        return repr_rows(arrays)
    return rows_text(arrays)

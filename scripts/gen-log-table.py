#!/usr/bin/env python3
"""Prints the table of ln_positive() in lib/include/hairlut/sampler/sampler.hpp: for each of the
256 subintervals of [0.6875, 1.375) that the top 8 mantissa bits of bits(x) - bits(0.6875) pick,
1/c rounded to double (c the subinterval's centre) and -ln of that double, correctly rounded
(Python's decimal at 60 digits: the standard library only). Run: python3 scripts/gen-log-table.py"""
import decimal
import struct

decimal.getcontext().prec = 60
N = 256
OFF = 0x3FE6000000000000  # bits of 0.6875


def as_double(bits):
    return struct.unpack("<d", struct.pack("<Q", bits))[0]


entries = []
for i in range(N):
    lo = decimal.Decimal(as_double(OFF + (i << 44)))
    hi = decimal.Decimal(as_double(OFF + ((i + 1) << 44)))
    invc = float(2 / (lo + hi))
    logc = float(-decimal.Decimal(invc).ln())
    entries.append("{%s, %s}" % (invc.hex(), logc.hex()))
for j in range(0, N, 2):
    print("    " + ", ".join(entries[j : j + 2]) + ",")

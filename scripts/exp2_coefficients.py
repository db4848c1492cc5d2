#!/usr/bin/env python3
"""Coefficients of fog_exp2_poly (kernels/fog_math.h): the Chebyshev fit of 2^r on [-1/2, 1/2]
(degree 6, mpmath.chebyfit, near-minimax), printed as float hex literals. The constant term of the
fit is 1 to 1e-17 and is set to 1 exactly, so that 2^0 = 1. Needs python3-mpmath (Debian)."""
import struct

import mpmath as mp

mp.mp.dps = 40
poly, err = mp.chebyfit(lambda r: mp.power(2, r), [-0.5, 0.5], 7, error=True)
coefficients = [float(c) for c in reversed(poly)]  # c0 + c1 r + ... + c6 r^6
print(f"approximation error of the fit (relative, before float rounding): {mp.nstr(err, 3)}")
for degree, c in enumerate(coefficients):
    as_float = struct.unpack("f", struct.pack("f", c))[0]
    print(f"c{degree} = {float.hex(as_float)}f  ({c!r})")

"""Writes the SciPy reference numbers the resampling tests compare with (run with Debian's
python3-scipy: /usr/bin/python3 make_scipy_reference.py). The inputs are formulas that the
tests compute again in C++.

scipy_resample_poly.csv: scipy.signal.resample_poly of
    x[i] = 0.8 sin(2 pi 0.004 i + 0.3) + 0.3 sin(2 pi 0.011 i + 1.1) + 0.1 sin(2 pi 0.023 i + 0.5),
    i = 0..799, for the factors up/down 3/4 (2000 -> 1500 Hz), 1/8 (2000 -> 250 Hz),
    2/1 (1000 -> 2000 Hz) and 1/10 (2000 -> 200 Hz).
scipy_pchip.csv: scipy.interpolate.PchipInterpolator through the nodes
    t_k = k + 0.3 sin(k), x_k = sin(0.4 t_k) + 0.2 (k mod 3), k = 0..39,
    at q_j = 0.37 j, j = 0..105.
"""
import os

import numpy as np
from scipy import interpolate, signal

here = os.path.dirname(os.path.abspath(__file__))
i = np.arange(800)
x = (0.8 * np.sin(2 * np.pi * 0.004 * i + 0.3) + 0.3 * np.sin(2 * np.pi * 0.011 * i + 1.1)
     + 0.1 * np.sin(2 * np.pi * 0.023 * i + 0.5))
with open(os.path.join(here, "scipy_resample_poly.csv"), "w") as f:
    f.write(f"# scipy {__import__('scipy').__version__} signal.resample_poly, see make_scipy_reference.py\n")
    f.write("up,down,index,value\n")
    for up, down in [(3, 4), (1, 8), (2, 1), (1, 10)]:
        for k, v in enumerate(signal.resample_poly(x, up, down)):
            f.write(f"{up},{down},{k},{v:.17g}\n")

k = np.arange(40)
t = k + 0.3 * np.sin(k)
y = np.sin(0.4 * t) + 0.2 * (k % 3)
q = 0.37 * np.arange(106)
with open(os.path.join(here, "scipy_pchip.csv"), "w") as f:
    f.write(f"# scipy {__import__('scipy').__version__} interpolate.PchipInterpolator, see make_scipy_reference.py\n")
    f.write("query,value\n")
    for qq, v in zip(q, interpolate.PchipInterpolator(t, y)(q)):
        f.write(f"{qq:.17g},{v:.17g}\n")

"""The median of a 1-D float array, the same double as ``numpy.median``, by one partition.

``numpy.median`` checks its input for masked arrays through ``numpy.ma``, whose import
(about 10 ms) every identifying process paid once; the estimators take medians of short
arrays, where that call's overhead is most of its cost. This is numpy's own rule (the
middle order statistic, or the two middle ones' sum halved; NaN when the array holds one;
+0.0 for -0.0) without either. No equation of MODEL.md: a helper of the estimators.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike


def median(values: ArrayLike) -> float:
    """The median of ``values`` (flattened), bit for bit the double ``numpy.median`` gives.

    Parameters
    ----------
    values : array_like, shape (n,)
        Real numbers; n >= 1.

    Returns
    -------
    float
        The middle order statistic (n odd) or the sum of the two middle ones halved (n even);
        NaN when ``values`` holds a NaN.
    """
    a = np.asarray(values, dtype=np.float64).ravel()
    n = a.size
    if n == 0:
        raise ValueError("median of an empty array: give at least one value")
    half = n // 2
    kth = [half, n - 1] if n % 2 else [half - 1, half, n - 1]
    part = np.partition(a, kth)
    if part[-1] != part[-1]:  # NaN sorts last: numpy's median is NaN then
        return float(part[-1])
    # numpy's mean starts its sum from +0.0, so a median of -0.0 reads +0.0
    if n % 2:
        return float(part[half] + 0.0)
    return float((part[half - 1] + part[half] + 0.0) / 2.0)

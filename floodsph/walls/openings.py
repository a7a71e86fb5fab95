"""Cut inflow sections out of wall segments that lie along them.

A breach section drawn on a closed DEM edge (or along a wall) must let water through: every
wall segment collinear with an opening loses the part that overlaps it. Collinear means both
end points of the segment lie within ``tol`` of the opening's line.
"""

from __future__ import annotations

import numpy as np


def cut_openings(seg: np.ndarray, openings, tol: float) -> np.ndarray:
    """Segments (ns, 4) with the parts along each opening ((2, 2) arrays) removed.

    With t the unit tangent of opening A-B and a segment P-Q on the same line, the segment
    covers [t.(P-A), t.(Q-A)] along it; the interval [0, |B-A|] is taken out, leaving up to
    two pieces.
    """
    out = np.asarray(seg, dtype=np.float64).reshape(-1, 4)
    for opening in openings:
        a, b = np.asarray(opening, dtype=np.float64)
        length = float(np.hypot(*(b - a)))
        t = (b - a) / length
        normal = np.array([-t[1], t[0]])
        pieces = []
        for x1, y1, x2, y2 in out:
            p, q = np.array([x1, y1]) - a, np.array([x2, y2]) - a
            if abs(p @ normal) > tol or abs(q @ normal) > tol:
                pieces.append((x1, y1, x2, y2))
                continue
            s1, s2 = sorted((float(p @ t), float(q @ t)))
            for lo, hi in ((s1, min(s2, 0.0)), (max(s1, length), s2)):
                if hi - lo > tol:
                    pieces.append((*(a + lo * t), *(a + hi * t)))
        out = np.asarray(pieces, dtype=np.float64).reshape(-1, 4)
    return out

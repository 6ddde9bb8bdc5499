#!/usr/bin/env python3
"""The error of --shade doppler's per-vertex modulation W(D) a against the exact shift toneMap(A(D) a)
(mesh4d/doppler_colour.h) over the colour cube, at a few Doppler factors (standard library only).

usage: scripts/doppler_modulation_error.py [STEPS]
  Colours a on a grid of STEPS + 1 values per channel (default 20) in [0, 1]^3. Prints per D the largest
  channel error max |W_i a_i - E_i|, the mean, and the share of colours off by more than 0.05; and the same
  for greys (a = (g, g, g)). The band model is docs/DOPPLER.md's, written here again.
"""
import math
import sys

CENTRES = (610.0, 550.0, 465.0)
WIDTH = 40.0


def band(x):
    return math.exp(-x * x / (2 * WIDTH * WIDTH))


def inverse(m):
    det = (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))
    inv = [[0.0] * 3 for _ in range(3)]
    for i in range(3):
        for j in range(3):
            r0, r1, c0, c1 = (j + 1) % 3, (j + 2) % 3, (i + 1) % 3, (i + 2) % 3
            inv[i][j] = (m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]) / det
    return inv


UNMIX = inverse([[band(k - c) for c in CENTRES] for k in CENTRES])


def matrix(d):
    g = [[d ** 3 * band(k * d - c) for c in CENTRES] for k in CENTRES]
    return [[sum(UNMIX[i][k] * g[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def tone(c):
    c = [max(0.0, x) for x in c]
    top = max(c)
    return [x / top for x in c] if top > 1 else c


def main(steps):
    print("| D | white W(D) | colours: max error | mean | share > 0.05 | greys: max error |")
    print("|---|---|---|---|---|---|")
    for d in (0.5, 0.7, 0.8, 0.9, 0.95, 1.05, 1.1, 1.25, 1.5, 2.0):
        a = matrix(d)
        w = tone([sum(row) for row in a])
        worst = total = over = grey = 0.0
        n = 0
        for r in range(steps + 1):
            for g in range(steps + 1):
                for b in range(steps + 1):
                    c = (r / steps, g / steps, b / steps)
                    exact = tone([sum(a[i][j] * c[j] for j in range(3)) for i in range(3)])
                    err = max(abs(w[i] * c[i] - exact[i]) for i in range(3))
                    worst = max(worst, err)
                    total += err
                    over += err > 0.05
                    n += 1
                    if r == g == b:
                        grey = max(grey, err)
        print("| %.2f | (%.3f, %.3f, %.3f) | %.3f | %.3f | %.0f %% | %.3f |" % (d, *w, worst, total / n, 100 * over / n,
                                                                             grey))


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 20)

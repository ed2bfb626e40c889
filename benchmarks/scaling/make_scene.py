#!/usr/bin/env python3
"""Writes a scene of the scaling benchmark from a template in this folder.

  make_scene.py --kind block|wall --mode strong|weak --ranks N --size ELEMENTS [--end SECONDS] -o FILE
  make_scene.py --kind block --cells X,Y,Z [--end SECONDS] -o FILE
  make_scene.py --kind wall --units U --courses C --unit-cells A,B,C [--end SECONDS] -o FILE

--size is the number of tetrahedra to aim for: of the whole scene in strong mode, per rank in weak
mode (the scene is then grown by N: the block in all three directions, the wall in length and
height, using the most even factorisation of N). The generated counts are whole cells and whole
stones, so the real number of tets differs from the target by a few per cent; it is printed (JSON
on stdout) and the benchmark reports the count from the run itself.

--cells (block) and --units/--courses/--unit-cells (wall) give the size explicitly instead (the
memory benchmark, scripts/bench-memory.sh); --mode and --size are then ignored.
"""
import argparse
import json
import math
import os
import string
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def prime_factors(n):
    factors, p = [], 2
    while p * p <= n:
        while n % p == 0:
            factors.append(p)
            n //= p
        p += 1
    if n > 1:
        factors.append(n)
    return factors


def even_factorisation(n, parts):
    """n as a product of `parts` factors as equal as possible, largest first (2 -> 2,1,1)."""
    bins = [1] * parts
    for p in sorted(prime_factors(n), reverse=True):
        bins[bins.index(min(bins))] *= p
    return sorted(bins, reverse=True)


def fmt(x):
    return repr(round(x, 9))


def block(mode, ranks, size, cells=None):
    # A cube of n^3 cells (6 tets each) per rank, repeated along x, y, z in weak mode.
    if cells is None:
        n = max(1, round((size / 6.0) ** (1.0 / 3.0)))
        grow = even_factorisation(ranks, 3) if mode == "weak" else [1, 1, 1]
        cells = [n * g for g in grow]
    cell = 0.05  # m
    v = {
        "cells_x": cells[0], "cells_y": cells[1], "cells_z": cells[2],
        "size_x": fmt(cells[0] * cell), "size_y": fmt(cells[1] * cell),
        "size_z": fmt(cells[2] * cell),
        "clamp_x": fmt(cells[0] * cell + 1), "clamp_y": fmt(cells[1] * cell + 1),
    }
    v["tets"] = 6 * cells[0] * cells[1] * cells[2]
    return v


def wall(mode, ranks, size, units=None, courses=None, unit_cells=(2, 1, 1)):
    # 12 tets per stone (cells_per_unit 2x1x1); a base wall of U units per course and C = U/2
    # courses (6x as long as high), grown in length and height in weak mode. The footing
    # (2 cells per unit, 6 tets each) adds ~1/C of the wall's count.
    if units is None or courses is None:
        units = max(2, round(math.sqrt(size / 6.0)))
        courses = max(2, units // 2)
        grow = even_factorisation(ranks, 2) if mode == "weak" else [1, 1]
        units *= grow[0]
        courses *= grow[1]
    per_unit = 6 * unit_cells[0] * unit_cells[1] * unit_cells[2]
    gap = 0.00005  # m: 0.05 mm above the stone below, closed within ~3 ms of free fall
    length = units * 0.24 + (units - 1) * gap
    footing_cells = 2 * units + 1
    stones = (courses + 1) // 2 * units + courses // 2 * (units + 1)  # running bond
    v = {
        "units": units, "courses": courses, "gap": fmt(gap),
        "footing_x": fmt(length + 0.1), "footing_cells": footing_cells,
        "unit_cells": ", ".join(str(c) for c in unit_cells),
        "tets": per_unit * (courses * units) + 6 * footing_cells,
        "stones": stones,
    }
    return v


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--kind", choices=["block", "wall"], required=True)
    ap.add_argument("--mode", choices=["strong", "weak"], default="strong")
    ap.add_argument("--ranks", type=int, default=1)
    ap.add_argument("--size", type=float, default=1.0, help="target tets (per rank when weak)")
    ap.add_argument("--cells", help="block: cells X,Y,Z (instead of --size)")
    ap.add_argument("--units", type=int, help="wall: full units per course (with --courses)")
    ap.add_argument("--courses", type=int, help="wall: courses (with --units)")
    ap.add_argument("--unit-cells", default="2,1,1", help="wall: cells per unit A,B,C")
    ap.add_argument("--end", type=float, default=1.0, help="time.end (s)")
    ap.add_argument("-o", "--output", required=True)
    a = ap.parse_args()
    if a.ranks < 1 or a.size < 1:
        sys.exit("make_scene.py: --ranks and --size must be positive")
    ints = lambda text: [int(x) for x in text.split(",")]
    if a.kind == "block":
        values = block(a.mode, a.ranks, a.size, ints(a.cells) if a.cells else None)
    else:
        values = wall(a.mode, a.ranks, a.size, a.units, a.courses, ints(a.unit_cells))
    values.update({"mode": a.mode, "ranks": a.ranks, "end": repr(a.end)})
    with open(os.path.join(HERE, a.kind + ".yaml.in")) as f:
        text = string.Template(f.read()).substitute(values)
    with open(a.output, "w") as f:
        f.write(text)
    json.dump({"kind": a.kind, "mode": a.mode, "ranks": a.ranks, "tets": values["tets"]},
              sys.stdout)
    print()


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""A slender block rocking on a fixed base (docs/verification.md, "Free rocking"): what the impact
on its heel keeps of the angular velocity, against Housner's rigid-block value, and whether the
heel then stays down, with the contact dashpot sized by the bodies (contact.dashpot: bodies, the
default) or by the tets (tets, the previous formulation), for several damping ratios.

  benchmarks/masonry_thresholds/rocking.py [--fdem build/drivers/fdem]
      [--cases 0.2/0,0.5/0,1.0/0,0.5/0.5] [--dashpots bodies,tets] [--penalty 4e9]
      [--csv docs/data/rocking_impact.csv]

A case `xc/xe` is the contact damping ratio xc and the element damping ratio xe.  The block is
0.25 × 0.2 × 1.0 m (b/h = 0.25, 2 × 2 × 8 cells, E = 1 GPa, ρ 2000, μ 0.8) on a 1.2 × 0.6 ×
0.1 m fixed base, set rocking about its toe edge with ω0 = p·α/2 as in the test.  Monitors at the
heel and toe edges (1 mm above the base) give the block's rotation θ from the bottom edge's
direction and the heel's lift and slide.  Measured per run:
  ratio      ω'/ω from the swing heights before and after the impact (the rigid block's energy,
             with the model's lumped-mass inertia: p = 3.751 1/s, Housner's 0.9130 — the
             values test_rocking computes from the model's nodal masses)
  bounce     the heel's largest lift in the 20 ms after the impact (mm)
  later      its largest lift from then until the block is back on its base (mm)
  hops       how many times the heel rises more than 20 µm in that time
  slide      the heel's horizontal travel while it is the pivot (mm)
  CPU        user CPU seconds of the fdem run (one core)
"""
import argparse, csv, math, os, subprocess, sys, tempfile

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))
B, H, G = 0.25, 1.0, 9.81
R = 0.5 * math.hypot(B, H)
ALPHA = math.atan(B / H)
P = math.sqrt(3 * G / (4 * R))
OMEGA0 = 0.5 * P * ALPHA
P_MODEL, HOUSNER = 3.751, 0.9130


def scene(xc, xe, penalty, dashpot, end):
    return f"""name: rocking
time: {{end: {end}, step: auto, safety: 0.5}}
gravity: [0, 0, {-G}]
contact: {{dashpot: {dashpot}}}
materials:
  stone:
    density: 2000
    elastic: {{young: 1.0e9, poisson: 0.2}}
    damping: {xe}
    contact: {{penalty: {penalty}, friction: 0.8, damping: {xc}}}
bodies:
  - name: base
    mesh: {{box: {{min: [-0.6, -0.3, -0.1], max: [0.6, 0.3, 0], cells: [6, 3, 1]}}}}
    material: stone
    fixed: true
  - name: block
    mesh: {{box: {{min: [{-B / 2}, -0.1, 0], max: [{B / 2}, 0.1, {H}], cells: [2, 2, 8]}}}}
    material: stone
    velocity: [{OMEGA0 * 0.5 * H}, 0, {OMEGA0 * 0.5 * B}]
    angular_velocity: [0, {OMEGA0}, 0]
output:
  every: 10
  histories:
    every: 5.0e-5
    monitors:
      - {{name: heel, point: [{-B / 2}, 0, 0.001]}}
      - {{name: toe, point: [{B / 2}, 0, 0.001]}}
"""


def measure(path):
    rows = list(csv.DictReader(open(path)))
    t = [float(r["time"]) for r in rows]
    hx = [-B / 2 + float(r["monitor.heel.ux"]) for r in rows]
    hz = [float(r["monitor.heel.uz"]) for r in rows]
    tx = [B / 2 + float(r["monitor.toe.ux"]) for r in rows]
    tz = [float(r["monitor.toe.uz"]) for r in rows]
    theta = [math.atan2(hz[i] - tz[i], tx[i] - hx[i]) for i in range(len(rows))]
    i, top = 1, 0.0  # first landing: θ back through 0 from its first swing
    while i < len(theta) and not (theta[i] <= 0 < theta[i - 1] and top > 0.1 * ALPHA):
        top = max(top, theta[i])
        i += 1
    j, bottom = i, 0.0  # back on the base after the swing about the heel
    while j < len(theta) and not (theta[j] >= 0 > theta[j - 1] and bottom < -0.1 * ALPHA):
        bottom = min(bottom, theta[j])
        j += 1
    if i >= len(theta) or j >= len(theta):
        return None
    omega = lambda a: math.sqrt(2 * P_MODEL ** 2 * (math.cos(ALPHA - a) - math.cos(ALPHA)))
    ratio = omega(-bottom) / omega(top)
    k = next(k for k in range(i, j) if t[k] > t[i] + 0.02)
    hops, up = 0, False
    for z in hz[k:j]:
        if z > 2e-5 and not up:
            hops, up = hops + 1, True
        elif z < 5e-6:
            up = False
    return dict(landed_s=t[i], ratio=ratio, error_pct=100 * (ratio / HOUSNER - 1),
                bounce_mm=1e3 * max(hz[i:k]), later_mm=1e3 * max(hz[k:j]), hops=hops,
                slide_mm=1e3 * (max(hx[i:j]) - min(hx[i:j])), back_s=t[j])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--fdem", default=os.path.join(root, "build/drivers/fdem"))
    ap.add_argument("--cases", default="0.2/0,0.5/0,1.0/0,0.5/0.5")
    ap.add_argument("--dashpots", default="bodies,tets")
    ap.add_argument("--penalty", default="4.0e9")
    ap.add_argument("--end", type=float, default=0.62)
    ap.add_argument("--csv", default="")
    a = ap.parse_args()
    fields = ["dashpot", "contact_damping", "element_damping", "penalty", "landed_s", "ratio",
              "error_pct", "bounce_mm", "later_mm", "hops", "slide_mm", "back_s", "steps", "cpu_s"]
    out = []
    print(" ".join(f"{f:>15}" for f in fields))
    for case in a.cases.split(","):
        xc, xe = case.split("/")
        for dashpot in a.dashpots.split(","):
            d = tempfile.mkdtemp(prefix="rocking-")
            with open(os.path.join(d, "scene.yaml"), "w") as f:
                f.write(scene(xc, xe, a.penalty, dashpot, a.end))
            p = subprocess.run(["/usr/bin/time", "-f", "%U", a.fdem, "run",
                                os.path.join(d, "scene.yaml"), "-o", os.path.join(d, "out")],
                               capture_output=True, text=True)
            if p.returncode != 0:
                sys.exit(f"fdem failed on {case} {dashpot}:\n{p.stdout[-2000:]}{p.stderr[-2000:]}")
            m = measure(os.path.join(d, "out", "histories.csv"))
            if m is None:
                sys.exit(f"{case} {dashpot}: the block did not land and come back in {a.end} s")
            import json
            summary = json.load(open(os.path.join(d, "out", "summary.json")))
            row = dict(dashpot=dashpot, contact_damping=xc, element_damping=xe,
                       penalty=a.penalty, steps=summary.get("steps", ""),
                       cpu_s=float(p.stderr.strip().split("\n")[-1]), **m)
            out.append(row)
            print(" ".join(f"{row[f]:>15.5g}" if isinstance(row[f], float) else f"{row[f]:>15}"
                           for f in fields), flush=True)
    if a.csv:
        with open(a.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=fields)
            w.writeheader()
            w.writerows(out)


if __name__ == "__main__":
    main()

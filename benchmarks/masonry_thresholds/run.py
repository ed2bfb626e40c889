#!/usr/bin/env python3
"""Collapse thresholds of dry masonry in fdem's quasi-static mode, against the rigid-block
values, with the steps and CPU time each answer costs.  Each case is a hold: the load is set
from the start at `ratio` × the rigid-block threshold and held under local damping 0.8
(quasi_static), and a monitor point says whether the structure settles or a mechanism runs.

  benchmarks/masonry_thresholds/run.py [--fdem build/drivers/fdem] [--cases all|NAME,...]
                                       [--ratios all|R,...] [--hold-scale 1]
                                       [--equilibrium-ratio R] [--stop-displacement D]
                                       [--penalty-factor F] [--damping local|kinetic]
                                       [--set KEY=VALUE ...]
                                       [--csv docs/data/masonry_thresholds.csv]
  benchmarks/masonry_thresholds/run.py --references   # the rigid-block values only

Problems (docs/references.md 17 and 20; docs/verification.md, "Tilting table" and "Arches"):
  wall_tilt          dry running-bond wall, 5 courses of 4 units 0.2 × 0.1 × 0.1 m, lowest
                     course held, gravity tilted θ in the wall's plane: tan θc = 0.6 (closed form)
  arch_min_thickness semicircular arch of 20 voussoirs on a fixed ground, centre-line radius 1 m,
                     own weight: stands for t/R ≥ 0.1074 (thrust line inside every joint)
  arch_horizontal    the same arch at t/R = 0.15 under a constant horizontal acceleration λg:
                     collapses at λc = 0.1490 (least four-hinge mechanism, virtual work)

The rigid-block values are computed here for the meshed geometry (voussoir faces are two chords
each, as the generator meshes them with 2 cells along the arc).  Outcome of a hold, from the
monitor's displacement u over the last two windows of the hold (w = a fifth of it):
d1 = |u(T)| − |u(T − w)|, d0 = |u(T − w)| − |u(T − 2w)|:
  stands     d1 < `still` (the problem's tolerance: the structure has stopped or turns back)
  turns      d1 > `moving` and d1 ≥ d0 (a mechanism accelerating)
  undecided  otherwise (still creeping: a longer hold would decide)
The holds are quasi-static throughout on bodies without joints, so the default contact
(contact.formulation: auto) is corner contact; --set contact.formulation=potential gives potential
contact's thresholds (docs/verification.md, "Corner contact").
With --penalty-factor F the contact penalty is F·E instead of the default (auto: 10 E): how
the thresholds move with the hinges' contact stiffness.
With --equilibrium-ratio R every hold also ends at equilibrium (quasi_static.equilibrium_ratio:
the mean unbalanced-force ratio below R); a hold that ends so `stands (equilibrium)`, before its
full time.  With --stop-displacement D every hold also ends once its monitor has moved D (m;
the monitor's stop_displacement): a hold that ends so `turns (stop)`.  With both, each hold ends
by itself whichever way it goes.  With --damping kinetic the holds take kinetic damping
(quasi_static.damping: kinetic: every free velocity zeroed at each peak of the kinetic energy)
instead of local damping 0.8.
Time is the user CPU time of the fdem process (/usr/bin/time), one core.
"""
import argparse, csv, itertools, json, math, os, subprocess, sys, tempfile

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))

VOUSSOIRS, ARC_CELLS = 20, 2


# --- rigid-block references -----------------------------------------------------------------

def voussoir(ri, re, a0, a1, chords):
    """Area and centroid (x, z) of a voussoir between joint angles a0 < a1 whose intrados and
    extrados are `chords` chords each."""
    pts = [(re * math.cos(a0 + (a1 - a0) * k / chords), re * math.sin(a0 + (a1 - a0) * k / chords))
           for k in range(chords + 1)]
    pts += [(ri * math.cos(a1 - (a1 - a0) * k / chords), ri * math.sin(a1 - (a1 - a0) * k / chords))
            for k in range(chords + 1)]
    area = cx = cz = 0.0
    for (x0, z0), (x1, z1) in zip(pts, pts[1:] + pts[:1]):
        c = x0 * z1 - x1 * z0
        area += c
        cx += (x0 + x1) * c
        cz += (z0 + z1) * c
    area *= 0.5
    return abs(area), cx / (6 * area), cz / (6 * area)


def thrust_gap(t, n=VOUSSOIRS, chords=ARC_CELLS, radius=1.0):
    """Largest slack of the thrust line of the symmetric half arch under its own weight over the
    crown thrust H (its line of action through every joint between intrados and extrados): ≥ 0
    when some thrust line fits.  Joint k at angle θ, weight W and first moment S above it: the
    line crosses the joint at ρ = (H·zc + S)/(H sin θ + W cos θ), zc the crown's height."""
    ri, re = radius - t / 2, radius + t / 2
    angles = [math.pi / 2 - k * math.pi / n for k in range(n // 2 + 1)]
    w = s = 0.0
    joints = []
    for upper, lower in zip(angles, angles[1:]):
        area, cx, _ = voussoir(ri, re, lower, upper, chords)
        w += area
        s += area * cx
        joints.append((math.sin(lower), math.cos(lower), w, s))

    def gap(h):  # interval of m = H·zc left open by the crown and every joint
        lo, hi = ri * h, re * h
        for sn, cs, wk, sk in joints:
            lo = max(lo, ri * (h * sn + wk * cs) - sk)
            hi = min(hi, re * (h * sn + wk * cs) - sk)
        return hi - lo

    a, b = 1e-6 * w, 5 * w  # the gap is concave in H: ternary search
    for _ in range(200):
        m1, m2 = a + (b - a) / 3, b - (b - a) / 3
        a, b = (m1, b) if gap(m1) < gap(m2) else (a, m2)
    return gap(0.5 * (a + b))


def minimum_thickness(n=VOUSSOIRS, chords=ARC_CELLS):
    a, b = 0.05, 0.2
    for _ in range(60):
        m = 0.5 * (a + b)
        a, b = (a, m) if thrust_gap(m, n, chords) >= 0 else (m, b)
    return b


def four_hinge_multiplier(t, n=VOUSSOIRS, chords=ARC_CELLS, radius=1.0):
    """Least horizontal-acceleration multiplier λ over the four-hinge mechanisms (hinges at
    joints a < b < c < d, each at the intrados or the extrados, opening), by virtual work:
    λ = Σ W v_z / Σ W v_x with the three moving parts' rigid velocities."""
    ri, re = radius - t / 2, radius + t / 2
    th = [k * math.pi / n for k in range(n + 1)]
    parts = [voussoir(ri, re, th[j], th[j + 1], chords) for j in range(n)]

    def spin(w, r):  # ω × r in the x–z plane
        return (-w * r[1], w * r[0])

    best = math.inf
    for a, b, c, d in itertools.combinations(range(n + 1), 4):
        for at in itertools.product((0, 1), repeat=4):  # 0: intrados, 1: extrados
            hinge = [((re if e else ri) * math.cos(th[k]), (re if e else ri) * math.sin(th[k]))
                     for k, e in zip((a, b, c, d), at)]
            for w1 in (1.0, -1.0):
                vb = spin(w1, (hinge[1][0] - hinge[0][0], hinge[1][1] - hinge[0][1]))
                r2 = (hinge[2][0] - hinge[1][0], hinge[2][1] - hinge[1][1])
                r3 = (hinge[2][0] - hinge[3][0], hinge[2][1] - hinge[3][1])
                det = r2[1] * r3[0] - r3[1] * r2[0]
                if abs(det) < 1e-14:
                    continue
                w2 = (vb[0] * r3[0] + r3[1] * vb[1]) / det
                w3 = (r2[1] * vb[1] + r2[0] * vb[0]) / det
                # a joint opens away from its hinge: intrados hinge Δω > 0, extrados Δω < 0
                turn = [w1, w2 - w1, w3 - w2, -w3]
                if not all((dw > 0) if e == 0 else (dw < 0) for dw, e in zip(turn, at)):
                    continue
                up = along = 0.0
                for j in range(a, d):
                    area, cx, cz = parts[j]
                    if j < b:
                        v = spin(w1, (cx - hinge[0][0], cz - hinge[0][1]))
                    elif j < c:
                        dv = spin(w2, (cx - hinge[1][0], cz - hinge[1][1]))
                        v = (vb[0] + dv[0], vb[1] + dv[1])
                    else:
                        v = spin(w3, (cx - hinge[3][0], cz - hinge[3][1]))
                    up += area * v[1]
                    along += area * v[0]
                if along > 0 and up > 0:
                    best = min(best, up / along)
    return best


# --- scenes ---------------------------------------------------------------------------------

def wall_scene(ratio, hold):
    theta = ratio * math.atan(0.6)
    g = (-9.81 * math.sin(theta), 0.0, -9.81 * math.cos(theta))
    return f"""name: wall-tilt
time: {{end: {hold}, step: auto, safety: 0.7}}
gravity: [{g[0]:.9f}, 0, {g[2]:.9f}]
quasi_static: {{local_damping: 0.8}}
materials:
  brick:
    density: 2000
    elastic: {{young: 1.0e9, poisson: 0.2}}
    contact: {{friction: 0.8}}
bodies:
  - name: wall
    mesh: {{wall: {{unit: [0.2, 0.1, 0.1], courses: 5, units_per_course: 4, bond: running,
                  mortar_gap: 0, cells_per_unit: [2, 1, 1], origin: [0, 0, 0]}}}}
    material: brick
loads:
  - {{region: {{box: {{min: [-1, -1, -0.001], max: [2, 1, 0.001]}}}}, velocity: [0, 0, 0]}}
output:
  every: 0
  histories: {{every: {hold / 40}, monitors: [{{name: m, point: [0.005, 0.05, 0.495]}}]}}
"""


def arch_scene(thickness, horizontal, hold):
    return f"""name: arch
time: {{end: {hold}, step: auto, safety: 0.7}}
gravity: [{horizontal * 9.81:.9f}, 0, -9.81]
quasi_static: {{local_damping: 0.8}}
materials:
  stone:
    density: 2000
    elastic: {{young: 1.0e9, poisson: 0.2}}
    contact: {{friction: 0.8}}
bodies:
  - name: ground
    mesh: {{box: {{min: [-1.5, -0.1, -0.1], max: [1.5, 0.2, 0], cells: [6, 1, 1]}}}}
    material: stone
    fixed: true
  - name: arch
    mesh: {{arch: {{kind: semicircular, radius: {1 - thickness / 2:.9f}, thickness: {thickness:.9f},
                  depth: 0.1, voussoirs: {VOUSSOIRS}, cells_per_voussoir: [2, {ARC_CELLS}, 1]}}}}
    material: stone
output:
  every: 0
  histories: {{every: {hold / 40}, monitors: [{{name: m, point: [0.001, 0.05, 1.0]}}]}}
"""


# (problem, ratio, hold (s), scene(hold), `still`, `moving` (m): see outcome())
def make_cases(refs):
    cases = []
    for ratio, hold in ((0.98, 0.2), (0.99, 0.2), (1.01, 0.2), (1.02, 0.12)):
        cases.append(("wall_tilt", ratio, hold,
                      lambda h, r=ratio: wall_scene(r, h), 2e-6, 2e-5))
    for ratio, hold in ((0.98, 0.3), (1.02, 0.7), (1.04, 0.4)):
        cases.append(("arch_min_thickness", ratio, hold,
                      lambda h, r=ratio: arch_scene(r * refs["arch_min_thickness"], 0.0, h),
                      5e-6, 2e-5))
    for ratio, hold in ((0.92, 0.6), (0.95, 0.6), (0.98, 0.6), (1.02, 0.6)):
        cases.append(("arch_horizontal", ratio, hold,
                      lambda h, r=ratio: arch_scene(0.15, r * refs["arch_horizontal"], h),
                      5e-6, 2e-5))
    return cases


def outcome(rows, still, moving):
    u = [math.sqrt(float(r["monitor.m.ux"]) ** 2 + float(r["monitor.m.uy"]) ** 2 +
                   float(r["monitor.m.uz"]) ** 2) for r in rows]
    w = max(1, len(u) // 5)
    d1, d0 = u[-1] - u[-1 - w], u[-1 - w] - u[-1 - 2 * w]
    if d1 < still:
        return "stands", u[-1], d1
    if d1 > moving and d1 >= d0:
        return "turns", u[-1], d1
    return "undecided", u[-1], d1


def run(fdem, text, workdir, overrides=()):
    path = os.path.join(workdir, "scene.yaml")
    with open(path, "w") as f:
        f.write(text)
    out = os.path.join(workdir, "out")
    command = ["/usr/bin/time", "-f", "%U", fdem, "run", path, "-o", out, "-q"]
    for o in overrides:
        command += ["--set", o]
    timing = subprocess.run(command, capture_output=True, text=True)
    if timing.returncode != 0:
        sys.exit(f"fdem failed:\n{timing.stderr}")
    cpu = float(timing.stderr.strip().splitlines()[-1])
    with open(os.path.join(out, "histories.csv")) as f:
        rows = list(csv.DictReader(f))
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    reason = summary.get("reason", "")
    return rows, cpu, summary["steps"], "equilibrium" in reason, "stop_displacement" in reason


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--fdem", default=os.path.join(root, "build", "drivers", "fdem"))
    p.add_argument("--cases", default="all")
    p.add_argument("--ratios", default="all", help="only these ratios, e.g. 0.95,0.98")
    p.add_argument("--csv", default=os.path.join(root, "docs", "data", "masonry_thresholds.csv"))
    p.add_argument("--references", action="store_true")
    p.add_argument("--hold-scale", type=float, default=1.0,
                   help="multiplies every hold (a quick check of the script: 0.1)")
    p.add_argument("--penalty-factor", type=float, default=0.0,
                   help="contact penalty as a multiple of E (default: the scene's auto, 10 E)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="a scene override passed to every hold (fdem run --set), e.g. "
                        "contact.sliver_tolerance=1e-8")
    p.add_argument("--equilibrium-ratio", type=float, default=0.0,
                   help="end holds at equilibrium (quasi_static.equilibrium_ratio), e.g. 1e-4")
    p.add_argument("--stop-displacement", type=float, default=0.0,
                   help="end holds once the monitor has moved this far (m), e.g. 0.001")
    p.add_argument("--damping", choices=("local", "kinetic"), default="local",
                   help="the quasi-static damping (quasi_static.damping): local 0.8 or kinetic")
    a = p.parse_args()
    refs = {"wall_tilt": math.degrees(math.atan(0.6)),
            "arch_min_thickness": minimum_thickness(),
            "arch_horizontal": four_hinge_multiplier(0.15)}
    print("rigid-block references: wall tilt θc = %.4f°, arch t/R min = %.5f, arch λc = %.5f "
          "(t/R 0.15)" % (refs["wall_tilt"], refs["arch_min_thickness"], refs["arch_horizontal"]))
    if a.references:
        return
    chosen = None if a.cases == "all" else set(a.cases.split(","))
    ratios = None if a.ratios == "all" else [float(r) for r in a.ratios.split(",")]
    results = []
    print("%-20s %6s %6s %9s %8s %11s %11s  %s" % ("problem", "ratio", "hold", "steps", "cpu_s",
                                                   "|u| end", "last window", "outcome"))
    for name, ratio, hold, scene, still, moving in make_cases(refs):
        if chosen and name not in chosen:
            continue
        if ratios and not any(abs(ratio - r) < 1e-9 for r in ratios):
            continue
        hold *= a.hold_scale
        text = scene(hold)
        if a.damping == "kinetic":
            text = text.replace("quasi_static: {local_damping: 0.8}",
                                "quasi_static: {damping: kinetic}")
        if a.equilibrium_ratio > 0:
            text = text.replace("quasi_static: {", "quasi_static: {equilibrium_ratio: %g, " %
                                a.equilibrium_ratio)
        if a.stop_displacement > 0:
            text = text.replace("point: [", "stop_displacement: %g, point: [" % a.stop_displacement)
        if a.penalty_factor > 0:
            text = text.replace("contact: {friction: 0.8}",
                                "contact: {friction: 0.8, penalty: %g}" % (a.penalty_factor * 1.0e9))
        with tempfile.TemporaryDirectory() as workdir:
            rows, cpu, steps, at_equilibrium, stopped = run(a.fdem, text, workdir, a.set)
        verdict, end, d1 = outcome(rows, still, moving)
        if at_equilibrium:
            verdict = "stands (equilibrium)"
        if stopped:
            verdict = "turns (stop)"
        print("%-20s %6.3f %6.2f %9d %8.1f %11.3e %11.3e  %s" % (name, ratio, hold, steps, cpu, end,
                                                                  d1, verdict), flush=True)
        results.append({"problem": name, "ratio": ratio, "reference": refs[name], "hold_s": hold,
                        "equilibrium_ratio": a.equilibrium_ratio,
                        "stop_displacement_m": a.stop_displacement,
                        "penalty_factor": a.penalty_factor or 10.0, "damping": a.damping,
                        "overrides": " ".join(a.set),
                        "steps": steps, "cpu_s": cpu, "displacement_m": end,
                        "last_window_m": d1, "outcome": verdict})
    os.makedirs(os.path.dirname(a.csv), exist_ok=True)
    with open(a.csv, "w", newline="") as f:
        out = csv.DictWriter(f, fieldnames=list(results[0].keys()))
        out.writeheader()
        out.writerows(results)
    print("wrote", a.csv)


if __name__ == "__main__":
    main()

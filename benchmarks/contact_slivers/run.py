#!/usr/bin/env python3
"""Contact pairs skipped under a proven bound (contact.sliver_tolerance, docs/benchmarks.md,
"Contact: slivers skipped under a proven bound"): run time and results of masonry scenes with the
default tolerance against 0 (every pair the face planes pass is integrated, the previous
algorithm), alternating in one invocation, one core each.

  benchmarks/contact_slivers/run.py [--fdem build/drivers/fdem] [--repeats 3]
      [--tolerances 0,1e-6] [--cases wall_tilt,arch,tower,dry_wall]
      [--also 'LABEL=KEY=VALUE' ...]
      [--baseline OLD_FDEM [--baseline-tolerance none]] [--csv docs/data/bench_contact_slivers.csv]

With --also, one more variant per option: the current binary at the last tolerance with the scene
key KEY set to VALUE (e.g. --also 'no replay=contact.clip_replay=false').

With --baseline, a third variant runs that binary (an older build) at the last tolerance, in the
same alternation: the ratio of the current code's skipping against the older one's.

Cases (each `fdem run` to a fixed time; the pieces' centroids at the end are compared between
tolerances):
  wall_tilt  the tilting-table wall of docs/verification.md at 0.9 of its collapse tilt, 0.05 s
             (5 courses of 4 touching units, 240 tets, quasi-static mode)
  arch       the 20-voussoir arch (t/R 0.15) under 0.13 g horizontal, 0.02 s (516 tets)
  tower      the default example (tower and projectile), first 0.1 s: the projectile hits at 14 ms
  tower_full the whole default example (1 s): the impact, then the blocks settling
  dry_wall   examples/dry-stone-wall-seismic.yaml, first 0.2 s (2 mm mortar gaps: the stones land)
  pile       bench_contact_pile's dense pile of 64 blocks (3,558 tets) as a scene, first 4 ms
  wall55     a dry running-bond wall of 55 blocks (10 courses of 5 units, E 5 GPa, penalty auto,
             642 tets with the table) on a tilting table turning at 10°/s from 0.02 s, fully
             dynamic (no quasi-static mode), first 0.03 s: issue 12's dry-wall scene
Measured per run: user CPU seconds, steps, the contact stage's seconds, the energy balance error,
the state_hash; per case: the speed-up (best of the repeats) and the largest difference of a
piece's centroid between the tolerances.
"""
import argparse, csv, json, os, resource, subprocess, sys, tempfile

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))
sys.path.insert(0, os.path.join(root, "benchmarks", "masonry_thresholds"))
import run as thresholds  # noqa: E402  (the wall and arch scenes)


def case_scene(name, workdir):
    """Scene path and the overrides of one case."""
    if name == "wall_tilt":
        path = os.path.join(workdir, "wall_tilt.yaml")
        with open(path, "w") as f:
            f.write(thresholds.wall_scene(0.9, 0.05))
        return path, []
    if name == "arch":
        path = os.path.join(workdir, "arch.yaml")
        with open(path, "w") as f:
            f.write(thresholds.arch_scene(0.15, 0.13, 0.02))
        return path, []
    if name == "tower":
        return os.path.join(root, "examples", "tower-projectile.yaml"), ["time.end=0.1"]
    if name == "tower_full":
        return os.path.join(root, "examples", "tower-projectile.yaml"), []
    if name == "dry_wall":
        return os.path.join(root, "examples", "dry-stone-wall-seismic.yaml"), ["time.end=0.2"]
    if name == "wall55":
        path = os.path.join(workdir, "wall55.yaml")
        with open(path, "w") as f:
            f.write(wall55_scene(0.03))
        return path, []
    if name == "pile":
        path = os.path.join(workdir, "pile.yaml")
        with open(path, "w") as f:
            f.write(pile_scene(4, 0.004))
        return path, []
    raise SystemExit(
        f"unknown case {name}: wall_tilt, arch, tower, tower_full, dry_wall, pile or wall55")


def wall55_scene(end):
    """55 touching blocks in running bond on a fixed table that tilts about y, dynamic."""
    return f"""name: wall55
time: {{end: {end}, step: auto, safety: 0.7}}
gravity: [0, 0, -9.81]
materials:
  brick:
    density: 2000
    elastic: {{young: 5.0e9, poisson: 0.2}}
    contact: {{friction: 0.7}}
bodies:
  - name: table
    mesh: {{box: {{min: [-0.2, -0.1, -0.1], max: [1.2, 0.2, 0], cells: [7, 1, 1]}}}}
    material: brick
    fixed: true
  - name: wall
    mesh: {{wall: {{unit: [0.2, 0.1, 0.1], courses: 10, units_per_course: 5, bond: running,
                  mortar_gap: 0, cells_per_unit: [2, 1, 1], origin: [0, 0, 0]}}}}
    material: brick
loads:
  - {{tilt: {{axis: [0, 1, 0], rate: 10.0, max: 40, start: 0.02}}}}
output:
  every: 0
"""


def pile_scene(k, end):
    """bench_contact_pile's dense pile as a scene: k³ blocks of 0.2 m (2×2×2 cells) stacked
    touching on a fixed base, falling at 0.5 m/s with small lateral velocities."""
    a = 0.2
    lines = [f"name: pile", f"time: {{end: {end}, step: auto, safety: 0.7}}",
             "gravity: [0, 0, -9.81]", "materials:", "  stone:", "    density: 2500",
             "    elastic: {young: 1.0e9, poisson: 0.2}", "    contact: {friction: 0.5}",
             "bodies:", "  - name: base",
             f"    mesh: {{box: {{min: [-0.1, -0.1, -0.2], max: [{k * a + 0.1}, {k * a + 0.1}, 0],"
             f" cells: [{2 * k + 1}, {2 * k + 1}, 1]}}}}",
             "    material: stone", "    fixed: true"]
    for i in range(k):
        for j in range(k):
            for l in range(k):
                lo = (i * a, j * a, l * a)
                hi = tuple(c + a for c in lo)
                lines += [f"  - name: b{i}_{j}_{l}",
                          f"    mesh: {{box: {{min: [{lo[0]:.6g}, {lo[1]:.6g}, {lo[2]:.6g}], "
                          f"max: [{hi[0]:.6g}, {hi[1]:.6g}, {hi[2]:.6g}], cells: [2, 2, 2]}}}}",
                          "    material: stone",
                          f"    velocity: [{0.01 * (i - j):.6g}, {0.01 * (l - i):.6g}, -0.5]"]
    lines += ["output: {every: 0}"]
    return "\n".join(lines) + "\n"


def final_centroids(outdir):
    rows = list(csv.DictReader(open(os.path.join(outdir, "bodies.csv"))))
    last = rows[-1]["time"]
    return {(r["body"], r["piece"]): tuple(float(r[k]) for k in ("x", "y", "z"))
            for r in rows if r["time"] == last}


def run_once(fdem, scene, overrides, tolerance, outdir):
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
    args = [fdem, "run", scene, "-o", outdir, "-q"]
    if tolerance != "none":  # "none": a binary older than the key
        args += ["--set", f"contact.sliver_tolerance={tolerance}"]
    for o in overrides:
        args += ["--set", o]
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL)
    cpu = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - before
    summary = json.load(open(os.path.join(outdir, "summary.json")))
    return {"cpu": cpu, "steps": summary["steps"], "hash": summary.get("state_hash", "-"),
            "contact": summary.get("stages", {}).get("contact_forces", {}).get("seconds", 0.0),
            "balance": summary["energy"]["balance_error"],
            "centroids": final_centroids(outdir)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--fdem", default=os.path.join(root, "build", "drivers", "fdem"))
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--tolerances", default="0,1e-6")
    ap.add_argument("--cases", default="wall_tilt,arch,tower,dry_wall")
    ap.add_argument("--also", action="append", default=[],
                    help="LABEL=KEY=VALUE: the current binary with a scene key set")
    ap.add_argument("--baseline", help="an older fdem binary, run at the last tolerance")
    ap.add_argument("--baseline-tolerance",
                    help="the baseline's tolerance instead (none: a binary without the key)")
    ap.add_argument("--csv", default=os.path.join(root, "docs", "data",
                                                  "bench_contact_slivers.csv"))
    a = ap.parse_args()
    tolerances = a.tolerances.split(",")
    # (label, binary, tolerance); the first is the reference of the speed-ups
    variants = [(f"tolerance {t}", a.fdem, t, []) for t in tolerances]
    for also in a.also:
        label, setting = also.split("=", 1)
        variants.append((label, a.fdem, tolerances[-1], [setting]))
    if a.baseline:
        t = a.baseline_tolerance or tolerances[-1]
        variants.append((f"baseline {t}", a.baseline, t, []))
    rows = []
    with tempfile.TemporaryDirectory() as workdir:
        for name in a.cases.split(","):
            scene, overrides = case_scene(name, workdir)
            best = {}
            for repeat in range(a.repeats):
                for label, fdem, tol, settings in variants:  # alternating: drift hits all
                    r = run_once(fdem, scene, overrides + settings, tol,
                                 os.path.join(workdir, f"{name}_{len(best)}"))
                    if label not in best or r["cpu"] < best[label]["cpu"]:
                        best[label] = r
            reference = best[variants[0][0]]
            for label, fdem, tol, settings in variants:
                r = best[label]
                moved = max(
                    (sum((p - q) ** 2 for p, q in zip(r["centroids"][k],
                                                       reference["centroids"][k])) ** 0.5
                     for k in reference["centroids"]), default=0.0)
                row = {"case": name, "variant": label, "sliver_tolerance": tol,
                       "steps": r["steps"], "cpu_seconds": round(r["cpu"], 3),
                       "contact_seconds": round(r["contact"], 3),
                       "speedup": round(reference["cpu"] / r["cpu"], 3),
                       "balance_error": f"{r['balance']:.3e}",
                       "centroid_difference_m": f"{moved:.3e}", "state_hash": r["hash"]}
                rows.append(row)
                print(" ".join(f"{k}={v}" for k, v in row.items()), flush=True)
    os.makedirs(os.path.dirname(os.path.abspath(a.csv)), exist_ok=True)
    with open(a.csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)


if __name__ == "__main__":
    main()

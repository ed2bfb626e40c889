#!/usr/bin/env python3
"""Reads the summary.json of every run of the scaling benchmark and writes scaling.csv.

  collect.py MANIFEST CSV

MANIFEST has one line per run: mode, scene, ranks, run directory (tab-separated). Efficiency is
taken against the smallest rank count of the same mode and scene (N0, time T0):
  strong: (N0 * T0) / (N * TN)   (with N0 = 1: T1 / (N * TN))
  weak:   T0 / TN
where T is the time per step. cores_used = CPU seconds of the run (all its local processes) /
elapsed seconds, from RUN.time when the launcher ran the ranks as its children (else nan).
Prints a table and, for strong scaling, whether the final state hash is the same on every rank
count; exits with status 3 if it is not (a bug: the engine is meant to be bit-identical on any
rank count).
"""
import csv
import json
import os
import sys

COLUMNS = [
    "mode", "scene", "ranks", "elements", "elements_per_rank", "steps", "wall_seconds",
    "seconds_per_step", "element_steps_per_second_per_core", "efficiency",
    "communication_share", "imbalance", "max_imbalance", "migrated_elements", "halo_elements_max",
    "ghost_nodes_max", "state_hash", "output_seconds", "communication_seconds", "cores_used",
]


def read_run(mode, scene, ranks, run_dir):
    with open(os.path.join(run_dir, "summary.json")) as f:
        s = json.load(f)
    if s.get("status", "completed") != "completed":
        sys.exit(f"collect.py: run {run_dir} did not complete: {s.get('reason', '?')}")
    if int(s.get("ranks", 1)) != ranks:
        sys.exit(f"collect.py: {run_dir}: summary says {s.get('ranks')} ranks, expected {ranks}")
    steps = int(s["steps"])
    wall = float(s["wall_seconds"])
    stages = s.get("stages", {})
    output = float(stages.get("output", {}).get("seconds", 0.0))
    d = s.get("decomposition", {})
    comm = float(d.get("communication_seconds", 0.0))
    elements = int(s["elements"])
    # CPU seconds of the run over its elapsed time (written by bench-scaling.sh next to the run
    # directory); only meaningful with a launcher that runs the ranks as its own children.
    cores_used = float("nan")
    try:
        with open(run_dir.rstrip("/") + ".time") as f:
            elapsed, user, system = (float(x) for x in f.read().split()[:3])
        if elapsed > 0:
            cores_used = (user + system) / elapsed
    except (OSError, ValueError):
        pass
    # Time per step: the wall time of the run less the first and last frame (output is not
    # part of what is scaled; it is kept small in these scenes and reported separately).
    per_step = (wall - output) / steps if steps else float("nan")
    return {
        "mode": mode, "scene": scene, "ranks": ranks, "elements": elements,
        "elements_per_rank": elements / ranks, "steps": steps, "wall_seconds": wall,
        "seconds_per_step": per_step,
        "element_steps_per_second_per_core": elements / (per_step * ranks) if per_step else 0.0,
        "efficiency": float("nan"),
        "communication_share": comm / wall if wall > 0 else 0.0,
        "imbalance": float(d.get("imbalance", 1.0)),
        "max_imbalance": float(d.get("max_imbalance", 1.0)),
        "migrated_elements": int(d.get("migrated_elements", 0)),
        "halo_elements_max": int(d.get("halo_elements_max", 0)),
        "ghost_nodes_max": int(d.get("ghost_nodes_max", 0)),
        "state_hash": s.get("state_hash", ""),
        "output_seconds": output, "communication_seconds": comm, "cores_used": cores_used,
    }


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    manifest, csv_path = sys.argv[1], sys.argv[2]
    rows = []
    with open(manifest) as f:
        for line in f:
            if line.strip():
                mode, scene, ranks, run_dir = line.rstrip("\n").split("\t")
                rows.append(read_run(mode, scene, int(ranks), run_dir))

    groups = {}
    for r in rows:
        groups.setdefault((r["mode"], r["scene"]), []).append(r)
    status = 0
    verdicts = []
    for (mode, scene), g in groups.items():
        g.sort(key=lambda r: r["ranks"])
        ref = g[0]
        for r in g:
            if mode == "strong":
                r["efficiency"] = (ref["ranks"] * ref["seconds_per_step"]) / (
                    r["ranks"] * r["seconds_per_step"])
            else:
                r["efficiency"] = ref["seconds_per_step"] / r["seconds_per_step"]
        if mode == "strong" and len(g) > 1:
            hashes = {r["state_hash"] for r in g}
            ranks = " ".join(str(r["ranks"]) for r in g)
            if len(hashes) == 1:
                verdicts.append(f"strong/{scene}: state_hash identical on {ranks} ranks "
                                f"({ref['state_hash']})")
            else:
                status = 3
                detail = ", ".join(f"{r['ranks']}: {r['state_hash']}" for r in g)
                verdicts.append(f"strong/{scene}: state_hash DIFFERS between rank counts ({detail})")

    rows = [r for (k, g) in groups.items() for r in g]
    with open(csv_path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        w.writeheader()
        for r in rows:
            out = dict(r)
            for k in ("wall_seconds", "output_seconds", "communication_seconds"):
                out[k] = f"{r[k]:.4f}"
            out["elements_per_rank"] = f"{r['elements_per_rank']:.1f}"
            out["seconds_per_step"] = f"{r['seconds_per_step']:.6g}"
            out["element_steps_per_second_per_core"] = f"{r['element_steps_per_second_per_core']:.4g}"
            for k in ("efficiency", "communication_share", "imbalance", "max_imbalance",
                      "cores_used"):
                out[k] = f"{r[k]:.4f}"
            w.writerow(out)

    head = (f"{'mode':<7}{'scene':<7}{'ranks':>6}{'elements':>10}{'el/rank':>10}{'steps':>7}"
            f"{'ms/step':>10}{'el-steps/s/core':>17}{'eff.':>7}{'comm':>7}{'imbal.':>8}"
            f"{'max imb.':>9}{'migrated':>9}{'halo el.':>9}{'ghosts':>8}{'cores':>7}  state_hash")
    print(head)
    for r in rows:
        print(f"{r['mode']:<7}{r['scene']:<7}{r['ranks']:>6}{r['elements']:>10}"
              f"{r['elements_per_rank']:>10.0f}{r['steps']:>7}{1e3 * r['seconds_per_step']:>10.3f}"
              f"{r['element_steps_per_second_per_core']:>17.4g}{r['efficiency']:>7.3f}"
              f"{100 * r['communication_share']:>6.1f}%{r['imbalance']:>8.3f}"
              f"{r['max_imbalance']:>9.3f}{r['migrated_elements']:>9}{r['halo_elements_max']:>9}"
              f"{r['ghost_nodes_max']:>8}{r['cores_used']:>7.2f}  {r['state_hash']}")
    for v in verdicts:
        print(v)
    print(f"csv: {csv_path}")
    sys.exit(status)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Reads the runs of the memory benchmark (scripts/bench-memory.sh) and writes its CSV and table.

  collect_memory.py MANIFEST CSV [FACTOR]

MANIFEST: one line per run, tab-separated: scene, ranks, path, run directory, load before the
run. path is "serial" (1 rank), "distributed" (parallel.distributed_start: true) or "whole"
(false: every rank builds the whole model first). Scene "tiny" (~100 tets) on P ranks gives the
fixed overhead per rank F(P) (MPI, VTK, HDF5 and the binary loaded), for start-up and step loop:
its largest per-rank peak.

Per run: peak RSS per rank (max and mean over ranks) at the end of start-up and in the step loop
(summary.json "memory"), its ratio to the 1-rank figure of the scene, start-up seconds (elapsed
seconds of the launcher, from RUN.time, less the run's wall_seconds: MPI start, scene reading,
building, distribution, and MPI finalisation). Criterion of the issue, at the largest rank count,
for each path: max per-rank peak at P ranks <= FACTOR (default 0.35) x the 1-rank peak + F(P). Also checks that
every run of a scene ends with the same state_hash. Exit status 3 if a hash differs, else 4 if the
criterion fails on the distributed path (the whole-model path is reported for comparison only).
"""
import csv
import json
import os
import sys

COLUMNS = [
    "scene", "ranks", "path", "elements", "steps", "startup_seconds", "elapsed_seconds",
    "startup_peak_rss_mib_max", "startup_peak_rss_mib_mean", "run_peak_rss_mib_max",
    "run_peak_rss_mib_mean", "startup_ratio_to_1_rank", "run_ratio_to_1_rank",
    "halo_elements_max", "ghost_nodes_max", "neighbours_max", "state_hash", "load_before",
]


def read_run(scene, ranks, path, run_dir, load):
    with open(os.path.join(run_dir, "summary.json")) as f:
        s = json.load(f)
    if s.get("status") != "completed":
        sys.exit(f"collect_memory.py: {run_dir} did not complete: {s.get('reason', '?')}")
    with open(run_dir.rstrip("/") + ".time") as f:
        elapsed = float(f.read().split()[0])
    m, d = s["memory"], s.get("decomposition", {})
    return {
        "scene": scene, "ranks": int(ranks), "path": path, "elements": int(s["elements"]),
        "steps": int(s["steps"]), "elapsed_seconds": elapsed,
        "startup_seconds": elapsed - float(s["wall_seconds"]),
        "startup_peak_rss_mib_max": m["startup_peak_rss_kib_max"] / 1024,
        "startup_peak_rss_mib_mean": m["startup_peak_rss_kib_mean"] / 1024,
        "run_peak_rss_mib_max": m["run_peak_rss_kib_max"] / 1024,
        "run_peak_rss_mib_mean": m["run_peak_rss_kib_mean"] / 1024,
        "halo_elements_max": d.get("halo_elements_max", 0),
        "ghost_nodes_max": d.get("ghost_nodes_max", 0),
        "neighbours_max": d.get("neighbours_max", 0),
        "state_hash": s["state_hash"], "load_before": load,
    }


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    factor = float(sys.argv[3]) if len(sys.argv) == 4 else 0.35
    with open(sys.argv[1]) as f:
        rows = [read_run(*line.rstrip("\n").split("\t")) for line in f if line.strip()]
    tiny = {r["ranks"]: r for r in rows if r["scene"] == "tiny"}
    overhead = {n: {"startup": t["startup_peak_rss_mib_max"], "run": t["run_peak_rss_mib_max"]}
                for n, t in tiny.items()}
    one = {r["scene"]: r for r in rows if r["ranks"] == 1}
    for r in rows:
        for k in ("startup", "run"):
            r[f"{k}_ratio_to_1_rank"] = r[f"{k}_peak_rss_mib_max"] / one[r["scene"]][f"{k}_peak_rss_mib_max"]

    with open(sys.argv[2], "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.3f}" if isinstance(v, float) else v) for k, v in r.items()})

    print(f"{'scene':<7}{'ranks':>6} {'path':<12}{'tets':>9}{'start-up s':>11}"
          f"{'start-up MiB max/mean':>23}{'ratio':>7}{'step loop MiB max/mean':>24}{'ratio':>7}"
          f"{'halo el.':>10}{'ghosts':>8}  load before")
    for r in rows:
        print(f"{r['scene']:<7}{r['ranks']:>6} {r['path']:<12}{r['elements']:>9}"
              f"{r['startup_seconds']:>11.1f}"
              f"{r['startup_peak_rss_mib_max']:>14.0f} / {r['startup_peak_rss_mib_mean']:<6.0f}"
              f"{r['startup_ratio_to_1_rank']:>7.3f}"
              f"{r['run_peak_rss_mib_max']:>15.0f} / {r['run_peak_rss_mib_mean']:<6.0f}"
              f"{r['run_ratio_to_1_rank']:>7.3f}{r['halo_elements_max']:>10}"
              f"{r['ghost_nodes_max']:>8}  {r['load_before']}")
    for n, f in sorted(overhead.items()):
        print(f"fixed overhead per rank F({n}) ({tiny[n]['elements']} tets on {n} rank(s)): "
              f"start-up {f['startup']:.1f} MiB, step loop {f['run']:.1f} MiB")
    status = 0
    for scene in [s for s in one if s != "tiny"]:  # (tiny's own runs are F)
        g = [r for r in rows if r["scene"] == scene]
        hashes = {r["state_hash"] for r in g}
        if len(hashes) != 1:
            status = 3
            print(f"{scene}: state_hash DIFFERS between runs: "
                  + ", ".join(f"{r['ranks']}/{r['path']} {r['state_hash']}" for r in g))
        else:
            print(f"{scene}: state_hash identical in all {len(g)} runs ({hashes.pop()})")
        top = max(r["ranks"] for r in g)
        for r in (r for r in g if r["ranks"] == top and top > 1):
            for k in ("startup", "run"):
                ref = one[scene][f"{k}_peak_rss_mib_max"]
                fixed = overhead[top][k]
                limit = factor * ref + fixed
                value = r[f"{k}_peak_rss_mib_max"]
                net = (value - fixed) / (ref - overhead[1][k])
                ok = value <= limit
                if r["path"] == "distributed" and not ok:  # the old path is shown, not judged
                    status = status or 4
                print(f"{scene} {r['path']:<12}{top} ranks {k:<8}: max {value:7.0f} MiB vs limit "
                      f"{factor} x {ref:.0f} + F({top}) {fixed:.0f} = {limit:7.0f} MiB -> "
                      f"{'holds' if ok else 'FAILS'} (ratio {value / ref:.3f}; less F: {net:.3f})")
    print(f"csv: {sys.argv[2]}")
    sys.exit(status)


if __name__ == "__main__":
    main()

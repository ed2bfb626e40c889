#!/usr/bin/env python3
"""What one contact pair costs in the masonry scenes, as the contact stage evaluates it, against the
kernel of issue 12's start: bench_contact_scene_pairs at chosen instants of the scenes of run.py
(docs/benchmarks.md, "What a pair costs in the scenes").

  benchmarks/contact_slivers/pair_costs.py [--bench build/benchmarks/bench_contact_scene_pairs]
      [--points tower@0.01,tower@0.04,...] [--csv docs/data/bench_contact_scene_pairs.csv]
      [--turns SECONDS]

A point is CASE@TIME (s), CASE one of run.py's cases (tower_full is tower).  Each point prints and
appends one block of rows to the CSV (the file is started afresh): the per-pair cost percentiles
and means of every candidate pair and of the overlapping ones, for the baseline kernel and the
stage's path, and their ratio of means with the stage's per-tet work added.  Run it on an idle
core: each pair is timed alone (best of 3 batches of 8 evaluations).  With --turns, each point
also times the pairs the stage integrates evaluated in turn (bench_contact_scene_pairs --turns):
rows of class integrated_in_turn.
"""
import argparse, importlib.util, os, subprocess, sys, tempfile

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))
spec = importlib.util.spec_from_file_location("contact_slivers_run", os.path.join(here, "run.py"))
slivers = importlib.util.module_from_spec(spec)
spec.loader.exec_module(slivers)

DEFAULT_POINTS = ("tower@0.01,tower@0.04,tower@0.3,tower@0.8,wall_tilt@0.04,arch@0.015,"
                  "dry_wall@0.15,wall55@0.025,pile@0.003")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bench", default=os.path.join(root, "build", "benchmarks",
                                                    "bench_contact_scene_pairs"))
    ap.add_argument("--points", default=DEFAULT_POINTS)
    ap.add_argument("--csv", default=os.path.join(root, "docs", "data",
                                                  "bench_contact_scene_pairs.csv"))
    ap.add_argument("--turns", type=float, default=0.0,
                    help="CPU seconds per point for the integrated pairs in turn (0: not timed)")
    a = ap.parse_args()
    if os.path.exists(a.csv):
        os.remove(a.csv)
    with tempfile.TemporaryDirectory() as workdir:
        for point in a.points.split(","):
            case, at = point.split("@")
            scene, overrides = slivers.case_scene("tower" if case == "tower_full" else case,
                                                  workdir)
            command = [a.bench, scene, at, a.csv, "--label", f"{case}@{at}"]
            if a.turns > 0:
                command += ["--turns", str(a.turns)]
            for o in overrides:
                if not o.startswith("time.end="):  # the benchmark steps to its instant itself
                    command += ["--set", o]
            print(f"== {point}", flush=True)
            subprocess.run(command, check=True)


if __name__ == "__main__":
    sys.exit(main())

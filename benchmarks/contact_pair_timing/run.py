#!/usr/bin/env python3
"""What one contact pair costs as the contact stage runs, friction and dashpot included, at
issue 12's start and now (docs/benchmarks.md, "Each pair timed in the running stage").

  benchmarks/contact_pair_timing/run.py [--start f37b868] [--now decbb23]
      [--workdir /tmp/fdem_pair_timing] [--cases tower,dry_wall,pile,wall55,arch]
      [--repeats 1] [--cpu 0] [--without-friction-and-dashpot]
      [--csv docs/data/contact_pair_timing.csv]
      [--histograms docs/data/contact_pair_timing_histograms.csv]

Each commit is checked out as a git worktree under --workdir, its contact/contact_stage.cpp
patched with start.patch or now.patch (they time every candidate pair from the top of the stage's
pair loop to the end of its body, with pair_timing_probe.hpp), and its `fdem` built (Release).
The probe is not part of the engine's build: main's stage has no timer in its loop. now.patch
fits the commit named by --now's default; after a change to the stage's loop, regenerate it.

Each case runs once per repeat with each binary, alternating, pinned to one core (--cpu), with
FDEM_PAIR_TIMING naming the histogram file. Pairs are classed at each step against the step's
largest pair normal force: "carries load" (at least 1e-6 of it), "overlapping, unloaded", "apart"
(evaluated, no overlap, or left out whole under the sliver tolerance) and "kept apart" (not
evaluated: apart by more than its tets have moved, only now). The probe's own cost (two clock
reads, ~50 ns on this machine) is measured at start and subtracted from every pair.

With --without-friction-and-dashpot every material's contact friction and damping are set to 0
(the trajectories then differ from the default runs): the difference of the means is what
friction and the dashpot cost per pair.

--histograms gets the last repeat's cost histograms of the overlapping pairs (80 bins per decade
from 1 ns), which plot.py draws (docs/contact_pair_costs.png).

Cases: the scenes of benchmarks/contact_slivers/run.py that the start's binary can read (its
reader has no quasi_static key): tower (default example, 0.1 s: the impact at 14 ms), dry_wall
(examples/dry-stone-wall-seismic.yaml, 0.2 s), pile (64 blocks, 4 ms), wall55 (issue 12's dry
wall, 0.03 s), arch (the 20-voussoir arch at 0.13 g, 0.02 s, without quasi_static: dynamic,
potential contact in both).
"""
import argparse, csv, importlib.util, json, math, os, subprocess, sys

import yaml

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))
sys.path.insert(0, os.path.join(root, "benchmarks", "masonry_thresholds"))
_spec = importlib.util.spec_from_file_location(
    "contact_slivers_run", os.path.join(root, "benchmarks", "contact_slivers", "run.py"))
slivers = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(slivers)

CLASSES = ["carries_load", "overlapping_unloaded", "apart", "kept_apart"]


def build(commit, patch, workdir, name):
    """A worktree of `commit` with the probe patched in and its fdem built; returns the binary."""
    tree = os.path.join(workdir, name)
    if not os.path.isdir(tree):
        subprocess.run(["git", "-C", root, "worktree", "add", "-f", "--detach", tree, commit],
                       check=True, stdout=subprocess.DEVNULL)
        subprocess.run(["cp", os.path.join(here, "pair_timing_probe.hpp"),
                        os.path.join(tree, "contact")], check=True)
        subprocess.run(["git", "-C", tree, "apply", os.path.join(here, patch)], check=True)
    return build_fdem(tree)


def build_fdem(tree):
    """`fdem` of a source tree built in TREE/build (Release); returns the binary."""
    build_dir = os.path.join(tree, "build")
    subprocess.run(["cmake", "-S", tree, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release"],
                   check=True, stdout=subprocess.DEVNULL)
    subprocess.run(["cmake", "--build", build_dir, "-j2", "--target", "fdem"], check=True,
                   stdout=subprocess.DEVNULL)
    return os.path.join(build_dir, "drivers", "fdem")


def scene_of(case, workdir):
    """The case's scene path and overrides, readable by both binaries."""
    path, overrides = slivers.case_scene(case, workdir)
    if case in ("arch", "wall_tilt"):  # no quasi_static block and no histories for the start
        with open(path) as f:
            lines = [l for l in f if not l.startswith("quasi_static:") and "histories:" not in l]
        path = os.path.join(workdir, case + "_dynamic.yaml")
        with open(path, "w") as f:
            f.writelines(lines)
    return path, overrides


def without_friction_and_dashpot(scene):
    """Overrides that set every material's contact friction and damping to 0."""
    with open(scene) as f:
        materials = yaml.safe_load(f).get("materials", {})
    out = []
    for name in materials:
        out += [f"materials.{name}.contact.friction=0", f"materials.{name}.contact.damping=0"]
    return out


def read_histograms(path):
    """{class: (count, mean_ns, [(low, high, pairs)])} and the header line."""
    with open(path) as f:
        header = f.readline().strip()
        rows = list(csv.DictReader(f))
    out = {}
    for r in rows:
        c = r["class"]
        entry = out.setdefault(c, [int(r["count"]), float(r["mean_ns"]), []])
        entry[2].append((float(r["bin_low_ns"]), float(r["bin_high_ns"]), float(r["pairs"])))
    return out, header


def quantile(bins, q):
    total = sum(n for _, _, n in bins)
    seen = 0.0
    for low, high, n in bins:
        seen += n
        if seen >= q * total:
            return math.sqrt(low * high)
    return float("nan")


def run_case(fdem, scene, overrides, cpu, outdir, histogram):
    args = ["taskset", "-c", str(cpu), fdem, "run", scene, "-o", outdir, "-q"]
    for o in overrides:
        args += ["--set", o]
    env = dict(os.environ, FDEM_PAIR_TIMING=histogram)
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL, env=env)
    summary = json.load(open(os.path.join(outdir, "summary.json")))
    return summary["steps"], summary["stages"]["contact_forces"]["seconds"]


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--start", default="f37b868")
    p.add_argument("--now", default="decbb23")
    p.add_argument("--workdir", default="/tmp/fdem_pair_timing")
    p.add_argument("--cases", default="tower,dry_wall,pile,wall55,arch")
    p.add_argument("--repeats", type=int, default=1)
    p.add_argument("--cpu", type=int, default=0)
    p.add_argument("--without-friction-and-dashpot", action="store_true")
    p.add_argument("--histograms",
                   default=os.path.join(root, "docs", "data", "contact_pair_timing_histograms.csv"))
    p.add_argument("--csv", default=os.path.join(root, "docs", "data", "contact_pair_timing.csv"))
    a = p.parse_args()
    os.makedirs(a.workdir, exist_ok=True)
    binaries = [("start", build(a.start, "start.patch", a.workdir, "start")),
                ("now", build(a.now, "now.patch", a.workdir, "now"))]
    histograms = open(a.histograms, "w", newline="")
    hw = csv.writer(histograms)
    hw.writerow(["case", "code", "repeat", "class", "bin", "pairs"])
    new_file = not os.path.exists(a.csv)
    out = open(a.csv, "a", newline="")
    w = csv.writer(out)
    if new_file:
        w.writerow(["case", "friction_and_dashpot", "repeat", "code", "commit", "steps", "contact_stage_s", "class",
                    "pairs", "mean_ns", "p10_ns", "p50_ns", "p90_ns", "p99_ns"])
    for case in a.cases.split(","):
        scene, overrides = scene_of(case, a.workdir)
        if a.without_friction_and_dashpot:
            overrides = overrides + without_friction_and_dashpot(scene)
        variant = "off" if a.without_friction_and_dashpot else "scene"
        means = {}
        for rep in range(a.repeats):
            for code, fdem in binaries:
                hist = os.path.join(a.workdir, f"{case}_{code}_{rep}.csv")
                steps, stage = run_case(fdem, scene, overrides, a.cpu,
                                        os.path.join(a.workdir, f"out_{case}_{code}"), hist)
                classes, header = read_histograms(hist)
                print(f"{case} ({code}, repeat {rep + 1}): {steps} steps, contact stage "
                      f"{stage:.3f} s; {header.lstrip('# ')}")
                for c in CLASSES:
                    if c not in classes:
                        continue
                    count, mean, bins = classes[c]
                    qs = [quantile(bins, q) for q in (0.1, 0.5, 0.9, 0.99)]
                    print(f"  {c:22s} {count:11d} pairs  mean {mean:8.1f} ns  p10/p50/p90/p99 "
                          + " / ".join(f"{x:.0f}" for x in qs))
                    w.writerow([case, variant, rep + 1, code, a.start if code == "start" else a.now, steps,
                                f"{stage:.4f}", c, count, f"{mean:.2f}"] + [f"{x:.1f}" for x in qs])
                    key = (code, c)
                    means[key] = min(means.get(key, 1e30), mean)
                if rep == a.repeats - 1:
                    for c in ("carries_load", "overlapping_unloaded"):
                        for low, _, n in classes.get(c, [0, 0, []])[2]:
                            hw.writerow([case, code, rep + 1, c,
                                         round(80 * math.log10(low)), f"{n:.0f}"])
                # Every overlapping pair, loaded or not: the pairs the start's stage integrated.
                both = [classes[c] for c in ("carries_load", "overlapping_unloaded") if c in classes]
                count = sum(e[0] for e in both)
                if count:
                    mean = sum(e[0] * e[1] for e in both) / count
                    bins = sorted(b for e in both for b in e[2])
                    qs = [quantile(bins, q) for q in (0.1, 0.5, 0.9, 0.99)]
                    print(f"  {'overlapping (all)':22s} {count:11d} pairs  mean {mean:8.1f} ns")
                    w.writerow([case, variant, rep + 1, code,
                                a.start if code == "start" else a.now, steps, f"{stage:.4f}",
                                "overlapping_all", count, f"{mean:.2f}"] + [f"{x:.1f}" for x in qs])
                    means[(code, "overlapping_all")] = min(
                        means.get((code, "overlapping_all"), 1e30), mean)
        for c in ("carries_load", "overlapping_unloaded", "overlapping_all"):
            if ("start", c) in means and ("now", c) in means:
                print(f"  {case}: {c}: {means[('start', c)]:.0f} -> {means[('now', c)]:.0f} ns, "
                      f"{means[('start', c)] / means[('now', c)]:.2f}x (best mean of the repeats)")
        out.flush()
        histograms.flush()
    print(f"appended to {a.csv}; histograms in {a.histograms}")


if __name__ == "__main__":
    main()

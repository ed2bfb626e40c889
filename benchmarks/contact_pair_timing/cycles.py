#!/usr/bin/env python3
"""Where the cycles of a contact pair that carries load go, part by part, in the running contact
stage (docs/benchmarks.md, "Where a pair that carries load spends its cycles").

  benchmarks/contact_pair_timing/cycles.py [--commits HEAD[,OTHER...]] [--workdir /tmp/fdem_pair_cycles]
      [--cases dry_wall,tower,wall55] [--cpu 1] [--repeats 2]
      [--csv docs/data/contact_pair_cycles.csv]

Each commit is checked out as a git worktree under --workdir, and time-stamp-counter probes are
written into its contact/contact_stage.cpp and contact/potential_contact.cpp by text edits (below;
they are not part of the engine's build), then its `fdem` is built (Release).  Each case then
runs --repeats times with each commit's binary, the commits alternating, pinned to one core.  For every pair the kernel finds overlapping (those that
carry load and the few that do not), the probes sum the cycles of:

  pair      the stage's whole loop body for the pair (kernel, dashpot, friction, scatter, records)
  kernel    potential_contact, of which
    frame     the pair's frame and its face-plane rejection (prepare_tet_pair),
    bound     the sliver bounds that choose the pieces left out (negligible_parts),
    side c/t  the contactor's and the target's pieces: the sub-tets set up and tested for
              emptiness ("setup"), their clips replayed or made afresh ("clip"), the clip records
              copied ("record") and the pieces integrated, fluxes included ("integrate"),
    forces    the nodal forces, the centroid and the rest of the kernel;
  stage     pair − kernel: friction, dashpot, the scatter to the nodes, the pair's records.

The figures are time-stamp-counter cycles (the counter's rate is measured and printed, so that
they convert to ns) and include the probes' own reads (~14 per pair; the counter read does not
wait for the work before it, so stamps may overlap it by some dozens of cycles): they give the
shares; the running stage's ns per pair come from run.py.  "fresh": pieces clipped afresh rather
than replayed from the step before (clip_replay.hpp).
"""
import argparse, csv, importlib.util, os, re, subprocess, sys

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))
_spec = importlib.util.spec_from_file_location(
    "contact_slivers_run", os.path.join(root, "benchmarks", "contact_slivers", "run.py"))
slivers = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(slivers)
_spec = importlib.util.spec_from_file_location("contact_pair_timing_run",
                                               os.path.join(here, "run.py"))
pair_timing = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(pair_timing)

PROBE_HEADER = r'''
#include <x86intrin.h>
#include <chrono>
#include <cstdio>
namespace fdem_cycles {
struct Sums {
  unsigned long long pair = 0, kernel = 0, frame = 0, bound = 0, forces = 0, pairs = 0;
  unsigned long long setup[2] = {0, 0}, clip[2] = {0, 0}, record[2] = {0, 0}, integrate[2] = {0, 0};
  unsigned long long pieces[2] = {0, 0}, fresh[2] = {0, 0};
  ~Sums() {
    // one counter read, and the counter's rate against the steady clock
    unsigned long long least = ~0ull;
    for (int i = 0; i < 1000; ++i) {
      const unsigned long long a = __rdtsc(), b = __rdtsc();
      if (b - a < least) least = b - a;
    }
    const auto t0 = std::chrono::steady_clock::now();
    const unsigned long long c0 = __rdtsc();
    while (std::chrono::steady_clock::now() - t0 < std::chrono::milliseconds(50)) {}
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double rate = double(__rdtsc() - c0) / seconds;
    const double n = pairs ? double(pairs) : 1.0;
    std::fprintf(stderr,
                 "CYCLES pairs=%llu pair=%.1f kernel=%.1f frame=%.1f bound=%.1f "
                 "setup_c=%.1f clip_c=%.1f record_c=%.1f integrate_c=%.1f pieces_c=%.3f "
                 "setup_t=%.1f clip_t=%.1f record_t=%.1f integrate_t=%.1f pieces_t=%.3f "
                 "fresh_c=%.3f fresh_t=%.3f forces=%.1f read=%llu rate_ghz=%.4f\n",
                 pairs, pair / n, kernel / n, frame / n, bound / n, setup[0] / n, clip[0] / n,
                 record[0] / n, integrate[0] / n, pieces[0] / n, setup[1] / n, clip[1] / n,
                 record[1] / n, integrate[1] / n, pieces[1] / n, fresh[0] / n, fresh[1] / n, forces / n,
                 least, rate * 1e-9);
  }
};
inline Sums sums;
// The current pair's stamps, summed into `sums` when it turns out overlapping.
struct Pair {
  unsigned long long start = 0, kernel_start = 0, kernel_end = 0, frame_end = 0, bound_end = 0,
                     sides_end = 0;
  unsigned long long setup[2] = {0, 0}, clip[2] = {0, 0}, record[2] = {0, 0}, integrate[2] = {0, 0};
  unsigned long long pieces[2] = {0, 0}, fresh[2] = {0, 0};
};
inline Pair now;
}  // namespace fdem_cycles
'''


def edit(path, replacements):
    with open(path) as f:
        text = f.read()
    for old, new in replacements:
        if old not in text:
            raise SystemExit(f"cycles.py: the probe does not fit {path} (looked for: {old[:60]!r})")
        text = text.replace(old, new, 1)
    with open(path, "w") as f:
        f.write(text)


def add_probes(tree):
    with open(os.path.join(tree, "contact", "cycles_probe.hpp"), "w") as f:
        f.write("#pragma once\n" + PROBE_HEADER)
    edit(os.path.join(tree, "contact", "contact_stage.cpp"), [
        ('#include "contact/clip_replay.hpp"\n',
         '#include "contact/clip_replay.hpp"\n#include "contact/cycles_probe.hpp"\n'),
        ('    std::uint32_t clip_read_at = kNoClipRecord;',
         '    fdem_cycles::now = fdem_cycles::Pair{};\n'
         '    fdem_cycles::now.start = __rdtsc();\n'
         '    struct End { bool overlapping = false; ~End() { if (!overlapping) return;\n'
         '      using namespace fdem_cycles; const Pair& p = now; Sums& s = sums;\n'
         '      s.pair += __rdtsc() - p.start; s.kernel += p.kernel_end - p.kernel_start;\n'
         '      s.frame += p.frame_end - p.kernel_start; s.bound += p.bound_end - p.frame_end;\n'
         '      unsigned long long sides = 0;\n'
         '      for (int k = 0; k < 2; ++k) { s.setup[k] += p.setup[k]; s.clip[k] += p.clip[k];\n'
         '        s.record[k] += p.record[k]; s.integrate[k] += p.integrate[k]; s.pieces[k] += p.pieces[k];\n'
         '        s.fresh[k] += p.fresh[k];\n'
         '        sides += p.setup[k] + p.clip[k] + p.record[k] + p.integrate[k]; }\n'
         '      s.forces += (p.kernel_end - p.bound_end) - sides; ++s.pairs; } } end_;\n'
         '    std::uint32_t clip_read_at = kNoClipRecord;'),
        ('    const ContactPairResult r =\n        corners_',
         '    fdem_cycles::now.kernel_start = __rdtsc();\n'
         '    const ContactPairResult r =\n        corners_'),
        ('    if (clip_replay_) {\n      const std::size_t length',
         '    fdem_cycles::now.kernel_end = __rdtsc();\n'
         '    end_.overlapping = r.overlapping && !corners_;\n'
         '    if (clip_replay_) {\n      const std::size_t length'),
    ])
    edit(os.path.join(tree, "contact", "potential_contact.cpp"), [
        ('#include "contact/clip_replay.hpp"\n',
         '#include "contact/clip_replay.hpp"\n#include "contact/cycles_probe.hpp"\n'),
        ('  Piece piece;\n  for (int i = 0; i < 4; ++i) {',
         '  Piece piece;\n  unsigned long long stamp = __rdtsc();\n'
         '  const auto lap = [&](unsigned long long (&sum)[2]) {\n'
         '    const unsigned long long t = __rdtsc(); sum[own] += t - stamp; stamp = t; };\n'
         '  struct Last { decltype(lap)& f; ~Last() { f(fdem_cycles::now.setup); } } last_{lap};\n'
         '  for (int i = 0; i < 4; ++i) {'),
        ('    const std::uint8_t* entry = memo ? find_recorded_piece',
         '    lap(fdem_cycles::now.setup); ++fdem_cycles::now.pieces[own];\n'
         '    const std::uint8_t* entry = memo ? find_recorded_piece'),
        ('    bool alive = replay == Replay::kept;\n',
         '    lap(fdem_cycles::now.clip);\n    bool alive = replay == Replay::kept;\n'),
        ('      ClipLog log;\n',
         '      ClipLog log;\n      const unsigned long long clip_from = __rdtsc();\n'),
        ('      if (memo) ++memo->clipped;\n',
         '      if (memo) ++memo->clipped;\n      ++fdem_cycles::now.fresh[own];\n'
         '      { const unsigned long long t = __rdtsc(); fdem_cycles::now.clip[own] += t - clip_from;\n'
         '        fdem_cycles::now.record[own] -= t - clip_from; }\n'),
        ('    if (walked) {  // (alive but not walked',
         '    lap(fdem_cycles::now.record);\n    if (walked) {  // (alive but not walked'),
        ('        integrate_piece<4>(vertex, n_vertices, faces, i, area_weight, side_weight, slots, out);\n    }\n',
         '        integrate_piece<4>(vertex, n_vertices, faces, i, area_weight, side_weight, slots, out);\n'
         '    }\n    lap(fdem_cycles::now.integrate);\n'),
        ('  const unsigned left_out =',
         '  fdem_cycles::now.frame_end = __rdtsc();\n  const unsigned left_out ='),
        ('  if (left_out == kEveryPiece) return zero_result();',
         '  if (left_out == kEveryPiece) return zero_result();\n'
         '  fdem_cycles::now.bound_end = __rdtsc();'),
    ])


def build(commit, workdir):
    tree = os.path.join(workdir, "tree_" + commit)
    if os.path.isdir(tree):  # the probes as this script writes them now; the build is kept
        subprocess.run(["git", "-C", tree, "checkout", "-q", "--", "contact"], check=True)
    else:
        subprocess.run(["git", "-C", root, "worktree", "add", "-f", "--detach", tree, commit],
                       check=True, stdout=subprocess.DEVNULL)
    add_probes(tree)
    return pair_timing.build_fdem(tree)


def run_case(fdem, case, workdir, cpu):
    scene, overrides = slivers.case_scene(case, workdir)
    args = ["taskset", "-c", str(cpu), fdem, "run", scene, "-o",
            os.path.join(workdir, "out_" + case), "-q"]
    for o in overrides:
        args += ["--set", o]
    done = subprocess.run(args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                          text=True)
    line = [l for l in done.stderr.splitlines() if l.startswith("CYCLES ")]
    if not line:
        raise SystemExit(f"cycles.py: {case} printed no CYCLES line")
    return {k: float(v) for k, v in re.findall(r"(\w+)=([0-9.]+)", line[-1])}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--commits", default="HEAD", help="comma-separated; the first is the reference")
    ap.add_argument("--workdir", default="/tmp/fdem_pair_cycles")
    ap.add_argument("--cases", default="dry_wall,tower,wall55")
    ap.add_argument("--cpu", type=int, default=1)
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--csv", default=os.path.join(root, "docs", "data", "contact_pair_cycles.csv"))
    a = ap.parse_args()
    os.makedirs(a.workdir, exist_ok=True)
    commits = [subprocess.run(["git", "-C", root, "rev-parse", "--short", c], check=True,
                              capture_output=True, text=True).stdout.strip()
               for c in a.commits.split(",")]
    binaries = {commit: build(commit, a.workdir) for commit in commits}
    rows = []
    for case in a.cases.split(","):
        for repeat in range(a.repeats):
            for commit in commits:
                r = run_case(binaries[commit], case, a.workdir, a.cpu)
                r.update(case=case, repeat=repeat + 1, commit=commit)
                rows.append(r)
                c = r["pair"]
                print(f"{case} #{repeat + 1} {commit}: {int(r['pairs'])} overlapping pair-steps, "
                      f"{c:.0f} cycles per pair ({c / r['rate_ghz']:.0f} ns): kernel "
                      f"{r['kernel'] / c:.0%} (frame {r['frame'] / c:.0%}, bound {r['bound'] / c:.0%}, "
                      f"setup {(r['setup_c'] + r['setup_t']) / c:.0%}, "
                      f"clip {(r['clip_c'] + r['clip_t']) / c:.0%}, "
                      f"record {(r['record_c'] + r['record_t']) / c:.0%}, "
                      f"integrate {(r['integrate_c'] + r['integrate_t']) / c:.0%}, "
                      f"forces {r['forces'] / c:.0%}), stage {(c - r['kernel']) / c:.0%}; "
                      f"{r['pieces_c'] + r['pieces_t']:.2f} pieces per pair, "
                      f"{r['fresh_c'] + r['fresh_t']:.2f} clipped afresh", flush=True)
    if len(commits) > 1:  # the least cycles per pair of each commit, against the first
        for case in a.cases.split(","):
            least = {c: min(r["pair"] for r in rows if r["case"] == case and r["commit"] == c)
                     for c in commits}
            print(f"{case}: " + ", ".join(f"{c} {least[c]:.0f} ({least[commits[0]] / least[c]:.3f}x)"
                                          for c in commits))
    keys = ["case", "repeat", "commit", "pairs", "pair", "kernel", "frame", "bound", "setup_c",
            "clip_c", "record_c", "integrate_c", "pieces_c", "setup_t", "clip_t", "record_t",
            "integrate_t", "pieces_t", "fresh_c", "fresh_t", "forces", "read", "rate_ghz"]
    os.makedirs(os.path.dirname(a.csv), exist_ok=True)
    with open(a.csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {a.csv}")


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Cost model of fdem's step on P ranks, fed with figures measured by scripts/cost-model-measure.sh.

  python3 scripts/cost-model.py [MEASURED_DIR] [--alpha S] [--beta B/S] [--alpha-coll S]
        [--active-halo F] [--redistribution-every STEPS] [--redistribution-collectives N]
        [--gather-scaling ranks|model] [--csv FILE]

MEASURED on this machine (MEASURED_DIR, default out/cost-model):
  t_tet      seconds per tet-step on 1 rank, all stages but output (summary.json "stages")
  halo       ghost nodes, halo tets and neighbours of the busiest of 4 ranks ("decomposition")
  bytes      halo bytes received per step and per ghost node, blocking collectives per step, and
             per redistribution the bytes of gather-type calls (Allgather(v): every rank receives
             what every other rank sends) and of Alltoall(v) (migration) and the count of
             collectives (PMPI interposer, rank<R>.json, busiest rank)
  redist.    redistributions per step (wall: after each contact detection)
  mpi        MPI_Allreduce and ping-pong on 2 ranks here (reported; too noisy on a shared 2-core
             machine to stand for a cluster network)
MODELLED (parameters, defaults = typical InfiniBand HDR100/EDR cluster):
  --alpha       point-to-point latency per message (1.5e-6 s)
  --beta        point-to-point bandwidth per rank (10e9 B/s)
  --alpha-coll  per tree level of a small collective: Allreduce = alpha_coll * ceil(log2 P)
                (2e-6 s: ~20 us at 1024 ranks); Alltoall(v) of small blocks = alpha * P
  --active-halo fraction of the held halo tets a rank computes as well as their owner (0.5), used
                only when summary.json has no "active_elements_max" (measured: active tets of the
                busiest rank less N/4 is the redundant work, scaled like the halo)
Step on P ranks, n = N/P tets per rank (no overlap of communication with computation assumed;
fdem overlaps the halo with interior tets, so the halo term is an upper bound):
  T = t_tet * (n + redundant(n)) + m * alpha + bytes(n) / beta + c * allreduce(P) + r * R(P)
  halo(n), ghosts(n) = 4-rank figure * (n / n4)^(2/3) * faces(P) / faces(4) (block: 3-D grid of
  parts; wall, one stone thick: a 2-D grid, exponent 1/2); m = neighbours (26 in 3-D, 8 in 2-D
  beyond 4 ranks); R(P) = redistribution: (collectives + non-blocking barriers) * allreduce(P) +
  alltoalls * alpha * P + messages (scaled to the neighbours) * alpha + gather bytes scaled with
  P (--gather-scaling model: with N - n) / beta + rows moved scaled with the halo / beta.
Strong: E = N t_tet / (P T(N/P)); weak (n fixed = the target model / 1024): E = t_tet n / T(n).
"""
import argparse
import csv
import glob
import json
import math
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def load_json(path):
    with open(path) as f:
        return json.load(f)


def per_tet_step(summary):
    s = summary["stages"]
    seconds = sum(v["seconds"] for k, v in s.items() if k != "output")
    return seconds / (summary["steps"] * summary["elements"])


def budget(run_dir):
    """Busiest rank's step and redistribution figures from the interposer's rank<R>.json."""
    ranks = [load_json(p)["phases"] for p in glob.glob(os.path.join(run_dir + ".budget", "rank*.json"))]
    if not ranks:
        sys.exit(f"cost-model.py: no interposer output in {run_dir}.budget")
    step = max((r["step"] for r in ranks), key=lambda p: p["bytes_received"])
    red = max((r.get("redistribution", {}) for r in ranks), key=lambda p: p.get("bytes_received", 0))
    calls = red.get("by_call", {})
    pick = lambda names, key: sum(calls.get(n, {}).get(key, 0) for n in names)
    halo_bytes = step["by_call"].get("MPI_Irecv", {}).get("bytes", 0)
    return {
        "halo_bytes": halo_bytes, "p2p_messages": step["p2p_messages"],
        "collectives": step["blocking_collectives"],
        "red_gather_bytes": pick(["MPI_Allgather", "MPI_Allgatherv"], "bytes"),
        # rows moved: all-to-all (before neighbour-only exchanges) or point-to-point (after)
        "red_alltoall_bytes": pick(["MPI_Alltoall", "MPI_Alltoallv", "MPI_Recv", "MPI_Irecv"],
                                   "bytes"),
        "red_alltoalls": pick(["MPI_Alltoall", "MPI_Alltoallv"], "calls"),
        "red_messages": red.get("p2p_messages", 0),
        "red_ibarriers": pick(["MPI_Ibarrier"], "calls"),
        "red_collectives": red.get("blocking_collectives", 0),
    }


def measured(d):
    m = {}
    for scene in ("block", "wall"):
        one = load_json(os.path.join(d, f"{scene}-n1", "summary.json"))
        four = load_json(os.path.join(d, f"{scene}-n4", "summary.json"))
        b = budget(os.path.join(d, f"{scene}-n4"))
        dec, steps = four["decomposition"], four["steps"]
        redistributions = four["stages"].get("redistribution", {}).get("calls", 0)
        r = max(redistributions, 1)
        m[scene] = {
            "t_tet": per_tet_step(one), "tets_1": one["elements"], "n4": four["elements"] / 4,
            "halo4": dec["halo_elements_max"], "ghosts4": dec["ghost_nodes_max"],
            # tets computed by the busiest rank that it does not own (both ranks compute them)
            "redundant4": dec.get("active_elements_max", 0) - four["elements"] / 4,
            "neighbours4": dec["neighbours_max"],
            "bytes_per_ghost": b["halo_bytes"] / steps / dec["ghost_nodes_max"],
            "messages_per_step": b["p2p_messages"] / steps,
            "collectives_per_step": b["collectives"] / steps,
            "redistributions_per_step": redistributions / steps,
            "red_gather_bytes": b["red_gather_bytes"] / r,
            "red_alltoall_bytes": b["red_alltoall_bytes"] / r,
            "red_alltoalls": b["red_alltoalls"] / r,
            "red_messages": b["red_messages"] / r,
            "red_ibarriers": b["red_ibarriers"] / r,
            "red_collectives": b["red_collectives"] / r,
            "N4": four["elements"],
        }
    mpi = {}
    with open(os.path.join(d, "mpi_latency.csv")) as f:
        for row in csv.DictReader(f):
            mpi[(row["kind"], int(row["bytes"]))] = float(row["seconds"])
    return m, mpi


def grid(p, dims):
    """Most even factorisation of p into dims factors."""
    f, q, x = [], p, 2
    while x * x <= q:
        while q % x == 0:
            f.append(x)
            q //= x
        x += 1
    if q > 1:
        f.append(q)
    bins = [1] * dims
    for x in sorted(f, reverse=True):
        bins[bins.index(min(bins))] *= x
    return bins


def faces(p, dims):  # cut faces of the busiest part in a grid of parts
    return sum(2 if g >= 3 else 1 if g == 2 else 0 for g in grid(p, dims))


def step_time(m, dims, p, n, N, a):
    """Seconds per step on p ranks with n tets per rank (model of N tets) and its terms."""
    if p == 1:
        return {"compute": m["t_tet"] * n, "halo": 0.0, "allreduce": 0.0, "redistribution": 0.0}
    shape = (n / m["n4"]) ** ((dims - 1) / dims) * faces(p, dims) / faces(4, dims)
    halo, ghosts = m["halo4"] * shape, m["ghosts4"] * shape
    messages = m["neighbours4"] if p <= 4 else (26 if dims == 3 else 8)
    allreduce = a.alpha_coll * math.ceil(math.log2(p))
    redundant = m["redundant4"] * shape if m["redundant4"] > 0 else a.active_halo * halo
    t = {"compute": m["t_tet"] * (n + redundant)}
    t["halo"] = messages * a.alpha + ghosts * m["bytes_per_ghost"] / a.beta
    t["allreduce"] = m["collectives_per_step"] * allreduce
    # Collectives and the neighbour-only exchanges' non-blocking barriers at a tree's depth;
    # all-to-alls at alpha * P; point-to-point messages with the neighbours; gathered bytes
    # (O(P) numbers per rank since the re-partition runs on each rank's own tets, or whole-model
    # before: --gather-scaling) and rows moved, which scale with a part's surface.
    gathered = ((p - 1) / 3 if a.gather_scaling == "ranks" else (N - n) / (m["N4"] * 3 / 4))
    messages_red = m["red_messages"] * (1 if p <= 4 else (26 if dims == 3 else 8) / m["neighbours4"])
    red = ((m["red_collectives"] + m["red_ibarriers"]) * allreduce
           + m["red_alltoalls"] * a.alpha * p + messages_red * a.alpha
           + m["red_gather_bytes"] * gathered / a.beta
           + m["red_alltoall_bytes"] * shape / a.beta)
    t["redistribution"] = m["redistributions_per_step"] * red
    return t


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("measured", nargs="?", default=os.path.join(ROOT, "out", "cost-model"))
    ap.add_argument("--alpha", type=float, default=1.5e-6)
    ap.add_argument("--beta", type=float, default=10e9)
    ap.add_argument("--alpha-coll", type=float, default=2e-6)
    ap.add_argument("--active-halo", type=float, default=0.5)
    ap.add_argument("--redistribution-every", type=float, default=0,
                    help="wall: one redistribution every this many steps instead of the measured "
                         "rate (a settling wall detects rarely; a shaken one every few tens of steps)")
    ap.add_argument("--redistribution-collectives", type=float, default=None,
                    help="wall: blocking collectives per redistribution instead of the measured "
                         "figure (e.g. a re-partition at every cycle: Zoltan's RIB adds ~60)")
    ap.add_argument("--gather-scaling", choices=["ranks", "model"], default="ranks",
                    help="how the bytes gathered at a redistribution grow: with the rank count "
                         "(O(P) numbers per rank, the code since the re-partition runs on each "
                         "rank's own tets) or with the whole model (the centroid gather before)")
    ap.add_argument("--csv", help="write the predictions here")
    a = ap.parse_args()
    m, mpi = measured(a.measured)
    if a.redistribution_every > 0:
        m["wall"]["redistributions_per_step"] = 1.0 / a.redistribution_every
    if a.redistribution_collectives is not None:
        m["wall"]["red_collectives"] = a.redistribution_collectives

    print("MEASURED here (1 rank; busiest of 4 ranks under the PMPI interposer):")
    for scene, x in m.items():
        print(f"  {scene}: {1e9 * x['t_tet']:.1f} ns per tet-step ({x['tets_1']} tets); 4 ranks "
              f"({x['N4']:.0f} tets): halo {x['halo4']} tets, {x['ghosts4']} ghost nodes, "
              f"{x['neighbours4']} neighbours, {x['redundant4']:.0f} tets computed twice, "
              f"{x['bytes_per_ghost']:.1f} B per ghost node-step, "
              f"{x['messages_per_step']:.2f} messages and {x['collectives_per_step']:.2f} blocking "
              f"collectives per step, {x['redistributions_per_step']:.4f} redistributions per step "
              f"({x['red_collectives']:.0f} collectives, {x['red_alltoalls']:.0f} all-to-alls, "
              f"{x['red_ibarriers']:.0f} non-blocking barriers, {x['red_messages']:.0f} messages, "
              f"{x['red_gather_bytes']:.0f} B gathered, {x['red_alltoall_bytes']:.0f} B moved each)")
    for (kind, size), s in sorted(mpi.items()):
        print(f"  mpi {kind} {size} B: {1e6 * s:.2f} us (2 ranks, shared machine)")
    print(f"MODELLED cluster: alpha {a.alpha * 1e6:.1f} us, beta {a.beta / 1e9:.0f} GB/s, allreduce "
          f"{a.alpha_coll * 1e6:.1f} us x log2 P; "
          "compute at this machine's measured speed")

    cases = [("block", 3, 1e8), ("wall", 2, 1e7)]
    rows = []
    for scene, dims, N in cases:
        for mode in ("strong", "weak"):
            for p in (16, 128, 1024):
                n = N / p if mode == "strong" else N / 1024
                model_n = n * p
                t = step_time(m[scene], dims, p, n, model_n, a)
                total = sum(t.values())
                eff = m[scene]["t_tet"] * n / total
                over = {k: v for k, v in t.items() if k != "compute"}
                over["redundant halo work"] = t["compute"] - m[scene]["t_tet"] * n
                first = max(over, key=over.get)
                rows.append({"scene": scene, "mode": mode, "ranks": p, "model_tets": model_n,
                             "tets_per_rank": n, "ms_per_step": 1e3 * total,
                             **{f"{k}_ms": 1e3 * v for k, v in t.items()},
                             "efficiency": eff, "largest_overhead": first})
    print(f"\n{'scene':<6}{'mode':<7}{'ranks':>6}{'model tets':>12}{'tets/rank':>11}{'ms/step':>9}"
          f"{'compute':>9}{'halo':>8}{'allred.':>8}{'redist.':>8}{'eff.':>7}  largest overhead")
    for r in rows:
        print(f"{r['scene']:<6}{r['mode']:<7}{r['ranks']:>6}{r['model_tets']:>12.3g}"
              f"{r['tets_per_rank']:>11.0f}{r['ms_per_step']:>9.3f}{r['compute_ms']:>9.3f}"
              f"{r['halo_ms']:>8.3f}{r['allreduce_ms']:>8.3f}{r['redistribution_ms']:>8.3f}"
              f"{r['efficiency']:>7.3f}  {r['largest_overhead']}")
    if a.csv:
        with open(a.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)


if __name__ == "__main__":
    main()

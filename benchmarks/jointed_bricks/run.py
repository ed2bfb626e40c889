#!/usr/bin/env python3
"""Jointed bricks apart and in contact, three contact algorithms in the same run, alternating, on
one core: `original` (every tet in contact, pairs narrowed by face planes), `enclosed` (enclosed
tets left out, contact.skip_enclosed) and `exact` (also narrowed by the tets' exact distance,
contact.narrowing: exact — the default).

  benchmarks/jointed_bricks/run.py [--fdem build/drivers/fdem] [--repeats 2] [--scale 1]
                                   [--variants original,enclosed,exact]
                                   [--baseline OLD_FDEM]
                                   [--csv docs/data/bench_jointed_bricks.csv]

--baseline runs every variant also with another fdem binary, alternating with this one, and
labels its rows `baseline:VARIANT`: the previous code of the same algorithm, e.g. built from an
earlier commit with
  git worktree add /tmp/fdem-base COMMIT && cmake -S /tmp/fdem-base -B /tmp/fdem-base/build \
    -DCMAKE_BUILD_TYPE=Release && cmake --build /tmp/fdem-base/build -j2 --target fdem

Prints per case the user CPU seconds (best of the repeats), tet-steps per CPU second, the
contact- and joint-forces stages' shares, peak RSS and its bytes per tet, the speed-up against
the first variant, and the state_hash (equal for all variants when no left-out pair can
overlap).  Release build; time is CPU time of the process (/usr/bin/time), so other load on the
machine counts only through caches.
"""
import argparse, csv, json, os, subprocess, sys, tempfile

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))


VARIANTS = {"original": {"SKIP": "false", "NARROWING": "face_planes"},
            "enclosed": {"SKIP": "true", "NARROWING": "face_planes"},
            "exact": {"SKIP": "true", "NARROWING": "exact"}}


def scene(case, variant, scale):
    nl, nu = 16 * scale, 8 * scale
    lx = 0.1 * nl
    ua, ub = 0.25 * lx, 0.25 * lx + 0.1 * nu
    z0 = 0.6005 if case == "contact" else 5.0
    text = open(os.path.join(here, "bricks.yaml.in")).read()
    for key, value in {"GAP": str(z0 - 0.6), "LX": repr(lx), "NL": str(nl), "NU": str(nu),
                       "UA": repr(ua), "UB": repr(ub), "Z0": repr(z0), "Z1": repr(z0 + 0.6),
                       **VARIANTS[variant]}.items():
        text = text.replace("@" + key + "@", value)
    return text


def run(fdem, case, variant, scale, work):
    variant = variant.split(":")[-1]
    path = os.path.join(work, f"{case}-{variant}.yaml")
    with open(path, "w") as f:
        f.write(scene(case, variant, scale))
    out = os.path.join(work, f"out-{case}-{variant}")
    timed = subprocess.run(["/usr/bin/time", "-f", "%U %M", fdem, "run", path, "-o", out, "-q"],
                           capture_output=True, text=True, check=True)
    user, rss_kib = timed.stderr.strip().splitlines()[-1].split()
    summary = json.load(open(os.path.join(out, "summary.json")))
    stages = summary["stages"]
    total = sum(s["seconds"] for s in stages.values())
    return {"user_s": float(user), "rss_kib": int(rss_kib), "tets": summary["elements"],
            "joints": summary["joints"], "steps": summary["steps"],
            "contact_share": stages["contact_forces"]["seconds"] / total,
            "joint_share": stages["joint_forces"]["seconds"] / total,
            "hash": summary["state_hash"]}


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--fdem", default=os.path.join(root, "build", "drivers", "fdem"))
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--scale", type=int, default=1)
    parser.add_argument("--variants", default="original,enclosed,exact")
    parser.add_argument("--baseline", help="another fdem binary to run alternately")
    parser.add_argument("--csv", default=os.path.join(root, "docs", "data",
                                                      "bench_jointed_bricks.csv"))
    args = parser.parse_args()
    variants = args.variants.split(",")
    for v in variants:
        if v not in VARIANTS:
            sys.exit(f"unknown variant '{v}'; valid: {', '.join(VARIANTS)}")
    if args.baseline:
        variants = [w for v in variants for w in ("baseline:" + v, v)]
    binary = {v: args.baseline if v.startswith("baseline:") else args.fdem for v in variants}
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for case in ("apart", "contact"):
            best = {}
            for _ in range(args.repeats):
                for v in variants:  # alternating: all see the same machine load
                    r = run(binary[v], case, v, args.scale, work)
                    if v not in best or r["user_s"] < best[v]["user_s"]:
                        best[v] = r
            for v in variants:
                r = best[v]
                rate = r["tets"] * r["steps"] / r["user_s"]
                rows.append({"case": case, "variant": v, "tets": r["tets"],
                             "joints": r["joints"], "steps": r["steps"],
                             "cpu_seconds": r["user_s"], "tet_steps_per_cpu_second": rate,
                             "contact_forces_share": round(r["contact_share"], 4),
                             "joint_forces_share": round(r["joint_share"], 4),
                             "peak_rss_kib": r["rss_kib"],
                             "bytes_per_tet": round(1024 * r["rss_kib"] / r["tets"]),
                             "speedup": round(best[variants[0]]["user_s"] / r["user_s"], 3),
                             "state_hash": r["hash"]})
    print(f"{'case':8} {'variant':17} {'tets':>8} {'CPU s':>7} {'tet-steps/s':>12} {'contact':>8} "
          f"{'joints':>7} {'RSS MiB':>8} {'B/tet':>6} {'speed-up':>8}  state_hash")
    for r in rows:
        print(f"{r['case']:8} {r['variant']:17} {r['tets']:8d} {r['cpu_seconds']:7.2f} "
              f"{r['tet_steps_per_cpu_second']:12.3e} {100 * r['contact_forces_share']:7.1f}% "
              f"{100 * r['joint_forces_share']:6.1f}% {r['peak_rss_kib'] / 1024:8.1f} "
              f"{r['bytes_per_tet']:6d} {r['speedup']:8.2f}  {r['state_hash']}")
    os.makedirs(os.path.dirname(args.csv), exist_ok=True)
    with open(args.csv, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    print("wrote", args.csv)


if __name__ == "__main__":
    sys.exit(main())

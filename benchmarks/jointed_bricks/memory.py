#!/usr/bin/env python3
"""Peak memory per tet of the jointed bricks apart (the scene of run.py, `exact` variant) at 10^5
and 10^6 tets on one rank, against a baseline binary in the same invocation; with --kind contact
or elastic, of the same bricks without joints (contact only) or of the lower brick alone (elastic
only).

  benchmarks/jointed_bricks/memory.py [--fdem build/drivers/fdem] [--baseline OLD_FDEM]
                                      [--scales 3,10] [--steps 40] [--kind jointed]
                                      [--csv docs/data/jointed_bricks_memory.csv]

Each run takes STEPS steps of the scene with a frame at the start and one at the end (the
default output), and reports from its summary.json the peak RSS of the start-up (model built,
stages set up) and of the step loop, and the process's peak RSS: the larger of the start-up's and
of /usr/bin/time's %M, which counts from the reset of the peak after start-up.  Bytes per
tet are given two ways: the run's peak over the tets, and the marginal figure, (peak − the peak of
the same scene at 30 tets) over the tets — the libraries' fixed ~37 MB (MPI, VTK, HDF5) left out,
which is what a larger model on a rank pays.  The state_hash of the two binaries must agree.
"""
import argparse, csv, json, os, subprocess, sys, tempfile

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))
sys.path.insert(0, here)
import run as bricks  # noqa: E402  (the scene of run.py)


def scene_text(scale, steps, kind="jointed"):
    """kind: jointed (the bricks apart, joints on every internal face), contact (the same bricks
    without joints, the upper one landing on the lower: contact only) or elastic (the lower brick
    alone without joints: no contact stage, no joints)."""
    text = bricks.scene("contact" if kind == "contact" else "apart", "exact", scale)
    text = text.replace("end: 5.0e-4", f"end: {steps * 5.0e-7!r}")
    if kind != "jointed":
        text = text.replace("    joints: all\n", "")
    if kind == "elastic":
        text = text[:text.index("  - name: upper")] + text[text.index("contact: {skip"):]
    return text


def tiny_text(steps, kind="jointed"):
    text = scene_text(1, steps, kind)
    return text.replace("cells: [16, 16, 6]", "cells: [2, 2, 1]").replace(
        "cells: [8, 8, 6]", "cells: [1, 1, 1]")


def measure(fdem, text, work, label):
    path = os.path.join(work, label + ".yaml")
    with open(path, "w") as f:
        f.write(text)
    out = os.path.join(work, "out-" + label)
    timed = subprocess.run(["/usr/bin/time", "-f", "%U %M", fdem, "run", path, "-o", out, "-q"],
                           capture_output=True, text=True, check=True)
    user, rss_kib = timed.stderr.strip().splitlines()[-1].split()
    summary = json.load(open(os.path.join(out, "summary.json")))
    memory = summary["memory"]
    # fdem restarts the peak count after start-up (to report the step loop's own), which resets
    # the process's maximum RSS too: the process's peak is the larger of the two.
    peak_kib = max(int(rss_kib), memory["startup_peak_rss_kib_max"])
    return {"tets": summary["elements"], "user_s": float(user), "rss_kib": peak_kib,
            "startup_kib": memory["startup_peak_rss_kib_max"],
            "run_kib": memory["run_peak_rss_kib_max"], "state_hash": summary["state_hash"]}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fdem", default=os.path.join(root, "build", "drivers", "fdem"))
    p.add_argument("--baseline")
    p.add_argument("--scales", default="3,10")
    p.add_argument("--steps", type=int, default=40)
    p.add_argument("--kind", default="jointed", choices=["jointed", "contact", "elastic"],
                   help="the jointed bricks apart (default), the bricks without joints in "
                        "contact, or the lower brick alone without joints (elastic only)")
    p.add_argument("--csv", default=os.path.join(root, "docs", "data", "jointed_bricks_memory.csv"))
    args = p.parse_args()
    binaries = [("now", args.fdem)] + ([("baseline", args.baseline)] if args.baseline else [])
    rows = []
    with tempfile.TemporaryDirectory() as work:
        fixed = {name: measure(fdem, tiny_text(args.steps, args.kind), work,
                               f"tiny-{name}")["rss_kib"] for name, fdem in binaries}
        for scale in [int(s) for s in args.scales.split(",")]:
            for name, fdem in binaries:
                r = measure(fdem, scene_text(scale, args.steps, args.kind), work,
                            f"s{scale}-{name}")
                r.update(binary=name, kind=args.kind, scale=scale, fixed_kib=fixed[name],
                         bytes_per_tet=round(1024 * r["rss_kib"] / r["tets"]),
                         marginal_bytes_per_tet=round(1024 * (r["rss_kib"] - fixed[name]) /
                                                      r["tets"]),
                         startup_bytes_per_tet=round(1024 * r["startup_kib"] / r["tets"]))
                rows.append(r)
                print(f"{name:9s} {r['tets']:>9,} tets  peak {r['rss_kib'] / 1024:8.1f} MiB "
                      f"({r['bytes_per_tet']:5d} B/tet, marginal {r['marginal_bytes_per_tet']:5d}; "
                      f"start-up {r['startup_bytes_per_tet']:5d} B/tet)  {r['user_s']:6.2f} s  "
                      f"{r['state_hash']}", flush=True)
    status = 0
    for scale in {r["scale"] for r in rows}:
        if len({r["state_hash"] for r in rows if r["scale"] == scale}) != 1:
            print(f"state_hash differs between the binaries at scale {scale}")
            status = 3
    keys = ["binary", "kind", "scale", "tets", "user_s", "rss_kib", "startup_kib", "run_kib",
            "fixed_kib",
            "bytes_per_tet", "marginal_bytes_per_tet", "startup_bytes_per_tet", "state_hash"]
    with open(args.csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    print("wrote", args.csv)
    return status


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Plots an fdem output directory: energy terms, the energy balance error and histories.csv.

    python3 scripts/plot.py OUT [--format png] [--dpi 120]

Writes PNGs next to the CSVs in OUT (Debian: python3-matplotlib, installed by
scripts/install-deps.sh):

  energy.png                   every energy.csv term (J) against time
  balance.png                  energy.csv balance_error against time
  histories_load_NAME.png      a load's reaction (N) and mean displacement (mm) against time, and
                               its force-displacement curve along the direction it moved most
  histories_body_NAME.png      a body's mean displacement and resultant force against time
  histories_monitor_NAME.png   a monitor's displacement, velocity and stress against time
  stress_strain_NAME.png       with --specimen NAME AREA LENGTH: load NAME's reaction over AREA
                               (m²) against its displacement over LENGTH (m), along the direction
                               it moved most (a compression test's stress-strain curve); --line
                               LABEL=MPA draws a reference stress on it (repeatable)

Files that are missing are skipped; exit code 2 when OUT holds none of the CSVs.
"""
import argparse
import csv
import os
import sys

ENERGY_TERMS = ["kinetic", "strain", "gravity", "contact", "joint", "dissipated_fracture",
                "dissipated_friction", "dissipated_damping", "external_work", "total"]


def read_csv(path):
    """Columns of a CSV file with a header, as {name: [float]}, in header order."""
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = next(reader, None)
        if header is None:
            return {}
        columns = {name: [] for name in header}
        for row in reader:
            if len(row) != len(header):
                continue  # a row cut short by a run that stopped while writing it
            for name, cell in zip(header, row):
                columns[name].append(float(cell))
    return columns


def time_axis(t):
    """Time in the unit that suits the run's length: (values, label)."""
    end = max((abs(v) for v in t), default=0.0)
    for scale, unit in ((1.0, "s"), (1e-3, "ms"), (1e-6, "µs")):
        if end >= 10 * scale or scale == 1e-6:
            return [v / scale for v in t], f"time ({unit})"
    return t, "time (s)"


def plot_energy(plt, energy, out, fmt, dpi):
    t, label = time_axis(energy["time"])
    fig, ax = plt.subplots(figsize=(8, 5))
    for term in ENERGY_TERMS:
        values = energy.get(term)
        if values and any(v != 0.0 for v in values):
            ax.plot(t, values, label=term, lw=2.0 if term == "total" else 1.2)
    ax.set_xlabel(label)
    ax.set_ylabel("energy (J)")
    ax.set_title("energy.csv")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    written = [save(fig, out, "energy", fmt, dpi)]
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.plot(t, [100.0 * v for v in energy["balance_error"]], color="C3")
    ax.set_xlabel(label)
    ax.set_ylabel("balance error (%)")
    ax.set_title("energy balance error (energy.csv balance_error)")
    ax.grid(alpha=0.3)
    written.append(save(fig, out, "balance", fmt, dpi))
    return written


def entities(histories):
    """(kind, name) -> [column suffixes] of histories.csv, in column order."""
    found = {}
    for column in histories:
        if column == "time":
            continue
        kind, rest = column.split(".", 1)
        name, quantity = rest.rsplit(".", 1)
        found.setdefault((kind, name), []).append(quantity)
    return found


def plot_group(plt, kind, name, h, t, label, out, fmt, dpi):
    """A load or a body: displacement and force against time (+ a load's force-displacement)."""
    col = lambda q: h[f"{kind}.{name}.{q}"]
    force_title = "reaction (N)" if kind == "load" else "resultant force (N)"
    panels = 3 if kind == "load" else 2
    fig, axes = plt.subplots(1, panels, figsize=(5 * panels, 4))
    for k, axis in enumerate("xyz"):
        axes[0].plot(t, [1e3 * v for v in col("u" + axis)], label="u" + axis)
        axes[1].plot(t, col("f" + axis), label="f" + axis)
    axes[0].set_ylabel("mean displacement (mm)")
    axes[1].set_ylabel(force_title)
    for ax in axes[:2]:
        ax.set_xlabel(label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize="small")
    if kind == "load":
        # Along the direction the load moved most: the force-displacement curve of a test.
        axis = max("xyz", key=lambda a: max((abs(v) for v in col("u" + a)), default=0.0))
        u, f = col("u" + axis), col("f" + axis)
        sign = -1.0 if sum(u) < 0 else 1.0  # plot the travel as positive
        axes[2].plot([sign * 1e3 * v for v in u], [sign * v for v in f], color="C3")
        axes[2].set_xlabel(f"displacement {'−' if sign < 0 else ''}u{axis} (mm)")
        axes[2].set_ylabel(f"reaction {'−' if sign < 0 else ''}f{axis} (N)")
        axes[2].set_title("force-displacement")
        axes[2].grid(alpha=0.3)
    fig.suptitle(f"{kind} '{name}' (histories.csv)")
    return save(fig, out, f"histories_{kind}_{name}", fmt, dpi)


def plot_monitor(plt, name, h, t, label, out, fmt, dpi):
    col = lambda q: h[f"monitor.{name}.{q}"]
    fig, axes = plt.subplots(1, 3, figsize=(15, 4))
    for axis in "xyz":
        axes[0].plot(t, [1e3 * v for v in col("u" + axis)], label="u" + axis)
        axes[1].plot(t, col("v" + axis), label="v" + axis)
    for s in ("sxx", "syy", "szz", "syz", "sxz", "sxy"):
        axes[2].plot(t, [1e-6 * v for v in col(s)], label=s)
    for ax, unit in zip(axes, ("displacement (mm)", "velocity (m/s)", "Cauchy stress (MPa)")):
        ax.set_xlabel(label)
        ax.set_ylabel(unit)
        ax.grid(alpha=0.3)
        ax.legend(fontsize="small")
    fig.suptitle(f"monitor '{name}' (histories.csv)")
    return save(fig, out, f"histories_monitor_{name}", fmt, dpi)


def plot_stress_strain(plt, name, area, length, lines, h, out, fmt, dpi):
    """Load NAME's reaction / area (MPa) against displacement / length (%), both positive."""
    col = lambda q: h[f"load.{name}.{q}"]
    axis = max("xyz", key=lambda a: max((abs(v) for v in col("u" + a)), default=0.0))
    u, f = col("u" + axis), col("f" + axis)
    sign = -1.0 if sum(u) < 0 else 1.0
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot([100 * sign * v / length for v in u], [1e-6 * sign * v / area for v in f], color="C3",
            label=f"load '{name}'")
    for k, (label, stress) in enumerate(lines):
        ax.axhline(stress, color=f"C{k}", linestyle="--", linewidth=1, label=f"{label} {stress:g} MPa")
    ax.set_xlabel(f"strain {'−' if sign < 0 else ''}u{axis} / {length:g} m (%)")
    ax.set_ylabel(f"stress {'−' if sign < 0 else ''}f{axis} / {area:g} m² (MPa)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    ax.set_title(f"stress-strain, load '{name}' (histories.csv)")
    return save(fig, out, f"stress_strain_{name}", fmt, dpi)


def save(fig, out, stem, fmt, dpi):
    path = os.path.join(out, f"{stem}.{fmt}")
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    fig.clear()
    return path


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out", help="an fdem output directory (fdem run ... -o OUT)")
    parser.add_argument("--format", default="png", help="image format (default png)")
    parser.add_argument("--dpi", type=int, default=120)
    parser.add_argument("--specimen", nargs=3, action="append", default=[],
                        metavar=("LOAD", "AREA", "LENGTH"),
                        help="also draw LOAD's stress-strain curve (area m², length m)")
    parser.add_argument("--line", action="append", default=[], metavar="LABEL=MPA",
                        help="a reference stress on the stress-strain curves")
    args = parser.parse_args()
    try:
        specimens = [(n, float(a), float(l)) for n, a, l in args.specimen]
        lines = [(x.rsplit("=", 1)[0], float(x.rsplit("=", 1)[1])) for x in args.line]
    except (ValueError, IndexError):
        parser.error("--specimen takes LOAD AREA LENGTH (numbers in m², m), --line LABEL=MPA")
    if any(a <= 0 or l <= 0 for _, a, l in specimens):
        parser.error("--specimen: AREA and LENGTH must be > 0")
    try:
        import matplotlib
        matplotlib.use("Agg")  # no display needed
        import matplotlib.pyplot as plt
    except ImportError:
        # Debian's python3-matplotlib belongs to /usr/bin/python3; another python3 first on PATH
        # (pyenv, a venv) does not see it: run this script again with Debian's.
        debian = "/usr/bin/python3"
        if os.path.exists(debian) and os.path.realpath(sys.executable) != os.path.realpath(debian) \
                and not os.environ.get("FDEM_PLOT_REEXEC"):
            os.environ["FDEM_PLOT_REEXEC"] = "1"
            os.execv(debian, [debian] + sys.argv)
        sys.exit("plot.py needs matplotlib: apt-get install python3-matplotlib "
                 "(scripts/install-deps.sh installs it)")
    energy_path = os.path.join(args.out, "energy.csv")
    histories_path = os.path.join(args.out, "histories.csv")
    if not os.path.exists(energy_path) and not os.path.exists(histories_path):
        print(f"plot.py: {args.out} has neither energy.csv nor histories.csv", file=sys.stderr)
        return 2
    written = []
    if os.path.exists(energy_path):
        energy = read_csv(energy_path)
        if energy.get("time"):
            written += plot_energy(plt, energy, args.out, args.format, args.dpi)
    if os.path.exists(histories_path):
        h = read_csv(histories_path)
        if h.get("time"):
            t, label = time_axis(h["time"])
            for (kind, name) in entities(h):
                if kind in ("load", "body"):
                    written.append(plot_group(plt, kind, name, h, t, label, args.out,
                                              args.format, args.dpi))
                elif kind == "monitor":
                    written.append(plot_monitor(plt, name, h, t, label, args.out, args.format,
                                                args.dpi))
            for name, area, length in specimens:
                if f"load.{name}.fx" not in h:
                    print(f"plot.py: --specimen: histories.csv has no load '{name}'",
                          file=sys.stderr)
                    return 2
                written.append(plot_stress_strain(plt, name, area, length, lines, h, args.out,
                                                  args.format, args.dpi))
        plt.close("all")
    for path in written:
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())

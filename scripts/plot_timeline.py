#!/usr/bin/python3
"""Plot a progressive-extraction timeline (one CSV row per sample) the way the dissertation does.

Usage: scripts/plot_timeline.py timeline.csv [--out PREFIX] [--title TEXT] [--logx]

Writes
  PREFIX_progress.png  correctness C, final pixels and share of rays cast (top), cells visited
                       and triangles in thousands (bottom) against time, with dashed lines where
                       C first reaches 90%, 99% and 99.9% (Figures 2.6 and 3.2);
  PREFIX_stages.png    the cumulative time spent in ray intersection, propagation, extraction
                       and rendering, stacked, against elapsed time (Figure 2.8);
and prints, for C and for final pixels at 90%, 99% and 99.9% and for the last row, the time,
triangles and rays at the first row reaching it.

The CSV needs a header row with these columns, in any order (others are ignored):
  time_s, rays, rays_share, cells_visited, triangles, groups, final_pixels, c,
  t_intersect_s, t_propagate_s, t_extract_s, t_render_s
Rows are samples in time order; rays_share, final_pixels and c are in [0,1]; the t_*_s columns
are cumulative seconds. Errors are one line on stderr and exit status 1.
"""
import argparse
import csv
import math
import os
import sys

PROG = "plot_timeline.py"
REQUIRED = ["time_s", "rays", "rays_share", "cells_visited", "triangles", "groups",
            "final_pixels", "c", "t_intersect_s", "t_propagate_s", "t_extract_s", "t_render_s"]
THRESHOLDS = [0.90, 0.99, 0.999]
STAGES = [("t_intersect_s", "ray intersection"), ("t_propagate_s", "propagation"),
          ("t_extract_s", "extraction"), ("t_render_s", "rendering")]


class InputError(Exception):
    """One line naming the file, the field, what was expected and what was found."""


def read_timeline(path):
    """Returns {column: [float per row]} for the required columns."""
    try:
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
    except OSError as e:
        raise InputError(f"{path}: cannot read: {e.strerror}")
    rows = [r for r in rows if any(cell.strip() for cell in r)]
    if not rows:
        raise InputError(f"{path}: empty file, expected a header row naming "
                         f"{', '.join(REQUIRED)}")
    header = [name.strip() for name in rows[0]]
    for name in REQUIRED:
        if name not in header:
            raise InputError(f"{path}: missing column '{name}' "
                             f"(header has: {', '.join(header)})")
    if len(rows) == 1:
        raise InputError(f"{path}: no data rows after the header")
    index = {name: header.index(name) for name in REQUIRED}
    columns = {name: [] for name in REQUIRED}
    for line, row in enumerate(rows[1:], start=2):
        for name, i in index.items():
            cell = row[i].strip() if i < len(row) else ""
            try:
                value = float(cell)
            except ValueError:
                raise InputError(f"{path}: line {line}: column '{name}': expected a number, "
                                 f"got '{cell}'")
            if math.isnan(value):
                raise InputError(f"{path}: line {line}: column '{name}': expected a number, "
                                 f"got NaN")
            columns[name].append(value)
    return columns


def first_reaching(values, threshold):
    """Index of the first row whose value is >= threshold, or None.

    A tiny slack keeps a value printed as 0.99 from missing 0.99 through rounding in the CSV.
    """
    for i, v in enumerate(values):
        if v >= threshold - 1e-12:
            return i
    return None


def percent(threshold):
    return f"{threshold * 100:g}%"


def summary_table(t):
    """The rows of the printed table: (measure, index or None)."""
    lines = []
    for key, label in [("c", "C"), ("final_pixels", "final pixels")]:
        for threshold in THRESHOLDS:
            lines.append((f"{label} >= {percent(threshold)}", first_reaching(t[key], threshold)))
    lines.append(("last row", len(t["time_s"]) - 1))
    return lines


def print_table(t, out=sys.stdout):
    header = f"{'reached':<22} {'time_s':>10} {'triangles':>12} {'rays':>12} {'C':>8} {'final':>8}"
    print(header, file=out)
    print("-" * len(header), file=out)
    for label, i in summary_table(t):
        if i is None:
            print(f"{label:<22} {'not reached':>10}", file=out)
            continue
        print(f"{label:<22} {t['time_s'][i]:>10.3f} {t['triangles'][i]:>12.0f} "
              f"{t['rays'][i]:>12.0f} {t['c'][i]:>8.4f} {t['final_pixels'][i]:>8.4f}", file=out)


def marker_style(n):
    # A handful of samples would vanish as a bare line (a single row draws nothing at all).
    return {"marker": "o", "markersize": 4} if n <= 30 else {}


def set_time_axis(ax, times, logx):
    if logx:
        ax.set_xscale("log", nonpositive="mask")
        ax.set_xlabel("time (s, log scale)")
    else:
        ax.set_xlabel("time (s)")
        ax.set_xlim(left=min(0.0, min(times)))
    if len(times) == 1 or max(times) == min(times):
        # Matplotlib would centre a zero-width range on the point; give it room instead.
        span = abs(times[0]) or 1.0
        if logx and times[0] > 0:
            ax.set_xlim(times[0] / 2, times[0] * 2)
        else:
            ax.set_xlim(min(0.0, times[0]) - 0.05 * span, times[0] + 0.5 * span)


# Not the colours of any plotted series, so a threshold line never reads as data.
THRESHOLD_COLOURS = ["0.5", "C5", "black"]


def label_threshold(ax, x, threshold, colour, level):
    """Labels the vertical at x inside the top headroom band; level staggers close labels."""
    ax.annotate(f"C\u2265{percent(threshold)}: {x:.3g} s", xy=(x, 1.0),
                xycoords=("data", "axes fraction"), xytext=(3, -3 - 11 * level),
                textcoords="offset points", ha="left", va="top", fontsize=8, color=colour)


def threshold_lines(ax, t, label):
    """Dashed verticals where C first reaches each threshold; labels only when label is set."""
    for level, (threshold, colour) in enumerate(zip(THRESHOLDS, THRESHOLD_COLOURS)):
        i = first_reaching(t["c"], threshold)
        if i is None:
            continue
        x = t["time_s"][i]
        ax.axvline(x, color=colour, linestyle="--", linewidth=1)
        if label:
            label_threshold(ax, x, threshold, colour, level)


def plot_progress(t, path, title, logx):
    import matplotlib.pyplot as plt
    from matplotlib.ticker import PercentFormatter

    times = t["time_s"]
    style = marker_style(len(times))
    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(9, 7.5),
                                      gridspec_kw={"height_ratios": [3, 2]})
    top.plot(times, [100 * v for v in t["c"]], label="correctness C", color="C0", linewidth=2,
             **style)
    top.plot(times, [100 * v for v in t["final_pixels"]], label="final pixels", color="C1",
             **style)
    top.plot(times, [100 * v for v in t["rays_share"]], label="rays cast (share of screen)",
             color="C2", linestyle="-.", **style)
    # Headroom above 100% keeps the threshold labels clear of curves that end near 100%.
    top.set_ylim(0, 120)
    top.set_yticks(range(0, 101, 20))
    top.yaxis.set_major_formatter(PercentFormatter(100))
    top.set_ylabel("percent")
    top.grid(True, alpha=0.3)
    threshold_lines(top, t, label=True)
    top.legend(loc="lower right", fontsize=9)
    top.set_title(title)

    bottom.plot(times, [v / 1000 for v in t["cells_visited"]], label="cells visited",
                color="C4", **style)
    bottom.set_ylabel("cells visited (thousands)", color="C4")
    bottom.tick_params(axis="y", colors="C4")
    bottom.set_ylim(bottom=0)
    right = bottom.twinx()
    right.plot(times, [v / 1000 for v in t["triangles"]], label="triangles", color="C3",
               linestyle="--", **style)
    right.set_ylabel("triangles (thousands)", color="C3")
    right.tick_params(axis="y", colors="C3")
    right.set_ylim(bottom=0)
    bottom.grid(True, alpha=0.3)
    threshold_lines(bottom, t, label=False)
    handles = bottom.get_legend_handles_labels()[0] + right.get_legend_handles_labels()[0]
    bottom.legend(handles, [h.get_label() for h in handles], loc="upper left", fontsize=9)
    set_time_axis(bottom, times, logx)

    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_stages(t, path, title, logx):
    import matplotlib.pyplot as plt

    times = t["time_s"]
    fig, ax = plt.subplots(figsize=(9, 5))
    series = [t[key] for key, _ in STAGES]
    labels = [label for _, label in STAGES]
    if len(times) == 1:
        # stackplot needs two x values to draw an area; show the one sample as stacked bars.
        bottom = 0.0
        width = 0.1 * (abs(times[0]) or 1.0)
        for values, label, colour in zip(series, labels, ["C0", "C1", "C2", "C3"]):
            ax.bar(times[0], values[0], width=width, bottom=bottom, label=label, color=colour,
                   alpha=0.8)
            bottom += values[0]
    else:
        ax.stackplot(times, *series, labels=labels, colors=["C0", "C1", "C2", "C3"], alpha=0.8)
    # Where one process runs the stages in turn, the gap between the stack and elapsed time is
    # time spent elsewhere (communication, waiting); summed over ranks the stack can exceed it.
    ax.plot(times, times, color="black", linestyle=":", linewidth=1, label="elapsed time",
            **marker_style(len(times)))
    i = first_reaching(t["c"], 0.99)
    if i is not None:
        colour = THRESHOLD_COLOURS[THRESHOLDS.index(0.99)]
        ax.axvline(times[i], color=colour, linestyle="--", linewidth=1)
        label_threshold(ax, times[i], 0.99, colour, 0)
    ax.set_ylabel("cumulative time in stage (s)")
    top = max(max(times), max(sum(values) for values in zip(*series)))
    ax.set_ylim(0, 1.15 * top if top > 0 else 1.0)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize=9)
    ax.set_title(f"{title}: time per stage" if title else "time per stage")
    set_time_axis(ax, times, logx)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None):
    # The docstring without its Usage paragraph, which argparse writes itself.
    paragraphs = __doc__.split("\n\n")
    parser = argparse.ArgumentParser(
        prog=PROG, description="\n\n".join(paragraphs[:1] + paragraphs[2:]),
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("csv", help="timeline CSV, one row per sample, in time order")
    parser.add_argument("--out", metavar="PREFIX",
                        help="write PREFIX_progress.png and PREFIX_stages.png "
                             "(default: the CSV path without .csv)")
    parser.add_argument("--title", default="", help="title of the progress plot")
    parser.add_argument("--logx", action="store_true",
                        help="logarithmic time axis (rows at time 0 are left out)")
    args = parser.parse_args(argv)

    try:
        t = read_timeline(args.csv)
    except InputError as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 1
    if args.logx and not any(x > 0 for x in t["time_s"]):
        print(f"{PROG}: warning: {args.csv}: no positive time_s, --logx ignored",
              file=sys.stderr)
        args.logx = False

    import matplotlib
    matplotlib.use("Agg")

    prefix = args.out or os.path.splitext(args.csv)[0]
    progress_png = f"{prefix}_progress.png"
    stages_png = f"{prefix}_stages.png"
    try:
        plot_progress(t, progress_png, args.title, args.logx)
        plot_stages(t, stages_png, args.title, args.logx)
    except OSError as e:
        print(f"{PROG}: error: {e.filename}: cannot write: {e.strerror}", file=sys.stderr)
        return 1
    print_table(t)
    print(f"wrote {progress_png}")
    print(f"wrote {stages_png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""The targets, tables and plot of scripts/bench_scaling.py, from its measured results:
one dict per scale with "progressive", "full" and "peer" (see bench_scaling.py)."""
import math
import statistics

# Time to C = 99% at most 1/N of FE + Embree, by scale (512, 1024, 2048 a side for the head).
PEER_LIMITS = {1: 1 / 4, 2: 1 / 10, 4: 1 / 40}
FULL_LIMIT = 1 / 3         # C = 99% against our --full, from scale 2 up
GROWTH_LIMIT = 2.0         # C = 99% from scale 1 to scale 4
TRIS_PER_PX_LIMIT = 2.0    # triangles drawn by C = 99% per covered pixel, every scale
EVERY_RAY_LIMIT = 1.5      # every ray against our --full, every scale
THREADS_LIMIT = 1 / 1.7     # two threads' time over one thread's, C=99% and every ray
AGREE_FRACTION = 0.005     # the peer's hit pixels against --full's covered pixels
# A speed verdict holds only when the picture of the same runs passes its gate: the fidelity gate,
# the final image at least as close to the truth (the full surface at 4x4 samples a pixel,
# box-filtered) as the full surface at one sample a pixel, within GATE_C in C_T and GATE_IOU in
# coverage IoU (`render --against-truth` judges it). Runs saved before the truth was measured are
# judged by the older gate: C and coverage IoU against the full surface at one sample a pixel.
GATE_C, GATE_IOU = 0.005, 0.002
PICTURE_C = 0.99
PICTURE_IOU = 0.999
# The two engines the two-thread target compares: the defaults on one thread, then on every core.
PAIR = ("full-res", "defaults")


def label(r):
    return "x".join(str(s) for s in r["sizes"])


def picture_problem(p):
    """Why an engine's final image fails its gate, or "" when it passes."""
    if "gate" in p:
        if p["gate"]:
            return ""
        return (f"fidelity gate fails: C_T {p['ct']:.4f} against the full surface's {p['full_ct']:.4f}, "
                f"IoU_T {p['iou_t']:.4f} against {p['full_iou_t']:.4f}")
    c, iou = p.get("c_vs_full"), p.get("iou_vs_full")
    if c is None:
        return "final image not measured against the full surface"
    why = [f"final image C {c:.4f} < {PICTURE_C}"] if c < PICTURE_C else []
    if iou is not None and iou < PICTURE_IOU:
        why.append(f"coverage IoU {iou:.4f} < {PICTURE_IOU}")
    return "; ".join(why)


def check(checks, target, r, figure, limit, note="", pictures=()):
    """One verdict. A speed verdict names the engine runs whose pictures must match the full one."""
    problems = [w for w in (picture_problem(p) for p in pictures) if w]
    if any(p.get("c_vs_full") is not None and p.get("iou_vs_full") is None for p in pictures):
        note = "; ".join(x for x in (note, "coverage IoU not measured (an older run)") if x)
    holds = None if figure is None else figure <= limit and not problems
    checks.append({"target": target, "volume": label(r) if r else "", "figure": figure,
                   "limit": limit, "holds": holds, "note": "; ".join([*problems, note] if note else problems)})


def missed(t):
    """A time to a threshold: a run that never got there is infinitely slow, never left out."""
    return math.inf if t is None else t


def median(xs):
    xs = [x for x in xs if x]
    return statistics.median(xs) if xs else None


def speed_checks(checks, r):
    p = r["progressive"]
    c99, peer = missed(p["c99"]), r["peer"].get("total_s")
    if r["scale"] in PEER_LIMITS and peer:
        check(checks, "C=99% / FE + Embree", r, c99 / peer, PEER_LIMITS[r["scale"]], pictures=[p])
    if r["scale"] >= 2:
        check(checks, "C=99% / our --full", r, c99 / r["full"]["full_s"], FULL_LIMIT, pictures=[p])
    tris, covered = p["triangles_c99"], r["full"]["covered_px"]
    check(checks, "triangles by C=99% per covered pixel", r,
          tris / covered if tris is not None and covered else None, TRIS_PER_PX_LIMIT)
    check(checks, "every ray / our --full", r, p["every_ray_s"] / r["full"]["full_s"], EVERY_RAY_LIMIT,
          pictures=[p])


def thread_checks(checks, r, pair):
    """Two threads against one: the median over the rounds of each round's own speed-up."""
    e = r.get("engines", {})
    if pair[0] not in e or pair[1] not in e:
        return
    for key, what in (("c99_speedup", "C=99%"), ("every_ray_speedup", "every ray")):
        gain = median(k[key] for k in r.get("pair_rounds", []))
        if gain:
            # A speed-up of at least 1.7 is a time ratio (2 threads / 1) of at most 1/1.7.
            check(checks, f"2 threads / 1 thread on {what} ({pair[1]}, median of rounds)", r, 1 / gain,
                  THREADS_LIMIT, pictures=[e[pair[1]]])


def growth_check(checks, results):
    by_scale = {r["scale"]: r for r in results}
    if 1 in by_scale and 4 in by_scale:
        lo, hi = by_scale[1]["progressive"], by_scale[4]["progressive"]
        a, b = missed(lo["c99"]), missed(hi["c99"])
        check(checks, "growth of C=99%, scale 1 -> 4", by_scale[4], math.inf if math.inf in (a, b) else b / a,
              GROWTH_LIMIT, pictures=[lo, hi])
    elif len(results) >= 2:
        lo, hi = results[0], results[-1]
        a, b = lo["progressive"]["c99"], hi["progressive"]["c99"]
        checks.append({"target": "growth of C=99%, scale 1 -> 4", "volume": f"{label(lo)} -> {label(hi)}",
                       "figure": b / a if a and b else None, "limit": GROWTH_LIMIT, "holds": None,
                       "note": "not tested: needs --scales with 1 and 4; figure over the scales run"})


def targets(results, pair=PAIR):
    """Every target of the issue that these scales can test, each with its figure and verdict."""
    checks = []
    for r in results:
        speed_checks(checks, r)
    for r in results:
        thread_checks(checks, r, pair)
    growth_check(checks, results)
    return checks


def fmt(x, digits=3):
    if x is None:
        return "-"
    return "missed" if x == math.inf else f"{x:.{digits}f}"


def count(n):
    if n is None:
        return "-"
    for div, unit in ((1e9, "G"), (1e6, "M"), (1e3, "K")):
        if n >= div:
            return f"{n / div:.3g} {unit}"
    return str(n)


def verdict(c):
    if c["holds"] is None:
        return "n/a" if c["figure"] is not None and c["note"] else "not reached"
    return "holds" if c["holds"] else "MISSED"


def times_table(results):
    lines = ["| volume | voxels | C=90% | C=99% | C=99.9% | C=100% | triangles by C=99% | per covered px "
             "| every ray | full (extract + draw) | FE + Embree (FE + BVH + rays) |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        p, f, q = r["progressive"], r["full"], r["peer"]
        per_px = p["triangles_c99"] / f["covered_px"] if p["triangles_c99"] and f["covered_px"] else None
        peer = (f"{fmt(q['total_s'])} ({fmt(q['fe_s'])} + {fmt(q['bvh_s'])} + {fmt(q['rays_s'])})"
                if "total_s" in q else f"skipped: {q['skipped']}")
        lines.append(f"| {label(r)} | {count(r['voxels'])} | {fmt(p['c90'])} | {fmt(p['c99'])} | {fmt(p['c999'])} "
                     f"| {fmt(p['c100'])} | {count(p['triangles_c99'])} | {fmt(per_px, 2)} | {fmt(p['every_ray_s'])} "
                     f"| {fmt(f['full_s'])} ({fmt(f['extract_s'])} + {fmt(f['draw_s'])}) | {peer} |")
    return lines


def truth_cells(p):
    if "gate" not in p:
        return "- | - | not measured"
    return (f"{p['ct']:.4f} / {p['full_ct']:.4f} | {p['iou_t']:.4f} / {p['full_iou_t']:.4f} | "
            f"{'holds' if p['gate'] else 'FAILS'}")


def engines_table(meta, results):
    lines = ["| volume | engine | C=90% | C=99% | C=99.9% | every ray | triangles by C=99% | per covered px "
             "| C of the final image against the full surface | its final px | its coverage IoU "
             "| C_T final / full | IoU_T final / full | fidelity gate |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        for name, p in r.get("engines", {}).items():
            per_px = p["triangles_c99"] / r["full"]["covered_px"] if p["triangles_c99"] and r["full"]["covered_px"] else None
            lines.append(f"| {label(r)} | {name} | {fmt(p['c90'])} | {fmt(p['c99'])} | {fmt(p['c999'])} "
                         f"| {fmt(p['every_ray_s'])} | {count(p['triangles_c99'])} | {fmt(per_px, 2)} "
                         f"| {fmt(p.get('c_vs_full'), 4)} | {fmt(100 * p['final_px_vs_full'] if p.get('final_px_vs_full') is not None else None, 1)}% "
                         f"| {fmt(p.get('iou_vs_full'), 4)} | {truth_cells(p)} |")
    names = "; ".join(f"{k}: `{v}`" for k, v in meta.get("engines", {}).items())
    return [f"Engines ({names}):", "", *lines]


def pixels_table(results):
    lines = ["| volume | progressive final image | --full | peer hit pixels | peer vs --full |",
             "|---|---|---|---|---|"]
    for r in results:
        full_px, hit = r["full"]["covered_px"], r["peer"].get("hit_px")
        diff = "-" if hit is None else f"{100 * (hit - full_px) / max(full_px, 1):+.3f}%" + (
            "" if abs(hit - full_px) <= AGREE_FRACTION * full_px else " (over 0.5%: check the views)")
        lines.append(f"| {label(r)} | {r['progressive']['covered_px']} | {full_px} | "
                     f"{'-' if hit is None else hit} | {diff} |")
    return lines


def round_medians(r):
    """The median over the rounds of each round's own speed-up (rounds: see rounds_table)."""
    rounds = r.get("pair_rounds", [])
    c99 = [k["c99_speedup"] for k in rounds if k["c99_speedup"]]
    every = [k["every_ray_speedup"] for k in rounds if k["every_ray_speedup"]]
    c99, every = (statistics.median(xs) if xs else None for xs in (c99, every))
    return f"{fmt(c99, 2)} / {fmt(every, 2)}"


def two_threads_table(results, pair):
    """Speed-ups of two threads over one (one thread's time / two threads'): ours, the peer's, and
    what the machine's cores gave plain work at the time (bench/cores)."""
    lines = ["Two threads against one (speed-up: one thread's time / two threads'; 1.7 is the target, "
             "2 is perfect):", "",
             "| volume | ours, C=99% | ours, every ray | ours, median of rounds (C=99% / every ray) | peer FE | "
             "peer BVH + rays | peer total | machine: arithmetic | machine: random reads |",
             "|---|---|---|---|---|---|---|---|---|"]

    def gain(one, two):
        return fmt(one / two, 2) if one and two else "-"

    for r in results:
        e = r.get("engines", {})
        one, two = e.get(pair[0], {}), e.get(pair[1], {})
        p1, p2 = r.get("peer_1t", {}), r.get("peer", {})
        cores = r.get("cores", {})
        lines.append(
            f"| {label(r)} | {gain(one.get('c99'), two.get('c99'))} | "
            f"{gain(one.get('every_ray_s'), two.get('every_ray_s'))} | {round_medians(r)} | "
            f"{gain(p1.get('fe_s'), p2.get('fe_s'))} | "
            f"{gain(p1.get('bvh_s', 0) + p1.get('rays_s', 0), p2.get('bvh_s', 0) + p2.get('rays_s', 0))} | "
            f"{gain(p1.get('total_s'), p2.get('total_s'))} | {fmt(cores.get('alu_speedup'), 2)} | "
            f"{fmt(cores.get('memory_speedup'), 2)} |")
    return lines


def rounds_table(results):
    """Each round in which both engines of the pair ran: its own speed-ups, and what the machine's
    two cores gave random reads right after it (pair rounds only; bench/cores)."""
    lines = ["Two threads against one, round by round (the runs of one round follow each other; "
             "machine: random reads on two threads right after the round, pair rounds only):", "",
             "| volume | round | C=99% | every ray | machine: random reads |", "|---|---|---|---|---|"]
    for r in results:
        for k in r.get("pair_rounds", []):
            m = k.get("machine") or {}
            lines.append(f"| {label(r)} | {k['round']} | {fmt(k['c99_speedup'], 2)} | "
                         f"{fmt(k['every_ray_speedup'], 2)} | {fmt(m.get('memory_speedup'), 2)} |")
    return lines


def frame_words(meta):
    if meta.get("frame", "cold") == "cold":
        return "each program's first run in a fresh process (cold)"
    return ("each program's run after an untimed one in the same process (warm: the progressive frame "
            "after one of the view turned 30 degrees, the peer's second flying edges, BVH and rays)")


def statistic_words(meta):
    """What each figure is: the same statistic for every contender, said once."""
    n, pair = meta["runs"], meta.get("pair", PAIR)
    rounds = n + meta.get("pair_rounds", 0)
    return (f"every contender (each engine, --full, FE + Embree) ran {n} time(s) and each figure is "
            f"its median run ({meta.get('statistic', 'median')}: by time to C = 99%, extract + draw, "
            f"FE + BVH + rays); the peer on one thread ran once; the two-thread verdict is the median "
            f"over {rounds} rounds of {pair[0]} and {pair[1]} of each round's own speed-up")


def report(meta, results, checks):
    load = ", ".join(f"{x:g}" for x in meta["load_average"])
    pair = meta.get("pair", PAIR)
    lines = [f"# Scaling: {meta['volume']}, iso {meta['iso']:g}, {meta['size']}", "",
             f"Measured {meta['date']} on {meta['cores']} cores (load average {load} over 1, 5, 15 min "
             f"at the end); {statistic_words(meta)}; seconds; {frame_words(meta)}. C is the share of "
             f"final pixels; the peer uses {meta['threads']} threads. The progressive columns and the "
             f"targets are the first engine's ({next(iter(meta.get('engines', {'': ''})))}); a speed "
             f"verdict holds only when that engine's final image passes the fidelity gate: C_T (C against "
             f"the truth, the full surface at 4x4 samples a pixel, box-filtered) within {GATE_C} and "
             f"coverage IoU within {GATE_IOU} of the full surface at one sample a pixel, or better; a "
             f"run that never reached a threshold counts as missed.", "",
             *times_table(results), "", *engines_table(meta, results), "",
             *two_threads_table(results, pair), "", *rounds_table(results), "",
             "Covered pixels (the same view in each):", "", *pixels_table(results), "",
             "Targets:", "", "| target | volume | figure | limit | verdict |", "|---|---|---|---|---|"]
    for c in checks:
        note = f" ({c['note']})" if c["note"] else ""
        lines.append(f"| {c['target']} | {c['volume']} | {fmt(c['figure'], 3)} | {c['limit']:.3g} "
                     f"| {verdict(c)}{note} |")
    return "\n".join(lines) + "\n"


def plot(meta, results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    x = [r["voxels"] for r in results]
    extra = [(f"C = 99%, {name}", (lambda n: lambda r: r["engines"][n]["c99"])(name), ":.")
             for name in list(meta.get("engines", {}))[1:]]
    series = [("C = 90%", lambda r: r["progressive"]["c90"], "-o"),
              ("C = 99%", lambda r: r["progressive"]["c99"], "-o"),
              ("C = 99.9%", lambda r: r["progressive"]["c999"], "-o"),
              ("every ray", lambda r: r["progressive"]["every_ray_s"], "-s"),
              ("our --full", lambda r: r["full"]["full_s"], "--^"),
              ("FE + Embree", lambda r: r["peer"].get("total_s"), "--v"),
              ("FE alone", lambda r: r["peer"].get("fe_s"), ":v")] + extra
    fig, ax = plt.subplots(figsize=(7.5, 5))
    for name, get, style in series:
        pts = [(xi, get(r)) for xi, r in zip(x, results) if get(r)]
        if pts:
            ax.plot([p[0] for p in pts], [p[1] for p in pts], style, label=name)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xticks(x)
    ax.set_xticklabels([f"{label(r)}\n{count(r['voxels'])}" for r in results], fontsize=8)
    ax.xaxis.set_minor_locator(matplotlib.ticker.NullLocator())
    # Seconds as numbers at 1, 2, 5 per decade: readable without crowding.
    ax.yaxis.set_major_locator(matplotlib.ticker.LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax.yaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
    ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_xlabel("volume (voxels)")
    ax.set_ylabel("seconds")
    first = next(iter(meta.get("engines", {"progressive": ""})))
    ax.set_title(f"iso {meta['iso']:g}, {meta['size']}, C from {first}, {meta.get('frame', 'cold')} frames: "
                 f"time against voxels (load avg {meta['load_average'][0]:g})", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)

"""Tables, targets and plots of scripts/bench_volumes.py from its cases: one dict per
volume, isovalue and scale, with "engine" (the default render's median run) and "peer"."""
import math

# The targets, per volume and isovalue. Every speed verdict holds only where the fidelity gate
# holds for the same runs: the final image at least as close to the truth (the full surface at
# 4x4 samples a pixel, box-filtered) as the full surface at one sample a pixel, within
# GATE_C in C_T and GATE_IOU in coverage IoU (`isowall render --against-truth` judges it).
GATE_C, GATE_IOU = 0.005, 0.002
GROWTH_LIMIT, GROWTH_RESOLVED = 1.5, 2.0  # time to C = 99% of the own final image, 1x to 4x
PEER_LIMIT = 1 / 20  # that time over FE + Embree, at 4x
TRIS_PER_PX_LIMIT = 2.0  # triangles drawn by C = 99% per covered pixel, every scale
# Peak RSS of a default render at 4x, plain or warm: at most this many times the voxels' bytes
# plus RSS_BASE_MIB. Memory is not a speed figure: it is judged without the gate.
RSS_VOXELS, RSS_BASE_MIB = 1.5, 200


def fmt(x, digits=3):
    if x is None:
        return "-"
    return "missed" if x == math.inf else f"{x:.{digits}f}"


def c99(case):
    """Seconds to C = 99% of the engine's own final image; inf where it never got there; None where
    the case did not run."""
    e = case.get("engine")
    if not e:
        return None
    t = e["own"]["c99"]
    return math.inf if t is None else t


def gate(case):
    return case["engine"]["gate"] if "engine" in case else None


def tris_per_px(case):
    e = case.get("engine")
    if not e or e["own"].get("tris_c99") is None or not e["covered_px"]:
        return None
    return e["own"]["tris_c99"] / e["covered_px"]


def drawn_per_px(case):
    """Triangles drawn over the whole final frame per covered pixel (those that cover a centre)."""
    e = case.get("engine")
    if not e or e.get("drawn") is None or not e["covered_px"]:
        return None
    return e["drawn"] / e["covered_px"]


def rss_ratio(case):
    """The larger peak RSS of the plain and the warm render over its limit; None where not measured
    (runs saved before it was)."""
    r = case.get("rss_mib")
    if not r or not case.get("voxel_bytes"):
        return None
    return max(r["plain"], r["warm"]) / (RSS_VOXELS * case["voxel_bytes"] / 2**20 + RSS_BASE_MIB)


def peer_ratio(case):
    t, p = c99(case), case.get("peer", {}).get("total_s")
    return t / p if t is not None and p else None


def groups(cases):
    """{(volume, iso): [cases by scale]} in the order measured."""
    out = {}
    for c in cases:
        out.setdefault((c["volume"], c["iso"]), []).append(c)
    return out


def judged(value, limit, picture):
    """A speed figure against its limit, where the picture of the same runs passed its gate: None
    (not measured), or whether it holds; a missed run (inf) never holds."""
    if value is None:
        return None
    return bool(picture) and value <= limit


def verdicts(cases):
    """One row per volume and isovalue: the gate at every scale, then growth, peer and triangles,
    each judged only with the gate."""
    rows = []
    for (name, iso), cs in groups(cases).items():
        ran = [c for c in cs if "engine" in c]
        one = next((c for c in ran if c["scale"] == 1), None)
        top = max(ran, key=lambda c: c["scale"], default=None)
        gate_all = all(gate(c) for c in ran) if ran else None
        growth = None
        if one and top and top is not one:
            a, b = c99(one), c99(top)
            growth = math.inf if math.inf in (a, b) else b / a
        at4 = top is not None and top["scale"] == 4
        # Drawn per pixel over the whole frame bounds those drawn by C = 99% from above; runs
        # saved before it was printed are judged on the triangles made by then.
        per_px = [drawn_per_px(c) if drawn_per_px(c) is not None else tris_per_px(c) for c in ran]
        worst_tris = max((t for t in per_px if t is not None), default=None)
        margins = [(c["engine"]["ct"] - c["engine"]["full_ct"], c) for c in ran]
        r = {"volume": name, "iso": iso, "top_scale": top["scale"] if top else None,
             "gate_holds": gate_all, "growth": growth,
             "growth_holds": judged(growth, GROWTH_LIMIT, gate_all) if at4 else None,
             "growth_resolved": judged(growth, GROWTH_RESOLVED, gate_all) if at4 else None,
             "worst_ct_margin": min((m for m, _ in margins), default=None),
             "c_vs_full": min((c["engine"]["c_vs_full"] for c in ran), default=None),
             "peer_ratio_4x": peer_ratio(top) if at4 else None,
             "tris_per_px": worst_tris,
             "skipped": [f"{c['scale']:g}x: {c['skipped']}" for c in cs if "skipped" in c]}
        r["peer_holds"] = judged(r["peer_ratio_4x"], PEER_LIMIT, gate(top) if top else None)
        r["tris_holds"] = judged(worst_tris, TRIS_PER_PX_LIMIT, gate_all)
        r["rss_ratio_4x"] = rss_ratio(top) if at4 else None
        r["rss_holds"] = None if r["rss_ratio_4x"] is None else r["rss_ratio_4x"] <= 1
        rows.append(r)
    return rows


def word(holds):
    return "not measured" if holds is None else ("holds" if holds else "MISSED")


def volume_table(cs):
    lines = ["| scale | voxels | C=99% own s | every ray s | C=99% vs full s | C_T final / full | "
             "IoU_T final / full | gate | C vs full | triangles by C=99% | per covered px | "
             "drawn / px (frame) | FE+Embree s | C=99% / peer | peak RSS MiB plain / warm |", "|" + "---|" * 15]
    for c in cs:
        if "skipped" in c:
            lines.append(f"| {c['scale']:g}x | {c['voxels'] / 1e6:.0f} M | skipped: {c['skipped']} |" + " |" * 12)
            continue
        e = c["engine"]
        lines.append(
            f"| {c['scale']:g}x | {c['voxels'] / 1e6:.0f} M | {fmt(c99(c))} | {fmt(e['every_ray_s'])} | "
            f"{fmt(e['truth']['c99'])} | {e['ct']:.5f} / {e['full_ct']:.5f} | "
            f"{e['iou_t']:.5f} / {e['full_iou_t']:.5f} | {'holds' if e['gate'] else 'FAILS'} | "
            f"{e['c_vs_full']:.5f} | {e['own'].get('tris_c99') or '-'} | {fmt(tris_per_px(c), 2)} | "
            f"{fmt(drawn_per_px(c), 2)} | {fmt(c.get('peer', {}).get('total_s'))} | {fmt(peer_ratio(c))} | "
            f"{rss_cell(c)} |")
    return "\n".join(lines)


def rss_cell(case):
    r = case.get("rss_mib")
    return "-" if not r else f"{r['plain']:.0f} / {r['warm']:.0f}"


def report(meta, cases):
    out = [f"# Every shared volume, default `isowall render` ({meta['date']}, {meta['cores']} cores, "
           f"load {meta['load_average']})", "",
           f"{meta['size']}, front view, warm (`--warm-up`), median of {meta['runs']} runs by time to "
           "C = 99% of the engine's own final image (\"own\"; a run that never got there counts as "
           "missed, never dropped). C_T and IoU_T: the final image (and the full surface at one sample "
           "a pixel) against the truth, the full surface at 4x4 samples a pixel, box-filtered; the "
           f"gate: C_T within {GATE_C} and IoU_T within {GATE_IOU} of the full surface's, or better. "
           "\"vs full\": against the full surface at one sample a pixel. Every speed target holds only "
           f"where the gate holds. The whole run took {meta['seconds']} s.", ""]
    for (name, iso), cs in groups(cases).items():
        out += [f"## {name}, iso {iso:g}", "", volume_table(cs), ""]
    rows = verdicts(cases)
    out += ["## Targets", "",
            f"| volume | iso | fidelity gate, every scale | worst C_T - full C_T | growth of C=99%, 1x to "
            f"largest | {GROWTH_LIMIT}x ({GROWTH_RESOLVED}x to resolve) | C=99% / peer at 4x | 1/20 | "
            f"worst triangles drawn per px | <= {TRIS_PER_PX_LIMIT:g} | peak RSS at 4x / "
            f"({RSS_VOXELS:g} x voxels + {RSS_BASE_MIB} MiB) | <= 1 | skipped |", "|" + "---|" * 13]
    for r in rows:
        g = "-" if r["growth"] is None else (
            "missed" if r["growth"] == math.inf else f"{r['growth']:.2f}x (to {r['top_scale']:g}x)")
        gw = word(r["growth_holds"]) + ("" if r["growth_resolved"] is None else
                                        f" / {word(r['growth_resolved'])}")
        out.append(f"| {r['volume']} | {r['iso']:g} | {word(r['gate_holds'])} | "
                   f"{fmt(r['worst_ct_margin'], 5)} | {g} | {gw} | {fmt(r['peer_ratio_4x'])} | "
                   f"{word(r['peer_holds'])} | {fmt(r['tris_per_px'], 2)} | {word(r['tris_holds'])} | "
                   f"{fmt(r['rss_ratio_4x'], 2)} | {word(r['rss_holds'])} | {'; '.join(r['skipped']) or '-'} |")
    out += ["", "## The worst case", ""]

    def worst(key, pick):
        have = [r for r in rows if r[key] is not None]
        return pick(have, key=lambda r: r[key]) if have else None
    for key, pick, what in (("growth", max, "growth of C = 99% of the own final image"),
                            ("worst_ct_margin", min, "final C_T less the full surface's"),
                            ("peer_ratio_4x", max, "C = 99% over FE + Embree at 4x"),
                            ("tris_per_px", max, "triangles drawn per covered pixel (made, in older runs)"),
                            ("rss_ratio_4x", max, "peak RSS at 4x over its limit")):
        r = worst(key, pick)
        out.append(f"- {what}: " + ("not measured" if r is None else
                                    f"{r[key]:.4g} ({r['volume']}, iso {r['iso']:g})"))
    return "\n".join(out) + "\n"


def plot_volume(meta, cs, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for (name, iso), g in groups(cs).items():
        ran = [c for c in g if "engine" in c and c99(c) not in (None, math.inf)]
        if not ran:
            continue
        xs = [c["voxels"] for c in ran]
        line = ax.plot(xs, [c99(c) for c in ran], "o-", label=f"iso {iso:g}: isowall, C = 99% (own)")[0]
        peers = [(c["voxels"], c["peer"]["total_s"]) for c in ran if c.get("peer", {}).get("total_s")]
        if peers:
            ax.plot(*zip(*peers), "s--", color=line.get_color(), alpha=0.6, label=f"iso {iso:g}: FE + Embree")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("voxels")
    ax.set_ylabel("seconds")
    name = cs[0]["volume"] if cs else ""
    ax.set_title(f"{name}: default render, {meta['size']}, warm")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)

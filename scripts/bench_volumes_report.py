"""Tables, targets and plots of scripts/bench_volumes.py from its cases: one dict per
volume, isovalue and scale, with "engine" (the default render's median run) and "peer"."""
# The acceptance, per volume and isovalue.
PICTURE_C, PICTURE_IOU = 0.99, 0.999  # the final image against the full surface, every scale
GROWTH_LIMIT, GROWTH_RESOLVED = 1.5, 2.0  # C = 99% against the truth, 1x to 4x
PEER_LIMIT = 1 / 20  # C = 99% against the truth over FE + Embree, at 4x
TRIS_PER_PX_LIMIT = 2.0  # triangles drawn by C = 99% per covered pixel, every scale


def fmt(x, digits=3):
    return "-" if x is None else f"{x:.{digits}f}"


def c99(case):
    return case.get("engine", {}).get("truth", {}).get("c99")


def tris_per_px(case):
    e = case.get("engine")
    if not e or e["truth"]["tris_c99"] is None or not e["covered_px"]:
        return None
    return e["truth"]["tris_c99"] / e["covered_px"]


def peer_ratio(case):
    t, p = c99(case), case.get("peer", {}).get("total_s")
    return t / p if t and p else None


def groups(cases):
    """{(volume, iso): [cases by scale]} in the order measured."""
    out = {}
    for c in cases:
        out.setdefault((c["volume"], c["iso"]), []).append(c)
    return out


def verdicts(cases):
    """One row per volume and isovalue: growth, picture, peer and triangle figures, each judged."""
    rows = []
    for (name, iso), cs in groups(cases).items():
        ran = [c for c in cs if "engine" in c]
        one = next((c for c in ran if c["scale"] == 1), None)
        top = max(ran, key=lambda c: c["scale"], default=None)
        growth = c99(top) / c99(one) if one and top and top is not one and c99(one) and c99(top) else None
        worst_c = min((c["engine"]["c_vs_full"] for c in ran), default=None)
        worst_iou = min((c["engine"]["iou_vs_full"] for c in ran), default=None)
        worst_tris = max((t for t in map(tris_per_px, ran) if t is not None), default=None)
        rows.append({
            "volume": name, "iso": iso, "top_scale": top["scale"] if top else None, "growth": growth,
            "growth_holds": None if growth is None or top["scale"] != 4 else growth <= GROWTH_LIMIT,
            "growth_resolved": None if growth is None or top["scale"] != 4 else growth <= GROWTH_RESOLVED,
            "c_vs_full": worst_c, "iou_vs_full": worst_iou,
            "picture_holds": None if worst_c is None else worst_c >= PICTURE_C and worst_iou >= PICTURE_IOU,
            "peer_ratio_4x": peer_ratio(top) if top and top["scale"] == 4 else None,
            "tris_per_px": worst_tris,
            "tris_holds": None if worst_tris is None else worst_tris <= TRIS_PER_PX_LIMIT,
            "skipped": [f"{c['scale']:g}x: {c['skipped']}" for c in cs if "skipped" in c]})
        r = rows[-1]
        r["peer_holds"] = None if r["peer_ratio_4x"] is None else r["peer_ratio_4x"] <= PEER_LIMIT
    return rows


def word(holds):
    return "not measured" if holds is None else ("holds" if holds else "MISSED")


def volume_table(cs):
    lines = ["| scale | voxels | C=90% s | C=99% s | C=99.9% s | C=99% own s | every ray s | "
             "final C vs full | IoU vs full | triangles by C=99% | per covered px | FE+Embree s | "
             "C=99% / peer |", "|" + "---|" * 13]
    for c in cs:
        if "skipped" in c:
            lines.append(f"| {c['scale']:g}x | {c['voxels'] / 1e6:.0f} M | skipped: {c['skipped']} |" + " |" * 10)
            continue
        e, t = c["engine"], c["engine"]["truth"]
        lines.append(
            f"| {c['scale']:g}x | {c['voxels'] / 1e6:.0f} M | {fmt(t['c90'])} | {fmt(t['c99'])} | "
            f"{fmt(t['c999'])} | {fmt(e['own']['c99'])} | {fmt(e['every_ray_s'])} | {e['c_vs_full']:.5f} | "
            f"{e['iou_vs_full']:.5f} | {t['tris_c99'] or '-'} | {fmt(tris_per_px(c), 2)} | "
            f"{fmt(c.get('peer', {}).get('total_s'))} | {fmt(peer_ratio(c))} |")
    return "\n".join(lines)


def report(meta, cases):
    out = [f"# Every shared volume, default `isowall render` ({meta['date']}, {meta['cores']} cores, "
           f"load {meta['load_average']})", "",
           f"{meta['size']}, front view, warm (`--warm-up`), median of {meta['runs']} runs by C = 99% "
           "against the full surface at full resolution (\"C=99% s\": the truth; \"own\": against the "
           f"engine's final image). The whole run took {meta['seconds']} s.", ""]
    for (name, iso), cs in groups(cases).items():
        out += [f"## {name}, iso {iso:g}", "", volume_table(cs), ""]
    rows = verdicts(cases)
    out += ["## Targets", "",
            f"| volume | iso | growth of C=99%, 1x to largest | {GROWTH_LIMIT}x ({GROWTH_RESOLVED}x to resolve) | "
            f"worst final C / IoU vs full | picture | C=99% / peer at 4x | 1/20 | worst triangles per px | "
            f"<= {TRIS_PER_PX_LIMIT:g} | skipped |", "|" + "---|" * 11]
    for r in rows:
        g = "-" if r["growth"] is None else f"{r['growth']:.2f}x (to {r['top_scale']:g}x)"
        gw = word(r["growth_holds"]) + ("" if r["growth_resolved"] is None else
                                        f" / {word(r['growth_resolved'])}")
        cf = "-" if r["c_vs_full"] is None else f"{r['c_vs_full']:.5f} / {r['iou_vs_full']:.5f}"
        out.append(f"| {r['volume']} | {r['iso']:g} | {g} | {gw} | {cf} | {word(r['picture_holds'])} | "
                   f"{fmt(r['peer_ratio_4x'])} | {word(r['peer_holds'])} | {fmt(r['tris_per_px'], 2)} | "
                   f"{word(r['tris_holds'])} | {'; '.join(r['skipped']) or '-'} |")
    out += ["", "## The worst case", ""]
    def worst(key, pick):
        have = [r for r in rows if r[key] is not None]
        return pick(have, key=lambda r: r[key]) if have else None
    for key, pick, what in (("growth", max, "growth of C = 99% against the truth"),
                            ("c_vs_full", min, "final image C against the full surface"),
                            ("peer_ratio_4x", max, "C = 99% over FE + Embree at 4x"),
                            ("tris_per_px", max, "triangles by C = 99% per covered pixel")):
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
        ran = [c for c in g if "engine" in c and c99(c)]
        if not ran:
            continue
        xs = [c["voxels"] for c in ran]
        line = ax.plot(xs, [c99(c) for c in ran], "o-", label=f"iso {iso:g}: isowall, C = 99% vs full")[0]
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

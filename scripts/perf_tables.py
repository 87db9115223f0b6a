#!/usr/bin/env python3
"""Write the tables of one scripts/perf-report.sh run into the docs.

    python3 scripts/perf_tables.py OUT [--check]

OUT is the folder perf-report.sh filled (machine.json, main/{ours,peers}.json, the
OpenCV-only peer runs t1/, map4k/, map4k-t1/, load.json, kernel-cost.md, views-cost.md,
frame4k.txt). Each table goes between a pair of markers in docs/performance.md and
docs/huge.md:

    <!-- perf-report:NAME -->
    ...replaced...
    <!-- /perf-report:NAME -->

A block whose inputs are missing (a step skipped) is left as it was, and said so on
stderr. --check: only report which blocks would change.
"""

import json
import os
import re
import sys

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOCS = ["docs/performance.md", "docs/huge.md"]


def load(out, *parts):
    p = os.path.join(out, *parts)
    if not os.path.exists(p):
        return None
    with open(p) as f:
        return json.load(f) if p.endswith(".json") else f.read()


def fmt(v, prec=2, dash="-"):
    return dash if v is None else f"{v:.{prec}f}"


def step_str(v):
    return "-" if v is None else str(v)


def run_block(m):
    if m is None:
        return None
    return (
        f"Run of {m['date']} (commit {m['commit']}): `nproc` = {m['nproc']}, "
        f"{m['cpu']}, {m['mem_gb']} GB RAM; load average {m['load_before']} before and "
        f"{m['load_after']} after the run; {m['kernel']}. Total {m['minutes']:.1f} min.\n"
    )


def table_name(r):
    """The table column: wide/high, with the surface when it is not the cylinder."""
    surface = r.get("surface")
    name = r["lut"] or "-"
    return f"{name} {surface}" if surface and surface != "cylinder" else name


def bench_table(rows, hfov, lut):
    sel = [r for r in rows if r["hfov"] == hfov and "psnr_ss_db" not in r
           and r["lut"] in (lut, None)]
    if not sel:
        return None
    out = [
        "| renderer | sampler | step | table | ms median | ms min | Mpx/s | max err px "
        "| mean err px | PSNR dB | exact px |",
        "|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in sel:
        ex = r.get("exact_fraction")
        out.append(
            f"| {r['renderer']} | {r['sampler']} | {step_str(r['index_step'])} | "
            f"{table_name(r)} | {r['ms_median']:.2f} | {r['ms_min']:.2f} | "
            f"{r.get('mpix_s', 0):.0f} | {fmt(r['max_err_px'], 4)} | "
            f"{fmt(r['mean_err_px'], 5)} | {fmt(r['psnr_db'], 1)} | "
            f"{'-' if ex is None else f'{ex * 100:.2f}%'} |")
    first = sel[0]
    head = (f"**hfov {hfov:g}** ({lut} table; {first['frames']} frames; "
            f"{first['width']}x{first['height']} from {first['map_width']}x"
            f"{first['map_height']}, {first['threads']} threads, kernel "
            f"{first.get('kernel', '?')})\n\n")
    return head + "\n".join(out) + "\n"


def minify_table(rows):
    sel = [r for r in rows if "psnr_ss_db" in r]
    if not sel:
        return None
    out = ["| renderer | sampler | step | output | ms median | PSNR vs 8x8 supersampled exact, dB |",
           "|---|---|---|---|---:|---:|"]
    for r in sel:
        out.append(f"| {r['renderer']} | {r['sampler']} | {step_str(r['index_step'])} | "
                   f"{r['width']}x{r['height']} hfov {r['hfov']:g} | {r['ms_median']:.2f} | "
                   f"{r['psnr_ss_db']:.2f} |")
    return "\n".join(out) + "\n"


def peers_table(p):
    if p is None:
        return None
    out = [f"{p['width']}x{p['height']} from {p['map_width']}x{p['map_height']}, "
           f"{p['threads']} threads, {p['views']} views x {p['reps']} reps\n",
           "| peer | their ms (median) | ours | our ms | ours/theirs | their PSNR vs our exact |",
           "|---|---:|---|---:|---:|---:|"]
    for r in p["rows"]:
        ratio = fmt(r["ratio_ours_over_theirs"], 3)
        ps = r["psnr_db_vs_exact"]
        ps = "-" if ps is None else ("identical" if ps == float("inf") else f"{ps:.1f} dB")
        out.append(f"| {r['peer']} | {r['ms_median']:.2f} | {r['ours']} | "
                   f"{fmt(r['ours_ms'])} | {ratio} | {ps} |")
    return "\n".join(out) + "\n"


def peer_row(p, key):
    if p is None:
        return None
    return next((r for r in p["rows"] if r["key"] == key), None)


def remap_table(runs):
    """OpenCV remap against the LUT bilinear frame, per map size and thread count."""
    out = ["| map, threads | LUT bilinear ms | OpenCV fixed-point ms | ours/theirs | "
           "OpenCV float ms | ours/theirs | LUT nearest ms | OpenCV fixed nearest ms | ours/theirs |",
           "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    any_row = False
    for name, p in runs:
        fb, fl, nn = (peer_row(p, k) for k in ("cv_fixed_bil", "cv_float_bil", "cv_fixed_nn"))
        if not fb:
            continue
        any_row = True
        out.append(
            f"| {p['map_width']}x{p['map_height']}, {p['threads']} | {fmt(fb['ours_ms'])} | "
            f"{fb['ms_median']:.2f} | {fmt(fb['ratio_ours_over_theirs'], 3)} | "
            f"{fmt(fl and fl['ms_median'])} | {fmt(fl and fl['ratio_ours_over_theirs'], 3)} | "
            f"{fmt(nn and nn['ours_ms'])} | {fmt(nn and nn['ms_median'])} | "
            f"{fmt(nn and nn['ratio_ours_over_theirs'], 3)} |")
    return "\n".join(out) + "\n" if any_row else None


def load_table(rows):
    if not rows:
        return None
    out = ["| map | JPEG | load s (read + decode + convert) | tables s | frame ms bilinear "
           "| frame ms nearest | pyramid s | frame ms trilinear | frame ms bilinear on the "
           "level | frame ms bilinear on the map | frame ms trilinear on the map | map GiB | pyramid GiB | peak RSS after load GiB "
           "| peak RSS GiB |",
           "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    g = 1 << 30
    for s in rows:
        out.append(
            f"| {s['width']}x{s['height']} | {s['file_bytes'] / 1e6:.1f} MB | "
            f"{s['load_s']:.2f} ({s['read_s']:.2f} + {s['decode_s']:.2f} + "
            f"{s['convert_s']:.2f}) | {s['tables_s']:.3f} | {s['frame_ms_bilinear']:.1f} | "
            f"{s['frame_ms_nearest']:.1f} | {s['pyramid_s']:.2f} | "
            f"{s['frame_ms_trilinear']:.1f} | {s.get('frame_ms_bilinear_level', 0):.1f} | "
            f"{s.get('frame_ms_bilinear_map', 0):.1f} | "
            f"{s.get('frame_ms_trilinear_map', 0):.1f} | "
            f"{s['map_bytes'] / g:.2f} | "
            f"{s['pyramid_bytes'] / g:.2f} | {s['peak_after_load_bytes'] / g:.2f} | "
            f"{s['peak_bytes'] / g:.2f} |")
    return "\n".join(out) + "\n"


def verdict(value, limit):
    if value is None:
        return "not measured"
    return "met" if value <= limit else f"**missed by {value / limit:.2f}x**"


def targets_table(ours, peers, runs, load, load120, frame4k):
    """Issue 16's targets against this run."""
    if not ours:
        return None

    def ms(renderer, sampler, hfov=90.0, step="adaptive"):
        for r in ours:
            if (r["renderer"] == renderer and r["sampler"] == sampler and r["hfov"] == hfov
                    and "psnr_ss_db" not in r and r.get("surface") in (None, "cylinder")
                    and (renderer != "lut" or r["index_step"] == step)):
                return r["ms_median"]
        return None

    rows = ["| target | measured | |", "|---|---|---|"]
    for name, p in runs:
        for key, what in (("cv_fixed_bil", "fixed-point"), ("cv_float_bil", "float")):
            r = peer_row(p, key)
            if r and r["ratio_ours_over_theirs"] is not None:
                q = r["ratio_ours_over_theirs"]
                rows.append(
                    f"| LUT bilinear <= 0.5x OpenCV remap, {what} maps ({p['map_width']}x"
                    f"{p['map_height']}, {p['threads']} thread{'s' if p['threads'] > 1 else ''}) | "
                    f"{r['ours_ms']:.2f} / "
                    f"{r['ms_median']:.2f} ms = {q:.2f}x | {verdict(q, 0.5)} |")
    lut_nn, gather = ms("lut", "nearest"), ms("gather", "nearest")
    if lut_nn and gather:
        q = lut_nn / gather
        rows.append(f"| LUT nearest <= 1.2x the plain gather (hfov 90) | {lut_nn:.2f} / "
                    f"{gather:.2f} ms = {q:.2f}x | {verdict(q, 1.2)} |")
    by_w = {s["width"]: s for s in load or []}
    if 8192 in by_w:
        s = by_w[8192]
        q = s["frame_ms_trilinear"] / s["frame_ms_bilinear"]
        rows.append(f"| trilinear <= 1.3x bilinear (8192 map pan, bench-load) | "
                    f"{s['frame_ms_trilinear']:.1f} / {s['frame_ms_bilinear']:.1f} ms = "
                    f"{q:.2f}x | {verdict(q, 1.3)} |")
    for hfov, rows_of in ((90, load), (120, load120)):
        by_w = {s["width"]: s for s in rows_of or []}
        if 8192 not in by_w or 32768 not in by_w:
            rows.append(f"| 32768 map frame <= 1.25x the 8192 frame, hfov {hfov} | - | "
                        "not measured |")
            continue
        a, b = by_w[8192], by_w[32768]
        for k, what in (("bilinear", "bilinear (still: the level no pixel is magnified "
                                     "beyond √2 on)"),
                        ("bilinear_map", "bilinear on the map itself"),
                        ("trilinear", "trilinear (still: the same level)"),
                        ("trilinear_map", "trilinear on the map itself"),
                        ("bilinear_level", "bilinear on the level (while moving)")):
            f = f"frame_ms_{k}"
            if not a.get(f) or not b.get(f):
                continue
            q = b[f] / a[f]
            v = ("for reference (the library's default; the window's still frames read the "
                 "level)" if k.endswith("_map") else verdict(q, 1.25))
            rows.append(f"| 32768 map frame <= 1.25x the 8192 frame, {what}, hfov {hfov} | "
                        f"{b[f]:.1f} / {a[f]:.1f} ms = {q:.2f}x | {v} |")
    cube, lut_bil = ms("cube-scanline", "bilinear"), ms("lut", "bilinear")
    if cube and lut_bil:
        q = cube / lut_bil
        rows.append(f"| cube scanline bilinear <= 1.0x LUT equirect bilinear | {cube:.2f} / "
                    f"{lut_bil:.2f} ms = {q:.2f}x | {verdict(q, 1.0)} |")
    if frame4k:
        m = re.search(r"median ([0-9.]+) ms", frame4k)
        if m:
            t = float(m.group(1))
            rows.append(f"| 3840x2160 from the 8192 map, bilinear, 2 threads: aim <= 16.7 ms | "
                        f"{t:.2f} ms | {verdict(t, 16.7)} |")
    errs = [r["max_err_px"] for r in ours
            if r["renderer"] == "lut" and r["max_err_px"] is not None and "psnr_ss_db" not in r]
    if errs:
        e = max(errs)
        rows.append(f"| accuracy: max sampling-position error <= 0.05 px | {e:.4f} px | "
                    f"{verdict(e, 0.05)} |")
    return "\n".join(rows) + "\n"


def blocks(out):
    m = load(out, "machine.json")
    ours = load(out, "main", "ours.json")
    peers = load(out, "main", "peers.json")
    runs = [(n, load(out, n, "peers.json")) for n in ("main", "t1", "map4k", "map4k-t1")]
    runs = [(n, p) for n, p in runs if p]
    load_rows = load(out, "load.json")
    load120 = load(out, "load120.json")
    frame4k = load(out, "frame4k.txt")
    return {
        "run": run_block(m),
        "bench-90": ours and bench_table(ours, 90.0, "wide"),
        "bench-50": ours and bench_table(ours, 50.0, "high"),
        "minify": ours and minify_table(ours),
        "peers": peers_table(peers),
        "remap": remap_table(runs),
        "targets16": targets_table(ours, peers, runs, load_rows, load120, frame4k),
        "kernel-cost": load(out, "kernel-cost.md"),
        "views-cost": load(out, "views-cost.md"),
        "bench-load": load_table(load_rows),
        "bench-load-120": load_table(load120),
    }


def main():
    args = [a for a in sys.argv[1:] if a != "--check"]
    check = "--check" in sys.argv[1:]
    if len(args) != 1:
        sys.exit(__doc__)
    out = args[0]
    if not os.path.isdir(out):
        sys.exit(f"perf_tables: {out}: not a folder (run scripts/perf-report.sh first)")
    new = blocks(out)
    seen = set()
    for doc in DOCS:
        path = os.path.join(REPO, doc)
        text = open(path).read()

        def sub(mt):
            name = mt.group(1)
            seen.add(name)
            body = new.get(name)
            if body is None:
                print(f"perf_tables: {doc}: {name}: no data in {out}, left as it was",
                      file=sys.stderr)
                return mt.group(0)
            return f"<!-- perf-report:{name} -->\n{body.rstrip()}\n<!-- /perf-report:{name} -->"

        pat = re.compile(r"<!-- perf-report:([a-z0-9-]+) -->\n.*?<!-- /perf-report:\1 -->",
                         re.S)
        updated = pat.sub(sub, text)
        if updated != text:
            print(f"perf_tables: {doc} {'would change' if check else 'updated'}",
                  file=sys.stderr)
            if not check:
                open(path, "w").write(updated)
    for name in new:
        if name not in seen:
            print(f"perf_tables: no marker for {name} in the docs", file=sys.stderr)


if __name__ == "__main__":
    main()

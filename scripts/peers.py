#!/usr/bin/env python3
"""Peers measured side by side with our LUT renderer, in one run.

    python3 scripts/peers.py [--size 1920x1080] [--threads 2] [--out /tmp/peers]
                             [--viewer target/release/viewer] [--no-install] [--no-ffmpeg]
                             [--no-py360] [--no-nona] [--rounds N]
                             [--view YAW,PITCH,HFOV ...]

1. Installs the peers with the ordinary tools if missing: `pip install
   opencv-python-headless numpy py360convert`, `apt-get install -y ffmpeg hugin-tools`.
2. Runs `viewer bench --json --export-maps OUT` (our numbers, hfov-90 view set, the
   generated 8192x4096 grid map, same thread count) which also exports the source map,
   the exact sampling maps (OpenCV convention: u - 0.5, v - 0.5) and our exact renders.
3. Renders the same views with
   * OpenCV `remap`, maps precomputed: float32 maps, and fixed point (`convertMaps` to
     CV_16SC2; the conversion is timed separately as map building), bilinear and nearest;
   * OpenCV with the map built per view in numpy (float64 math, float32 maps), + remap;
   * ffmpeg `v360` (equirect -> flat), which builds its whole table for each view: timed
     as (ffmpeg run with v360) - (the same run with a plain crop instead), per view;
   * py360convert `e2p` (numpy; builds its sampling grid on every call), one call per view;
   * Hugin's `nona` from a PTO project per view, timed minus a 1x1-output run (loading).
   All with the same thread count (`cv2.setNumThreads`, ffmpeg `-filter_threads`).
4. With `--rounds N`, N - 1 more rounds of ours (`viewer bench --only-default`: the
   LUT's default nearest and bilinear alone) then OpenCV's four remaps, in turns: our
   time is the median of the rounds' medians, OpenCV's the median of all its rounds'
   timings, so a machine whose speed drifts weighs on both alike.
5. Prints a table: median ms per frame, our time as a ratio to theirs, and their PSNR
   against our exact render (same sampler). Writes OUT/peers.json.
6. With `--view YAW,PITCH,HFOV` (repeatable): `viewer bench --view` times exactly those
   views (ours, every round) and OpenCV remaps exactly those; a per-view table follows
   (our LUT bilinear against OpenCV's fixed-point and float bilinear remap of the same
   view), also in peers.json as "per_view" (each with its "view": [yaw, pitch, hfov]).

The source map is padded by one wrapped column on each side so OpenCV's
BORDER_REPLICATE clamps vertically and wraps horizontally, as our convention does.
"""

import argparse
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import time

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def install(no_install):
    try:
        import cv2  # noqa: F401
        import numpy  # noqa: F401
    except ImportError:
        if no_install:
            sys.exit("peers: opencv-python-headless and numpy are missing (pip install them)")
        subprocess.run([sys.executable, "-m", "pip", "install", "-q",
                        "opencv-python-headless", "numpy"], check=True)
    try:
        import py360convert  # noqa: F401
    except ImportError:
        if not no_install:
            subprocess.run([sys.executable, "-m", "pip", "install", "-q", "py360convert"],
                           check=True)
    missing = [pkg for pkg, exe in [("ffmpeg", "ffmpeg"), ("hugin-tools", "nona")]
               if shutil.which(exe) is None]
    if missing and not no_install:
        env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
        subprocess.run(["apt-get", "update", "-q"], check=True, env=env)
        subprocess.run(["apt-get", "install", "-y", "-q"] + missing, check=True, env=env)


def psnr(a, b):
    import numpy as np
    d = a.astype(np.float64) - b.astype(np.float64)
    mse = float(np.mean(d * d))
    return float("inf") if mse == 0 else 10.0 * np.log10(255.0 ** 2 / mse)


def pooled_psnr(pairs):
    import numpy as np
    sse, n = 0.0, 0
    for a, b in pairs:
        d = a.astype(np.float64) - b.astype(np.float64)
        sse += float(np.sum(d * d))
        n += d.size
    return float("inf") if sse == 0 else 10.0 * np.log10(255.0 ** 2 / (sse / n))


def numpy_maps(yaw, pitch, hfov, w, h, mw, mh):
    """The exact equirect sampling map of conventions.md, in numpy (OpenCV centers)."""
    import numpy as np
    f = (w / 2) / np.tan(np.radians(hfov) / 2)
    x = np.arange(w, dtype=np.float64) + 0.5 - w / 2
    y = h / 2 - (np.arange(h, dtype=np.float64) + 0.5)
    X, Y = np.meshgrid(x, y)
    Z = np.full_like(X, f)
    p, q = np.radians(pitch), np.radians(yaw)
    # pitch about X (Z toward +Y), then yaw about Y (Z toward +X)
    Y1 = Y * np.cos(p) + Z * np.sin(p)
    Z1 = -Y * np.sin(p) + Z * np.cos(p)
    X2 = X * np.cos(q) + Z1 * np.sin(q)
    Z2 = -X * np.sin(q) + Z1 * np.cos(q)
    lam = np.arctan2(X2, Z2)
    phi = np.arctan2(Y1, np.hypot(X2, Z2))
    u = (lam + np.pi) / (2 * np.pi) * mw
    v = (np.pi / 2 - phi) / np.pi * mh
    return (u - 0.5).astype(np.float32), (v - 0.5).astype(np.float32)


def median_ms(times):
    return statistics.median(times) * 1e3


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", default="1920x1080")
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    ap.add_argument("--out", default="/tmp/peers")
    ap.add_argument("--viewer", default=os.path.join(REPO, "target/release/viewer"))
    ap.add_argument("--reps", type=int, default=3, help="timed repetitions per view")
    ap.add_argument("--no-install", action="store_true")
    ap.add_argument("--no-ffmpeg", action="store_true")
    ap.add_argument("--no-py360", action="store_true", help="skip py360convert")
    ap.add_argument("--no-nona", action="store_true", help="skip Hugin's nona")
    ap.add_argument("--bench-args", default="", help="extra arguments for viewer bench")
    ap.add_argument("--view", action="append", default=[], metavar="YAW,PITCH,HFOV",
                    help="time exactly this view (repeatable; passed to viewer bench --view)")
    ap.add_argument("--rounds", type=int, default=1,
                    help="rounds of the OpenCV remap timings, each after a `viewer bench "
                         "--only-default` of ours (the first after the full bench): ours and "
                         "theirs timed in turns, medians over the rounds")
    a = ap.parse_args()
    given = []
    for s in a.view:
        try:
            vals = [float(x) for x in s.split(",")]
        except ValueError:
            vals = []
        if len(vals) != 3 or not all(math.isfinite(x) for x in vals):
            sys.exit(f"peers: --view '{s}' must be YAW,PITCH,HFOV in degrees (three numbers)")
        given.append(vals)
    view_args = [x for s in a.view for x in ("--view", s)]
    install(a.no_install)
    import cv2
    import numpy as np

    if not os.path.exists(a.viewer):
        sys.exit(f"peers: {a.viewer} not found (cargo build --release -p viewer)")
    os.makedirs(a.out, exist_ok=True)
    ours_path = os.path.join(a.out, "ours.json")
    cmd = [a.viewer, "bench", "--size", a.size, "--threads", str(a.threads),
           "--export-maps", a.out, "--json"] + view_args + a.bench_args.split()
    print("peers: running", " ".join(cmd), file=sys.stderr)
    with open(ours_path, "w") as fo:
        subprocess.run(cmd, check=True, stdout=fo)
    ours = json.load(open(ours_path))
    meta = json.load(open(os.path.join(a.out, "views.json")))
    w, h, mw, mh = meta["width"], meta["height"], meta["map_width"], meta["map_height"]
    n = a.threads
    cv2.setNumThreads(n)

    src = np.fromfile(os.path.join(a.out, meta["map"]), dtype=np.uint8).reshape(mh, mw, 3)
    srcp = np.ascontiguousarray(np.concatenate([src[:, -1:], src, src[:, :1]], axis=1))

    res = {k: [] for k in ["cv_float_bil", "cv_fixed_bil", "cv_float_nn", "cv_fixed_nn",
                           "cv_convert", "np_build", "np_build_remap", "ff_v360", "py360", "nona"]}
    imgs = {k: [] for k in ["cv_float_bil", "cv_fixed_bil", "cv_float_nn", "cv_fixed_nn",
                            "np_build_remap", "ff_v360", "py360", "nona"]}
    np_map_err = 0.0
    # Per view (index in views.json): the remap timings, for the per-view table.
    per_view = {k: {} for k in ["cv_float_bil", "cv_fixed_bil", "cv_float_nn", "cv_fixed_nn"]}
    for i, v in enumerate(meta["views"]):
        rd = lambda name, dt: np.fromfile(os.path.join(a.out, v[name]), dtype=dt)  # noqa: E731
        mx = rd("mapx", np.float32).reshape(h, w) + 1.0  # +1: the padding column
        my = rd("mapy", np.float32).reshape(h, w)
        ex_bil = rd("exact_bilinear", np.uint8).reshape(h, w, 3)
        ex_nn = rd("exact_nearest", np.uint8).reshape(h, w, 3)

        def timed(key, fn, reps=a.reps):
            out = None
            for _ in range(reps + 1):  # +1 warm-up
                t = time.perf_counter()
                out = fn()
                dt = time.perf_counter() - t
                if _ > 0:
                    res[key].append(dt)
                    if key in per_view:
                        per_view[key].setdefault(i, []).append(dt)
            return out

        bil, nn, rep = cv2.INTER_LINEAR, cv2.INTER_NEAREST, cv2.BORDER_REPLICATE
        o = timed("cv_float_bil", lambda: cv2.remap(srcp, mx, my, bil, borderMode=rep))
        imgs["cv_float_bil"].append((o, ex_bil))
        m1, m2 = timed("cv_convert", lambda: cv2.convertMaps(mx, my, cv2.CV_16SC2))
        o = timed("cv_fixed_bil", lambda: cv2.remap(srcp, m1, m2, bil, borderMode=rep))
        imgs["cv_fixed_bil"].append((o, ex_bil))
        # Nearest: OpenCV rounds to the nearest integer center, ours takes the pixel
        # containing (u, v): the same choice, up to ties.
        o = timed("cv_float_nn", lambda: cv2.remap(srcp, mx, my, nn, borderMode=rep))
        imgs["cv_float_nn"].append((o, ex_nn))
        n1, _ = cv2.convertMaps(mx, my, cv2.CV_16SC2, nninterpolation=True)
        o = timed("cv_fixed_nn", lambda: cv2.remap(srcp, n1, None, nn, borderMode=rep))
        imgs["cv_fixed_nn"].append((o, ex_nn))

        # Per view: build the map in numpy, then remap (float maps).
        def np_remap_per_view():
            t = time.perf_counter()
            bx, by = numpy_maps(v["yaw"], v["pitch"], v["hfov"], w, h, mw, mh)
            res["np_build"].append(time.perf_counter() - t)
            return cv2.remap(srcp, bx + 1.0, by, bil, borderMode=rep), bx, by
        o, bx, by = timed("np_build_remap", np_remap_per_view, reps=1)
        imgs["np_build_remap"].append((o, ex_bil))
        np_map_err = max(np_map_err, float(np.max(np.abs(bx + 1.0 - mx))),
                         float(np.max(np.abs(by - my))))
        print(f"peers: opencv view {i + 1}/{len(meta['views'])}", file=sys.stderr)

    if not a.no_ffmpeg and shutil.which("ffmpeg"):
        mapfile = os.path.join(a.out, meta["map"])
        outfile = os.path.join(a.out, "ff.rgb")
        vfov = lambda hf: 2 * np.degrees(np.arctan(np.tan(np.radians(hf) / 2) * h / w))  # noqa: E731

        def ff(vf):
            cmd = ["ffmpeg", "-v", "error", "-y", "-threads", str(n), "-filter_threads", str(n),
                   "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{mw}x{mh}", "-i", mapfile,
                   "-vf", vf, "-frames:v", "1", "-f", "rawvideo", "-pix_fmt", "rgb24", outfile]
            t = time.perf_counter()
            subprocess.run(cmd, check=True)
            return time.perf_counter() - t

        base = [ff(f"format=gbrp,crop={w}:{h}:0:0") for _ in range(a.reps + 1)][1:]
        base_s = statistics.median(base)
        for i, v in enumerate(meta["views"]):
            ex_bil = np.fromfile(os.path.join(a.out, v["exact_bilinear"]),
                                 dtype=np.uint8).reshape(h, w, 3)
            # Mapping to our conventions: v360's yaw and pitch have our signs (checked by
            # PSNR: the opposite signs give a different picture); its yaw range is
            # [-180, 180], so yaw is wrapped; h_fov/v_fov are the full angles of the flat
            # output, v_fov from our square-pixel aspect.
            yaw = (v["yaw"] + 180.0) % 360.0 - 180.0
            vf = (f"format=gbrp,v360=input=e:output=flat:yaw={yaw}:pitch={v['pitch']}:"
                  f"h_fov={v['hfov']}:v_fov={vfov(v['hfov'])}:w={w}:h={h}:interp=linear")
            times = [ff(vf) for _ in range(a.reps)]
            res["ff_v360"].extend(max(t - base_s, 0.0) for t in times)
            o = np.fromfile(outfile, dtype=np.uint8).reshape(h, w, 3)
            imgs["ff_v360"].append((o, ex_bil))
            print(f"peers: ffmpeg view {i + 1}/{len(meta['views'])}", file=sys.stderr)
        res["ff_base"] = base

    try:
        import py360convert
    except ImportError:
        py360convert = None
    if not a.no_py360 and py360convert is not None:
        vfov_deg = lambda hf: 2 * np.degrees(np.arctan(np.tan(np.radians(hf) / 2) * h / w))  # noqa: E731
        for i, v in enumerate(meta["views"]):
            ex_bil = np.fromfile(os.path.join(a.out, v["exact_bilinear"]),
                                 dtype=np.uint8).reshape(h, w, 3)
            # e2p(equirect, (h_fov, v_fov), u_deg (yaw, + right), v_deg (pitch, + up),
            # (out_h, out_w)): it builds its sampling grid for every call, like v360.
            yaw = (v["yaw"] + 180.0) % 360.0 - 180.0
            t = time.perf_counter()
            o = py360convert.e2p(src, (v["hfov"], vfov_deg(v["hfov"])), yaw, v["pitch"],
                                 (h, w), mode="bilinear")
            res["py360"].append(time.perf_counter() - t)
            imgs["py360"].append((np.clip(o, 0, 255).astype(np.uint8), ex_bil))
            print(f"peers: py360convert view {i + 1}/{len(meta['views'])}", file=sys.stderr)

    if not a.no_nona and shutil.which("nona"):
        # Hugin's nona: one run per view from a PTO project (equirect input, rectilinear
        # output), timed minus the same run with a 1x1 output (loading the map).
        tif = os.path.join(a.out, "map.tif")
        cv2.imwrite(tif, src[:, :, ::-1])
        pto_path, out_prefix = os.path.join(a.out, "view.pto"), os.path.join(a.out, "nona")

        def nona(yaw, pitch, hfov, ow, oh):
            # The source is turned by -yaw, -pitch (PTools image yaw/pitch). PTools applies
            # pitch before yaw, so only pitch-0 views match our camera exactly; the cost
            # does not depend on the view.
            with open(pto_path, "w") as f:
                f.write(f'p f0 w{ow} h{oh} v{hfov} E0 R0 n"TIFF_m c:NONE"\nm i0\n'
                        f'i w{mw} h{mh} f4 v360 Ra0 Rb0 Rc0 Rd0 Re0 Eev0 Er1 Eb1 r0 '
                        f'p{-pitch} y{-yaw} TrX0 TrY0 TrZ0 j0 a0 b0 c0 d0 e0 g0 t0 Va1 Vb0 '
                        f'Vc0 Vd0 Vx0 Vy0 Vm5 n"{tif}"\n')
            t = time.perf_counter()
            subprocess.run(["nona", "-o", out_prefix, pto_path], check=True,
                           stdout=subprocess.DEVNULL)
            return time.perf_counter() - t

        base_s = statistics.median([nona(0, 0, 90, 1, 1) for _ in range(a.reps + 1)][1:])
        for i, v in enumerate(meta["views"]):
            yaw = (v["yaw"] + 180.0) % 360.0 - 180.0
            times = [nona(yaw, v["pitch"], v["hfov"], w, h) for _ in range(a.reps)]
            res["nona"].extend(max(t - base_s, 0.0) for t in times)
            if v["pitch"] == 0:
                o = cv2.imread(out_prefix + "0000.tif", cv2.IMREAD_UNCHANGED)[:, :, 2::-1]
                ex_bil = np.fromfile(os.path.join(a.out, v["exact_bilinear"]),
                                     dtype=np.uint8).reshape(h, w, 3)
                imgs["nona"].append((np.ascontiguousarray(o[:, :, :3]), ex_bil))
            print(f"peers: nona view {i + 1}/{len(meta['views'])}", file=sys.stderr)

    # Later rounds: ours (`viewer bench --only-default`: the LUT's default configurations
    # alone) and then OpenCV's remaps again, in turns, so that a VM whose speed drifts by
    # 20-30 % over seconds weighs on both alike (one round timed ours and theirs a minute
    # apart: the 8k fixed-point ratio measured 0.40x and 0.56x in two runs of one code).
    round_args, skip = [], False
    for x in a.bench_args.split():
        if skip:
            skip = False
        elif x in ("--plot", "--export-maps"):
            skip = True
        else:
            round_args.append(x)
    later = []
    for rnd in range(2, a.rounds + 1):
        cmd = [a.viewer, "bench", "--size", a.size, "--threads", str(a.threads), "--json",
               "--only-default"] + view_args + round_args
        later.append(json.loads(subprocess.run(cmd, check=True, stdout=subprocess.PIPE,
                                               stderr=subprocess.DEVNULL).stdout))
        for vi, v in enumerate(meta["views"]):
            rd = lambda name, dt: np.fromfile(os.path.join(a.out, v[name]), dtype=dt)  # noqa: E731
            mx = rd("mapx", np.float32).reshape(h, w) + 1.0
            my = rd("mapy", np.float32).reshape(h, w)
            m1, m2 = cv2.convertMaps(mx, my, cv2.CV_16SC2)
            n1, _ = cv2.convertMaps(mx, my, cv2.CV_16SC2, nninterpolation=True)
            bil, nn, rep = cv2.INTER_LINEAR, cv2.INTER_NEAREST, cv2.BORDER_REPLICATE
            for key, fn in [
                ("cv_float_bil", lambda: cv2.remap(srcp, mx, my, bil, borderMode=rep)),
                ("cv_fixed_bil", lambda: cv2.remap(srcp, m1, m2, bil, borderMode=rep)),
                ("cv_float_nn", lambda: cv2.remap(srcp, mx, my, nn, borderMode=rep)),
                ("cv_fixed_nn", lambda: cv2.remap(srcp, n1, None, nn, borderMode=rep)),
            ]:
                for rep_i in range(a.reps + 1):  # +1 warm-up
                    t = time.perf_counter()
                    fn()
                    if rep_i > 0:
                        dt = time.perf_counter() - t
                        res[key].append(dt)
                        per_view[key].setdefault(vi, []).append(dt)
        print(f"peers: round {rnd}/{a.rounds} (ours, then OpenCV remap)", file=sys.stderr)

    def our_view(sampler, view):
        """Median over the rounds of our LUT (adaptive step) row timing `view`."""
        vals = [r["ms_median"] for rows in [ours] + later for r in rows
                if r["renderer"] == "lut" and r["sampler"] == sampler
                and r.get("surface", "cylinder") == "cylinder"
                and r["index_step"] == "adaptive" and r.get("view") == view]
        return statistics.median(vals) if vals else None

    def our(sampler, step, rows=None):
        if given:
            # The given views: the median over them of our per-view medians.
            vals = [our_view(sampler, [v["yaw"], v["pitch"], v["hfov"]]) for v in meta["views"]]
            vals = [x for x in vals if x is not None]
            return statistics.median(vals) if vals else None
        if rows is None:
            vals = [our(sampler, step, r) for r in [ours] + later]
            vals = [x for x in vals if x is not None]
            return statistics.median(vals) if vals else None
        for r in rows:
            if (r["renderer"] == "lut" and r["sampler"] == sampler and r["lut"] == "wide"
                    and r.get("surface", "cylinder") == "cylinder"
                    and r["index_step"] == step and r["hfov"] == 90.0):
                return r["ms_median"]
        return None

    def ours_of(name, sampler):
        for r in ours:
            if r["renderer"] == name and r["sampler"] == sampler and r["hfov"] == 90.0:
                return r["ms_median"]
        return None

    # Our default configuration: the adaptive index step (the same 0.05 px bound as any
    # fixed step; the longest spans the bound allows).
    lut_bil, lut_nn = our("bilinear", "adaptive"), our("nearest", "adaptive")
    rows = []

    def add(name, key, ours_ms, what, extra=None):
        if not res.get(key):
            return
        ms = median_ms(res[key])
        if extra:
            ms += median_ms(res[extra])
        p = pooled_psnr(imgs[key]) if key in imgs and imgs[key] else None
        # Identical images have an infinite PSNR, which JSON cannot hold (Python would
        # write `Infinity`, which `viewer bench --replot` rightly refuses): null with
        # "identical": true instead.
        same = p is not None and math.isinf(p)
        rows.append({"peer": name, "key": key, "ms_median": ms, "ours_ms": ours_ms,
                     "ours": what, "ratio_ours_over_theirs": ours_ms / ms if ours_ms and ms > 0 else None,
                     "psnr_db_vs_exact": None if same else p, "identical": same})

    add("OpenCV remap, float maps, bilinear", "cv_float_bil", lut_bil, "lut bilinear adaptive")
    add("OpenCV remap, fixed-point maps, bilinear", "cv_fixed_bil", lut_bil, "lut bilinear adaptive")
    add("OpenCV remap, float maps, nearest", "cv_float_nn", lut_nn, "lut nearest adaptive")
    add("OpenCV remap, fixed-point maps, nearest", "cv_fixed_nn", lut_nn, "lut nearest adaptive")
    add("OpenCV convertMaps (map building only)", "cv_convert", None, "-")
    add("numpy map build per view (float64)", "np_build", None, "-")
    add("OpenCV per view: numpy map + remap", "np_build_remap", lut_bil, "lut bilinear adaptive")
    add("ffmpeg v360 per view (table build + 1 frame)", "ff_v360", lut_bil, "lut bilinear adaptive")
    add("py360convert e2p per view (grid + 1 frame)", "py360", lut_bil, "lut bilinear adaptive")
    add("Hugin nona per view (minus loading; PSNR: pitch-0 views)", "nona", lut_bil,
        "lut bilinear adaptive")
    add("our plain gather (precomputed indices)", "cv_fixed_nn", ours_of("gather", "nearest"),
        "gather")
    rows[-1]["peer"] = "OpenCV fixed nearest vs our plain gather"

    summary = {"threads": n, "width": w, "height": h, "map_width": mw, "map_height": mh,
               "views": len(meta["views"]), "reps": a.reps, "rounds": a.rounds,
               "ours_lut_bilinear_adaptive_rounds_ms":
                   [our("bilinear", "adaptive", r) for r in [ours] + later],
               "ours_lut_bilinear_adaptive_ms": lut_bil, "ours_lut_nearest_adaptive_ms": lut_nn,
               "ours_lut_nearest_step4_ms": lut_nn,
               "numpy_map_max_diff_px": np_map_err,
               "ffmpeg_baseline_ms": median_ms(res["ff_base"]) if res.get("ff_base") else None,
               "rows": rows, "per_view": []}
    for i, v in enumerate(meta["views"]):
        view = [v["yaw"], v["pitch"], v["hfov"]]
        row = {"view": view, "ours_lut_bilinear_adaptive_ms": our_view("bilinear", view)}
        for key in ["cv_fixed_bil", "cv_float_bil"]:
            t = per_view[key].get(i)
            ms = median_ms(t) if t else None
            row[key + "_ms"] = ms
            o = row["ours_lut_bilinear_adaptive_ms"]
            row["ratio_ours_over_" + key] = o / ms if o and ms else None
        summary["per_view"].append(row)
    json.dump(summary, open(os.path.join(a.out, "peers.json"), "w"), indent=2, allow_nan=False)
    print(f"peers: {w}x{h} from {mw}x{mh}, {n} threads, {len(meta['views'])} views x {a.reps} reps")
    print(f"| peer | their ms (median) | ours | our ms | ours/theirs | their PSNR vs our exact |")
    print("|---|---:|---|---:|---:|---:|")
    for r in rows:
        ratio = f"{r['ratio_ours_over_theirs']:.3f}" if r["ratio_ours_over_theirs"] else "-"
        om = f"{r['ours_ms']:.2f}" if r["ours_ms"] else "-"
        p = r["psnr_db_vs_exact"]
        ps = "identical" if r["identical"] else ("-" if p is None else f"{p:.1f} dB")
        print(f"| {r['peer']} | {r['ms_median']:.2f} | {r['ours']} | {om} | {ratio} | {ps} |")
    print(f"numpy-built maps vs our exported exact maps: max |diff| {np_map_err:.2e} px")
    if given:
        print("| view [yaw, pitch, hfov] | ours (LUT bilinear) ms | OpenCV fixed ms | ours/fixed "
              "| OpenCV float ms | ours/float |")
        print("|---|---:|---:|---:|---:|---:|")
        f = lambda x, d=2: "-" if x is None else f"{x:.{d}f}"  # noqa: E731
        for r in summary["per_view"]:
            print(f"| {r['view']} | {f(r['ours_lut_bilinear_adaptive_ms'])} "
                  f"| {f(r['cv_fixed_bil_ms'])} | {f(r['ratio_ours_over_cv_fixed_bil'], 3)} "
                  f"| {f(r['cv_float_bil_ms'])} | {f(r['ratio_ours_over_cv_float_bil'], 3)} |")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Writes the EULUMDAT fixtures of this folder (and the IES twins of the synthetic ones).

Run from this folder: python3 make_fixtures.py. Deterministic; the output is committed.
Values are written with few decimals so the LDT and IES twins hold exactly the same
numbers (LDT cd/klm × lamp flux / 1000 × conversion factor = IES candela × multiplier).
"""
import math

IES_DIR = "../ies/"


def read_ies_values(path):
    """(vertical angles, horizontal angles, candela rows) of an IES fixture, as strings."""
    text = open(path).read().split("\n")
    i = next(k for k, l in enumerate(text) if l.startswith("TILT="))
    toks = " ".join(text[i + 1:]).split()
    if text[i].strip() == "TILT=INCLUDE":
        n = int(toks[1])
        toks = toks[2 + 2 * n:]
    nv, nh = int(toks[3]), int(toks[4])
    toks = toks[13:]
    v, h, c = toks[:nv], toks[nv:nv + nh], toks[nv + nh:]
    return v, h, [c[k * nv:(k + 1) * nv] for k in range(nh)]


def fmt(x, nd=2):
    s = f"{x:.{nd}f}".rstrip("0").rstrip(".")
    return s if s not in ("-0", "") else "0"


def ldt(name, *, ityp, isym, c_angles, g_angles, planes, flux, lamps=1, conv=1.0,
        lorl=100.0, dff=100.0, tilt=0.0, sets=None, dc=None, dg=None, luminaire=None,
        company="lutpano test fixtures", eol="\n", encoding="ascii", dr=None, dims=None):
    """planes: the stored planes' cd/klm columns, already in file order, as strings."""
    mc, ng = len(c_angles), len(g_angles)
    if dc is None:
        dc = c_angles[1] - c_angles[0] if mc > 1 else 0
    if dg is None:
        dg = g_angles[1] - g_angles[0]
    sets = sets or [(lamps, "LED module", flux, "3000", "80", 15)]
    dims = dims or [120, 0, 40, 100, 0, 0, 0, 0, 0]
    lines = [company, ityp, isym, mc, fmt(dc), ng, fmt(dg), "FIXTURE-" + name,
             luminaire or name, name.upper(), name + ".ldt", "2025-01-01 lutpano"]
    lines += [fmt(d) for d in dims]
    lines += [fmt(dff), fmt(lorl), fmt(conv, 3), fmt(tilt), len(sets)]
    for (n, kind, fl, cct, cri, w) in sets:
        lines += [n, kind, fmt(fl), cct, cri, fmt(w)]
    lines += [fmt(d, 3) for d in (dr or [0.5, 0.55, 0.6, 0.65, 0.68, 0.72, 0.75, 0.77, 0.8, 0.82])]
    lines += [fmt(a) for a in c_angles] + [fmt(a) for a in g_angles]
    for col in planes:
        lines += col
    data = eol.join(str(l) for l in lines) + eol
    open(name + ".ldt", "wb").write(data.encode(encoding))


def ies(name, v, h, rows, lumens, mult=1.0):
    out = ["IESNA:LM-63-2002", f"[TEST] twin of {name}.ldt", "[MANUFAC] lutpano test fixtures",
           "TILT=NONE", f"1 {fmt(lumens)} {fmt(mult)} {len(v)} {len(h)} 1 2 0 0 0", "1 1 15",
           " ".join(fmt(a) for a in v), " ".join(fmt(a) for a in h)]
    out += [" ".join(r) for r in rows]
    open(name + ".ies", "w").write("\n".join(out) + "\n")


# --- from the photompy IES fixtures (same candela, LDT units) -------------------------
v, _, rows = read_ies_values(IES_DIR + "label_lines.ies")
g = [float(a) for a in v]
# Relative, 2000 lm: cd/klm = cd / 2.
ldt("rotational_label_lines", ityp=1, isym=1, c_angles=[0], g_angles=g, dc=0,
    planes=[[fmt(float(c) / 2, 3) for c in rows[0]]], flux=2000)
# Absolute (negative lamp count), luminaire flux 4000 lm: cd/klm = cd / 4.
ldt("absolute_led", ityp=1, isym=1, c_angles=[0], g_angles=g, dc=0, lamps=-1,
    planes=[[fmt(float(c) / 4, 4) for c in rows[0]]], flux=4000)
# 500 lm and conversion factor 1.5, the twin of relative_photometry_with_multiplier.ies
# (500 lm, multiplier 1.5): cd/klm = cd × 2.
v, _, rows = read_ies_values(IES_DIR + "relative_photometry_with_multiplier.ies")
ldt("relative_conversion", ityp=1, isym=1, c_angles=[0], g_angles=[float(a) for a in v],
    dc=0, planes=[[fmt(float(c) * 2, 3) for c in rows[0]]], flux=500, conv=1.5)
# Quadrant: tilt_include_v19.ies has C 0, 45, 90 (Mc = 8, Dc = 45); 1000 lm: cd/klm = cd.
v, h, rows = read_ies_values(IES_DIR + "tilt_include_v19.ies")
ldt("quadrant_tilt_include", ityp=3, isym=4, c_angles=[45.0 * i for i in range(8)],
    g_angles=[float(a) for a in v], planes=rows, flux=1000)

# --- synthetic twins: the same distribution as LDT and as IES --------------------------
G = [5.0 * i for i in range(37)]  # 0..180
C = [15.0 * i for i in range(24)]  # 0..345


def down(gam):
    """A downlight with some uplight (cd)."""
    r = math.radians(gam)
    return 800 * math.cos(r) ** 2 if gam < 90 else 120 * abs(math.cos(r))


def table(f, cs):
    return [[round(f(c, gg), 1) for gg in G] for c in cs]


def twin(name, isym, f, ies_cs, ldt_cs):
    flux = 2000.0  # cd/klm = cd / 2, exactly, with two decimals
    ldt(name, ityp=3, isym=isym, c_angles=C, g_angles=G, flux=flux,
        planes=[[fmt(x / 2) for x in col] for col in table(f, ldt_cs)])
    ies(name, G, ies_cs, [[fmt(x, 1) for x in col] for col in table(f, ies_cs)], flux)


cosd = lambda a: math.cos(math.radians(a))
sind = lambda a: math.sin(math.radians(a))
twin("bilateral_c0_c180", 2, lambda c, g: down(g) * (1 + 0.35 * cosd(c)),
     C[:13], C[:13])
# Isym 3 stores C270 ... C345, C0 ... C90; the IES twin stores C90 ... C270.
twin("bilateral_c90_c270", 3, lambda c, g: down(g) * (1 + 0.4 * sind(c) + 0.1 * cosd(2 * c)),
     [90 + 15.0 * i for i in range(13)], C[18:] + C[:7])
twin("no_symmetry", 0,
     lambda c, g: down(g) * (1 + 0.3 * cosd(c) + 0.2 * sind(c) + 0.1 * cosd(2 * c)), C, C)
# A wall washer: dark behind (C90 to C180 all zero) and above the horizontal.
twin("wallwasher_c0_c180", 2,
     lambda c, g: (0 if g >= 90 or c >= 90 else
                   900 * math.sin(math.radians(g)) ** 0.7 * cosd(c) ** 1.5 + 20 * cosd(g)),
     C[:13], C[:13])

# --- a realistic file -------------------------------------------------------------------
# A recessed 600 mm office louvre luminaire with 2 × T5 28 W, as manufacturers publish
# them: Ityp 2 (linear), Isym 4, 24 C planes × 37 γ, CR LF line ends, ISO-8859-1 text,
# no light above the horizontal, a second (alternative) lamp set, and intensities scaled
# so that they integrate to LORL = 74.6 % of the lamp flux.
def louvre(c, gam):
    if gam >= 90:
        return 0.0
    r = math.radians(gam)
    across = math.cos(r) ** 1.2 * (1 + 0.25 * math.sin(2 * r))  # C0: across the lamps
    along = math.cos(r) ** 2.2  # C90: along the lamps
    w = math.cos(math.radians(c)) ** 2
    return w * across + (1 - w) * along


def flux_per_klm(f):
    """Lumens per 1000 lm of a distribution given in cd/klm (fine midpoint rule)."""
    n, m, tot = 720, 360, 0.0
    for i in range(n):
        th = (i + 0.5) * math.pi / n
        ring = sum(f(360.0 * (j + 0.5) / m, math.degrees(th)) for j in range(m)) / m
        tot += ring * math.sin(th) * math.pi / n * 2 * math.pi
    return tot


LORL = 74.6
k = LORL * 10 / flux_per_klm(louvre)  # cd/klm so that Φ = LORL % of 1000 lm
quarter = [[fmt(k * louvre(c, gg), 1) for gg in G] for c in C[:7]]
ldt("office_louvre_2x28w", ityp=2, isym=4, c_angles=C, g_angles=G, flux=5200, lorl=LORL,
    dff=100, company="Beispiel Leuchten GmbH (synthetic, for tests)",
    luminaire="Einbauleuchte Büro 2x28W T5 Raster", eol="\r\n", encoding="latin-1",
    sets=[(2, "T5 28W/840", 5200, "4000", "1B", 62),
          (2, "T5 35W/840 (alternative)", 6600, "4000", "1B", 78)],
    dims=[597, 597, 80, 570, 570, 0, 0, 0, 0],
    dr=[0.61, 0.68, 0.73, 0.78, 0.81, 0.86, 0.89, 0.91, 0.94, 0.96], planes=quarter)

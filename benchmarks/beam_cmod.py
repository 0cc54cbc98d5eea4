#!/usr/bin/env python3
"""Load against crack-mouth opening of sppm's beams over the experimental envelope.

Usage:
  python3 benchmarks/beam_cmod.py --envelope FILE --out FIGURE.svg --title TEXT \
      RUN_DIR=LABEL [RUN_DIR=LABEL ...]

RUN_DIR is a folder written by `sppm run` of a beam with a gauge named CMOD
(lattices/beam_3pb_*_3d.toml have one); its force_displacement.csv gives the load (the
probe's force, sign turned to positive) against `gauge_CMOD_m`. A CSV file written by
benchmarks/cohesive_beam.py --csv may stand in its place (its CMOD over 20 mm).

FILE is the envelope of the experiments of Grégoire et al. (2013), d = 50 mm, as digitised by
Hobbs (2021) and published with his code (the public repository mark-hobbs/pypd):
  - the half-notched beam: examples/data/half_notched_beam.csv, columns
    `cmod, load_min, load_max` (CMOD in mm, loads in N);
  - the unnotched beam: tests/experimental_data.h5, dataset `load_CMOD`, rows CMOD (mm),
    mean, minimum and maximum load (kN); reading it needs h5py (`pip install h5py`).

The script writes one SVG (no plotting library needed) and prints, for each run and for the
envelope, the peak load and the CMOD at the peak, as Markdown rows.
"""
import csv
import math
import sys

COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"]


def envelope(path):
    """(cmod_mm, load_min_N, load_max_N, load_mean_N or None) lists, zero rows dropped."""
    if path.endswith(".h5"):
        import h5py

        d = h5py.File(path, "r")["load_CMOD"][()]
        rows = [
            (d[0][i], 1e3 * d[2][i], 1e3 * d[3][i], 1e3 * d[1][i])
            for i in range(len(d[0]))
            if d[0][i] > 0.0
        ]
    else:
        with open(path) as f:
            r = csv.reader(f)
            next(r)
            rows = [(float(a), float(b), float(c), None) for a, b, c in r]
    rows.sort(key=lambda t: t[0])
    return rows


def run(path):
    """(cmod_mm, load_N) of an sppm run's folder (its force_displacement.csv, the gauge named
    CMOD) or of the CSV of benchmarks/cohesive_beam.py (its CMOD over 20 mm)."""
    name = path if path.endswith(".csv") else f"{path}/force_displacement.csv"
    with open(name) as f:
        rows = list(csv.DictReader(f))
    if rows and "cmod_20mm_m" in rows[0]:
        return [(1e3 * float(r["cmod_20mm_m"]), float(r["load_N"])) for r in rows]
    if not rows or "gauge_CMOD_m" not in rows[0]:
        sys.exit(f"{name} has no gauge_CMOD_m column: run a beam with a gauge named CMOD")
    return [(1e3 * float(r["gauge_CMOD_m"]), -float(r["force_N"])) for r in rows]


def peak(points):
    return max(points, key=lambda p: p[1])


def svg(env, runs, title, out):
    w, h, left, right, top, bottom = 640, 420, 70, 20, 40, 55
    xmax = max(p[0] for _, pts in runs for p in pts)
    xmax = max(xmax, 2.5 * peak([(e[0], e[2]) for e in env])[0])
    ymax = 1.1 * max(max(e[2] for e in env), max(p[1] for _, pts in runs for p in pts))
    sx = lambda x: left + (w - left - right) * x / xmax
    sy = lambda y: h - bottom - (h - top - bottom) * y / ymax
    env = [e for e in env if e[0] <= xmax]
    parts = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12">',
        f'<rect width="{w}" height="{h}" fill="white"/>',
        f'<text x="{w / 2}" y="22" text-anchor="middle" font-size="14">{title}</text>',
    ]
    band = [(sx(e[0]), sy(e[2])) for e in env] + [(sx(e[0]), sy(e[1])) for e in reversed(env)]
    parts.append(
        '<polygon fill="#bbbbbb" fill-opacity="0.6" stroke="none" points="'
        + " ".join(f"{x:.1f},{y:.1f}" for x, y in band)
        + '"/>'
    )
    if env[0][3] is not None:
        parts.append(
            '<polyline fill="none" stroke="#555555" stroke-dasharray="4,3" points="'
            + " ".join(f"{sx(e[0]):.1f},{sy(e[3]):.1f}" for e in env)
            + '"/>'
        )
    for k, (label, pts) in enumerate(runs):
        c = COLOURS[k % len(COLOURS)]
        parts.append(
            f'<polyline fill="none" stroke="{c}" stroke-width="1.8" points="'
            + " ".join(f"{sx(x):.1f},{sy(max(y, 0.0)):.1f}" for x, y in pts if x <= xmax)
            + '"/>'
        )
    # axes, ticks and labels
    x0, y0 = sx(0), sy(0)
    parts.append(f'<line x1="{x0}" y1="{y0}" x2="{sx(xmax)}" y2="{y0}" stroke="black"/>')
    parts.append(f'<line x1="{x0}" y1="{y0}" x2="{x0}" y2="{sy(ymax)}" stroke="black"/>')
    for t in ticks(xmax):
        parts.append(f'<line x1="{sx(t):.1f}" y1="{y0}" x2="{sx(t):.1f}" y2="{y0 + 5}" stroke="black"/>')
        parts.append(f'<text x="{sx(t):.1f}" y="{y0 + 18}" text-anchor="middle">{t:g}</text>')
    for t in ticks(ymax / 1e3):
        parts.append(f'<line x1="{x0 - 5}" y1="{sy(1e3 * t):.1f}" x2="{x0}" y2="{sy(1e3 * t):.1f}" stroke="black"/>')
        parts.append(f'<text x="{x0 - 8}" y="{sy(1e3 * t) + 4:.1f}" text-anchor="end">{t:g}</text>')
    parts.append(f'<text x="{(left + w - right) / 2}" y="{h - 15}" text-anchor="middle">CMOD (mm)</text>')
    parts.append(
        f'<text x="18" y="{(top + h - bottom) / 2}" text-anchor="middle" transform="rotate(-90 18 {(top + h - bottom) / 2})">load (kN)</text>'
    )
    # legend
    items = [("#bbbbbb", "experiments: min–max envelope", "10")]
    if env[0][3] is not None:
        items.append(("#555555", "experiments: mean", "4,3"))
    items += [(COLOURS[k % len(COLOURS)], label, None) for k, (label, _) in enumerate(runs)]
    for k, (c, text, dash) in enumerate(items):
        y = top + 12 + 17 * k
        xl = w - right - 270
        if dash == "10":
            parts.append(f'<rect x="{xl}" y="{y - 6}" width="24" height="10" fill="{c}" fill-opacity="0.6"/>')
        else:
            d = f' stroke-dasharray="{dash}"' if dash else ""
            parts.append(f'<line x1="{xl}" y1="{y}" x2="{xl + 24}" y2="{y}" stroke="{c}" stroke-width="1.8"{d}/>')
        parts.append(f'<text x="{xl + 30}" y="{y + 4}">{text}</text>')
    parts.append("</svg>")
    with open(out, "w") as f:
        f.write("\n".join(parts) + "\n")


def ticks(top):
    """About five round ticks from 0 to top."""
    mag = 10 ** math.floor(math.log10(top / 5))
    step = next(m * mag for m in (1, 2, 2.5, 5, 10) if m * mag >= top / 5)
    return [k * step for k in range(int(top / step + 1e-9) + 1)]


def main(argv):
    args = {"--envelope": None, "--out": None, "--title": ""}
    runs = []
    it = iter(argv)
    for a in it:
        if a in args:
            args[a] = next(it)
        else:
            folder, _, label = a.partition("=")
            runs.append((label or folder, run(folder)))
    if not args["--envelope"] or not args["--out"] or not runs:
        sys.exit(__doc__)
    env = envelope(args["--envelope"])
    svg(env, runs, args["--title"], args["--out"])
    lo, hi = peak([(e[0], e[1]) for e in env]), peak([(e[0], e[2]) for e in env])
    print("| curve | peak (N) | CMOD at the peak (mm) |")
    print("|---|---:|---:|")
    print(f"| experiments, minimum | {lo[1]:.0f} | {lo[0]:.4f} |")
    print(f"| experiments, maximum | {hi[1]:.0f} | {hi[0]:.4f} |")
    if env[0][3] is not None:
        m = peak([(e[0], e[3]) for e in env])
        print(f"| experiments, mean | {m[1]:.0f} | {m[0]:.4f} |")
    for label, pts in runs:
        p = peak(pts)
        print(f"| {label} | {p[1]:.0f} | {p[0]:.4f} |")


if __name__ == "__main__":
    main(sys.argv[1:])

#!/usr/bin/python3
"""pdnav plotting tool: figures a field tester wants from a replay output directory.

  tools/plot.py replay OUT_DIR [--background RASTER|MBTILES] [--title T] [--out DIR]
      track.png  estimated track, reference track, 1-sigma ellipses (over hillshaded terrain
                 when a GDAL-readable RASTER is given, e.g. /vsizip/N42E001.hgt.zip/N42E001.hgt,
                 or over the offline basemap when an .mbtiles from dem-tools/pdnav_basemap.py
                 is given: paths, streets, water, contours at the highest zoom that covers it)
      error.png  horizontal error vs time with the predicted 1-sigma and 2-sigma radius
                 (the layout of Broyles et al. 2018, Figs. 8-10)
  tools/plot.py fusion OUT_DIR [--title T] [--out DIR]
      fusion.png  a fused replay: the track coloured by the engine shown, and the horizontal
                  error and predicted 1-sigma vs time with every span without GNSS shaded;
                  with the replay's engines.csv, a third panel: each engine's own error
  tools/plot.py outage DIR [--title T] [--out DIR]
      <walk>_outage.png for every <walk>.csv of `pdnav eval-outage --out DIR` (and
      outage_summary.png when there are several walks or --start-fracs windows): the reference
                  (withheld fixes or truth), the fused track and dead reckoning from the last fix,
                  the withheld window highlighted; below, the error of both and the fused
                  1-sigma (semi-major) and 68 % radius vs time, the window shaded
  tools/plot.py gnss CSV [--out DIR]
      gnss_track.png, gnss_error.png, gnss_sats.png from `pdnav gnss --out CSV`

Uses Debian's python3-matplotlib / python3-numpy / python3-gdal (tools/setup installs them).
"""
import argparse
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

R_EARTH_M = 6378137.0


def read_csv(path):
    if not os.path.exists(path):
        sys.exit(f"plot: {path}: no such file")
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"plot: {path}: no rows to plot")
    return rows


def col(rows, name, default=float("nan")):
    out = []
    for r in rows:
        v = r.get(name, "")
        try:
            out.append(float(v) if v not in ("", None) else default)
        except ValueError:
            out.append(default)
    return np.array(out)


def local_en(lat, lon, lat0, lon0):
    e = np.radians(lon - lon0) * R_EARTH_M * math.cos(math.radians(lat0))
    n = np.radians(lat - lat0) * R_EARTH_M
    return e, n


def hillshade_background(ax, raster, lat0, lon0, extent_en):
    try:
        from osgeo import gdal
    except ImportError:
        print("plot: python3-gdal missing, no terrain background", file=sys.stderr)
        return
    gdal.UseExceptions()
    ds = gdal.Open(raster)
    gt = ds.GetGeoTransform()
    band = ds.GetRasterBand(1)
    e_min, e_max, n_min, n_max = extent_en
    lon_min = lon0 + math.degrees(e_min / (R_EARTH_M * math.cos(math.radians(lat0))))
    lon_max = lon0 + math.degrees(e_max / (R_EARTH_M * math.cos(math.radians(lat0))))
    lat_min = lat0 + math.degrees(n_min / R_EARTH_M)
    lat_max = lat0 + math.degrees(n_max / R_EARTH_M)
    x0 = int(max(0, math.floor((lon_min - gt[0]) / gt[1])))
    x1 = int(min(ds.RasterXSize, math.ceil((lon_max - gt[0]) / gt[1]) + 1))
    y0 = int(max(0, math.floor((lat_max - gt[3]) / gt[5])))
    y1 = int(min(ds.RasterYSize, math.ceil((lat_min - gt[3]) / gt[5]) + 1))
    if x1 - x0 < 2 or y1 - y0 < 2:
        print("plot: track is outside the background raster", file=sys.stderr)
        return
    z = band.ReadAsArray(x0, y0, x1 - x0, y1 - y0).astype(float)
    nodata = band.GetNoDataValue()
    if nodata is not None:
        z[z == nodata] = np.nan
    dx = gt[1] * math.pi / 180 * R_EARTH_M * math.cos(math.radians(lat0))
    dy = -gt[5] * math.pi / 180 * R_EARTH_M
    gy, gx = np.gradient(z, dy, dx)
    slope = np.arctan(np.hypot(gx, gy))
    aspect = np.arctan2(-gx, gy)
    az, alt = math.radians(315), math.radians(45)
    shade = np.sin(alt) * np.cos(slope) + np.cos(alt) * np.sin(slope) * np.cos(az - aspect)
    le0, ln1 = local_en(gt[3] + y0 * gt[5], gt[0] + x0 * gt[1], lat0, lon0)
    le1, ln0 = local_en(gt[3] + y1 * gt[5], gt[0] + x1 * gt[1], lat0, lon0)
    ax.imshow(shade, cmap="gray", extent=[le0, le1, ln0, ln1], origin="upper", alpha=0.55, zorder=0)
    cs = ax.contour(np.linspace(le0, le1, z.shape[1]), np.linspace(ln1, ln0, z.shape[0]), z,
                    levels=12, colors="saddlebrown", linewidths=0.4, alpha=0.6, zorder=1)
    ax.clabel(cs, fontsize=6, fmt="%d m")


def mbtiles_background(ax, path, lat0, lon0, extent_en, max_px=2400):
    """Draws the basemap tiles under the track: the highest zoom whose tiles cover the plot
    extent in at most max_px a side. Web Mercator tiles are placed by their corners in the
    local east/north plane (over a few km the map is linear in both to < 0.1 %)."""
    import io
    import sqlite3
    try:
        from PIL import Image
    except ImportError:
        print("plot: python3-pil missing, no basemap background", file=sys.stderr)
        return
    if not os.path.isfile(path):
        raise SystemExit(f"plot: {path}: no such MBTiles file")
    con = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
    try:
        meta = dict(con.execute("SELECT name, value FROM metadata").fetchall())
        zooms = sorted((r[0] for r in con.execute("SELECT DISTINCT zoom_level FROM tiles")), reverse=True)
    except sqlite3.Error as err:
        raise SystemExit(f"plot: {path}: not an MBTiles file: {err}")
    e_min, e_max, n_min, n_max = extent_en
    coslat = math.cos(math.radians(lat0))
    lon_w = lon0 + math.degrees(e_min / (R_EARTH_M * coslat))
    lon_e = lon0 + math.degrees(e_max / (R_EARTH_M * coslat))
    lat_s = lat0 + math.degrees(n_min / R_EARTH_M)
    lat_n = lat0 + math.degrees(n_max / R_EARTH_M)

    def tile_xy(lon, lat, z):
        n = 2 ** z
        return ((lon + 180.0) / 360.0 * n,
                (1.0 - math.asinh(math.tan(math.radians(lat))) / math.pi) / 2.0 * n)

    def tile_lonlat(x, y, z):
        n = 2 ** z
        return x / n * 360.0 - 180.0, math.degrees(math.atan(math.sinh(math.pi * (1 - 2 * y / n))))

    for z in zooms:
        fx0, fy0 = tile_xy(lon_w, lat_n, z)
        fx1, fy1 = tile_xy(lon_e, lat_s, z)
        x0, x1, y0, y1 = int(fx0), int(fx1), int(fy0), int(fy1)
        if (x1 - x0 + 1) * 256 > max_px or (y1 - y0 + 1) * 256 > max_px:
            continue
        need = [(x, y) for x in range(x0, x1 + 1) for y in range(y0, y1 + 1)]
        got = {}
        for x, y in need:
            row = con.execute("SELECT tile_data FROM tiles WHERE zoom_level=? AND tile_column=? AND tile_row=?",
                              (z, x, 2 ** z - 1 - y)).fetchone()
            if row is None:
                break
            got[(x, y)] = row[0]
        if len(got) < len(need):
            continue  # this zoom does not cover the plot (area of interest only): go lower
        img = Image.new("RGB", ((x1 - x0 + 1) * 256, (y1 - y0 + 1) * 256))
        for (x, y), data in got.items():
            img.paste(Image.open(io.BytesIO(data)).convert("RGB"), ((x - x0) * 256, (y - y0) * 256))
        lw, ln = tile_lonlat(x0, y0, z)
        le, ls = tile_lonlat(x1 + 1, y1 + 1, z)
        ew, nn = local_en(ln, lw, lat0, lon0)
        ee, ns = local_en(ls, le, lat0, lon0)
        ax.imshow(np.asarray(img), extent=[ew, ee, ns, nn], origin="upper", zorder=0, interpolation="bilinear")
        ax.text(0.995, 0.005, f"basemap z{z}: " + meta.get("attribution", ""), transform=ax.transAxes,
                ha="right", va="bottom", fontsize=5.5, color="#333333",
                bbox=dict(facecolor="white", alpha=0.7, lw=0, pad=1), zorder=10)
        con.close()
        print(f"plot: basemap {path} at zoom {z} ({len(got)} tiles)")
        return
    con.close()
    print(f"plot: {path}: no zoom covers the track (lon {lon_w:.5f}..{lon_e:.5f}, lat {lat_s:.5f}..{lat_n:.5f})",
          file=sys.stderr)


def ellipse_xy(e, n, a, b, orient_deg, k=1.0, pts=48):
    t = np.linspace(0, 2 * math.pi, pts)
    u, v = k * a * np.cos(t), k * b * np.sin(t)
    so, co = math.sin(math.radians(orient_deg)), math.cos(math.radians(orient_deg))
    return e + u * so + v * co, n + u * co - v * so


def plot_replay(args):
    rows = read_csv(os.path.join(args.dir, "track.csv"))
    t = (col(rows, "t_ns") - float(rows[0]["t_ns"])) * 1e-9
    lat, lon = col(rows, "lat_deg"), col(rows, "lon_deg")
    rlat, rlon = col(rows, "ref_lat_deg"), col(rows, "ref_lon_deg")
    lat0, lon0 = float(np.nanmean(lat)), float(np.nanmean(lon))
    e, n = local_en(lat, lon, lat0, lon0)
    re_, rn = local_en(rlat, rlon, lat0, lon0)
    a, b, o = col(rows, "semi_major_m"), col(rows, "semi_minor_m"), col(rows, "orientation_deg")
    engines = [r["engine"] for r in rows]

    fig, ax = plt.subplots(figsize=(9, 8))
    all_e = np.concatenate([e, re_[np.isfinite(re_)]])
    all_n = np.concatenate([n, rn[np.isfinite(rn)]])
    pad = max(50.0, 0.1 * max(np.nanmax(all_e) - np.nanmin(all_e), np.nanmax(all_n) - np.nanmin(all_n)))
    extent = (np.nanmin(all_e) - pad, np.nanmax(all_e) + pad, np.nanmin(all_n) - pad, np.nanmax(all_n) + pad)
    if args.background and args.background.endswith(".mbtiles"):
        mbtiles_background(ax, args.background, lat0, lon0, extent)
    elif args.background:
        hillshade_background(ax, args.background, lat0, lon0, extent)
    if np.isfinite(re_).any():
        ax.plot(re_, rn, "k-", lw=1.5, label="reference", zorder=3)
    for eng, colr in (("dead-reckoning", "tab:orange"), ("terrain", "tab:blue"), ("route", "tab:green"),
                      ("gnss", "tab:purple")):
        m = np.array([x == eng for x in engines])
        if m.any():
            ax.plot(np.where(m, e, np.nan), np.where(m, n, np.nan), "-", color=colr, lw=1.2,
                    label=f"estimate ({eng})", zorder=4)
    step = max(1, len(rows) // 40)
    for i in range(0, len(rows), step):
        if np.isfinite(a[i]):
            x, y = ellipse_xy(e[i], n[i], a[i], b[i], o[i])
            ax.plot(x, y, "-", color="tab:red", lw=0.6, alpha=0.7, zorder=5)
    ax.plot([], [], "-", color="tab:red", lw=0.6, label="1-sigma ellipse")
    ax.set_xlim(extent[0], extent[1])
    ax.set_ylim(extent[2], extent[3])
    ax.set_aspect("equal")
    ax.set_xlabel("east (m)")
    ax.set_ylabel("north (m)")
    ax.set_title(args.title or f"track: {os.path.basename(os.path.normpath(args.dir))}")
    ax.legend(loc="best", fontsize=8)
    fig.tight_layout()
    out_dir = args.out or args.dir
    os.makedirs(out_dir, exist_ok=True)
    out1 = os.path.join(out_dir, "track.png")
    fig.savefig(out1, dpi=110)
    plt.close(fig)
    written = [out1]

    err = np.hypot(col(rows, "err_e_m"), col(rows, "err_n_m"))
    if np.isfinite(err).any():
        sig = np.sqrt(a ** 2 + b ** 2)  # predicted DRMS
        fig, ax = plt.subplots(figsize=(9, 4))
        ax.plot(t, err, "b-", lw=1, label="horizontal error")
        ax.plot(t, sig, "r--", lw=1, label="predicted 1-sigma (DRMS)")
        ax.plot(t, 2 * sig, "r:", lw=1, label="predicted 2-sigma")
        ax.set_xlabel("time (s)")
        ax.set_ylabel("m")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        ax.set_title("error vs predicted uncertainty")
        fig.tight_layout()
        out2 = os.path.join(out_dir, "error.png")
        fig.savefig(out2, dpi=110)
        plt.close(fig)
        written.append(out2)
    for w in written:
        print(f"plot: wrote {w}")


ENGINE_COLOURS = {"gnss": "tab:blue", "route": "tab:green", "terrain": "tab:brown",
                  "dead-reckoning": "tab:red"}


def plot_fusion(args):
    """Track by engine and error/sigma vs time with the spans where GNSS was not shown shaded."""
    rows = read_csv(os.path.join(args.dir, "track.csv"))
    t = (col(rows, "t_ns") - float(rows[0]["t_ns"])) * 1e-9
    e, n = col(rows, "e_m"), col(rows, "n_m")
    err = np.hypot(col(rows, "err_e_m"), col(rows, "err_n_m"))
    sig = col(rows, "semi_major_m")
    eng = [r["engine"] for r in rows]
    if not np.isfinite(err).any():
        sys.exit(f"plot: {args.dir}/track.csv has no reference (Truth lines or phone fixes): nothing to score")
    # each engine's own estimate (replay's engines.csv), when the replay wrote one
    eng_path = os.path.join(args.dir, "engines.csv")
    eng_rows = read_csv(eng_path) if os.path.exists(eng_path) else []
    if eng_rows:
        fig, (ax1, ax2, ax3) = plt.subplots(3, 1, figsize=(9, 13), gridspec_kw={"height_ratios": [3, 2, 2]})
    else:
        fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(9, 10), gridspec_kw={"height_ratios": [3, 2]})
    for name in sorted(set(eng)):
        m = np.array([x == name for x in eng])
        ax1.plot(e[m], n[m], ".", ms=2, color=ENGINE_COLOURS.get(name, "tab:gray"), label=f"shown: {name}")
    ref_e, ref_n = e - col(rows, "err_e_m"), n - col(rows, "err_n_m")
    ax1.plot(ref_e, ref_n, "k-", lw=0.8, label="truth")
    ax1.set_aspect("equal")
    ax1.set_xlabel("east (m)")
    ax1.set_ylabel("north (m)")
    ax1.legend(loc="best", fontsize=8)
    ax1.set_title(args.title or "fused replay: the shown estimate by engine")
    no_gnss = np.array([x != "gnss" for x in eng])
    start = None
    for i, flag in enumerate(list(no_gnss) + [False]):
        if flag and start is None:
            start = i
        elif not flag and start is not None:
            ax2.axvspan(t[start], t[i - 1], color="0.85", lw=0)
            start = None
    ax2.plot(t, err, "b-", lw=0.8, label="horizontal error")
    ax2.plot(t, sig, "r--", lw=0.8, label="predicted 1-sigma (semi-major)")
    ax2.set_xlabel("time (s); grey = GNSS not shown")
    ax2.set_ylabel("m")
    ax2.legend(loc="upper left", fontsize=8)
    if eng_rows:
        # which engine said what: each engine's own error (engines.csv, once a second) beside the shown one
        te = (col(eng_rows, "t_ns") - float(rows[0]["t_ns"])) * 1e-9
        ee = np.hypot(col(eng_rows, "err_e_m"), col(eng_rows, "err_n_m"))
        names = [r["engine"] for r in eng_rows]
        for name in sorted(set(names)):
            m = np.array([x == name for x in names]) & np.isfinite(ee)
            if m.any():
                tt, yy = te[m], np.maximum(ee[m], 0.1)
                gap = np.where(np.diff(tt) > 3.0)[0] + 1  # no valid estimate in between: no line
                tt, yy = np.insert(tt, gap, np.nan), np.insert(yy, gap, np.nan)
                ax3.plot(tt, yy, "-", lw=0.9, color=ENGINE_COLOURS.get(name, "tab:gray"),
                         label=f"{name} engine on its own")
        ax3.plot(t, np.maximum(err, 0.1), "k-", lw=0.8, label="shown (fused)")
        ax3.set_yscale("log")
        ax3.set_xlabel("time (s)")
        ax3.set_ylabel("horizontal error (m)")
        ax3.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    out = args.out or args.dir
    os.makedirs(out, exist_ok=True)
    p = os.path.join(out, "fusion.png")
    fig.savefig(p, dpi=110)
    plt.close(fig)
    print(f"plot: wrote {p}")


def plot_outage(args):
    """Each walk of an eval-outage output folder: map and error/sigma vs time, window shaded."""
    import glob
    import json
    paths = sorted(p for p in glob.glob(os.path.join(args.dir, "*.csv")))
    if not paths:
        sys.exit(f"plot: {args.dir}: no per-walk CSV (run pdnav eval-outage --out {args.dir})")
    out = args.out or args.dir
    os.makedirs(out, exist_ok=True)
    metas = []
    for path in paths:
        rows = read_csv(path)
        stem = os.path.splitext(os.path.basename(path))[0]
        meta = {}
        if os.path.exists(os.path.join(args.dir, stem + ".json")):
            with open(os.path.join(args.dir, stem + ".json")) as f:
                meta = json.load(f)
            metas.append((stem, meta))
        t = col(rows, "t_s")
        win = col(rows, "in_window") > 0.5
        re_, rn = col(rows, "ref_e_m"), col(rows, "ref_n_m")
        fe, fn = col(rows, "fused_e_m"), col(rows, "fused_n_m")
        de, dn = col(rows, "dr_e_m"), col(rows, "dr_n_m")
        cee, cen, cnn = col(rows, "fused_cov_ee_m2"), col(rows, "fused_cov_en_m2"), col(rows, "fused_cov_nn_m2")
        # semi-major 1-sigma of the fused covariance
        tr, det = cee + cnn, cee * cnn - cen * cen
        smaj = np.sqrt(np.maximum(0.0, 0.5 * tr + np.sqrt(np.maximum(0.0, 0.25 * tr * tr - det))))
        ref_sig = col(rows, "ref_sigma_m")
        fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(9, 11), gridspec_kw={"height_ratios": [3, 2]})
        ax1.plot(re_[~win], rn[~win], ".", ms=3, color="0.55", label="reference (fixes used)")
        ax1.plot(re_[win], rn[win], ".", ms=4, color="k", label="reference withheld (the outage window)")
        ax1.plot(fe, fn, "-", lw=1.0, color="tab:blue", label="fused (auto)")
        ax1.plot(fe[win], fn[win], "-", lw=2.2, color="tab:blue", alpha=0.6)
        m = np.isfinite(de) & win
        ax1.plot(de[m], dn[m], "-", lw=1.2, color="tab:red", label="dead reckoning from the last fix (uncalibrated)")
        ia = np.where(win)[0]
        if len(ia):
            ax1.plot(re_[ia[0]], rn[ia[0]], "g^", ms=9, label="window start")
            ax1.plot(re_[ia[-1]], rn[ia[-1]], "ms", ms=8, label="window end")
            for i in ia[:: max(1, len(ia) // 12)]:  # 1-sigma ellipses along the window
                a, b = cee[i], cnn[i]
                c = cen[i]
                if not (np.isfinite(a) and np.isfinite(b) and np.isfinite(c)):
                    continue
                w, v = np.linalg.eigh(np.array([[a, c], [c, b]]))
                ang = np.linspace(0, 2 * np.pi, 48)
                pts = v @ (np.sqrt(np.maximum(w, 0))[:, None] * np.vstack([np.cos(ang), np.sin(ang)]))
                ax1.plot(fe[i] + pts[0], fn[i] + pts[1], "-", lw=0.6, color="tab:blue", alpha=0.7)
        ax1.set_aspect("equal")
        ax1.set_xlabel("east (m)")
        ax1.set_ylabel("north (m)")
        ax1.legend(loc="best", fontsize=8)
        cal = meta.get("calibration_before_window", {})
        sub = ""
        if cal.get("valid"):
            sub = (f"\ncalibration before the window: scale {cal['scale']:.3f} +- {cal['scale_sigma']:.3f}, "
                   f"heading bias {cal['heading_bias_deg']:.1f} +- {cal['heading_bias_sigma_deg']:.1f} deg "
                   f"({cal.get('window_epochs', cal.get('epochs'))} epochs, {cal['baseline_m']:.0f} m)"
                   + (f"\nheading from the GNSS course over ground: {cal['course_bias_deg']:.1f} +- "
                      f"{cal['course_bias_sigma_deg']:.1f} deg ({cal['course_epochs']} epochs)"
                      if cal.get("course_epochs", 0) > 0 else "")
                   + (f"\nscale from the GNSS speed: {cal['speed_scale']:.3f} +- {cal['speed_scale_sigma']:.3f} "
                      f"({cal['speed_epochs']} epochs)" if cal.get("speed_epochs", 0) > 0 else ""))
        elif meta:
            sub = "\nno calibration published before the window"
        ax1.set_title((args.title or f"{stem}: GNSS outage cut into the recording") + sub, fontsize=10)
        if len(ia):
            ax2.axvspan(t[ia[0]], t[ia[-1]], color="0.88", lw=0, label="GNSS withheld")
        ax2.plot(t, col(rows, "fused_err_m"), "b-", lw=0.9, label="fused error")
        ax2.plot(t, col(rows, "dr_err_m"), "r-", lw=0.9, label="dead reckoning error")
        ax2.plot(t, smaj, "b--", lw=0.8, label="fused 1-sigma (semi-major)")
        ax2.plot(t, np.sqrt(2.2958 * (smaj ** 2 + ref_sig ** 2)), "c:", lw=0.8,
                 label="68 % radius of fused + reference accuracy")
        if meta:
            ax2.set_title(f"in the window: fused RMS {meta['fused']['rms_m']:.1f} m, DR RMS {meta['dr']['rms_m']:.1f} m, "
                          f"ratio {meta['outage_ratio']:.2f}, coverage_68 {meta['coverage_68']:.2f}, "
                          f"max jump {meta['max_jump_sigma']:.2f} sigma"
                          + (f"\nthe median error at percentile {meta['median_percentile']:.0f} of the stated "
                             f"distribution (50 = calibrated)" if meta.get("median_percentile") is not None else ""),
                          fontsize=9)
        ax2.set_xlabel("time since the first GNSS (s)")
        ax2.set_ylabel("m")
        ax2.legend(loc="upper left", fontsize=8)
        fig.tight_layout()
        p = os.path.join(out, stem + "_outage.png")
        fig.savefig(p, dpi=110)
        plt.close(fig)
        print(f"plot: wrote {p}")
    if len(metas) >= 2:
        plot_outage_summary(metas, out, args.title)


def plot_outage_summary(metas, out, title):
    """Several walks (or windows of one walk, --start-fracs): ratio, RMS and coverage per walk
    against the bars, the summary line's median ratio and pooled coverage drawn across."""
    names = [m[0] for m in metas]
    ratio = np.array([m[1].get("outage_ratio", np.nan) for m in metas], dtype=float)
    cov = np.array([m[1].get("coverage_68", np.nan) for m in metas], dtype=float)
    n_ep = np.array([m[1].get("epochs_in_window", 0) for m in metas], dtype=float)
    f_rms = np.array([m[1].get("fused", {}).get("rms_m", np.nan) for m in metas], dtype=float)
    d_rms = np.array([m[1].get("dr", {}).get("rms_m", np.nan) for m in metas], dtype=float)
    ok = np.isfinite(cov) & (n_ep > 0)
    pooled = float(np.sum(cov[ok] * n_ep[ok]) / np.sum(n_ep[ok])) if ok.any() else float("nan")
    pct = np.array([np.nan if m[1].get("median_percentile") is None else m[1]["median_percentile"] for m in metas],
                   dtype=float)
    x = np.arange(len(names))
    fig, (a1, a2, a3, a4) = plt.subplots(4, 1, figsize=(max(7, 0.9 * len(names) + 3), 11.5), sharex=True)
    a1.bar(x, ratio, color="tab:blue")
    a1.axhline(0.5, color="k", ls="--", lw=0.8, label="bar 0.5")
    a1.axhline(np.nanmedian(ratio), color="tab:red", lw=1.0, label=f"median {np.nanmedian(ratio):.3f}")
    a1.set_ylabel("fused RMS / DR RMS")
    a1.legend(fontsize=8)
    a2.bar(x - 0.2, f_rms, 0.4, color="tab:blue", label="fused")
    a2.bar(x + 0.2, d_rms, 0.4, color="tab:red", label="dead reckoning from the last fix")
    a2.set_ylabel("RMS in the window, m")
    a2.legend(fontsize=8)
    a3.bar(x, cov, color="tab:green")
    a3.axhspan(0.5, 0.9, color="0.9", label="bar 0.5-0.9", zorder=0)
    a3.axhline(pooled, color="tab:red", lw=1.0, label=f"pooled {pooled:.3f}")
    a3.set_ylim(0, 1.05)
    a3.set_ylabel("inside the 68 % region")
    a3.legend(fontsize=8)
    # a window's error is correlated over minutes: its coverage is near 0 or 1; where its median
    # error falls in the stated distribution says how far inside or outside it sat
    a4.bar(x, pct, color="tab:purple")
    a4.axhline(50, color="k", ls="--", lw=0.8, label="50 = calibrated")
    if np.isfinite(pct).any():
        a4.axhline(np.nanmedian(pct), color="tab:red", lw=1.0, label=f"median {np.nanmedian(pct):.1f}")
    a4.set_ylim(0, 100)
    a4.set_ylabel("median error: percentile\nof the stated distribution")
    a4.legend(fontsize=8)
    a4.set_xticks(x)
    a4.set_xticklabels(names, rotation=30, ha="right", fontsize=8)
    a1.set_title(title or f"eval-outage over {len(names)} walks / windows", fontsize=10)
    fig.tight_layout()
    p = os.path.join(out, "outage_summary.png")
    fig.savefig(p, dpi=110)
    plt.close(fig)
    print(f"plot: wrote {p}")


def plot_gnss(args):
    rows = read_csv(args.csv)
    out = args.out or os.path.dirname(os.path.abspath(args.csv))
    os.makedirs(out, exist_ok=True)
    keys = rows[0].keys()
    tcol = "t_s" if "t_s" in keys else ("t_ns" if "t_ns" in keys else None)
    t = col(rows, tcol) if tcol else np.arange(len(rows), dtype=float)
    if tcol == "t_ns":
        t = (t - t[0]) * 1e-9
    else:
        t = t - t[0]
    written = []
    fig, ax = plt.subplots(figsize=(7, 7))
    for pre, colr in (("spp", "tab:orange"), ("kf", "tab:blue")):
        if f"{pre}_e_m" in keys:
            ax.plot(col(rows, f"{pre}_e_m"), col(rows, f"{pre}_n_m"), ".", ms=3, color=colr, label=pre.upper())
    ax.plot([0], [0], "k+", ms=14, label="truth")
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    ax.set_xlabel("east error (m)")
    ax.set_ylabel("north error (m)")
    ax.legend()
    fig.tight_layout()
    p = os.path.join(out, "gnss_track.png")
    fig.savefig(p, dpi=110)
    plt.close(fig)
    written.append(p)
    fig, ax = plt.subplots(figsize=(9, 4))
    for pre, colr in (("spp", "tab:orange"), ("kf", "tab:blue")):
        if f"{pre}_e_m" in keys:
            ax.plot(t, np.hypot(col(rows, f"{pre}_e_m"), col(rows, f"{pre}_n_m")), "-", color=colr, label=pre.upper())
    ax.set_xlabel("time (s)")
    ax.set_ylabel("horizontal error (m)")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    p = os.path.join(out, "gnss_error.png")
    fig.savefig(p, dpi=110)
    plt.close(fig)
    written.append(p)
    sat_cols = [k for k in keys if k.startswith("sats_")]
    if sat_cols:
        fig, ax = plt.subplots(figsize=(9, 3.5))
        for k in sat_cols:
            ax.step(t, col(rows, k), where="post", label=k[5:])
        ax.set_xlabel("time (s)")
        ax.set_ylabel("satellites used")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        p = os.path.join(out, "gnss_sats.png")
        fig.savefig(p, dpi=110)
        plt.close(fig)
        written.append(p)
    for w in written:
        print(f"plot: wrote {w}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("replay", help="plots of a `pdnav replay` output directory")
    r.add_argument("dir")
    r.add_argument("--background", help="GDAL raster for a hillshade background, or an .mbtiles "
                   "basemap (dem-tools/pdnav_basemap.py)")
    r.add_argument("--out", help="folder for the PNGs (default: the replay folder)")
    r.add_argument("--title")
    fu = sub.add_parser("fusion", help="track by engine and error vs time of a fused `pdnav replay`")
    fu.add_argument("dir")
    fu.add_argument("--out")
    fu.add_argument("--title")
    o = sub.add_parser("outage", help="per-walk plots of a `pdnav eval-outage --out DIR` folder")
    o.add_argument("dir")
    o.add_argument("--out")
    o.add_argument("--title")
    g = sub.add_parser("gnss", help="plots of a `pdnav gnss --out CSV` file")
    g.add_argument("csv")
    g.add_argument("--out")
    args = ap.parse_args()
    {"replay": plot_replay, "fusion": plot_fusion, "outage": plot_outage, "gnss": plot_gnss}[args.cmd](args)


if __name__ == "__main__":
    main()

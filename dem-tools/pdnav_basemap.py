#!/usr/bin/python3
"""pdnav offline basemap renderer (host only; Mapnik and GDAL from Debian). docs/basemap.md.

From the same DEM and OpenStreetMap extract the engines use, render raster XYZ tiles with
Mapnik (the renderer of the OpenStreetMap tile servers) into an MBTiles file osmdroid reads:
hillshade, labelled contour lines (gdal_contour, interval by zoom), footways / paths / tracks /
steps / streets styled by type, buildings, water, forests and names. The style is the one file
dem-tools/basemap-style.xml.

Zooms: --min-zoom..--max-zoom (default 10..17). Zooms below --detail-zoom (default 15) cover
the whole area (--center/--radius or --bbox); zooms from --detail-zoom up cover the area of
interest (--detail-radius around the centre, default 3000 m), so z17 stays small.

  pdnav_basemap.py render DEM OSM -o OUT.mbtiles --center LAT LON --radius M [...]
  pdnav_basemap.py preview MBTILES --zoom Z [--zoom Z ...] -o DIR     (PNG mosaics)

Errors (area outside the DEM or the OSM extract, unreadable input, bad arguments) print one line
"pdnav_basemap: error: <reason>" on stderr and exit with status 2.
"""
import argparse
import math
import os
import sqlite3
import sys
import tempfile
import time

from osgeo import gdal, ogr, osr

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pdnav_dem  # noqa: E402  (Area, raster checks: one definition of an area for all tools)

gdal.UseExceptions()
ogr.UseExceptions()

STYLE_PATH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "basemap-style.xml")
EARTH_R_M = 6378137.0  # EPSG:3857 sphere
ORIGIN_SHIFT_M = math.pi * EARTH_R_M
TILE_PX = 256
ATTRIBUTION = ("© OpenStreetMap contributors (ODbL, openstreetmap.org/copyright); "
               "terrain: SRTM (NASA/USGS, public domain)")
CONTOUR_BASE_M = 20.0  # finest contour interval drawn (z15+); coarser ones are subsets
CONTOUR_STEPS_M = (500, 100, 50, 20)


class BasemapError(Exception):
    """A user-facing error: printed as one line, exit status 2."""


# ---------------------------------------------------------------------------------------------
# Web Mercator tile arithmetic (XYZ, y down from the north; MBTiles stores TMS rows)
# ---------------------------------------------------------------------------------------------
def lonlat_to_merc_m(lon_deg, lat_deg):
    x = math.radians(lon_deg) * EARTH_R_M
    y = math.log(math.tan(math.pi / 4 + math.radians(lat_deg) / 2)) * EARTH_R_M
    return x, y


def merc_m_to_lonlat(x_m, y_m):
    lon = math.degrees(x_m / EARTH_R_M)
    lat = math.degrees(2 * math.atan(math.exp(y_m / EARTH_R_M)) - math.pi / 2)
    return lon, lat


def tile_size_m(z):
    return 2 * ORIGIN_SHIFT_M / (1 << z)


def tile_bounds_m(z, x, y):
    """(minx, miny, maxx, maxy) in EPSG:3857 metres of XYZ tile (z, x, y)."""
    s = tile_size_m(z)
    minx = -ORIGIN_SHIFT_M + x * s
    maxy = ORIGIN_SHIFT_M - y * s
    return minx, maxy - s, minx + s, maxy


def lonlat_to_tile_px(lon_deg, lat_deg, z):
    """Global pixel coordinates (x right, y down) at zoom z."""
    x, y = lonlat_to_merc_m(lon_deg, lat_deg)
    res = tile_size_m(z) / TILE_PX
    return (x + ORIGIN_SHIFT_M) / res, (ORIGIN_SHIFT_M - y) / res


def tile_range(bounds_lonlat, z):
    """Inclusive XYZ tile ranges (x0, x1, y0, y1) covering a (W, S, E, N) box at zoom z."""
    w, s, e, n = bounds_lonlat
    px0, py0 = lonlat_to_tile_px(w, n, z)
    px1, py1 = lonlat_to_tile_px(e, s, z)
    last = (1 << z) - 1
    return (max(0, int(px0 // TILE_PX)), min(last, int(px1 // TILE_PX)),
            max(0, int(py0 // TILE_PX)), min(last, int(py1 // TILE_PX)))


def km2_per_tile(z, lat_deg):
    side_m = tile_size_m(z) * math.cos(math.radians(lat_deg))
    return side_m * side_m / 1e6


# ---------------------------------------------------------------------------------------------
# Areas and data checks
# ---------------------------------------------------------------------------------------------
def lonlat_box(area):
    lons, lats = zip(*area.geographic_corners())
    return min(lons), min(lats), max(lons), max(lats)


def detail_area(area, radius_m):
    r = min(radius_m, max(-area.xmin, area.xmax, -area.ymin, area.ymax))
    return pdnav_dem.Area(area.lat0, area.lon0, max(area.xmin, -r), max(area.ymin, -r),
                          min(area.xmax, r), min(area.ymax, r))


def osm_extent_lonlat(path):
    """(W, S, E, N) of the OSM extract: its header bounds, else the extent of its ways."""
    try:
        ds = gdal.OpenEx(path, gdal.OF_VECTOR)
    except RuntimeError as e:
        raise BasemapError(f"{path}: cannot open as OpenStreetMap / vector data: {str(e).strip()}") from None
    if ds is None or ds.GetLayerByName("lines") is None or ds.GetLayerByName("multipolygons") is None:
        raise BasemapError(f"{path}: not an OSM extract (needs the GDAL OSM driver's lines and "
                           "multipolygons layers)")
    def plausible(e):  # an .osm file without <bounds> gives an undefined extent (GDAL 3.6)
        return -180 <= e[0] < e[1] <= 180 and -90 <= e[2] < e[3] <= 90

    ext = None
    for name in ("lines", "multipolygons", "points"):
        lyr = ds.GetLayerByName(name)
        try:
            e = lyr.GetExtent(force=1)  # (minx, maxx, miny, maxy), EPSG:4326 lon/lat
        except RuntimeError:
            continue
        if not plausible(e):
            continue
        ext = e if ext is None else (min(ext[0], e[0]), max(ext[1], e[1]),
                                     min(ext[2], e[2]), max(ext[3], e[3]))
    if ext is None:  # no header bounds: the envelope of the features themselves
        ds = gdal.OpenEx(path, gdal.OF_VECTOR)
        for name in ("points", "lines", "multipolygons"):
            lyr = ds.GetLayerByName(name)
            for feat in lyr:
                g = feat.GetGeometryRef()
                if g is None or g.IsEmpty():
                    continue
                e = g.GetEnvelope()
                ext = e if ext is None else (min(ext[0], e[0]), max(ext[1], e[1]),
                                             min(ext[2], e[2]), max(ext[3], e[3]))
    if ext is None:
        raise BasemapError(f"{path}: the OSM extract holds no features")
    return ext[0], ext[2], ext[1], ext[3]


def check_inside(box, data_box, what, allow_partial):
    w, s, e, n = box
    dw, ds_, de, dn = data_box
    if e < dw or w > de or n < ds_ or s > dn:
        raise BasemapError(f"the requested area (lon {w:.5f}..{e:.5f}, lat {s:.5f}..{n:.5f}) is "
                           f"outside the {what} (lon {dw:.5f}..{de:.5f}, lat {ds_:.5f}..{dn:.5f})")
    if not allow_partial and (w < dw or e > de or s < ds_ or n > dn):
        raise BasemapError(f"the requested area (lon {w:.5f}..{e:.5f}, lat {s:.5f}..{n:.5f}) is only "
                           f"partly inside the {what} (lon {dw:.5f}..{de:.5f}, lat {ds_:.5f}..{dn:.5f}); "
                           "use --allow-partial to render the rest empty")


# ---------------------------------------------------------------------------------------------
# Data preparation (work folder read by basemap-style.xml)
# ---------------------------------------------------------------------------------------------
def prepare_dem(dem_ds, box_merc, work, z_factor, lat0, cell_m):
    minx, miny, maxx, maxy = box_merc
    band = dem_ds.GetRasterBand(1)
    dem = os.path.join(work, "dem_3857.tif")
    # cubic spline: SRTM's 90 m cells upsampled without the staircase a bilinear warp
    # leaves in hillshade and contours at z15-17
    gdal.Warp(dem, dem_ds, dstSRS="EPSG:3857", outputBounds=(minx, miny, maxx, maxy),
              xRes=cell_m, yRes=cell_m, resampleAlg="cubicspline", outputType=gdal.GDT_Float32,
              srcNodata=band.GetNoDataValue(), dstNodata=pdnav_dem.NODATA, multithread=False)
    out = gdal.Open(dem, gdal.GA_Update)
    gdal.FillNodata(out.GetRasterBand(1), None, maxSearchDist=100, smoothingIterations=0)
    out = None
    shade = os.path.join(work, "hillshade.tif")
    # gdaldem divides by (pixel size * scale): one EPSG:3857 metre is cos(lat) true metres
    gdal.DEMProcessing(shade, dem, "hillshade", zFactor=z_factor,
                       scale=math.cos(math.radians(lat0)), azimuth=315, altitude=45,
                       computeEdges=True, multiDirectional=False)
    # contours: every CONTOUR_BASE_M; every_m = the coarsest step dividing the height, which
    # the style uses to pick the interval by zoom and the labelled index lines
    cont = os.path.join(work, "contours.gpkg")
    drv = ogr.GetDriverByName("GPKG")
    cds = drv.CreateDataSource(cont)
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(3857)
    lyr = cds.CreateLayer("contours", srs, ogr.wkbLineString)
    lyr.CreateField(ogr.FieldDefn("id", ogr.OFTInteger))
    lyr.CreateField(ogr.FieldDefn("elev_m", ogr.OFTInteger))
    src = gdal.Open(dem)
    gdal.ContourGenerate(src.GetRasterBand(1), CONTOUR_BASE_M, 0.0, [], 1, pdnav_dem.NODATA,
                         lyr, 0, 1)
    lyr.CreateField(ogr.FieldDefn("every_m", ogr.OFTInteger))
    lyr.StartTransaction()
    n = 0
    for f in lyr:
        h = int(round(f.GetField("elev_m")))
        f.SetField("every_m", next((s for s in CONTOUR_STEPS_M if h % s == 0), int(CONTOUR_BASE_M)))
        lyr.SetFeature(f)
        n += 1
    lyr.CommitTransaction()
    cds = None
    return n


def prepare_osm(osm_path, box_lonlat, work):
    out = os.path.join(work, "osm.gpkg")
    w, s, e, n = box_lonlat
    gdal.VectorTranslate(out, osm_path, format="GPKG", dstSRS="EPSG:3857",
                         spatFilter=(w, s, e, n), layers=["points", "lines", "multipolygons"])
    ds = ogr.Open(out)
    counts = {ds.GetLayer(i).GetName(): ds.GetLayer(i).GetFeatureCount() for i in range(ds.GetLayerCount())}
    return counts


# ---------------------------------------------------------------------------------------------
# MBTiles
# ---------------------------------------------------------------------------------------------
def mbtiles_create(path):
    if os.path.exists(path):
        os.remove(path)
    con = sqlite3.connect(path)
    con.executescript("""
        CREATE TABLE metadata (name TEXT, value TEXT);
        CREATE UNIQUE INDEX metadata_name ON metadata (name);
        CREATE TABLE tiles (zoom_level INTEGER, tile_column INTEGER, tile_row INTEGER, tile_data BLOB);
        CREATE UNIQUE INDEX tile_index ON tiles (zoom_level, tile_column, tile_row);
    """)
    return con


def mbtiles_read(path, z, x, y):
    """PNG bytes of XYZ tile (z, x, y), or None."""
    con = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
    try:
        row = con.execute("SELECT tile_data FROM tiles WHERE zoom_level=? AND tile_column=? AND tile_row=?",
                          (z, x, (1 << z) - 1 - y)).fetchone()
    finally:
        con.close()
    return row[0] if row else None


def mbtiles_open_checked(path):
    if not os.path.isfile(path):
        raise BasemapError(f"{path}: no such MBTiles file")
    try:
        con = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        meta = dict(con.execute("SELECT name, value FROM metadata").fetchall())
        zooms = dict(con.execute("SELECT zoom_level, COUNT(*) FROM tiles GROUP BY zoom_level").fetchall())
    except sqlite3.Error as e:
        raise BasemapError(f"{path}: not an MBTiles file: {e}") from None
    return con, meta, zooms


# ---------------------------------------------------------------------------------------------
# render
# ---------------------------------------------------------------------------------------------
def load_map(work, size_px):
    try:
        import mapnik
    except ImportError:
        raise BasemapError("python3-mapnik is not installed (tools/setup installs it)") from None
    m = mapnik.Map(size_px, size_px)
    try:
        mapnik.load_map(m, STYLE_PATH, True, work)
    except RuntimeError as e:
        raise BasemapError(f"{STYLE_PATH}: Mapnik cannot load the style: {str(e).strip()}") from None
    return mapnik, m


def render_tiles(con, work, jobs, metatile, fmt, progress):
    """jobs: list of (z, x0, x1, y0, y1). Renders metatiles of metatile x metatile tiles, so
    labels and dashes run across tile edges, and stores each 256 px tile."""
    mapnik, m = load_map(work, metatile * TILE_PX)
    counts = {}
    t0 = time.monotonic()
    for z, x0, x1, y0, y1 in jobs:
        n = 0
        for mx in range(x0 - x0 % metatile, x1 + 1, metatile):
            for my in range(y0 - y0 % metatile, y1 + 1, metatile):
                nx = min(metatile, (1 << z) - mx)
                ny = min(metatile, (1 << z) - my)
                m.resize(nx * TILE_PX, ny * TILE_PX)
                minx, _, _, maxy = tile_bounds_m(z, mx, my)
                s = tile_size_m(z)
                m.zoom_to_box(mapnik.Box2d(minx, maxy - ny * s, minx + nx * s, maxy))
                img = mapnik.Image(nx * TILE_PX, ny * TILE_PX)
                mapnik.render(m, img)
                rows = []
                for dx in range(nx):
                    for dy in range(ny):
                        x, y = mx + dx, my + dy
                        if not (x0 <= x <= x1 and y0 <= y <= y1):
                            continue
                        data = img.view(dx * TILE_PX, dy * TILE_PX, TILE_PX, TILE_PX).tostring(fmt)
                        rows.append((z, x, (1 << z) - 1 - y, sqlite3.Binary(data)))
                con.executemany("INSERT INTO tiles VALUES (?, ?, ?, ?)", rows)
                n += len(rows)
        con.commit()
        counts[z] = n
        if progress:
            print(f"  z{z}: {n} tiles ({time.monotonic() - t0:.1f} s so far)", flush=True)
    return counts


def cmd_render(args):
    if not 0 <= args.min_zoom <= args.max_zoom <= 19:
        raise BasemapError("need 0 <= --min-zoom <= --max-zoom <= 19")
    if not args.min_zoom <= args.detail_zoom <= args.max_zoom + 1:
        raise BasemapError("--detail-zoom must be within --min-zoom..--max-zoom+1")
    if args.detail_radius is not None and not args.detail_radius > 0:
        raise BasemapError("--detail-radius must be > 0 metres")
    if not args.attribution.strip():
        raise BasemapError("--attribution must not be empty (ODbL: the map must credit OpenStreetMap)")
    if args.metatile < 1 or args.metatile > 16:
        raise BasemapError("--metatile must be 1..16")
    try:
        area = pdnav_dem.Area.from_args(args)
        dem_ds = pdnav_dem.open_raster(args.dem)
        pdnav_dem.raster_footprint_check(dem_ds, area, args.dem, args.allow_partial)
    except pdnav_dem.DemToolError as e:
        raise BasemapError(str(e)) from None
    box = lonlat_box(area)
    check_inside(box, osm_extent_lonlat(args.osm), f"OSM extract {args.osm}", args.allow_partial)
    detail = detail_area(area, args.detail_radius if args.detail_radius else 3000.0)
    dbox = lonlat_box(detail)

    # data bounds in EPSG:3857, with a margin of one z(min) tile for labels and hillshade edges
    pad = min(tile_size_m(args.min_zoom), 5000.0)
    x0, y0 = lonlat_to_merc_m(box[0], box[1])
    x1, y1 = lonlat_to_merc_m(box[2], box[3])
    box_merc = (x0 - pad, y0 - pad, x1 + pad, y1 + pad)
    pad_ll = merc_m_to_lonlat(box_merc[0], box_merc[1]) + merc_m_to_lonlat(box_merc[2], box_merc[3])

    jobs = []
    for z in range(args.min_zoom, args.max_zoom + 1):
        jobs.append((z,) + tile_range(dbox if z >= args.detail_zoom else box, z))
    total = sum((j[2] - j[1] + 1) * (j[4] - j[3] + 1) for j in jobs)
    if total > args.max_tiles:
        raise BasemapError(f"{total} tiles requested (more than --max-tiles {args.max_tiles}); "
                           "use a smaller --radius / --detail-radius or a lower --max-zoom")

    t0 = time.monotonic()
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="pdnav_basemap_") as work:
        n_contours = prepare_dem(dem_ds, box_merc, work, args.z_factor, area.lat0, args.dem_cell)
        osm_counts = prepare_osm(args.osm, pad_ll, work)
        print(f"data: {n_contours} contour lines every {CONTOUR_BASE_M:g} m, OSM "
              + ", ".join(f"{k} {v}" for k, v in sorted(osm_counts.items())), flush=True)
        tmp_out = args.output + ".tmp"
        con = mbtiles_create(tmp_out)
        try:
            counts = render_tiles(con, work, jobs, args.metatile, args.format, not args.quiet)
            meta = {
                "name": args.name, "type": "baselayer", "version": "1.1", "format": "png",
                "description": (f"pdnav offline basemap (Mapnik {os.path.basename(STYLE_PATH)}): "
                                f"{os.path.basename(args.dem)} + {os.path.basename(args.osm)}; "
                                f"z{args.min_zoom}-{args.detail_zoom - 1} whole area, "
                                f"z{args.detail_zoom}-{args.max_zoom} within {detail.xmax:.0f} m "
                                "of the centre"),
                "attribution": args.attribution,
                "bounds": ",".join(f"{v:.6f}" for v in box),
                "center": f"{area.lon0:.6f},{area.lat0:.6f},{min(15, args.max_zoom)}",
                "minzoom": str(args.min_zoom), "maxzoom": str(args.max_zoom),
                "detail_bounds": ",".join(f"{v:.6f}" for v in dbox),
                "detail_minzoom": str(args.detail_zoom),
            }
            con.executemany("INSERT INTO metadata VALUES (?, ?)", sorted(meta.items()))
            con.commit()
        finally:
            con.close()
        os.replace(tmp_out, args.output)
    size = os.path.getsize(args.output)
    print(f"wrote {args.output}: zoom {args.min_zoom}..{args.max_zoom}, {sum(counts.values())} tiles "
          + ", ".join(f"z{z}={counts[z]}" for z in sorted(counts))
          + f", {size / 1e6:.2f} MB, {time.monotonic() - t0:.1f} s")
    # size per km^2 at each zoom (tile area at the centre latitude)
    per = []
    for z in sorted(counts):
        con = sqlite3.connect(args.output)
        b = con.execute("SELECT SUM(LENGTH(tile_data)) FROM tiles WHERE zoom_level=?", (z,)).fetchone()[0] or 0
        con.close()
        per.append(f"z{z} {b / 1e3 / max(1, counts[z]) / km2_per_tile(z, area.lat0):.0f}")
    print("kB per km^2: " + ", ".join(per) + f" (area of interest z{args.detail_zoom}+: "
          f"{(detail.xmax - detail.xmin) * (detail.ymax - detail.ymin) / 1e6:.1f} km^2)")
    return 0


# ---------------------------------------------------------------------------------------------
# preview: PNG mosaic of one zoom level, read back from the MBTiles
# ---------------------------------------------------------------------------------------------
def mosaic(path, z, max_px, center_lonlat=None):
    """PIL image of the tiles of zoom z (at most max_px a side, around the centre) and the XYZ
    (x0, y0) of its top-left tile."""
    from PIL import Image
    import io
    con, meta, zooms = mbtiles_open_checked(path)
    try:
        if z not in zooms:
            raise BasemapError(f"{path}: no tiles at zoom {z} (has {sorted(zooms)})")
        rows = con.execute("SELECT tile_column, tile_row FROM tiles WHERE zoom_level=?", (z,)).fetchall()
        xs = [r[0] for r in rows]
        ys = [(1 << z) - 1 - r[1] for r in rows]
        x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
        limit = max(1, max_px // TILE_PX)
        if center_lonlat is None and "center" in meta:
            lon, lat = (float(v) for v in meta["center"].split(",")[:2])
            center_lonlat = (lon, lat)
        if center_lonlat is not None:
            cx, cy = (int(v // TILE_PX) for v in lonlat_to_tile_px(center_lonlat[0], center_lonlat[1], z))
        else:
            cx, cy = (x0 + x1) // 2, (y0 + y1) // 2
        if x1 - x0 + 1 > limit:
            x0 = max(x0, min(cx - limit // 2, x1 - limit + 1))
            x1 = x0 + limit - 1
        if y1 - y0 + 1 > limit:
            y0 = max(y0, min(cy - limit // 2, y1 - limit + 1))
            y1 = y0 + limit - 1
        img = Image.new("RGB", ((x1 - x0 + 1) * TILE_PX, (y1 - y0 + 1) * TILE_PX), (255, 255, 255))
        for x in range(x0, x1 + 1):
            for y in range(y0, y1 + 1):
                row = con.execute("SELECT tile_data FROM tiles WHERE zoom_level=? AND tile_column=? "
                                  "AND tile_row=?", (z, x, (1 << z) - 1 - y)).fetchone()
                if row:
                    img.paste(Image.open(io.BytesIO(row[0])).convert("RGB"),
                              ((x - x0) * TILE_PX, (y - y0) * TILE_PX))
    finally:
        con.close()
    return img, (x0, y0), meta


def cmd_preview(args):
    os.makedirs(args.output, exist_ok=True)
    stem = os.path.splitext(os.path.basename(args.mbtiles))[0]
    for z in args.zoom:
        img, _, meta = mosaic(args.mbtiles, z, args.max_px)
        out = os.path.join(args.output, f"{stem}-z{z}.png")
        img.save(out)
        print(f"preview z{z}: {out} ({img.size[0]}x{img.size[1]} px; {meta.get('attribution', '')})")
    return 0


# ---------------------------------------------------------------------------------------------
def build_parser():
    ap = argparse.ArgumentParser(prog="pdnav_basemap.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="command", required=True)
    r = sub.add_parser("render", help="DEM + OSM extract -> MBTiles basemap (Mapnik)")
    r.add_argument("dem", help="GDAL raster, e.g. /vsizip/N42E001.hgt.zip/N42E001.hgt")
    r.add_argument("osm", help="OpenStreetMap extract (.osm.pbf / .osm)")
    r.add_argument("-o", "--output", required=True)
    pdnav_dem.add_area_args(r)
    r.add_argument("--detail-radius", type=float, help="half side (m) of the area of interest "
                   "rendered from --detail-zoom up (default 3000)")
    r.add_argument("--min-zoom", type=int, default=10)
    r.add_argument("--max-zoom", type=int, default=17)
    r.add_argument("--detail-zoom", type=int, default=15)
    r.add_argument("--dem-cell", type=float, default=15.0,
                   help="EPSG:3857 cell (m) of the resampled DEM for hillshade and contours")
    r.add_argument("--z-factor", type=float, default=1.0, help="hillshade vertical exaggeration")
    r.add_argument("--metatile", type=int, default=8, help="render N x N tiles at once (default 8)")
    r.add_argument("--format", default="png256",
                   help="Mapnik image format of the tiles (default png256, as the OSM tile servers)")
    r.add_argument("--max-tiles", type=int, default=60000)
    r.add_argument("--name", default="pdnav basemap")
    r.add_argument("--attribution", default=ATTRIBUTION,
                   help="text to show on the map (MBTiles metadata 'attribution'; always written)")
    r.add_argument("--quiet", action="store_true")
    r.set_defaults(func=cmd_render)
    p = sub.add_parser("preview", help="PNG mosaic of zoom levels of an MBTiles")
    p.add_argument("mbtiles")
    p.add_argument("--zoom", type=int, action="append", required=True)
    p.add_argument("--max-px", type=int, default=1536)
    p.add_argument("-o", "--output", required=True, help="folder for the PNGs")
    p.set_defaults(func=cmd_preview)
    return ap


def main(argv=None):
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except BasemapError as e:
        print(f"pdnav_basemap: error: {e}", file=sys.stderr)
        return 2
    except RuntimeError as e:  # GDAL / Mapnik errors not anticipated above
        print(f"pdnav_basemap: error: {str(e).strip()}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())

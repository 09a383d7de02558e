#!/usr/bin/python3
"""pdnav DEM tiler and basemap maker (host only, GDAL from Debian).

Subcommands
  tile     any GDAL raster (SRTM .hgt/.hgt.zip, GeoTIFF, DTED, ...) -> project DEM tile (.pdem,
           docs/dem-format.md) on a regular grid in the local ENU tangent plane of the area centre
  basemap  the same DEM -> hillshade (gdaldem) -> MBTiles (EPSG:3857 XYZ tiles, PNG) with
           overviews, for osmdroid's offline tile source

Errors (unreadable input, area outside the raster, all-void area, bad arguments) print one
line "pdnav_dem: error: <reason>" on stderr and exit with status 2.
The core's DemReader (core-cpp/src/terrain/dem.cpp) is the one reader of the .pdem format.
"""
import argparse
import hashlib
import math
import os
import sqlite3
import sys
import tempfile
import zlib

import numpy as np
from osgeo import gdal, osr

gdal.UseExceptions()

PDEM_MAGIC = "PDEM"
PDEM_VERSION = 1
NODATA = -32768.0
WEB_MERCATOR_RES0 = 2 * math.pi * 6378137.0 / 256.0  # m/pixel at zoom 0 (EPSG:3857)


class DemToolError(Exception):
    """A user-facing error: printed as one line, exit status 2."""


# ---------------------------------------------------------------------------------------------
# Area and frames
# ---------------------------------------------------------------------------------------------
def geographic_srs():
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(4326)
    srs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)  # (lon, lat)
    return srs


def local_enu_proj4(lat0, lon0):
    """Ellipsoidal orthographic projection = the ENU tangent plane at (lat0, lon0, h=0).

    PROJ >= 7.2 implements +proj=ortho on the ellipsoid exactly as east/north of the ECEF
    difference rotated into ENU, i.e. pdnav::geo::LocalFrame(Geodetic(lat0, lon0, 0)).
    """
    return (f"+proj=ortho +lat_0={lat0:.12f} +lon_0={lon0:.12f} +x_0=0 +y_0=0 "
            "+ellps=WGS84 +units=m +no_defs")


def srs_from_proj4(text):
    srs = osr.SpatialReference()
    srs.ImportFromProj4(text)
    srs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    return srs


class Area:
    """A request: origin (lat0, lon0) and a rectangle in the local ENU plane (metres)."""

    def __init__(self, lat0, lon0, xmin, ymin, xmax, ymax):
        self.lat0, self.lon0 = lat0, lon0
        self.xmin, self.ymin, self.xmax, self.ymax = xmin, ymin, xmax, ymax

    @staticmethod
    def from_args(args):
        if args.bbox and args.center:
            raise DemToolError("give either --bbox or --center/--radius, not both")
        if args.bbox:
            south, west, north, east = args.bbox
            if not (-90 <= south < north <= 90 and -180 <= west < east <= 180):
                raise DemToolError(f"bad --bbox {args.bbox}: need S < N and W < E in degrees")
            lat0, lon0 = 0.5 * (south + north), 0.5 * (west + east)
            to_local = osr.CoordinateTransformation(geographic_srs(),
                                                    srs_from_proj4(local_enu_proj4(lat0, lon0)))
            pts = []
            for k in range(21):  # densified boundary
                t = k / 20.0
                for lat, lon in ((south, west + t * (east - west)), (north, west + t * (east - west)),
                                 (south + t * (north - south), west), (south + t * (north - south), east)):
                    pts.append(to_local.TransformPoint(lon, lat)[:2])
            xs, ys = zip(*pts)
            return Area(lat0, lon0, min(xs), min(ys), max(xs), max(ys))
        if args.center:
            lat0, lon0 = args.center
            if not (-90 < lat0 < 90 and -180 <= lon0 <= 180):
                raise DemToolError(f"bad --center {args.center}")
            if args.radius is None or not args.radius > 0:
                raise DemToolError("--center needs --radius METRES > 0")
            r = args.radius
            return Area(lat0, lon0, -r, -r, r, r)
        raise DemToolError("give the area: --bbox S W N E or --center LAT LON --radius M")

    def geographic_corners(self, n=21):
        """Densified boundary of the local rectangle as (lon, lat) points."""
        to_geo = osr.CoordinateTransformation(srs_from_proj4(local_enu_proj4(self.lat0, self.lon0)),
                                              geographic_srs())
        pts = []
        for k in range(n):
            t = k / (n - 1.0)
            x = self.xmin + t * (self.xmax - self.xmin)
            y = self.ymin + t * (self.ymax - self.ymin)
            for px, py in ((x, self.ymin), (x, self.ymax), (self.xmin, y), (self.xmax, y)):
                pts.append(to_geo.TransformPoint(px, py)[:2])
        return pts


def open_raster(path):
    try:
        ds = gdal.Open(path)
    except RuntimeError as e:
        raise DemToolError(f"{path}: cannot open as a raster: {str(e).strip()}") from None
    if ds is None or ds.RasterCount < 1:
        raise DemToolError(f"{path}: not a raster with at least one band")
    if not ds.GetProjection():
        raise DemToolError(f"{path}: raster has no coordinate reference system")
    return ds


def raster_footprint_check(ds, area, path, allow_partial):
    """Error when the area is outside (or, unless allow_partial, not inside) the raster."""
    src_srs = osr.SpatialReference(wkt=ds.GetProjection())
    src_srs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    to_src = osr.CoordinateTransformation(geographic_srs(), src_srs)
    gt = ds.GetGeoTransform()
    if gt[2] != 0 or gt[4] != 0:
        raise DemToolError(f"{path}: rotated rasters are not supported")
    x0, x1 = sorted((gt[0], gt[0] + gt[1] * ds.RasterXSize))
    y0, y1 = sorted((gt[3], gt[3] + gt[5] * ds.RasterYSize))
    inside = 0
    pts = area.geographic_corners()
    for lon, lat in pts:
        x, y = to_src.TransformPoint(lon, lat)[:2]
        if x0 <= x <= x1 and y0 <= y <= y1:
            inside += 1
    if inside == 0:
        raise DemToolError(f"{path}: the requested area (centre {area.lat0:.6f}, {area.lon0:.6f}) "
                           f"is outside the raster (extent {x0:.6f}..{x1:.6f} x {y0:.6f}..{y1:.6f})")
    if inside < len(pts) and not allow_partial:
        raise DemToolError(f"{path}: the requested area is only partly inside the raster "
                           "(use --allow-partial to keep the outside as voids)")


def source_checksum(path):
    """sha256 of the source bytes, read through GDAL's VSI layer (works inside /vsizip/)."""
    h = hashlib.sha256()
    f = gdal.VSIFOpenL(path, "rb")
    if f is None:
        raise DemToolError(f"{path}: cannot read the source bytes")
    try:
        while True:
            chunk = gdal.VSIFReadL(1, 1 << 20, f)
            if not chunk:
                break
            h.update(chunk)
    finally:
        gdal.VSIFCloseL(f)
    return h.hexdigest()


# ---------------------------------------------------------------------------------------------
# tile
# ---------------------------------------------------------------------------------------------
def warp_to_grid(ds, area, cell, resampling):
    """Warp the source to nodes (pixel centres) every `cell` metres covering the area."""
    i0 = math.floor(area.xmin / cell)
    i1 = math.ceil(area.xmax / cell)
    j0 = math.floor(area.ymin / cell)
    j1 = math.ceil(area.ymax / cell)
    cols, rows = i1 - i0 + 1, j1 - j0 + 1
    if cols < 2 or rows < 2:
        raise DemToolError("area smaller than two cells; use a smaller --cell or a larger area")
    if cols * rows > 64_000_000:
        raise DemToolError(f"grid of {cols}x{rows} cells is too large (max 64M); use a larger --cell")
    band = ds.GetRasterBand(1)
    src_nodata = band.GetNoDataValue()
    half = 0.5 * cell
    out = gdal.Warp("", ds, format="MEM",
                    dstSRS=local_enu_proj4(area.lat0, area.lon0),
                    outputBounds=(i0 * cell - half, j0 * cell - half, i1 * cell + half, j1 * cell + half),
                    width=cols, height=rows, resampleAlg=resampling, outputType=gdal.GDT_Float32,
                    srcNodata=src_nodata, dstNodata=NODATA, multithread=False)
    return out, i0 * cell, j0 * cell, cols, rows


def fill_voids(mem_ds, max_distance_px):
    band = mem_ds.GetRasterBand(1)
    gdal.FillNodata(band, None, maxSearchDist=max_distance_px, smoothingIterations=0)


def grid_values(mem_ds):
    """Float32 array with rows south -> north (GDAL rows run north -> south)."""
    a = mem_ds.GetRasterBand(1).ReadAsArray().astype(np.float32)
    a[~np.isfinite(a)] = NODATA
    a[a <= NODATA + 0.5] = NODATA
    return np.ascontiguousarray(a[::-1, :])


def pdem_header(fields):
    lines = [f"{PDEM_MAGIC} {PDEM_VERSION}"]
    for k, v in fields:
        lines.append(f"{k} {v}")
    lines.append("end_header")
    return ("\n".join(lines) + "\n").encode("ascii")


def write_pdem(path, fields, values):
    data = values.astype("<f4").tobytes()
    fields = list(fields) + [("data_crc32", f"{zlib.crc32(data) & 0xFFFFFFFF:08x}")]
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(pdem_header(fields))
        f.write(data)
    os.replace(tmp, path)


def cmd_tile(args):
    if not args.cell > 0:
        raise DemToolError("--cell must be > 0 metres")
    area = Area.from_args(args)
    ds = open_raster(args.input)
    raster_footprint_check(ds, area, args.input, args.allow_partial)
    mem, x0, y0, cols, rows = warp_to_grid(ds, area, args.cell, args.resampling)
    raw = grid_values(mem)
    voids_before = int(np.count_nonzero(raw == NODATA))
    if voids_before == raw.size:
        raise DemToolError(f"{args.input}: every cell of the requested area is void (nodata)")
    if args.fill_voids and voids_before:
        fill_voids(mem, args.max_fill_px)
    values = grid_values(mem)
    voids = int(np.count_nonzero(values == NODATA))
    valid = values[values != NODATA]
    fields = [
        ("crs", "local_enu"),
        ("origin_lat_deg", f"{area.lat0:.12f}"),
        ("origin_lon_deg", f"{area.lon0:.12f}"),
        ("proj4", local_enu_proj4(area.lat0, area.lon0).replace(" ", "_")),
        ("cols", cols),
        ("rows", rows),
        ("cell_m", repr(float(args.cell))),
        ("x0_m", repr(float(x0))),
        ("y0_m", repr(float(y0))),
        ("nodata", repr(NODATA)),
        ("vertical_datum", args.vertical_datum),
        ("resampling", args.resampling),
        ("void_fill", f"gdal_fillnodata:{args.max_fill_px}px" if args.fill_voids else "none"),
        ("voids_source", voids_before),
        ("voids", voids),
        ("min_m", f"{float(valid.min()):.3f}"),
        ("max_m", f"{float(valid.max()):.3f}"),
        ("source", os.path.basename(args.input.rstrip("/")).replace(" ", "_")),
        ("source_sha256", source_checksum(args.input)),
    ]
    write_pdem(args.output, fields, values)
    print(f"wrote {args.output}: {cols}x{rows} cells of {args.cell} m, origin "
          f"{area.lat0:.6f} {area.lon0:.6f}, voids {voids} (source voids {voids_before}), "
          f"elevation {float(valid.min()):.1f}..{float(valid.max()):.1f} m")
    return 0


# ---------------------------------------------------------------------------------------------
# basemap
# ---------------------------------------------------------------------------------------------
def mbtiles_zoom_counts(path):
    con = sqlite3.connect(path)
    try:
        rows = con.execute("SELECT zoom_level, COUNT(*) FROM tiles GROUP BY zoom_level").fetchall()
        meta = dict(con.execute("SELECT name, value FROM metadata").fetchall())
    finally:
        con.close()
    return dict(rows), meta


def cmd_basemap(args):
    if not 0 <= args.min_zoom <= args.max_zoom <= 18:
        raise DemToolError("need 0 <= --min-zoom <= --max-zoom <= 18")
    area = Area.from_args(args)
    ds = open_raster(args.input)
    raster_footprint_check(ds, area, args.input, args.allow_partial)
    lons, lats = zip(*area.geographic_corners())
    res = WEB_MERCATOR_RES0 / (2 ** args.max_zoom)
    with tempfile.TemporaryDirectory(prefix="pdnav_basemap_") as tmp:
        merc = os.path.join(tmp, "dem_3857.tif")
        gdal.Warp(merc, ds, dstSRS="EPSG:3857", xRes=res, yRes=res, resampleAlg="bilinear",
                  outputBounds=(min(lons), min(lats), max(lons), max(lats)),
                  outputBoundsSRS="EPSG:4326", outputType=gdal.GDT_Float32,
                  srcNodata=ds.GetRasterBand(1).GetNoDataValue(), dstNodata=NODATA)
        shade = os.path.join(tmp, "hillshade.tif")
        # gdaldem divides by (pixel size * scale): one EPSG:3857 metre is cos(lat) true metres.
        scale = math.cos(math.radians(area.lat0))
        gdal.DEMProcessing(shade, merc, "hillshade", zFactor=args.z_factor, scale=scale,
                           azimuth=315, altitude=45, computeEdges=True)
        tmp_out = args.output + ".tmp"
        if os.path.exists(tmp_out):
            os.remove(tmp_out)
        gdal.Translate(tmp_out, shade, format="MBTILES",
                       creationOptions=["TILE_FORMAT=PNG", "ZOOM_LEVEL_STRATEGY=UPPER",
                                        "RESAMPLING=BILINEAR", "NAME=pdnav hillshade",
                                        "TYPE=baselayer", "DESCRIPTION=hillshade of "
                                        + os.path.basename(args.input)])
        out = gdal.Open(tmp_out, gdal.GA_Update)
        levels = [2 ** k for k in range(1, args.max_zoom - args.min_zoom + 1)]
        if levels:
            out.BuildOverviews("AVERAGE", levels)
        out = None
        os.replace(tmp_out, args.output)
    counts, meta = mbtiles_zoom_counts(args.output)
    zooms = sorted(counts)
    if not zooms or zooms[0] != args.min_zoom or zooms[-1] != args.max_zoom:
        raise DemToolError(f"{args.output}: expected zoom {args.min_zoom}..{args.max_zoom}, got {zooms}")
    print(f"wrote {args.output}: zoom {zooms[0]}..{zooms[-1]}, tiles "
          + ", ".join(f"z{z}={counts[z]}" for z in zooms) + f", format {meta.get('format')}")
    return 0


# ---------------------------------------------------------------------------------------------
def add_area_args(p):
    p.add_argument("--bbox", type=float, nargs=4, metavar=("S", "W", "N", "E"),
                   help="geographic bounding box in degrees")
    p.add_argument("--center", type=float, nargs=2, metavar=("LAT", "LON"), help="area centre, degrees")
    p.add_argument("--radius", type=float, metavar="M", help="half side of the square area, metres")
    p.add_argument("--allow-partial", action="store_true",
                   help="accept an area only partly inside the raster (outside = voids)")


def build_parser():
    ap = argparse.ArgumentParser(prog="pdnav_dem.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="command", required=True)
    t = sub.add_parser("tile", help="raster -> .pdem tile (docs/dem-format.md)")
    t.add_argument("input", help="any GDAL raster path, e.g. /vsizip/N42E001.hgt.zip/N42E001.hgt")
    t.add_argument("-o", "--output", required=True)
    add_area_args(t)
    t.add_argument("--cell", type=float, default=30.0, help="grid spacing in metres (default 30)")
    t.add_argument("--resampling", default="bilinear", choices=["near", "bilinear", "cubic", "cubicspline"])
    t.add_argument("--fill-voids", action="store_true", help="fill voids with gdal FillNodata")
    t.add_argument("--max-fill-px", type=float, default=100.0, help="FillNodata search distance (cells)")
    t.add_argument("--vertical-datum", default="EGM96",
                   help="datum of the source heights (SRTM: EGM96 geoid; default EGM96)")
    t.set_defaults(func=cmd_tile)
    b = sub.add_parser("basemap", help="raster -> hillshade MBTiles for osmdroid")
    b.add_argument("input")
    b.add_argument("-o", "--output", required=True)
    add_area_args(b)
    b.add_argument("--min-zoom", type=int, default=10)
    b.add_argument("--max-zoom", type=int, default=14)
    b.add_argument("--z-factor", type=float, default=1.0, help="vertical exaggeration")
    b.set_defaults(func=cmd_basemap)
    return ap


def main(argv=None):
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except DemToolError as e:
        print(f"pdnav_dem: error: {e}", file=sys.stderr)
        return 2
    except RuntimeError as e:  # GDAL errors not anticipated above
        print(f"pdnav_dem: error: GDAL: {str(e).strip()}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())

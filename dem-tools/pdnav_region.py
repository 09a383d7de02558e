#!/usr/bin/python3
"""pdnav region pack: one file with the DEM tile, walkway graph and basemap of one area.

  pdnav_region.py build --osm EXTRACT.osm.pbf --dem RASTER [RASTER ...]
                        (--center LAT,LON --radius M | --bbox S,W,N,E) [--name NAME]
                        -o NAME.pdnav-region
  pdnav_region.py info FILE.pdnav-region        (prints the manifest, verifies sizes and sha256)

`build` runs the existing tools in this process (imported, not shelled out) on the same area:
pdnav_dem.py tile (DEM tile, docs/dem-format.md), pdnav_graph.py (walkway graph,
docs/graph-format.md) and pdnav_basemap.py render (Mapnik MBTiles, docs/basemap.md), then packs
them with manifest.json into a ZIP (format in docs/region.md). Several DEM rasters are mosaicked
with a GDAL VRT first. All three files share one local frame: the area centre.

Errors (area outside the raster or the OSM extract, empty extract, no walkways in the area,
unreadable input, a damaged pack) print one line "pdnav_region: error: <reason>" on stderr and
exit with status 2; no output file is left behind.
"""
import argparse
import datetime
import hashlib
import json
import os
import re
import sys
import tempfile
import time
import zipfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pdnav_basemap  # noqa: E402
import pdnav_dem  # noqa: E402
import pdnav_graph  # noqa: E402

FORMAT = "pdnav-region"
FORMAT_VERSION = 1
TOOL_VERSION = "1.0"
OSM_ATTRIBUTION = "© OpenStreetMap contributors"
DEFAULT_DEM_ATTRIBUTION = "SRTM: NASA/USGS (public domain)"
FILES = (("dem.pdem", "dem"), ("graph.pgraph", "graph"), ("basemap.mbtiles", "basemap"))
MAX_MANIFEST_BYTES = 1 << 20


class RegionError(Exception):
    """A user-facing error: printed as one line, exit status 2."""


def progress(msg):
    print(f"pdnav_region: {msg}", flush=True)


def parse_numbers(tokens, n, what):
    """'42.5,1.5' or '42.5 1.5' (argparse tokens) -> n floats."""
    parts = [p for t in tokens for p in t.replace(",", " ").split()]
    try:
        vals = [float(p) for p in parts]
    except ValueError:
        raise RegionError(f"{what}: expected {n} numbers, got '{' '.join(tokens)}'") from None
    if len(vals) != n:
        raise RegionError(f"{what}: expected {n} numbers, got '{' '.join(tokens)}'")
    return vals


def sha256_file(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def tool_versions():
    from osgeo import gdal
    try:
        import mapnik
        mapnik_version = mapnik.mapnik_version_string()
    except (ImportError, AttributeError):
        mapnik_version = None
    return {"pdnav_region": TOOL_VERSION, "gdal": gdal.__version__, "mapnik": mapnik_version}


def dem_input(rasters, work):
    """One GDAL path for the DEM tools: the raster itself, or a VRT mosaic of several."""
    from osgeo import gdal
    for r in rasters:
        if not r.startswith("/vsi") and not os.path.exists(r):
            raise RegionError(f"{r}: no such DEM raster")
    if len(rasters) == 1:
        return rasters[0]
    vrt = os.path.join(work, "dem-mosaic.vrt")
    try:
        ds = gdal.BuildVRT(vrt, rasters)
    except RuntimeError as e:
        raise RegionError(f"cannot mosaic the DEM rasters: {str(e).strip()}") from None
    if ds is None:
        raise RegionError("cannot mosaic the DEM rasters (GDAL BuildVRT failed)")
    ds = None  # flush the VRT
    return vrt


def build_graph(osm, area, out_path):
    """Walkways of the area (ways intersecting its box) in the area's frame."""
    w, s, e, n = pdnav_basemap.lonlat_box(area)
    try:
        ways = pdnav_graph.read_ways(osm, (w, s, e, n))
    except RuntimeError as ex:
        raise RegionError(f"{osm}: {str(ex).strip()}") from None
    if not ways:
        raise RegionError(f"{osm}: no walkways (footway, path, track, street ...) in the area "
                          f"{s:.5f},{w:.5f},{n:.5f},{e:.5f}")
    vertices, edges = pdnav_graph.split_at_junctions(ways)
    pdnav_graph.write_graph(out_path, osm, pdnav_graph.LocalFrame(area.lat0, area.lon0), vertices, edges)
    return len(ways), len(vertices), len(edges)


def cmd_build(args):
    t_start = time.monotonic()
    if bool(args.bbox) == bool(args.center):
        raise RegionError("give the area: --center LAT,LON --radius M or --bbox S,W,N,E")
    area_argv = []
    radius = None
    if args.center:
        lat, lon = parse_numbers(args.center, 2, "--center")
        if args.radius is None:
            raise RegionError("--center needs --radius METRES")
        radius = args.radius
        area_argv = ["--center", repr(lat), repr(lon), "--radius", repr(radius)]
    else:
        if args.radius is not None:
            raise RegionError("--radius goes with --center, not --bbox")
        area_argv = ["--bbox"] + [repr(v) for v in parse_numbers(args.bbox, 4, "--bbox")]
    if args.allow_partial:
        area_argv.append("--allow-partial")
    if not os.path.isfile(args.osm):
        raise RegionError(f"{args.osm}: no such OSM extract")
    out = args.output
    if not out.endswith(".pdnav-region"):
        raise RegionError(f"{out}: the output name must end in .pdnav-region")
    name = args.name or os.path.basename(out)[:-len(".pdnav-region")]
    # the app installs into filesDir/regions/<name>/: a plain folder name
    if not re.fullmatch(r"[\w .-]{1,64}", name) or name.startswith(".") or name != name.strip():
        raise RegionError(f"bad region name '{name}': use 1-64 letters, digits, space, '.', '-', '_' "
                          "(not starting with '.')")

    # the area once, with the DEM tools' own parser (same checks and frame for all three files)
    area_ns = pdnav_dem.build_parser().parse_args(["tile", "-", "-o", "-"] + area_argv)
    try:
        area = pdnav_dem.Area.from_args(area_ns)
    except pdnav_dem.DemToolError as e:
        raise RegionError(str(e)) from None
    w, s, e, n = pdnav_basemap.lonlat_box(area)

    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="pdnav_region_") as work:
        dem_src = dem_input(args.dem, work)
        # checks before the long steps: raster footprint, OSM extract extent
        try:
            ds = pdnav_dem.open_raster(dem_src)
            pdnav_dem.raster_footprint_check(ds, area, dem_src, args.allow_partial)
            ds = None
            extent = pdnav_basemap.osm_extent_lonlat(args.osm)
            pdnav_basemap.check_inside((w, s, e, n), extent, f"OSM extract {args.osm}", args.allow_partial)
        except (pdnav_dem.DemToolError, pdnav_basemap.BasemapError) as ex:
            raise RegionError(str(ex)) from None

        paths = {kind: os.path.join(work, fname) for fname, kind in FILES}
        progress(f"[1/4] DEM tile ({args.cell:g} m cells) from {', '.join(args.dem)}")
        t0 = time.monotonic()
        dem_ns = pdnav_dem.build_parser().parse_args(
            ["tile", dem_src, "-o", paths["dem"], "--cell", repr(args.cell), "--fill-voids"] + area_argv)
        try:
            dem_ns.func(dem_ns)
        except pdnav_dem.DemToolError as ex:
            raise RegionError(str(ex)) from None
        progress(f"[1/4] DEM tile done in {time.monotonic() - t0:.1f} s")

        progress(f"[2/4] walkway graph from {args.osm}")
        t0 = time.monotonic()
        n_ways, n_vertices, n_edges = build_graph(args.osm, area, paths["graph"])
        progress(f"[2/4] graph: {n_ways} ways -> {n_vertices} vertices, {n_edges} edges "
                 f"in {time.monotonic() - t0:.1f} s")

        attribution = f"{OSM_ATTRIBUTION}; {args.dem_attribution}"
        progress(f"[3/4] basemap z{args.min_zoom}-{args.max_zoom} (Mapnik; the longest step)")
        t0 = time.monotonic()
        bm_argv = ["render", dem_src, args.osm, "-o", paths["basemap"], "--min-zoom", str(args.min_zoom),
                   "--max-zoom", str(args.max_zoom), "--name", name, "--attribution", attribution] + area_argv
        if args.detail_radius is not None:
            bm_argv += ["--detail-radius", repr(args.detail_radius)]
        if args.detail_zoom is not None:
            bm_argv += ["--detail-zoom", str(args.detail_zoom)]
        bm_ns = pdnav_basemap.build_parser().parse_args(bm_argv)
        try:
            bm_ns.func(bm_ns)
        except (pdnav_basemap.BasemapError, pdnav_dem.DemToolError) as ex:
            raise RegionError(str(ex)) from None
        except RuntimeError as ex:  # GDAL / Mapnik
            raise RegionError(f"basemap: {str(ex).strip()}") from None
        progress(f"[3/4] basemap done in {time.monotonic() - t0:.1f} s")

        progress("[4/4] packing")
        manifest = {
            "format": FORMAT,
            "version": FORMAT_VERSION,
            "name": name,
            "bounds": {"south": s, "west": w, "north": n, "east": e},
            "center": {"lat": area.lat0, "lon": area.lon0},
            "radius_m": radius,
            "created_utc": datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0).isoformat()
                                   .replace("+00:00", "Z"),
            "attribution": attribution,
            "sources": [
                {"name": "OpenStreetMap", "file": os.path.basename(args.osm), "licence": "ODbL 1.0",
                 "attribution": OSM_ATTRIBUTION},
            ] + [
                {"name": args.dem_name, "file": os.path.basename(r.rstrip("/")), "licence": args.dem_licence,
                 "attribution": args.dem_attribution} for r in args.dem
            ],
            "tools": tool_versions(),
            "files": [
                {"path": fname, "kind": kind, "bytes": os.path.getsize(paths[kind]),
                 "sha256": sha256_file(paths[kind])} for fname, kind in FILES
            ],
        }
        tmp = out + ".tmp"
        try:
            with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_DEFLATED) as z:
                z.writestr("manifest.json", json.dumps(manifest, indent=2, ensure_ascii=False) + "\n")
                for fname, kind in FILES:
                    # PNG tiles do not deflate: the basemap is stored
                    z.write(paths[kind], fname,
                            compress_type=zipfile.ZIP_STORED if kind == "basemap" else zipfile.ZIP_DEFLATED)
            os.replace(tmp, out)
        finally:
            if os.path.exists(tmp):
                os.unlink(tmp)
    size = os.path.getsize(out)
    progress(f"wrote {out}: region '{name}', bounds {s:.5f},{w:.5f},{n:.5f},{e:.5f}, "
             + ", ".join(f"{f['path']} {f['bytes'] / 1e6:.2f} MB" for f in manifest["files"])
             + f", pack {size / 1e6:.2f} MB, {time.monotonic() - t_start:.1f} s")
    return 0


def read_manifest(z, path):
    try:
        info = z.getinfo("manifest.json")
    except KeyError:
        raise RegionError(f"{path}: no manifest.json (not a pdnav region)") from None
    if info.file_size > MAX_MANIFEST_BYTES:
        raise RegionError(f"{path}: manifest.json is {info.file_size} bytes (max {MAX_MANIFEST_BYTES})")
    try:
        m = json.loads(z.read(info).decode("utf-8"))
    except (ValueError, UnicodeDecodeError) as e:
        raise RegionError(f"{path}: manifest.json is not valid JSON: {e}") from None
    if not isinstance(m, dict) or m.get("format") != FORMAT:
        raise RegionError(f"{path}: manifest format is not '{FORMAT}'")
    if m.get("version") != FORMAT_VERSION:
        raise RegionError(f"{path}: region format version {m.get('version')!r} (this tool reads {FORMAT_VERSION})")
    for key in ("name", "bounds", "center", "attribution", "files"):
        if key not in m:
            raise RegionError(f"{path}: manifest has no '{key}'")
    return m


def verify(path):
    """Manifest of a pack after checking every listed file's size and sha256."""
    try:
        z = zipfile.ZipFile(path)
    except FileNotFoundError:
        raise RegionError(f"{path}: no such file") from None
    except (zipfile.BadZipFile, OSError) as e:
        raise RegionError(f"{path}: not a region pack (ZIP): {e}") from None
    with z:
        m = read_manifest(z, path)
        kinds = set()
        for f in m["files"]:
            try:
                name, kind, size, digest = f["path"], f["kind"], int(f["bytes"]), f["sha256"]
            except (KeyError, TypeError, ValueError):
                raise RegionError(f"{path}: manifest file entry {f!r} lacks path/kind/bytes/sha256") from None
            kinds.add(kind)
            try:
                info = z.getinfo(name)
            except KeyError:
                raise RegionError(f"{path}: {name} is listed in the manifest but missing") from None
            if info.file_size != size:
                raise RegionError(f"{path}: {name} has {info.file_size} bytes, the manifest says {size}")
            h = hashlib.sha256()
            try:
                with z.open(info) as src:
                    for chunk in iter(lambda: src.read(1 << 20), b""):
                        h.update(chunk)
            except (zipfile.BadZipFile, OSError, EOFError) as e:
                raise RegionError(f"{path}: {name} cannot be read: {e}") from None
            if h.hexdigest() != digest:
                raise RegionError(f"{path}: {name} sha256 {h.hexdigest()} differs from the manifest's {digest}")
        missing = {"dem", "graph", "basemap"} - kinds
        if missing:
            raise RegionError(f"{path}: manifest lists no {', '.join(sorted(missing))} file")
    return m


def cmd_info(args):
    m = verify(args.file)
    print(json.dumps(m, indent=2, ensure_ascii=False))
    b = m["bounds"]
    print(f"pdnav_region: {args.file}: region '{m['name']}' {b['south']:.5f},{b['west']:.5f},"
          f"{b['north']:.5f},{b['east']:.5f}: {len(m['files'])} files, sizes and sha256 ok")
    return 0


def build_parser():
    ap = argparse.ArgumentParser(prog="pdnav_region.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="command", required=True)
    b = sub.add_parser("build", help="OSM extract + DEM raster(s) -> NAME.pdnav-region")
    b.add_argument("--osm", required=True, help="OpenStreetMap extract (.osm.pbf / .osm)")
    b.add_argument("--dem", required=True, nargs="+", help="GDAL raster(s), e.g. N42E001.hgt.zip")
    b.add_argument("--center", nargs="+", metavar="LAT,LON", help="area centre in degrees")
    b.add_argument("--radius", type=float, metavar="M", help="half side of the square area, metres")
    b.add_argument("--bbox", nargs="+", metavar="S,W,N,E", help="area as a geographic box, degrees")
    b.add_argument("--allow-partial", action="store_true",
                   help="accept an area only partly inside the raster / extract")
    b.add_argument("--name", help="region name (default: the output file name)")
    b.add_argument("-o", "--output", required=True, help="NAME.pdnav-region")
    b.add_argument("--cell", type=float, default=30.0, help="DEM tile cell, m (default 30)")
    b.add_argument("--min-zoom", type=int, default=10)
    b.add_argument("--max-zoom", type=int, default=16)
    b.add_argument("--detail-zoom", type=int, help="basemap: zooms from here cover --detail-radius only")
    b.add_argument("--detail-radius", type=float, help="basemap: half side of the detailed area, m")
    b.add_argument("--dem-name", default="SRTM", help="name of the DEM source (manifest)")
    b.add_argument("--dem-licence", default="public domain", help="licence of the DEM source")
    b.add_argument("--dem-attribution", default=DEFAULT_DEM_ATTRIBUTION,
                   help="attribution of the DEM source shown on the map")
    b.set_defaults(func=cmd_build)
    i = sub.add_parser("info", help="print the manifest and verify sizes and checksums")
    i.add_argument("file")
    i.set_defaults(func=cmd_info)
    return ap


def main(argv=None):
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except RegionError as e:
        print(f"pdnav_region: error: {e}", file=sys.stderr)
        return 2
    except RuntimeError as e:  # GDAL errors not anticipated above
        print(f"pdnav_region: error: GDAL: {str(e).strip()}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())

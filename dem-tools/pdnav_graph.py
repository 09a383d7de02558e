#!/usr/bin/python3
"""pdnav_graph: walkable network of an OpenStreetMap extract -> pdnav walkway graph.

Reads .osm.pbf / .osm with GDAL's OSM driver (layer `lines`), keeps the ways a pedestrian
may use, splits them at junctions and writes the text format of docs/graph-format.md:
a geodetic origin, vertices in the local ENU tangent plane at that origin (metres), and
edges as polylines of straight segments with their OSM highway class.

Junctions: GDAL's `lines` layer gives geometries, not node ids. OSM ways that meet share
one node object, so their vertex coordinates are bit-identical doubles; a coordinate used
by two or more ways (or twice by one way) is a junction. Ways that merely cross without a
shared node (bridges, tunnels) are correctly NOT joined.

Usage: pdnav_graph.py INPUT.osm[.pbf] OUTPUT.graph [--bbox W S E N] [--origin LAT LON]
"""
import argparse
import math
import os
import sys
import tempfile

# Highway classes a pedestrian can walk on (unless tagged foot=no / access=private...).
WALKABLE_HIGHWAYS = {
    "footway", "path", "pedestrian", "steps", "track", "living_street", "residential",
    "service", "unclassified", "road", "tertiary", "tertiary_link", "secondary",
    "secondary_link", "primary", "primary_link", "cycleway", "bridleway", "corridor",
}
# Classes that are walkable only with an explicit foot=yes/designated/permissive.
FOOT_EXPLICIT_ONLY = {"trunk", "trunk_link", "motorway", "motorway_link"}
FOOT_YES = {"yes", "designated", "permissive", "official"}
ACCESS_NO = {"no", "private"}

OSMCONF = """closed_ways_are_polygons=aeroway,amenity,boundary,building,craft,geological,historic,landuse,leisure,military,natural,office,place,shop,sport,tourism,highway=platform,public_transport=platform
[points]
osm_id=yes
attributes=highway
[lines]
osm_id=yes
attributes=highway,foot,access,area
[multipolygons]
osm_id=yes
attributes=name
[multilinestrings]
osm_id=yes
attributes=name
[other_relations]
osm_id=yes
attributes=name
"""

# WGS84 (NIMA TR8350.2), same constants and formulas as core-cpp/src/geo/frames.cpp.
WGS84_A = 6378137.0
WGS84_F = 1.0 / 298.257223563
WGS84_E2 = WGS84_F * (2.0 - WGS84_F)


def geodetic_to_ecef(lat_deg, lon_deg, h_m):
    lat, lon = math.radians(lat_deg), math.radians(lon_deg)
    s, c = math.sin(lat), math.cos(lat)
    n = WGS84_A / math.sqrt(1.0 - WGS84_E2 * s * s)
    return ((n + h_m) * c * math.cos(lon), (n + h_m) * c * math.sin(lon),
            (n * (1.0 - WGS84_E2) + h_m) * s)


class LocalFrame:
    """ENU tangent plane at a geodetic origin (pdnav::geo::LocalFrame)."""

    def __init__(self, lat_deg, lon_deg, h_m=0.0):
        self.origin = (lat_deg, lon_deg, h_m)
        self.o = geodetic_to_ecef(lat_deg, lon_deg, h_m)
        lat, lon = math.radians(lat_deg), math.radians(lon_deg)
        sl, cl, so, co = math.sin(lat), math.cos(lat), math.sin(lon), math.cos(lon)
        self.r_e = (-so, co, 0.0)
        self.r_n = (-sl * co, -sl * so, cl)

    def to_en(self, lat_deg, lon_deg):
        x = geodetic_to_ecef(lat_deg, lon_deg, 0.0)
        d = (x[0] - self.o[0], x[1] - self.o[1], x[2] - self.o[2])
        return (sum(a * b for a, b in zip(self.r_e, d)), sum(a * b for a, b in zip(self.r_n, d)))


def is_walkable(highway, foot, access):
    """Pedestrian access rule. oneway is deliberately ignored: it binds vehicles only."""
    foot = (foot or "").strip().lower()
    access = (access or "").strip().lower()
    highway = (highway or "").strip().lower()
    if foot == "no" or foot in ACCESS_NO:
        return False
    if highway in FOOT_EXPLICIT_ONLY:
        return foot in FOOT_YES
    if highway not in WALKABLE_HIGHWAYS:
        return False
    if access in ACCESS_NO and foot not in FOOT_YES:
        return False
    return True


def read_ways(path, bbox):
    """[(way_id, highway, [(lon, lat), ...])] of the walkable ways in the file."""
    from osgeo import gdal, ogr
    gdal.UseExceptions()
    with tempfile.NamedTemporaryFile("w", suffix=".ini", delete=False) as f:
        f.write(OSMCONF)
        conf = f.name
    try:
        ds = gdal.OpenEx(path, gdal.OF_VECTOR, allowed_drivers=["OSM"],
                         open_options=["CONFIG_FILE=" + conf, "INTERLEAVED_READING=NO"])
        if ds is None:
            raise RuntimeError(f"{path}: GDAL cannot open it as OpenStreetMap")
        layer = ds.GetLayerByName("lines")
        if bbox:
            layer.SetSpatialFilterRect(*bbox)
        ways = []
        for feat in layer:
            if not is_walkable(feat.GetField("highway"), feat.GetField("foot"),
                               feat.GetField("access")):
                continue
            if (feat.GetField("area") or "").lower() == "yes":
                continue
            geom = feat.GetGeometryRef()
            if geom is None or geom.GetGeometryType() not in (ogr.wkbLineString, ogr.wkbLineString25D):
                continue
            pts = [(geom.GetX(i), geom.GetY(i)) for i in range(geom.GetPointCount())]
            pts = [p for i, p in enumerate(pts) if i == 0 or p != pts[i - 1]]
            if len(pts) >= 2:
                ways.append((int(feat.GetField("osm_id")), feat.GetField("highway").lower(), pts))
        return ways
    finally:
        os.unlink(conf)


def split_at_junctions(ways):
    """Split ways at shared coordinates. Returns (vertex_coords, edges) where edges are
    (from_vertex, to_vertex, highway, way_id, [coords incl. both ends])."""
    use = {}
    for _, _, pts in ways:
        for p in pts:
            use[p] = use.get(p, 0) + 1
    vertex_id = {}
    vertices = []

    def vid(p):
        if p not in vertex_id:
            vertex_id[p] = len(vertices)
            vertices.append(p)
        return vertex_id[p]

    edges = []
    for way_id, highway, pts in ways:
        start = 0
        for i in range(1, len(pts)):
            if i == len(pts) - 1 or use[pts[i]] > 1:
                piece = pts[start:i + 1]
                edges.append((vid(piece[0]), vid(piece[-1]), highway, way_id, piece))
                start = i
    return vertices, edges


def write_graph(out_path, source, frame, vertices, edges):
    lat0, lon0, h0 = frame.origin
    tmp = out_path + ".tmp"
    with open(tmp, "w") as f:
        f.write("pdnav-graph 1\n")
        f.write(f"# source {os.path.basename(source)} (c) OpenStreetMap contributors, ODbL\n")
        f.write(f"origin {lat0:.9f} {lon0:.9f} {h0:.3f}\n")
        f.write(f"vertices {len(vertices)}\n")
        for i, (lon, lat) in enumerate(vertices):
            e, n = frame.to_en(lat, lon)
            f.write(f"v {i} {e:.3f} {n:.3f}\n")
        f.write(f"edges {len(edges)}\n")
        for i, (a, b, highway, way_id, piece) in enumerate(edges):
            inner = piece[1:-1]
            coords = []
            for lon, lat in inner:
                e, n = frame.to_en(lat, lon)
                coords.append(f"{e:.3f} {n:.3f}")
            tail = (" " + " ".join(coords)) if coords else ""
            f.write(f"e {i} {a} {b} {highway} {way_id} {len(inner)}{tail}\n")
        f.write("end\n")
    os.replace(tmp, out_path)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("input", help=".osm.pbf or .osm file")
    ap.add_argument("output", help="graph file to write")
    ap.add_argument("--bbox", nargs=4, type=float, metavar=("W", "S", "E", "N"),
                    help="keep ways intersecting this lon/lat box")
    ap.add_argument("--origin", nargs=2, type=float, metavar=("LAT", "LON"),
                    help="origin of the local frame (default: centre of the ways' extent)")
    args = ap.parse_args(argv)
    if not os.path.exists(args.input):
        print(f"pdnav_graph: error: {args.input}: no such file", file=sys.stderr)
        return 2
    ways = read_ways(args.input, args.bbox)
    if not ways:
        print(f"pdnav_graph: error: {args.input}: no walkable ways found", file=sys.stderr)
        return 1
    if args.origin:
        lat0, lon0 = args.origin
    else:
        lons = [p[0] for _, _, pts in ways for p in pts]
        lats = [p[1] for _, _, pts in ways for p in pts]
        lat0, lon0 = 0.5 * (min(lats) + max(lats)), 0.5 * (min(lons) + max(lons))
    vertices, edges = split_at_junctions(ways)
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    write_graph(args.output, args.input, LocalFrame(lat0, lon0), vertices, edges)
    print(f"pdnav_graph: {len(ways)} ways -> {len(vertices)} vertices, {len(edges)} edges -> "
          f"{args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/python3
"""Basemap renderer tests (dem-tools/pdnav_basemap.py), on the real Andorra SRTM tile and OSM
extract (../shared/data/terrain-andorra), over a small area (2.6 km square, z12-17) around the
Lac d'Engolasters so the 2 shared cores render it in well under a minute.

  test_basemap.py SHARED_DATA_DIR SCRATCH_DIR

What is checked, each against data read here independently of the renderer:
- the tile holding a known footway (OSM way 75746395, highway=footway, "Cami del Ferrer de
  l'Olla") and a known path (way 75746397, highway=path, the lake's north shore) has
  path-coloured pixels along the way's own geometry at z15-17, and not away from paths;
- tiles over the lake (OSM way 6593464, natural=water) have water colour inside its outline;
- every zoom of the stated range has exactly the tiles covering its area (own slippy-map
  formula), and the metadata carries the OSM attribution;
- the MBTiles opens in GDAL (driver MBTiles, one overview per lower zoom) and reads back the
  water colour there;
- areas outside the DEM or outside the OSM extract fail with a clear one-line error.
"""
import io
import math
import os
import sqlite3
import subprocess
import sys
import unittest

from osgeo import gdal, ogr, osr
from PIL import Image

gdal.UseExceptions()
ogr.UseExceptions()
HERE = os.path.dirname(os.path.abspath(__file__))
TOOL = os.path.join(HERE, "..", "..", "dem-tools", "pdnav_basemap.py")
SHARED = SCRATCH = None
CENTER = (42.524, 1.572)
RADIUS_M = 1300
ZOOMS = range(12, 18)
DETAIL_ZOOM = 15
PATH_RGB = (0xfa, 0x80, 0x72)    # footway / path salmon, basemap-style.xml
WATER_RGB = (0xaa, 0xd3, 0xdf)
FOOTWAY_WAY, PATH_WAY, LAKE_WAY = "75746395", "75746397", "6593464"


def run(*args):
    return subprocess.run(["/usr/bin/python3", TOOL, *args], capture_output=True, text=True)


def dem():
    return "/vsizip/" + os.path.join(SHARED, "terrain-andorra", "N42E001.hgt.zip") + "/N42E001.hgt"


def osm():
    return os.path.join(SHARED, "terrain-andorra", "andorra.osm.pbf")


# --- independent slippy-map arithmetic (OSM wiki formulas) -----------------------------------
def global_px(lon, lat, z):
    n = 256 * 2 ** z
    x = (lon + 180.0) / 360.0 * n
    y = (1.0 - math.asinh(math.tan(math.radians(lat))) / math.pi) / 2.0 * n
    return x, y


def tiles_covering(w, s, e, n, z):
    x0, y0 = global_px(w, n, z)
    x1, y1 = global_px(e, s, z)
    return {(x, y) for x in range(int(x0 // 256), int(x1 // 256) + 1)
            for y in range(int(y0 // 256), int(y1 // 256) + 1)}


def close(rgb, ref, tol):
    return sum((a - b) ** 2 for a, b in zip(rgb, ref)) <= tol * tol


def way_geometry(layer, field, value):
    ds = ogr.Open(osm())
    lyr = ds.GetLayerByName(layer)
    lyr.SetAttributeFilter(f"{field} = '{value}'")
    f = lyr.GetNextFeature()
    if f is None:
        raise AssertionError(f"OSM {layer} {field}={value} not in {osm()}")
    return f.GetGeometryRef().Clone(), ds


class Basemap(unittest.TestCase):
    mbtiles = None

    @classmethod
    def setUpClass(cls):
        cls.mbtiles = os.path.join(SCRATCH, "engolasters.mbtiles")
        r = run("render", dem(), osm(), "-o", cls.mbtiles, "--center", *map(str, CENTER),
                "--radius", str(RADIUS_M), "--detail-radius", str(RADIUS_M),
                "--min-zoom", str(ZOOMS[0]), "--max-zoom", str(ZOOMS[-1]),
                "--detail-zoom", str(DETAIL_ZOOM), "--quiet")
        if r.returncode != 0:
            raise AssertionError(f"render failed ({r.returncode}): {r.stderr}")
        cls.stdout = r.stdout
        cls.con = sqlite3.connect(cls.mbtiles)
        cls.meta = dict(cls.con.execute("SELECT name, value FROM metadata").fetchall())
        cls.cache = {}

    @classmethod
    def tearDownClass(cls):
        cls.con.close()

    def tile(self, z, x, y):
        key = (z, x, y)
        if key not in self.cache:
            row = self.con.execute("SELECT tile_data FROM tiles WHERE zoom_level=? AND tile_column=? "
                                   "AND tile_row=?", (z, x, 2 ** z - 1 - y)).fetchone()
            self.cache[key] = Image.open(io.BytesIO(row[0])).convert("RGB") if row else None
        return self.cache[key]

    def pixel(self, lon, lat, z):
        gx, gy = global_px(lon, lat, z)
        img = self.tile(z, int(gx // 256), int(gy // 256))
        if img is None:
            return None
        return img.getpixel((min(255, int(gx % 256)), min(255, int(gy % 256))))

    def colour_near(self, lon, lat, z, ref, radius_px, tol):
        gx, gy = global_px(lon, lat, z)
        for dx in range(-radius_px, radius_px + 1):
            for dy in range(-radius_px, radius_px + 1):
                px, py = gx + dx, gy + dy
                img = self.tile(z, int(px // 256), int(py // 256))
                if img is not None and close(img.getpixel((int(px % 256), int(py % 256))), ref, tol):
                    return True
        return False

    def along(self, geom, step_m):
        """(lon, lat) every step_m along a way, inside the rendered area of interest."""
        w, s, e, n = (float(v) for v in self.meta["detail_bounds"].split(","))
        g = geom.Clone()
        g.AssignSpatialReference(None)
        pts = []
        for i in range(g.GetPointCount() - 1):
            lon0, lat0 = g.GetX(i), g.GetY(i)
            lon1, lat1 = g.GetX(i + 1), g.GetY(i + 1)
            d = math.hypot((lon1 - lon0) * math.cos(math.radians(lat0)), lat1 - lat0) * 111195.0
            k = max(1, int(d / step_m))
            for j in range(k):
                lon, lat = lon0 + (lon1 - lon0) * j / k, lat0 + (lat1 - lat0) * j / k
                if w < lon < e and s < lat < n:
                    pts.append((lon, lat))
        return pts

    # --------------------------------------------------------------------------------------
    def test_footway_and_path_have_path_coloured_pixels_along_them(self):
        for way in (FOOTWAY_WAY, PATH_WAY):
            geom, _ds = way_geometry("lines", "osm_id", way)
            pts = self.along(geom, 8.0)
            self.assertGreater(len(pts), 20, f"way {way} hardly inside the test area")
            for z in (15, 16, 17):
                hits = sum(self.colour_near(lon, lat, z, PATH_RGB, 2, 45) for lon, lat in pts)
                frac = hits / len(pts)
                # dashes (5 on, 2 off) and crossings with streets drawn above: >= 75 % near
                self.assertGreaterEqual(frac, 0.75, f"way {way} z{z}: path colour near {frac:.2f} of "
                                        f"{len(pts)} points")

    def test_path_colour_is_not_everywhere(self):
        # 150 m south-east of the footway, on open slope: no path within 2 px at z17
        geom, _ds = way_geometry("lines", "osm_id", FOOTWAY_WAY)
        pts = self.along(geom, 8.0)
        off = [(lon + 0.0015, lat - 0.0010) for lon, lat in pts]
        osm_ds = ogr.Open(osm())
        lines = osm_ds.GetLayerByName("lines")
        w, s, e, n = (float(v) for v in self.meta["detail_bounds"].split(","))
        lines.SetSpatialFilterRect(w - 0.01, s - 0.01, e + 0.01, n + 0.01)
        ways = ogr.Geometry(ogr.wkbMultiLineString)
        for f in lines:
            if f.GetField("highway") and f.GetGeometryRef() is not None:
                ways.AddGeometry(f.GetGeometryRef())
        self.assertGreater(ways.GetGeometryCount(), 50)
        clean = [(lon, lat) for lon, lat in off
                 if ways.Distance(ogr.CreateGeometryFromWkt(f"POINT ({lon} {lat})")) > 0.0004]
        self.assertGreater(len(clean), 10)
        hits = sum(self.colour_near(lon, lat, 17, PATH_RGB, 2, 45) for lon, lat in clean)
        self.assertLessEqual(hits / len(clean), 0.05, "path colour away from any way")

    @classmethod
    def lake_points(cls):
        """(lon, lat) on a 40 x 40 grid over the lake, ~20 m inside its shore."""
        geom, _ds = way_geometry("multipolygons", "osm_way_id", LAKE_WAY)
        inner = geom.Buffer(-0.0002)
        env = inner.GetEnvelope()
        pts = []
        for i in range(40):
            for j in range(40):
                lon = env[0] + (env[1] - env[0]) * (i + 0.5) / 40
                lat = env[2] + (env[3] - env[2]) * (j + 0.5) / 40
                if inner.Contains(ogr.CreateGeometryFromWkt(f"POINT ({lon} {lat})")):
                    pts.append((lon, lat))
        return pts

    def test_lake_tiles_have_water_colour(self):
        pts = self.lake_points()
        self.assertGreater(len(pts), 100)
        for z in (13, 14, 15, 16, 17):
            water = sum(close(self.pixel(lon, lat, z) or (0, 0, 0), WATER_RGB, 20) for lon, lat in pts)
            # the lake's name label (z14+) is the only thing drawn on the water
            self.assertGreaterEqual(water / len(pts), 0.75, f"z{z}: water colour on {water}/{len(pts)}")

    def test_every_stated_zoom_has_exactly_its_tiles(self):
        self.assertEqual(int(self.meta["minzoom"]), ZOOMS[0])
        self.assertEqual(int(self.meta["maxzoom"]), ZOOMS[-1])
        box = [float(v) for v in self.meta["bounds"].split(",")]
        dbox = [float(v) for v in self.meta["detail_bounds"].split(",")]
        # the stated bounds are the requested square
        lat0, lon0 = CENTER
        half_lat = RADIUS_M / 111132.0
        half_lon = RADIUS_M / (111319.5 * math.cos(math.radians(lat0)))
        for got, want in zip(box, (lon0 - half_lon, lat0 - half_lat, lon0 + half_lon, lat0 + half_lat)):
            self.assertAlmostEqual(got, want, delta=0.0005)
        for z in ZOOMS:
            rows = self.con.execute("SELECT tile_column, tile_row FROM tiles WHERE zoom_level=?", (z,)).fetchall()
            have = {(x, 2 ** z - 1 - r) for x, r in rows}
            want = tiles_covering(*(dbox if z >= DETAIL_ZOOM else box), z)
            self.assertEqual(have, want, f"z{z}")
            self.assertIn(f"z{z}=", self.stdout)
        self.assertEqual(self.con.execute("SELECT COUNT(*) FROM tiles WHERE zoom_level NOT BETWEEN ? AND ?",
                                          (ZOOMS[0], ZOOMS[-1])).fetchone()[0], 0)
        self.assertIn("kB per km^2", self.stdout)

    def test_metadata_attribution_and_format(self):
        self.assertIn("© OpenStreetMap contributors", self.meta["attribution"])
        self.assertEqual(self.meta["format"], "png")
        self.assertEqual(self.meta["type"], "baselayer")
        data = self.con.execute("SELECT tile_data FROM tiles LIMIT 1").fetchone()[0]
        self.assertEqual(bytes(data[:8]), b"\x89PNG\r\n\x1a\n")

    def test_opens_in_gdal(self):
        ds = gdal.Open(self.mbtiles)
        self.assertEqual(ds.GetDriver().ShortName, "MBTiles")
        self.assertGreaterEqual(ds.RasterCount, 3)
        gt = ds.GetGeoTransform()
        z17_m_per_px = 2 * math.pi * 6378137.0 / 256 / 2 ** ZOOMS[-1]
        self.assertAlmostEqual(gt[1], z17_m_per_px, delta=1e-6 * z17_m_per_px)
        band = ds.GetRasterBand(1)
        # one overview per lower zoom (GDAL stops before a level smaller than one tile)
        self.assertGreaterEqual(band.GetOverviewCount(), 3)
        for k in range(band.GetOverviewCount()):
            self.assertAlmostEqual(band.GetOverview(k).XSize, ds.RasterXSize / 2 ** (k + 1), delta=1.0)
        # the lake, read through GDAL at full resolution (z17)
        t = osr.CoordinateTransformation(_srs(4326), _srs(3857))
        gt = ds.GetGeoTransform()
        bands = [ds.GetRasterBand(b + 1) for b in range(3)]
        pts = self.lake_points()[::7]
        water = 0
        for lon, lat in pts:
            x, y = t.TransformPoint(lon, lat)[:2]
            col, row = int((x - gt[0]) / gt[1]), int((y - gt[3]) / gt[5])
            rgb = tuple(int(b.ReadAsArray(col, row, 1, 1)[0, 0]) for b in bands)
            water += close(rgb, WATER_RGB, 20)
        self.assertGreaterEqual(water / len(pts), 0.75, f"GDAL reads water on {water}/{len(pts)}")

    def test_preview_pngs(self):
        out = os.path.join(SCRATCH, "preview")
        r = run("preview", self.mbtiles, "--zoom", "13", "--zoom", "16", "-o", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        for z in (13, 16):
            p = os.path.join(out, f"engolasters-z{z}.png")
            self.assertIn(p, r.stdout)
            with Image.open(p) as img:
                w, h = img.size
            self.assertEqual((w % 256, h % 256), (0, 0))
        r = run("preview", self.mbtiles, "--zoom", "9", "-o", out)
        self.assertEqual(r.returncode, 2)
        self.assertIn("no tiles at zoom 9", r.stderr)


def _srs(epsg):
    s = osr.SpatialReference()
    s.ImportFromEPSG(epsg)
    s.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    return s


class Errors(unittest.TestCase):
    def test_area_outside_the_dem(self):
        r = run("render", dem(), osm(), "-o", os.path.join(SCRATCH, "x.mbtiles"),
                "--center", "40.0", "-30.0", "--radius", "500")
        self.assertEqual(r.returncode, 2)
        self.assertIn("pdnav_basemap: error:", r.stderr)
        self.assertIn("outside the raster", r.stderr)
        self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)

    def test_area_inside_the_dem_but_outside_the_osm_extract(self):
        r = run("render", dem(), osm(), "-o", os.path.join(SCRATCH, "x.mbtiles"),
                "--center", "42.93", "1.5", "--radius", "500")
        self.assertEqual(r.returncode, 2)
        self.assertIn("outside the OSM extract", r.stderr)
        self.assertFalse(os.path.exists(os.path.join(SCRATCH, "x.mbtiles")))

    def test_not_an_osm_file(self):
        bad = os.path.join(SCRATCH, "not-osm.pbf")
        with open(bad, "wb") as f:
            f.write(b"\x00\x01garbage")
        r = run("render", dem(), bad, "-o", os.path.join(SCRATCH, "x.mbtiles"),
                "--center", *map(str, CENTER), "--radius", "500")
        self.assertEqual(r.returncode, 2)
        self.assertIn("not-osm.pbf", r.stderr)

    def test_too_many_tiles_refused(self):
        r = run("render", dem(), osm(), "-o", os.path.join(SCRATCH, "x.mbtiles"),
                "--center", *map(str, CENTER), "--radius", "20000", "--detail-radius", "20000",
                "--allow-partial", "--max-tiles", "1000")
        self.assertEqual(r.returncode, 2)
        self.assertIn("--max-tiles", r.stderr)


if __name__ == "__main__":
    if len(sys.argv) < 3:
        print("usage: test_basemap.py SHARED_DATA_DIR SCRATCH_DIR", file=sys.stderr)
        sys.exit(2)
    SHARED, SCRATCH = sys.argv[1], sys.argv[2]
    os.makedirs(SCRATCH, exist_ok=True)
    unittest.main(argv=[sys.argv[0]] + sys.argv[3:], verbosity=2)

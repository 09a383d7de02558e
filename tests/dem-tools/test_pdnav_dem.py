#!/usr/bin/python3
"""dem-tools tests (run by ctest with Debian's /usr/bin/python3, which has GDAL).

  test_pdnav_dem.py SHARED_DATA_DIR SCRATCH_DIR

Checks the tiler on the real Andorra SRTM tile (voids included) and on a GeoTIFF made here
with GDAL, the error paths, and the MBTiles basemap (opens in GDAL, expected zoom levels).
The .pdem payload itself is read by the core (tests/terrain/dem_tools_test.cpp); here only
the text header is inspected.
"""
import os
import sqlite3
import subprocess
import sys
import unittest

from osgeo import gdal

gdal.UseExceptions()
HERE = os.path.dirname(os.path.abspath(__file__))
TOOL = os.path.join(HERE, "..", "..", "dem-tools", "pdnav_dem.py")
SHARED = SCRATCH = None


def run(*args):
    return subprocess.run(["/usr/bin/python3", TOOL, *args], capture_output=True, text=True)


def header(path):
    """The text header of a .pdem file as a dict (inspection only)."""
    fields = {}
    with open(path, "rb") as f:
        magic = f.readline().decode("ascii").strip()
        fields["magic"] = magic
        for raw in f:
            line = raw.decode("ascii").strip()
            if line == "end_header":
                break
            k, v = line.split(" ", 1)
            fields[k] = v
    return fields


def andorra():
    return "/vsizip/" + os.path.join(SHARED, "terrain-andorra", "N42E001.hgt.zip") + "/N42E001.hgt"


class TileTests(unittest.TestCase):
    def test_andorra_voids_flagged_and_filled(self):
        out = os.path.join(SCRATCH, "voids.pdem")
        r = run("tile", andorra(), "-o", out, "--center", "42.68", "1.42", "--radius", "2000")
        self.assertEqual(r.returncode, 0, r.stderr)
        h = header(out)
        self.assertEqual(h["magic"], "PDEM 1")
        self.assertEqual(h["crs"], "local_enu")
        self.assertEqual(h["vertical_datum"], "EGM96")
        self.assertEqual(h["source"], "N42E001.hgt")
        self.assertEqual(len(h["source_sha256"]), 64)
        cols, rows = int(h["cols"]), int(h["rows"])
        self.assertEqual((cols, rows), (135, 135))
        self.assertGreater(int(h["voids"]), 100)  # SRTM voids on the ridges NW of Andorra
        self.assertEqual(os.path.getsize(out) - self.header_size(out), cols * rows * 4)
        filled = os.path.join(SCRATCH, "filled.pdem")
        r = run("tile", andorra(), "-o", filled, "--center", "42.68", "1.42", "--radius", "2000", "--fill-voids")
        self.assertEqual(r.returncode, 0, r.stderr)
        hf = header(filled)
        self.assertEqual(int(hf["voids"]), 0)
        self.assertEqual(int(hf["voids_source"]), int(h["voids"]))
        self.assertTrue(hf["void_fill"].startswith("gdal_fillnodata"))
        self.assertGreaterEqual(float(hf["min_m"]), 349.0)
        self.assertLessEqual(float(hf["max_m"]), 3100.0)

    def test_bbox_area(self):
        out = os.path.join(SCRATCH, "bbox.pdem")
        r = run("tile", andorra(), "-o", out, "--bbox", "42.50", "1.50", "42.52", "1.53", "--cell", "45")
        self.assertEqual(r.returncode, 0, r.stderr)
        h = header(out)
        self.assertAlmostEqual(float(h["origin_lat_deg"]), 42.51, places=9)
        self.assertAlmostEqual(float(h["cell_m"]), 45.0)
        # 2.5 km x 2.2 km box -> about 56 x 50 cells of 45 m
        self.assertTrue(54 <= int(h["cols"]) <= 60 and 48 <= int(h["rows"]) <= 54, h)

    def test_geotiff_made_with_gdal(self):
        tif = os.path.join(SCRATCH, "plane.tif")
        subprocess.run(["/usr/bin/python3", os.path.join(HERE, "make_test_geotiff.py"), tif,
                        os.path.join(SCRATCH, "plane.csv")], check=True, capture_output=True)
        out = os.path.join(SCRATCH, "plane.pdem")
        r = run("tile", tif, "-o", out, "--center", "42.5", "1.5", "--radius", "2800", "--cell", "20")
        self.assertEqual(r.returncode, 0, r.stderr)
        h = header(out)
        self.assertEqual(int(h["voids"]), int(h["voids_source"]))
        self.assertTrue(1 <= int(h["voids"]) <= 9, h["voids"])  # the 30 m hole at the centre
        self.assertAlmostEqual(float(h["min_m"]), 1000 - 0.08 * 2800, delta=8)

    def test_errors(self):
        r = run("tile", "/nonexistent.tif", "-o", os.path.join(SCRATCH, "x.pdem"), "--center", "42", "1", "--radius", "100")
        self.assertEqual(r.returncode, 2)
        self.assertIn("cannot open as a raster", r.stderr)
        r = run("tile", andorra(), "-o", os.path.join(SCRATCH, "x.pdem"), "--center", "45.5", "1.5", "--radius", "1000")
        self.assertEqual(r.returncode, 2)
        self.assertIn("outside the raster", r.stderr)
        r = run("tile", andorra(), "-o", os.path.join(SCRATCH, "x.pdem"), "--center", "42.001", "1.5", "--radius", "1000")
        self.assertEqual(r.returncode, 2)
        self.assertIn("only partly inside", r.stderr)
        r = run("tile", andorra(), "-o", os.path.join(SCRATCH, "x.pdem"), "--center", "42.001", "1.5", "--radius", "1000",
                "--allow-partial")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertGreater(int(header(os.path.join(SCRATCH, "x.pdem"))["voids"]), 0)
        tif = os.path.join(SCRATCH, "void.tif")
        subprocess.run(["/usr/bin/python3", os.path.join(HERE, "make_test_geotiff.py"), tif,
                        os.path.join(SCRATCH, "void.csv"), "--all-void"], check=True, capture_output=True)
        r = run("tile", tif, "-o", os.path.join(SCRATCH, "v.pdem"), "--center", "42.5", "1.5", "--radius", "1000")
        self.assertEqual(r.returncode, 2)
        self.assertIn("every cell of the requested area is void", r.stderr)
        r = run("tile", andorra(), "-o", os.path.join(SCRATCH, "x.pdem"))
        self.assertEqual(r.returncode, 2)
        self.assertIn("give the area", r.stderr)
        notraster = os.path.join(SCRATCH, "notraster.txt")
        with open(notraster, "w") as f:
            f.write("hello\n")
        r = run("tile", notraster, "-o", os.path.join(SCRATCH, "x.pdem"), "--center", "42", "1", "--radius", "100")
        self.assertEqual(r.returncode, 2)
        self.assertIn("pdnav_dem: error:", r.stderr)

    @staticmethod
    def header_size(path):
        with open(path, "rb") as f:
            data = f.read(65536)
        return data.index(b"end_header\n") + len(b"end_header\n")


class BasemapTests(unittest.TestCase):
    def test_hillshade_mbtiles(self):
        out = os.path.join(SCRATCH, "andorra.mbtiles")
        r = run("basemap", andorra(), "-o", out, "--center", "42.55", "1.55", "--radius", "12000",
                "--min-zoom", "10", "--max-zoom", "12")
        self.assertEqual(r.returncode, 0, r.stderr)
        ds = gdal.Open(out)
        self.assertEqual(ds.GetDriver().ShortName, "MBTiles")
        self.assertEqual(ds.GetRasterBand(1).GetOverviewCount(), 2)  # z11, z10 below z12
        con = sqlite3.connect(out)
        zooms = dict(con.execute("SELECT zoom_level, COUNT(*) FROM tiles GROUP BY zoom_level").fetchall())
        meta = dict(con.execute("SELECT name, value FROM metadata").fetchall())
        con.close()
        self.assertEqual(sorted(zooms), [10, 11, 12])
        self.assertGreater(zooms[12], zooms[10])
        self.assertEqual(meta["format"], "png")
        self.assertEqual((int(meta["minzoom"]), int(meta["maxzoom"])), (10, 12))
        band = ds.GetRasterBand(1).ReadAsArray(ds.RasterXSize // 2 - 64, ds.RasterYSize // 2 - 64, 128, 128)
        self.assertGreater(float(band.std()), 5.0)  # real relief, not a flat image


if __name__ == "__main__":
    SHARED, SCRATCH = sys.argv[1], sys.argv[2]
    if not os.path.exists(os.path.join(SHARED, "terrain-andorra", "N42E001.hgt.zip")):
        sys.exit(f"shared data missing: {SHARED}/terrain-andorra/N42E001.hgt.zip")
    os.makedirs(SCRATCH, exist_ok=True)
    unittest.main(argv=[sys.argv[0], "-v"])

#!/usr/bin/python3
"""Region pack tests (dem-tools/pdnav_region.py, issue 29), on the real Andorra SRTM tile and OSM
extract (../shared/data/terrain-andorra), over a small area (600 m radius around the Lac
d'Engolasters, basemap z12-15) so one build takes ~10-20 s on the shared cores.

  test_region.py SHARED_DATA_DIR SCRATCH_DIR [PDNAV_CLI]

Checked, each against data read here independently of the tool:
- the ZIP holds manifest.json + dem.pdem + graph.pgraph + basemap.mbtiles; every size and sha256
  in the manifest is that of the member; manifest fields of interface-29 (format, version, name,
  bounds containing the centre, radius, ISO-8601 UTC time, attribution with "© OpenStreetMap
  contributors", sources with licences, tool versions);
- the three files share the area: the DEM header's origin and the graph's origin are the centre,
  the DEM covers the radius, the basemap's metadata bounds equal the manifest's, and its
  `attribution` metadata equals the manifest's;
- the graph holds the known footway of the area (OSM way 75746395) and, with PDNAV_CLI,
  `pdnav route` finds a path on it between two points of the area;
- `info` verifies a good pack and refuses a damaged one (one byte changed) naming the member;
- clear errors and no output file: area outside the raster, an empty OSM extract, an extract
  with no walkway in the area, --center without --radius.
"""
import datetime
import hashlib
import json
import math
import os
import shutil
import sqlite3
import subprocess
import sys
import unittest
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
TOOL = os.path.join(HERE, "..", "..", "dem-tools", "pdnav_region.py")
SHARED = SCRATCH = CLI = None
CENTER = (42.524, 1.572)
RADIUS_M = 600
FOOTWAY_WAY = "75746395"


def run(*args):
    return subprocess.run(["/usr/bin/python3", TOOL, *args], capture_output=True, text=True)


def osm():
    return os.path.join(SHARED, "terrain-andorra", "andorra.osm.pbf")


def srtm():
    return os.path.join(SHARED, "terrain-andorra", "N42E001.hgt.zip")


def pdem_header(data):
    head = data[:data.index(b"end_header")].decode("ascii").splitlines()
    return dict(line.split(" ", 1) for line in head[1:])


class RegionPackTest(unittest.TestCase):
    pack = None
    build_out = None

    @classmethod
    def setUpClass(cls):
        cls.pack = os.path.join(SCRATCH, "engolasters.pdnav-region")
        if os.path.exists(cls.pack):
            os.unlink(cls.pack)
        r = run("build", "--osm", osm(), "--dem", srtm(), "--center", f"{CENTER[0]},{CENTER[1]}",
                "--radius", str(RADIUS_M), "--min-zoom", "12", "--max-zoom", "15", "-o", cls.pack)
        cls.build_out = r.stdout + r.stderr
        assert r.returncode == 0, cls.build_out

    def members(self):
        with zipfile.ZipFile(self.pack) as z:
            return {i.filename: z.read(i) for i in z.infolist()}

    def test_progress_lines_on_the_long_steps(self):
        for step in ("[1/4] DEM tile", "[2/4] walkway graph", "[3/4] basemap", "[4/4] packing", "wrote "):
            self.assertIn(step, self.build_out)

    def test_manifest_and_checksums(self):
        m = self.members()
        self.assertEqual(set(m), {"manifest.json", "dem.pdem", "graph.pgraph", "basemap.mbtiles"})
        man = json.loads(m["manifest.json"])
        self.assertEqual(man["format"], "pdnav-region")
        self.assertEqual(man["version"], 1)
        self.assertEqual(man["name"], "engolasters")
        self.assertEqual(man["radius_m"], RADIUS_M)
        self.assertEqual((man["center"]["lat"], man["center"]["lon"]), CENTER)
        b = man["bounds"]
        self.assertTrue(b["south"] < CENTER[0] < b["north"] and b["west"] < CENTER[1] < b["east"])
        # a 1.2 km square: 1200 m of latitude / longitude at 42.5 deg
        self.assertAlmostEqual((b["north"] - b["south"]) * 111_000, 2 * RADIUS_M, delta=30)
        self.assertAlmostEqual((b["east"] - b["west"]) * 111_000 * 0.7373, 2 * RADIUS_M, delta=30)
        created = datetime.datetime.fromisoformat(man["created_utc"].replace("Z", "+00:00"))
        self.assertEqual(created.utcoffset(), datetime.timedelta(0))
        self.assertLess(abs((datetime.datetime.now(datetime.timezone.utc) - created).total_seconds()), 3600)
        self.assertIn("© OpenStreetMap contributors", man["attribution"])
        self.assertIn("SRTM", man["attribution"])
        licences = {s["name"]: s["licence"] for s in man["sources"]}
        self.assertEqual(licences["OpenStreetMap"], "ODbL 1.0")
        self.assertEqual(licences["SRTM"], "public domain")
        self.assertEqual({s["file"] for s in man["sources"]}, {"andorra.osm.pbf", "N42E001.hgt.zip"})
        self.assertTrue(man["tools"]["gdal"] and man["tools"]["mapnik"] and man["tools"]["pdnav_region"])
        kinds = {f["kind"]: f for f in man["files"]}
        self.assertEqual(set(kinds), {"dem", "graph", "basemap"})
        for f in man["files"]:
            data = m[f["path"]]
            self.assertEqual(f["bytes"], len(data), f["path"])
            self.assertEqual(f["sha256"], hashlib.sha256(data).hexdigest(), f["path"])

    def test_three_files_share_the_area(self):
        m = self.members()
        man = json.loads(m["manifest.json"])
        h = pdem_header(m["dem.pdem"])
        self.assertAlmostEqual(float(h["origin_lat_deg"]), CENTER[0], places=9)
        self.assertAlmostEqual(float(h["origin_lon_deg"]), CENTER[1], places=9)
        cell = float(h["cell_m"])
        x0, y0 = float(h["x0_m"]), float(h["y0_m"])
        self.assertLessEqual(x0, -RADIUS_M)
        self.assertLessEqual(y0, -RADIUS_M)
        self.assertGreaterEqual(x0 + (int(h["cols"]) - 1) * cell, RADIUS_M)
        self.assertGreaterEqual(y0 + (int(h["rows"]) - 1) * cell, RADIUS_M)
        graph = m["graph.pgraph"].decode("ascii").splitlines()
        self.assertEqual(graph[0], "pdnav-graph 1")
        self.assertEqual(graph[-1], "end")
        origin = next(l for l in graph if l.startswith("origin ")).split()
        self.assertAlmostEqual(float(origin[1]), CENTER[0], places=8)
        self.assertAlmostEqual(float(origin[2]), CENTER[1], places=8)
        self.assertTrue(any(l.startswith("e ") and l.split()[5] == FOOTWAY_WAY for l in graph),
                        "the known footway of the area is in the graph")
        mb = os.path.join(SCRATCH, "basemap-check.mbtiles")
        with open(mb, "wb") as f:
            f.write(m["basemap.mbtiles"])
        con = sqlite3.connect(mb)
        meta = dict(con.execute("SELECT name, value FROM metadata").fetchall())
        tiles = con.execute("SELECT COUNT(*), MIN(zoom_level), MAX(zoom_level) FROM tiles").fetchone()
        con.close()
        self.assertEqual(meta["attribution"], man["attribution"])
        self.assertEqual(meta["name"], "engolasters")
        w, s, e, n = (float(v) for v in meta["bounds"].split(","))
        b = man["bounds"]
        for got, want in ((w, b["west"]), (s, b["south"]), (e, b["east"]), (n, b["north"])):
            self.assertAlmostEqual(got, want, places=5)
        self.assertEqual((tiles[1], tiles[2]), (12, 15))
        self.assertGreater(tiles[0], 4)

    def test_route_on_the_packed_graph(self):
        self.assertTrue(CLI, "give the pdnav CLI as the third argument")
        g = os.path.join(SCRATCH, "packed.pgraph")
        text = self.members()["graph.pgraph"].decode("ascii")
        with open(g, "w") as f:
            f.write(text)
        lines = text.splitlines()
        lat0, lon0 = (float(v) for v in next(l for l in lines if l.startswith("origin ")).split()[1:3])
        verts = {int(l.split()[1]): (float(l.split()[2]), float(l.split()[3])) for l in lines if l.startswith("v ")}
        foot = next(l.split() for l in lines if l.startswith("e ") and l.split()[5] == FOOTWAY_WAY)
        # the footway's two end vertices, to lat/lon with the local scale (error << 1 m over 1 km)
        m_per_deg_lat = 111132.95 - 559.82 * math.cos(2 * math.radians(lat0))
        m_per_deg_lon = 111412.84 * math.cos(math.radians(lat0))
        ends = []
        for v in (int(foot[2]), int(foot[3])):
            e, n = verts[v]
            ends.append(f"{lat0 + n / m_per_deg_lat:.8f},{lon0 + e / m_per_deg_lon:.8f}")
        straight = math.dist(verts[int(foot[2])], verts[int(foot[3])])
        r = subprocess.run([CLI, "route", "--graph", g, "--from", ends[0], "--to", ends[1], "--json"],
                           capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        j = json.loads(r.stdout)
        self.assertTrue(j["found"])
        self.assertLess(j["from_snap_m"], 1.0)
        self.assertLess(j["to_snap_m"], 1.0)
        # along walkways: at least the straight line, at most the footway itself
        shape = [(float(foot[7 + 2 * i]), float(foot[8 + 2 * i])) for i in range(int(foot[6]))]
        pts = [verts[int(foot[2])]] + shape + [verts[int(foot[3])]]
        along = sum(math.dist(a, b) for a, b in zip(pts, pts[1:]))
        self.assertGreaterEqual(j["length_m"], straight - 2.0)
        self.assertLessEqual(j["length_m"], along + 2.0)

    def test_info_verifies_and_refuses_damage(self):
        r = run("info", self.pack)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("sizes and sha256 ok", r.stdout)
        self.assertEqual(json.loads(r.stdout[:r.stdout.rindex("}") + 1])["name"], "engolasters")
        # change one byte of the graph (same size) inside a copy
        bad = os.path.join(SCRATCH, "damaged.pdnav-region")
        m = self.members()
        g = bytearray(m["graph.pgraph"])
        i = g.index(b"v 1 ") + 2
        g[i] = ord("7") if g[i] != ord("7") else ord("8")
        with zipfile.ZipFile(bad, "w") as z:
            for name, data in m.items():
                z.writestr(name, bytes(g) if name == "graph.pgraph" else data)
        r = run("info", bad)
        self.assertEqual(r.returncode, 2)
        self.assertIn("graph.pgraph sha256", r.stderr)
        self.assertEqual(r.stderr.count("\n"), 1, "one line")
        # a member missing
        with zipfile.ZipFile(bad, "w") as z:
            for name, data in m.items():
                if name != "dem.pdem":
                    z.writestr(name, data)
        r = run("info", bad)
        self.assertEqual(r.returncode, 2)
        self.assertIn("dem.pdem is listed in the manifest but missing", r.stderr)
        # not a zip
        with open(bad, "wb") as f:
            f.write(b"not a zip")
        r = run("info", bad)
        self.assertEqual(r.returncode, 2)
        self.assertIn("not a region pack", r.stderr)


class RegionErrorsTest(unittest.TestCase):
    def assert_error(self, out_name, args, text):
        out = os.path.join(SCRATCH, out_name)
        r = run("build", *args, "-o", out)
        self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
        self.assertIn("pdnav_region: error:", r.stderr)
        self.assertIn(text, r.stderr)
        self.assertFalse(os.path.exists(out), "no output file after an error")
        self.assertFalse(os.path.exists(out + ".tmp"))

    def test_area_outside_the_raster(self):
        self.assert_error("outside.pdnav-region", ["--osm", osm(), "--dem", srtm(), "--center", "45.5,7.5",
                                                   "--radius", "500"], "outside the raster")

    def test_empty_extract(self):
        empty = os.path.join(SCRATCH, "empty.osm")
        with open(empty, "w") as f:
            f.write('<?xml version="1.0" encoding="UTF-8"?>\n<osm version="0.6" generator="test"></osm>\n')
        self.assert_error("empty.pdnav-region", ["--osm", empty, "--dem", srtm(), "--center",
                                                 f"{CENTER[0]},{CENTER[1]}", "--radius", "500"], "no features")

    def test_no_walkways_in_the_area(self):
        # one building and one river in the area, no way a pedestrian may use
        lat, lon = CENTER
        nodes = [(1, lat - 0.001, lon - 0.001), (2, lat - 0.001, lon + 0.001), (3, lat + 0.001, lon + 0.001),
                 (4, lat + 0.001, lon - 0.001), (5, lat - 0.004, lon - 0.004), (6, lat + 0.004, lon + 0.004)]
        xml = ['<?xml version="1.0" encoding="UTF-8"?>', '<osm version="0.6" generator="test">']
        xml += [f'<node id="{i}" version="1" lat="{a}" lon="{o}"/>' for i, a, o in nodes]
        xml += ['<way id="10" version="1"><nd ref="1"/><nd ref="2"/><nd ref="3"/><nd ref="4"/><nd ref="1"/>'
                '<tag k="building" v="yes"/></way>',
                '<way id="11" version="1"><nd ref="5"/><nd ref="6"/><tag k="waterway" v="river"/></way>',
                '</osm>']
        f = os.path.join(SCRATCH, "nowalk.osm")
        with open(f, "w") as fh:
            fh.write("\n".join(xml) + "\n")
        self.assert_error("nowalk.pdnav-region", ["--osm", f, "--dem", srtm(), "--center", f"{lat},{lon}",
                                                  "--radius", "300"], "no walkways")

    def test_center_needs_radius_and_bad_numbers(self):
        self.assert_error("r.pdnav-region", ["--osm", osm(), "--dem", srtm(), "--center", "42.5,1.5"],
                          "--center needs --radius")
        self.assert_error("r.pdnav-region", ["--osm", osm(), "--dem", srtm(), "--center", "42.5;1.5",
                                             "--radius", "300"], "--center: expected 2 numbers")
        self.assert_error("r.pdnav-region", ["--osm", osm(), "--dem", srtm(), "--center", "42.5,1.5",
                                             "--radius", "300", "--name", "../escape"], "bad region name")
        self.assert_error("r.pdnav-region", ["--osm", osm(), "--dem", os.path.join(SCRATCH, "none.tif"),
                                             "--center", "42.5,1.5", "--radius", "300"], "no such DEM raster")


if __name__ == "__main__":
    SHARED, SCRATCH = sys.argv[1], sys.argv[2]
    CLI = sys.argv[3] if len(sys.argv) > 3 else None
    os.makedirs(SCRATCH, exist_ok=True)
    del sys.argv[1:]
    unittest.main(verbosity=2)

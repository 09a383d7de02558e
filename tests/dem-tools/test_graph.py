#!/usr/bin/python3
"""Tests of dem-tools/pdnav_graph.py on a small OpenStreetMap XML file written here.

Run by ctest (tests/dem-tools/graph.cmake): /usr/bin/python3 test_graph.py SRC_DIR SCRATCH_DIR
"""
import math
import os
import subprocess
import sys
import unittest

SRC = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..")
SCRATCH = sys.argv[2] if len(sys.argv) > 2 else "/tmp/pdnav-test-graph"
TOOL = os.path.join(SRC, "dem-tools", "pdnav_graph.py")
sys.path.insert(0, os.path.join(SRC, "dem-tools"))
import pdnav_graph  # noqa: E402

LAT0, LON0 = 42.5, 1.5
D = 0.0005  # ~55 m north, ~41 m east

# Node grid (id: (lat, lon)):
#   1 --- 2 --- 3        west-east residential street, oneway=yes, through node 2
#         |
#         4              footway 2-4-5 (north-south), shares node 2 with the street
#         |
#         5
#   6 ----------- 7      path 6-7 crosses 4-5's line between 4 and 5 with NO shared node (bridge)
#   8 --- 9              foot=no service road
#  10 --- 11             access=private service road
#  12 --- 13             access=private + foot=yes: walkable
#  14 --- 15             motorway: not walkable
#  16 --- 17             building outline (not a highway)
NODES = {
    1: (LAT0, LON0), 2: (LAT0, LON0 + D), 3: (LAT0, LON0 + 2 * D),
    4: (LAT0 - D, LON0 + D), 5: (LAT0 - 2 * D, LON0 + D),
    6: (LAT0 - 1.5 * D, LON0), 7: (LAT0 - 1.5 * D, LON0 + 2 * D),
    8: (LAT0 + D, LON0), 9: (LAT0 + D, LON0 + D),
    10: (LAT0 + 2 * D, LON0), 11: (LAT0 + 2 * D, LON0 + D),
    12: (LAT0 + 3 * D, LON0), 13: (LAT0 + 3 * D, LON0 + D),
    14: (LAT0 + 4 * D, LON0), 15: (LAT0 + 4 * D, LON0 + D),
    16: (LAT0 + 5 * D, LON0), 17: (LAT0 + 5 * D, LON0 + D),
}
WAYS = [
    (101, [1, 2, 3], {"highway": "residential", "oneway": "yes"}),
    (102, [2, 4, 5], {"highway": "footway"}),
    (103, [6, 7], {"highway": "path", "bridge": "yes", "layer": "1"}),
    (104, [8, 9], {"highway": "service", "foot": "no"}),
    (105, [10, 11], {"highway": "service", "access": "private"}),
    (106, [12, 13], {"highway": "service", "access": "private", "foot": "yes"}),
    (107, [14, 15], {"highway": "motorway"}),
    (108, [16, 17, 16], {"building": "yes"}),
]


def write_osm(path):
    with open(path, "w") as f:
        f.write('<?xml version="1.0" encoding="UTF-8"?>\n<osm version="0.6" generator="pdnav-test">\n')
        for nid, (lat, lon) in NODES.items():
            f.write(f'  <node id="{nid}" version="1" lat="{lat:.7f}" lon="{lon:.7f}"/>\n')
        for wid, nds, tags in WAYS:
            f.write(f'  <way id="{wid}" version="1">\n')
            for n in nds:
                f.write(f'    <nd ref="{n}"/>\n')
            for k, v in tags.items():
                f.write(f'    <tag k="{k}" v="{v}"/>\n')
            f.write("  </way>\n")
        f.write("</osm>\n")


def read_graph(path):
    g = {"vertices": [], "edges": []}
    with open(path) as f:
        lines = [l.split() for l in f if l.strip() and not l.startswith("#")]
    assert lines[0] == ["pdnav-graph", "1"], lines[0]
    g["origin"] = tuple(float(x) for x in lines[1][1:])
    for t in lines[2:]:
        if t[0] == "v":
            g["vertices"].append((float(t[2]), float(t[3])))
        elif t[0] == "e":
            k = int(t[6])
            g["edges"].append({"from": int(t[2]), "to": int(t[3]), "highway": t[4], "way": int(t[5]),
                               "shape": [(float(t[7 + 2 * i]), float(t[8 + 2 * i])) for i in range(k)]})
    assert lines[-1] == ["end"]
    return g


class GraphExtraction(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        os.makedirs(SCRATCH, exist_ok=True)
        cls.osm = os.path.join(SCRATCH, "small.osm")
        cls.out = os.path.join(SCRATCH, "small.graph")
        write_osm(cls.osm)
        r = subprocess.run(["/usr/bin/python3", TOOL, cls.osm, cls.out, "--origin", str(LAT0), str(LON0)],
                           capture_output=True, text=True)
        if r.returncode != 0:
            raise AssertionError("pdnav_graph.py failed: " + r.stderr)
        cls.g = read_graph(cls.out)

    def ways(self):
        return sorted({e["way"] for e in self.g["edges"]})

    def test_kept_and_excluded_ways(self):
        # foot=no (104), access=private (105), motorway (107), building (108) are excluded;
        # access=private with foot=yes (106) is kept.
        self.assertEqual(self.ways(), [101, 102, 103, 106])

    def test_junction_split_at_shared_node(self):
        street = [e for e in self.g["edges"] if e["way"] == 101]
        foot = [e for e in self.g["edges"] if e["way"] == 102]
        self.assertEqual(len(street), 2, "street 1-2-3 must be split at the shared node 2")
        self.assertEqual(len(foot), 1, "footway 2-4-5 has no junction inside")
        shared = set(v for e in street for v in (e["from"], e["to"])) & {foot[0]["from"], foot[0]["to"]}
        self.assertEqual(len(shared), 1)
        self.assertEqual(len(foot[0]["shape"]), 1, "node 4 stays a shape point of the footway")

    def test_crossing_without_shared_node_not_split(self):
        bridge = [e for e in self.g["edges"] if e["way"] == 103]
        self.assertEqual(len(bridge), 1)
        self.assertEqual(len([e for e in self.g["edges"] if e["way"] == 102]), 1)

    def test_oneway_ignored(self):
        # Edges are undirected in the format; the oneway street is present in full (both
        # pieces, 1-2 and 2-3), nothing dropped or duplicated for pedestrians.
        street = [e for e in self.g["edges"] if e["way"] == 101]
        length = sum(math.dist(self.g["vertices"][e["from"]], self.g["vertices"][e["to"]]) for e in street)
        self.assertAlmostEqual(length, 2 * D * 111319.49 * math.cos(math.radians(LAT0)), delta=1.0)

    def test_local_frame_metres(self):
        self.assertAlmostEqual(self.g["origin"][0], LAT0, places=9)
        self.assertAlmostEqual(self.g["origin"][1], LON0, places=9)
        v = self.g["vertices"]
        # Node 1 is the origin; node 4 is D deg south of node 2.
        origin_vertex = min(v, key=lambda p: math.hypot(*p))
        self.assertLess(math.hypot(*origin_vertex), 1e-3)
        foot = [e for e in self.g["edges"] if e["way"] == 102][0]
        s4 = foot["shape"][0]
        a = v[foot["from"]]
        # 0.0005 deg of latitude at 42.5 deg ~ 55.5 m (WGS84 meridian arc).
        self.assertAlmostEqual(a[1] - s4[1], 55.53, delta=0.05)
        self.assertAlmostEqual(a[0] - s4[0], 0.0, delta=0.01)

    def test_walkability_rule(self):
        self.assertTrue(pdnav_graph.is_walkable("residential", None, None))
        self.assertFalse(pdnav_graph.is_walkable("residential", "no", None))
        self.assertFalse(pdnav_graph.is_walkable("footway", None, "private"))
        self.assertTrue(pdnav_graph.is_walkable("footway", "designated", "no"))
        self.assertFalse(pdnav_graph.is_walkable("trunk", None, None))
        self.assertTrue(pdnav_graph.is_walkable("trunk", "yes", None))
        self.assertFalse(pdnav_graph.is_walkable(None, None, None))

    def test_missing_input_fails_clearly(self):
        r = subprocess.run(["/usr/bin/python3", TOOL, os.path.join(SCRATCH, "nope.osm"),
                            os.path.join(SCRATCH, "nope.graph")], capture_output=True, text=True)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("nope.osm", r.stderr)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])

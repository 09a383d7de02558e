#!/usr/bin/python3
"""`pdnav route` against an independent shortest-path computation on the same graph file.

Reads the walkway graph itself (docs/graph-format.md), projects the query points with GDAL/osr
(EPSG:4326 -> EPSG:4978 and the ENU rotation at the origin, h = 0), snaps them with numpy (the
nearest point of each connected component, scipy.sparse.csgraph.connected_components; the
component with the smallest sum of the two snaps, each <= --max-snap), and runs
scipy.sparse.csgraph.dijkstra on the graph plus the two snapped points. Queries are fixed-seed
random: half near random graph vertices (jittered up to 60 m), half uniform over the graph's
extent (some of them beyond --max-snap of any walkway: both must then report no path).

  check_shortest_path.py --pdnav PDNAV --graph G [--pairs 60] [--seed 1] [--tol 0.1]
Exit 0 when every length and both snaps agree within --tol metres; prints one line per query.
"""
import argparse
import json
import math
import subprocess
import sys

import numpy as np
from osgeo import osr
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components, dijkstra


def read_graph(path):
    origin, verts, pts, pieces = None, [], [], []
    with open(path) as f:
        lines = [ln.split() for ln in f if ln.strip() and not ln.startswith("#")]
    assert lines[0] == ["pdnav-graph", "1"], f"{path}: not a pdnav graph"
    for t in lines[1:]:
        if t[0] == "origin":
            origin = (float(t[1]), float(t[2]))
        elif t[0] == "v":
            verts.append((float(t[2]), float(t[3])))
    pts = list(verts)
    for t in lines[1:]:
        if t[0] != "e":
            continue
        a, b, k = int(t[2]), int(t[3]), int(t[6])
        chain = [a]
        for i in range(k):
            pts.append((float(t[7 + 2 * i]), float(t[8 + 2 * i])))
            chain.append(len(pts) - 1)
        chain.append(b)
        for u, v in zip(chain, chain[1:]):
            pieces.append((u, v))
    P = np.array(pts, dtype=float)
    E = np.array(pieces, dtype=np.int64)
    length = np.linalg.norm(P[E[:, 1]] - P[E[:, 0]], axis=1)
    keep = length > 0.0
    return origin, len(verts), P, E[keep], length[keep]


class Projector:
    """Geodetic (h = 0) -> east/north at the origin, through osr's ECEF (EPSG:4978)."""

    def __init__(self, lat0, lon0):
        geo = osr.SpatialReference()
        geo.ImportFromEPSG(4979)
        geo.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
        ecef = osr.SpatialReference()
        ecef.ImportFromEPSG(4978)
        self.to_ecef = osr.CoordinateTransformation(geo, ecef)
        self.to_geo = osr.CoordinateTransformation(ecef, geo)
        self.o = np.array(self.to_ecef.TransformPoint(lon0, lat0, 0.0))
        la, lo = math.radians(lat0), math.radians(lon0)
        self.R = np.array([[-math.sin(lo), math.cos(lo), 0.0],
                           [-math.sin(la) * math.cos(lo), -math.sin(la) * math.sin(lo), math.cos(la)],
                           [math.cos(la) * math.cos(lo), math.cos(la) * math.sin(lo), math.sin(la)]])

    def en(self, lat, lon):
        x = np.array(self.to_ecef.TransformPoint(lon, lat, 0.0)) - self.o
        e, n, _ = self.R @ x
        return np.array([e, n])

    def latlon(self, e, n):
        """A point of the tangent plane (up = 0) back to lat/lon (to make query points)."""
        x = self.o + self.R.T @ np.array([e, n, 0.0])
        lon, lat, _ = self.to_geo.TransformPoint(*x)
        return lat, lon


def snap_per_component(P, E, comp_of_piece, q, max_snap):
    a, b = P[E[:, 0]], P[E[:, 1]]
    d = b - a
    L2 = np.einsum("ij,ij->i", d, d)
    t = np.clip(np.einsum("ij,ij->i", q - a, d) / L2, 0.0, 1.0)
    c = a + t[:, None] * d
    dist = np.linalg.norm(c - q, axis=1)
    best = {}
    order = np.lexsort((dist, comp_of_piece))
    seen = set()
    for i in order:
        k = int(comp_of_piece[i])
        if k in seen:
            continue
        seen.add(k)
        if dist[i] <= max_snap:
            best[k] = (float(dist[i]), int(i), float(t[i]), c[i])
    return best


def independent_route(P, E, L, comp_of_node, qa, qb, max_snap):
    comp_of_piece = comp_of_node[E[:, 0]]
    A = snap_per_component(P, E, comp_of_piece, qa, max_snap)
    B = snap_per_component(P, E, comp_of_piece, qb, max_snap)
    common = [(A[k][0] + B[k][0], k) for k in A if k in B]
    if not common:
        return None
    _, k = min(common)
    da, ia, ta, _ = A[k]
    db, ib, tb, _ = B[k]
    n = len(P)
    S, T = n, n + 1
    w = {}

    def add(u, v, x):
        key = (min(u, v), max(u, v))
        w[key] = min(w.get(key, math.inf), max(x, 1e-12))  # csgraph drops explicit zeros

    for (u, v), x in zip(E.tolist(), L.tolist()):
        add(u, v, x)
    add(S, int(E[ia, 0]), ta * L[ia])
    add(S, int(E[ia, 1]), (1 - ta) * L[ia])
    add(T, int(E[ib, 0]), tb * L[ib])
    add(T, int(E[ib, 1]), (1 - tb) * L[ib])
    if ia == ib:
        add(S, T, abs(ta - tb) * L[ia])
    keys = np.array(list(w.keys()))
    vals = np.array(list(w.values()))
    M = coo_matrix((vals, (keys[:, 0], keys[:, 1])), shape=(n + 2, n + 2)).tocsr()
    dist = dijkstra(M, directed=False, indices=S)
    return float(dist[T]), da, db


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--pdnav", required=True)
    ap.add_argument("--graph", required=True)
    ap.add_argument("--pairs", type=int, default=60)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--tol", type=float, default=0.1)
    ap.add_argument("--max-snap", type=float, default=1000.0)
    args = ap.parse_args()

    origin, n_vertices, P, E, L = read_graph(args.graph)
    n = len(P)
    adj = coo_matrix((np.ones(len(E)), (E[:, 0], E[:, 1])), shape=(n, n))
    n_comp, comp_of_node = connected_components(adj, directed=False)
    proj = Projector(*origin)
    rng = np.random.default_rng(args.seed)
    lo, hi = P.min(axis=0), P.max(axis=0)
    print(f"graph {args.graph}: {n_vertices} vertices, {n} nodes, {len(E)} pieces, {n_comp} components")

    def query_point(near):
        if near:
            v = P[rng.integers(0, n_vertices)]
            ang, r = rng.uniform(0, 2 * math.pi), rng.uniform(0, 60)
            return v + r * np.array([math.cos(ang), math.sin(ang)])
        return rng.uniform(lo, hi)

    failures, found, none, worst = 0, 0, 0, 0.0
    for i in range(args.pairs):
        qa, qb = query_point(i % 3 != 2), query_point(i % 3 != 1)  # both near a vertex, or one anywhere
        lat_a, lon_a = proj.latlon(*qa)
        lat_b, lon_b = proj.latlon(*qb)
        # the query as the CLI receives it, projected back independently (h = 0)
        qa, qb = proj.en(lat_a, lon_a), proj.en(lat_b, lon_b)
        ref = independent_route(P, E, L, comp_of_node, qa, qb, args.max_snap)
        cmd = [args.pdnav, "route", "--graph", args.graph, "--from", f"{lat_a:.10f},{lon_a:.10f}",
               "--to", f"{lat_b:.10f},{lon_b:.10f}", "--json", "--max-snap", str(args.max_snap)]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode not in (0, 3):
            print(f"pair {i}: pdnav route failed ({r.returncode}): {r.stderr.strip()}")
            failures += 1
            continue
        got = json.loads(r.stdout)
        if ref is None or not got["found"]:
            ok = ref is None and not got["found"]
            none += ok
            print(f"pair {i}: no path: reference {'none' if ref is None else f'{ref[0]:.2f} m'}, "
                  f"pdnav {got.get('reason') or got.get('length_m')} {'ok' if ok else 'MISMATCH'}")
            failures += not ok
            continue
        dl, df, dt = (abs(got["length_m"] - ref[0]), abs(got["from_snap_m"] - ref[1]),
                      abs(got["to_snap_m"] - ref[2]))
        ok = max(dl, df, dt) <= args.tol
        worst = max(worst, dl, df, dt)
        found += ok
        failures += not ok
        print(f"pair {i}: length {got['length_m']:.3f} vs {ref[0]:.3f} m (d {dl:.4f}), snaps "
              f"{got['from_snap_m']:.2f}/{got['to_snap_m']:.2f} vs {ref[1]:.2f}/{ref[2]:.2f} "
              f"{'ok' if ok else 'MISMATCH'}")
    print(f"pairs: {args.pairs}  paths agreeing: {found}  no-path agreeing: {none}  failures: {failures}  "
          f"largest difference (length or snap): {worst:.6f} m (tolerance {args.tol} m)")
    if found < args.pairs // 3:
        print("too few pairs with a path: the check would prove little")
        return 1
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

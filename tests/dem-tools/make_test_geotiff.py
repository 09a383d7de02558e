#!/usr/bin/python3
"""Writes a GeoTIFF made with GDAL for the dem-tools tests, and a CSV of check points.

  make_test_geotiff.py OUT.tif POINTS.csv [--all-void]

The raster is in UTM zone 31N (EPSG:32631), 10 m pixels, 6 x 6 km around 42.5 N 1.5 E,
z = 1000 + 0.05 (x - xc) + 0.03 (y - yc) metres (a plane: bilinear resampling keeps it exact),
with a 3 x 3 pixel nodata hole at the centre. POINTS.csv lists lat,lon,z of the plane at
points away from the hole, computed with GDAL/PROJ, for the C++ test to compare against.
"""
import sys

import numpy as np
from osgeo import gdal, osr

gdal.UseExceptions()


def main(argv):
    out, points = argv[1], argv[2]
    all_void = "--all-void" in argv
    utm = osr.SpatialReference()
    utm.ImportFromEPSG(32631)
    utm.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    geo = osr.SpatialReference()
    geo.ImportFromEPSG(4326)
    geo.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    to_utm = osr.CoordinateTransformation(geo, utm)
    to_geo = osr.CoordinateTransformation(utm, geo)
    xc, yc = to_utm.TransformPoint(1.5, 42.5)[:2]
    xc, yc = round(xc), round(yc)
    n, px = 600, 10.0
    x0, y0 = xc - n * px / 2, yc + n * px / 2
    xs = x0 + (np.arange(n) + 0.5) * px
    ys = y0 - (np.arange(n) + 0.5) * px
    gx, gy = np.meshgrid(xs, ys)
    z = (1000.0 + 0.05 * (gx - xc) + 0.03 * (gy - yc)).astype(np.float32)
    z[n // 2 - 1:n // 2 + 2, n // 2 - 1:n // 2 + 2] = -9999.0
    if all_void:
        z[:, :] = -9999.0
    ds = gdal.GetDriverByName("GTiff").Create(out, n, n, 1, gdal.GDT_Float32, ["COMPRESS=DEFLATE"])
    ds.SetGeoTransform((x0, px, 0, y0, 0, -px))
    ds.SetProjection(utm.ExportToWkt())
    band = ds.GetRasterBand(1)
    band.SetNoDataValue(-9999.0)
    band.WriteArray(z)
    ds = None
    with open(points, "w") as f:
        f.write("lat_deg,lon_deg,z_m\n")
        for dx, dy in ((-2000, -1500), (0, 800), (1700, 1700), (-600, 2200), (2500, -2500), (333, -77)):
            lon, lat = to_geo.TransformPoint(xc + dx, yc + dy)[:2]
            f.write(f"{lat:.10f},{lon:.10f},{1000.0 + 0.05 * dx + 0.03 * dy:.4f}\n")
    print(f"wrote {out} and {points}")


if __name__ == "__main__":
    main(sys.argv)

package org.pdnav.app.map

import org.pdnav.app.nav.NativeBridge
import java.io.File

/**
 * The map screen's static data, read through the core's own readers (so the app shows what
 * the navigator uses): the walkway graph's edges as polylines, the DEM tile's bounds. Read
 * off the main thread (the screen calls [load] on a worker); a bad file gives [error].
 */
class MapData private constructor(
    val graphLines: List<List<DoubleArray>>,
    val demBounds: GeoBounds?,
    val error: String?,
) {
    companion object {
        fun load(graphPath: String, demPath: String): MapData {
            val errors = mutableListOf<String>()
            var lines: List<List<DoubleArray>> = emptyList()
            var bounds: GeoBounds? = null
            try {
                if (graphPath.isNotEmpty() && File(graphPath).isFile) lines = split(NativeBridge.graphPolylines(graphPath))
            } catch (e: Exception) {
                errors += "graph: ${e.message}"
            } catch (e: LinkageError) {
                errors += "graph: native library missing"
            }
            try {
                if (demPath.isNotEmpty() && File(demPath).isFile) {
                    val b = NativeBridge.demBounds(demPath)
                    bounds = GeoBounds(b[0], b[1], b[2], b[3]).takeIf { it.valid }
                }
            } catch (e: Exception) {
                errors += "DEM: ${e.message}"
            } catch (e: LinkageError) {
                errors += "DEM: native library missing"
            }
            return MapData(lines, bounds, errors.joinToString("; ").ifEmpty { null })
        }

        /** lat, lon pairs with NaN, NaN after each edge -> one point list per edge. */
        fun split(flat: DoubleArray): List<List<DoubleArray>> {
            val out = mutableListOf<List<DoubleArray>>()
            var cur = mutableListOf<DoubleArray>()
            for (i in 0 until flat.size / 2) {
                val lat = flat[2 * i]
                val lon = flat[2 * i + 1]
                if (lat.isNaN() || lon.isNaN()) {
                    if (cur.size >= 2) out += cur
                    cur = mutableListOf()
                } else {
                    cur += doubleArrayOf(lat, lon)
                }
            }
            if (cur.size >= 2) out += cur
            return out
        }
    }
}

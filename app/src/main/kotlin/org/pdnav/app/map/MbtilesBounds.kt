package org.pdnav.app.map

import android.database.sqlite.SQLiteDatabase
import android.database.sqlite.SQLiteException
import java.io.File
import kotlin.math.PI
import kotlin.math.atan
import kotlin.math.exp

/** Geographic bounds (degrees) of a map data set: what the map centres on when it opens. */
data class GeoBounds(val minLatDeg: Double, val minLonDeg: Double, val maxLatDeg: Double, val maxLonDeg: Double) {
    val centerLatDeg: Double get() = 0.5 * (minLatDeg + maxLatDeg)
    val centerLonDeg: Double get() = 0.5 * (minLonDeg + maxLonDeg)

    val valid: Boolean
        get() = minLatDeg.isFinite() && maxLatDeg.isFinite() && minLonDeg.isFinite() && maxLonDeg.isFinite() &&
            minLatDeg <= maxLatDeg && minLonDeg <= maxLonDeg && minLatDeg >= -90.0 && maxLatDeg <= 90.0 &&
            minLonDeg >= -180.0 && maxLonDeg <= 180.0
}

/**
 * Bounds of an MBTiles file: the `bounds` row of its metadata table (MBTiles 1.3:
 * "left,bottom,right,top" in WGS84 degrees), else the extent of the tiles at the deepest
 * zoom (TMS rows). Null when the file is not a readable MBTiles database.
 */
object MbtilesBounds {
    fun read(file: File): GeoBounds? {
        if (!file.isFile) return null
        return try {
            SQLiteDatabase.openDatabase(file.path, null, SQLiteDatabase.OPEN_READONLY).use { db ->
                fromMetadata(db) ?: fromTiles(db)
            }
        } catch (e: SQLiteException) {
            null
        }
    }

    /** The deepest zoom level with tiles, or null. */
    fun maxZoom(file: File): Int? {
        if (!file.isFile) return null
        return try {
            SQLiteDatabase.openDatabase(file.path, null, SQLiteDatabase.OPEN_READONLY).use { db ->
                db.rawQuery("SELECT MAX(zoom_level) FROM tiles", null).use { c -> if (c.moveToFirst() && !c.isNull(0)) c.getInt(0) else null }
            }
        } catch (e: SQLiteException) {
            null
        }
    }

    /** The `attribution` row of the metadata table (MBTiles 1.3), or null. */
    fun attribution(file: File): String? {
        if (!file.isFile) return null
        return try {
            SQLiteDatabase.openDatabase(file.path, null, SQLiteDatabase.OPEN_READONLY).use { db ->
                db.rawQuery("SELECT value FROM metadata WHERE name = 'attribution'", null).use { c ->
                    if (c.moveToFirst() && !c.isNull(0)) c.getString(0).trim().ifEmpty { null } else null
                }
            }
        } catch (e: SQLiteException) {
            null
        }
    }

    private fun fromMetadata(db: SQLiteDatabase): GeoBounds? = try {
        db.rawQuery("SELECT value FROM metadata WHERE name = 'bounds'", null).use { c ->
            if (!c.moveToFirst()) return null
            val v = c.getString(0).split(',').map { it.trim().toDoubleOrNull() ?: Double.NaN }
            if (v.size != 4) return null
            GeoBounds(v[1], v[0], v[3], v[2]).takeIf { it.valid }
        }
    } catch (e: SQLiteException) {
        null
    }

    private fun fromTiles(db: SQLiteDatabase): GeoBounds? = try {
        db.rawQuery(
            "SELECT zoom_level, MIN(tile_column), MAX(tile_column), MIN(tile_row), MAX(tile_row) FROM tiles " +
                "WHERE zoom_level = (SELECT MAX(zoom_level) FROM tiles)", null,
        ).use { c ->
            if (!c.moveToFirst() || c.isNull(0)) return null
            val z = c.getInt(0)
            val n = (1 shl z).toDouble()
            val x0 = c.getInt(1); val x1 = c.getInt(2) + 1
            // TMS: row 0 is the south edge
            val ySouth = c.getInt(3); val yNorth = c.getInt(4) + 1
            fun lon(x: Int) = x / n * 360.0 - 180.0
            fun lat(tmsY: Int): Double {
                val yXyz = n - tmsY
                return Math.toDegrees(2.0 * atan(exp(PI * (1.0 - 2.0 * yXyz / n))) - PI / 2.0)
            }
            GeoBounds(lat(ySouth), lon(x0), lat(yNorth), lon(x1)).takeIf { it.valid }
        }
    } catch (e: SQLiteException) {
        null
    }
}

package org.pdnav.app.region

import org.json.JSONArray
import org.json.JSONException
import org.json.JSONObject
import java.io.File

/** A place the walker can go back to: the session start, a saved point, a checkpoint. */
data class Place(val name: String, val latDeg: Double, val lonDeg: Double, val kind: String, val createdMs: Long) {
    companion object {
        const val START = "start"
        const val SAVED = "place"
        const val CHECKPOINT = "checkpoint"
    }
}

/**
 * The places of one region, kept across sessions in a small JSON file
 * (`filesDir/places/<region>.json`; `_no_region` outside every region), written whole to a
 * temporary file and renamed, so a killed app never leaves half a list.
 */
class PlaceStore(filesDir: File, val region: String?) {
    val file = File(File(filesDir, "places"), (region ?: NO_REGION).replace('/', '_') + ".json")

    /** Places, oldest first; an unreadable file reads as none (and is kept for inspection). */
    fun list(): List<Place> {
        if (!file.isFile) return emptyList()
        return try {
            val a = JSONObject(file.readText()).getJSONArray("places")
            (0 until a.length()).map { i ->
                val p = a.getJSONObject(i)
                Place(p.getString("name"), p.getDouble("lat"), p.getDouble("lon"), p.optString("kind", Place.SAVED), p.optLong("created_ms"))
            }
        } catch (e: JSONException) {
            emptyList()
        }
    }

    fun add(p: Place): Place {
        require(p.latDeg.isFinite() && p.lonDeg.isFinite() && p.latDeg in -90.0..90.0 && p.lonDeg in -180.0..180.0) {
            "place ${p.name}: position ${p.latDeg}, ${p.lonDeg} out of range"
        }
        write(list() + p)
        return p
    }

    fun remove(p: Place): Boolean {
        val all = list()
        val kept = all.filterNot { it == p }
        if (kept.size == all.size) return false
        write(kept)
        return true
    }

    private fun write(places: List<Place>) {
        file.parentFile?.mkdirs()
        val a = JSONArray()
        for (p in places) {
            a.put(JSONObject().put("name", p.name).put("lat", p.latDeg).put("lon", p.lonDeg).put("kind", p.kind).put("created_ms", p.createdMs))
        }
        val tmp = File(file.path + ".tmp")
        tmp.writeText(JSONObject().put("version", 1).put("region", region ?: JSONObject.NULL).put("places", a).toString(1))
        if (!tmp.renameTo(file)) throw java.io.IOException("cannot write $file")
    }

    companion object {
        const val NO_REGION = "_no_region"
    }
}

package org.pdnav.app.robo

import org.json.JSONArray
import org.json.JSONObject
import java.io.File
import java.security.MessageDigest
import java.util.concurrent.TimeUnit
import java.util.zip.ZipEntry
import java.util.zip.ZipOutputStream

/**
 * Region files for the host tests: [pack] writes a `.pdnav-region` ZIP by hand (manifest of
 * interface-29.md with true sizes and SHA-256) from any three files, so the store's checks can
 * be tried on good and bad packs; [build] runs the real tool (dem-tools/pdnav_region.py) on
 * the shared Andorra SRTM tile and OSM extract.
 */
object RegionFixture {
    fun sha256(f: File): String = MessageDigest.getInstance("SHA-256").digest(f.readBytes()).joinToString("") { "%02x".format(it) }

    fun manifest(name: String, south: Double, west: Double, north: Double, east: Double,
                 files: List<Pair<String, File>>, attribution: String = "© OpenStreetMap contributors; SRTM: NASA/USGS (public domain)",
                 version: Int = 1): JSONObject {
        val fs = JSONArray()
        for ((kind, f) in files) {
            fs.put(JSONObject().put("path", f.name).put("kind", kind).put("bytes", f.length()).put("sha256", sha256(f)))
        }
        return JSONObject().put("format", "pdnav-region").put("version", version).put("name", name)
            .put("bounds", JSONObject().put("south", south).put("west", west).put("north", north).put("east", east))
            .put("center", JSONObject().put("lat", 0.5 * (south + north)).put("lon", 0.5 * (west + east)))
            .put("radius_m", JSONObject.NULL).put("created_utc", "2026-12-03T09:00:00Z").put("attribution", attribution)
            .put("sources", JSONArray()).put("tools", JSONObject().put("pdnav_region", "test")).put("files", fs)
    }

    /** Writes [out] with manifest.json (unless null) and the files as entries named [entryNames] or their names. */
    fun pack(out: File, manifest: JSONObject?, files: List<File>, entryNames: List<String>? = null): File {
        out.parentFile?.mkdirs()
        ZipOutputStream(out.outputStream()).use { z ->
            if (manifest != null) {
                z.putNextEntry(ZipEntry("manifest.json"))
                z.write(manifest.toString(1).toByteArray())
                z.closeEntry()
            }
            for ((i, f) in files.withIndex()) {
                z.putNextEntry(ZipEntry(entryNames?.get(i) ?: f.name))
                f.inputStream().use { it.copyTo(z) }
                z.closeEntry()
            }
        }
        return out
    }

    /** Three small stand-in files (the store checks the pack, not the data). */
    fun standIns(dir: File): List<Pair<String, File>> {
        dir.mkdirs()
        return listOf("dem" to "dem.pdem", "graph" to "graph.pgraph", "basemap" to "basemap.mbtiles").mapIndexed { i, (k, n) ->
            k to File(dir, n).apply { writeBytes(ByteArray(1000 + 37 * i) { (it * (i + 3)).toByte() }) }
        }
    }

    private fun root(): File = File(System.getProperty("pdnav.root") ?: error("pdnav.root not set"))

    /** The real tool: `pdnav_region.py build` over the shared Andorra data; cached per arguments. */
    @Synchronized
    fun build(name: String, vararg area: String): File {
        val dir = File(System.getProperty("pdnav.scratch"), "region-fixture").apply { mkdirs() }
        val out = File(dir, "$name.pdnav-region")
        val tool = File(root(), "dem-tools/pdnav_region.py")
        check(tool.isFile) { "dem-tools/pdnav_region.py missing" }
        if (out.isFile && out.lastModified() > tool.lastModified()) return out
        val srtm = org.pdnav.app.nav.TestPaths.sharedData("terrain-andorra/N42E001.hgt.zip")
        val osm = org.pdnav.app.nav.TestPaths.sharedData("terrain-andorra/andorra.osm.pbf")
        val cmd = listOf("/usr/bin/python3", tool.path, "build", "--osm", osm.path, "--dem", srtm.path) + area.toList() +
            listOf("--name", name, "-o", out.path)
        val p = ProcessBuilder(cmd).redirectErrorStream(true).start()
        val text = p.inputStream.bufferedReader().readText()
        check(p.waitFor(600, TimeUnit.SECONDS)) { "timed out: $cmd" }
        check(p.exitValue() == 0) { "failed (${p.exitValue()}): ${cmd.joinToString(" ")}\n$text" }
        return out
    }
}

package org.pdnav.app.region

import org.json.JSONException
import org.json.JSONObject
import java.io.File
import java.io.IOException
import java.io.InputStream
import java.security.MessageDigest
import java.util.zip.ZipException
import java.util.zip.ZipInputStream

/** The area a region covers (degrees, from its manifest). */
data class RegionBounds(val southDeg: Double, val westDeg: Double, val northDeg: Double, val eastDeg: Double) {
    val valid: Boolean
        get() = listOf(southDeg, westDeg, northDeg, eastDeg).all { it.isFinite() } && southDeg < northDeg && westDeg < eastDeg &&
            southDeg >= -90.0 && northDeg <= 90.0 && westDeg >= -180.0 && eastDeg <= 180.0

    fun contains(latDeg: Double, lonDeg: Double): Boolean =
        latDeg in southDeg..northDeg && lonDeg in westDeg..eastDeg

    val areaDeg2: Double get() = (northDeg - southDeg) * (eastDeg - westDeg)
}

/** One installed region: its manifest's name, bounds and attribution, and its three files. */
data class RegionInfo(
    val name: String,
    val dir: File,
    val bounds: RegionBounds,
    val attribution: String,
    val createdUtc: String,
    val bytes: Long,
    val demPath: String,
    val graphPath: String,
    val basemapPath: String,
)

/** A refused region file: what is wrong with it, said so a walker can act on it. */
class RegionException(message: String) : IOException(message)

/**
 * The installed `.pdnav-region` packs (docs/android.md, "Regions"): each is unpacked into
 * `filesDir/regions/<name>/` after its manifest, sizes and SHA-256 checksums are verified;
 * a refused or interrupted import leaves nothing behind (it is unpacked into a hidden
 * `.incoming-*` folder first and renamed into place only when whole and verified).
 */
class RegionStore(filesDir: File) {
    val root = File(filesDir, "regions")

    /** Installed regions, by name. Folders without a readable manifest are skipped. */
    fun list(): List<RegionInfo> {
        val dirs = root.listFiles { f -> f.isDirectory && !f.name.startsWith(".") } ?: return emptyList()
        return dirs.mapNotNull { d ->
            try {
                read(d)
            } catch (e: IOException) {
                null
            } catch (e: JSONException) {
                null
            }
        }.sortedBy { it.name }
    }

    fun find(name: String): RegionInfo? = list().firstOrNull { it.name == name }

    /** The region whose bounds contain the point (the smallest, when several do), or null. */
    fun containing(latDeg: Double, lonDeg: Double): RegionInfo? {
        if (!latDeg.isFinite() || !lonDeg.isFinite()) return null
        return list().filter { it.bounds.contains(latDeg, lonDeg) }.minByOrNull { it.bounds.areaDeg2 }
    }

    /** Deletes region [name] (its places stay); false when there is no such region. */
    fun delete(name: String): Boolean {
        val d = File(root, name)
        if (!d.isDirectory || name.startsWith(".") || name.contains('/')) return false
        return d.deleteRecursively()
    }

    /**
     * Reads a region ZIP from [input] ([label] names it in errors), verifies and installs it.
     * [onProgress] gets the bytes unpacked so far. A region of the same name is replaced.
     */
    fun install(input: InputStream, label: String, onProgress: (Long) -> Unit = {}): RegionInfo {
        root.mkdirs()
        val tmp = File(root, ".incoming-" + System.nanoTime())
        check(tmp.mkdirs()) { "cannot create $tmp" }
        try {
            val got = unpack(input, label, tmp, onProgress)
            val manifestFile = File(tmp, MANIFEST)
            if (!manifestFile.isFile) throw RegionException("$label: not a pdnav region (no $MANIFEST in it)")
            val m = try {
                JSONObject(manifestFile.readText())
            } catch (e: JSONException) {
                throw RegionException("$label: $MANIFEST is not valid JSON (${e.message})")
            }
            val name = checkManifest(m, label)
            val files = m.getJSONArray("files")
            for (i in 0 until files.length()) {
                val f = files.getJSONObject(i)
                val path = f.getString("path")
                val have = got[path] ?: throw RegionException("$label: $path is listed in the manifest but missing")
                val bytes = f.getLong("bytes")
                if (have.first != bytes) throw RegionException("$label: $path has ${have.first} bytes, the manifest says $bytes (truncated download?)")
                val sha = f.getString("sha256").lowercase()
                if (have.second != sha) throw RegionException("$label: $path is damaged (SHA-256 ${have.second.take(12)}… instead of ${sha.take(12)}…)")
            }
            val info = read(tmp)  // the same reader as list(): what installs is what lists
            // atomic replace: the old region is moved aside, the new one renamed into place
            val dest = File(root, name)
            val old = File(root, ".old-" + System.nanoTime())
            if (dest.exists() && !dest.renameTo(old)) throw IOException("cannot replace region $name")
            if (!tmp.renameTo(dest)) {
                old.renameTo(dest)
                throw IOException("cannot install region $name into $dest")
            }
            old.deleteRecursively()
            return info.copy(dir = dest, demPath = File(dest, File(info.demPath).name).path,
                graphPath = File(dest, File(info.graphPath).name).path, basemapPath = File(dest, File(info.basemapPath).name).path)
        } catch (e: JSONException) {
            throw RegionException("$label: manifest incomplete (${e.message})")
        } finally {
            if (tmp.exists()) tmp.deleteRecursively()
        }
    }

    /** Unpacks plain file entries into [dir]; returns name -> (bytes, sha256 hex). */
    private fun unpack(input: InputStream, label: String, dir: File, onProgress: (Long) -> Unit): Map<String, Pair<Long, String>> {
        val out = mutableMapOf<String, Pair<Long, String>>()
        var total = 0L
        try {
            ZipInputStream(input.buffered()).use { zip ->
                while (true) {
                    val e = zip.nextEntry ?: break
                    if (e.isDirectory) continue
                    val n = e.name
                    if (n.isEmpty() || n.contains('/') || n.contains('\\') || n.startsWith(".") || n in out) {
                        throw RegionException("$label: unexpected entry \"$n\" (a region holds plain files only)")
                    }
                    val md = MessageDigest.getInstance("SHA-256")
                    var bytes = 0L
                    File(dir, n).outputStream().use { o ->
                        val buf = ByteArray(1 shl 16)
                        while (true) {
                            val k = zip.read(buf)
                            if (k < 0) break
                            o.write(buf, 0, k)
                            md.update(buf, 0, k)
                            bytes += k
                            total += k
                            if (total and 0xFFFFF < k) onProgress(total)
                        }
                    }
                    out[n] = bytes to md.digest().joinToString("") { "%02x".format(it) }
                }
            }
        } catch (e: ZipException) {
            throw RegionException("$label: not a region file (${e.message ?: "not a ZIP archive"})")
        } catch (e: java.io.EOFException) {
            throw RegionException("$label: the file ends early (truncated download?)")
        }
        if (out.isEmpty()) throw RegionException("$label: not a region file (empty or not a ZIP archive)")
        onProgress(total)
        return out
    }

    /** Checks format, version, name, bounds and the three files; returns the folder name. */
    private fun checkManifest(m: JSONObject, label: String): String {
        if (m.optString("format") != FORMAT) throw RegionException("$label: not a pdnav region (format \"${m.optString("format")}\")")
        val v = m.optInt("version", -1)
        if (v != VERSION) throw RegionException("$label: region format version $v; this app reads version $VERSION")
        val name = m.optString("name")
        if (!NAME.matches(name)) throw RegionException("$label: region name \"$name\" (letters, digits, space, . _ - only)")
        val b = bounds(m)
        if (!b.valid) throw RegionException("$label: region bounds $b are not a valid area")
        val files = m.getJSONArray("files")
        val kinds = (0 until files.length()).map { files.getJSONObject(it).getString("kind") }
        for (k in KINDS) if (kinds.count { it == k } != 1) throw RegionException("$label: the manifest must list one $k file")
        return name
    }

    private fun bounds(m: JSONObject): RegionBounds {
        val b = m.getJSONObject("bounds")
        return RegionBounds(b.getDouble("south"), b.getDouble("west"), b.getDouble("north"), b.getDouble("east"))
    }

    /** A region folder's manifest -> RegionInfo (sizes from the files on disk). */
    private fun read(dir: File): RegionInfo {
        val m = JSONObject(File(dir, MANIFEST).readText())
        val files = m.getJSONArray("files")
        val byKind = (0 until files.length()).associate { files.getJSONObject(it).let { f -> f.getString("kind") to File(dir, f.getString("path")) } }
        for (k in KINDS) if (byKind[k]?.isFile != true) throw IOException("${dir.name}: $k file missing")
        val bytes = dir.listFiles()?.sumOf { it.length() } ?: 0L
        return RegionInfo(
            name = m.getString("name"), dir = dir, bounds = bounds(m),
            attribution = m.optString("attribution").ifEmpty { OSM_ATTRIBUTION },
            createdUtc = m.optString("created_utc"), bytes = bytes,
            demPath = byKind.getValue("dem").path, graphPath = byKind.getValue("graph").path, basemapPath = byKind.getValue("basemap").path,
        )
    }

    companion object {
        const val MANIFEST = "manifest.json"
        const val FORMAT = "pdnav-region"
        const val VERSION = 1
        const val EXTENSION = ".pdnav-region"
        /** ODbL: whenever OSM-derived tiles or a graph made from OSM are shown. */
        const val OSM_ATTRIBUTION = "© OpenStreetMap contributors"
        val KINDS = listOf("dem", "graph", "basemap")
        private val NAME = Regex("[A-Za-z0-9][A-Za-z0-9 ._-]{0,63}")
    }
}

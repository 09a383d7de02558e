package org.pdnav.app.robo

import android.graphics.Bitmap
import android.graphics.Canvas
import android.graphics.Color
import android.view.View
import android.view.ViewGroup
import android.widget.TextView
import org.pdnav.app.nav.TestPaths
import java.io.File
import java.util.concurrent.TimeUnit
import kotlin.math.abs
import kotlin.test.assertEquals
import kotlin.test.assertTrue

/**
 * A small real basemap for the host tests: dem-tools/pdnav_basemap.py (Mapnik) over 2 km
 * around the Lac d'Engolasters and the footway "Cami del Ferrer de l'Olla" (OSM way 75746395),
 * zooms 15-17, from the shared Andorra SRTM tile and OSM extract. Rendered once per checkout
 * state (re-rendered when the tool or its style is newer than the file).
 */
object BasemapFixture {
    const val CENTER_LAT = 42.5225
    const val CENTER_LON = 1.5720
    const val RADIUS_M = 1000
    const val MIN_ZOOM = 15
    const val MAX_ZOOM = 17
    /** Lac d'Engolasters (OSM way 6593464): points along its axis, each >= 25 m inside the
     *  shore (checked with GDAL on the extract); the name label may cover one or two. */
    val LAKE_POINTS = listOf(42.51905 to 1.56723, 42.51940 to 1.56774, 42.51975 to 1.56825,
        42.52010 to 1.56876, 42.52045 to 1.56927)
    /** basemap-style.xml colours. */
    val WATER = Color.rgb(0xaa, 0xd3, 0xdf)
    val PATH = Color.rgb(0xfa, 0x80, 0x72)

    private fun root(): File {
        val v = System.getProperty("pdnav.root")
        check(!v.isNullOrEmpty()) { "system property pdnav.root not set (run through tools/android-host/run)" }
        return File(v)
    }

    private fun run(vararg cmd: String) {
        val p = ProcessBuilder(*cmd).redirectErrorStream(true).start()
        val text = p.inputStream.bufferedReader().readText()
        check(p.waitFor(600, TimeUnit.SECONDS)) { "timed out: ${cmd.joinToString(" ")}" }
        check(p.exitValue() == 0) { "failed (${p.exitValue()}): ${cmd.joinToString(" ")}\n$text" }
    }

    @Synchronized
    fun mbtiles(): File {
        val scratch = System.getProperty("pdnav.scratch")
        check(!scratch.isNullOrEmpty()) { "system property pdnav.scratch not set" }
        val out = File(scratch, "basemap-fixture/engolasters.mbtiles")
        val tool = File(root(), "dem-tools/pdnav_basemap.py")
        val style = File(root(), "dem-tools/basemap-style.xml")
        if (out.isFile && out.lastModified() > maxOf(tool.lastModified(), style.lastModified())) return out
        out.parentFile.mkdirs()
        val srtm = "/vsizip/" + TestPaths.sharedData("terrain-andorra/N42E001.hgt.zip").path + "/N42E001.hgt"
        run("/usr/bin/python3", tool.path, "render", srtm, TestPaths.sharedData("terrain-andorra/andorra.osm.pbf").path,
            "-o", out.path, "--center", "$CENTER_LAT", "$CENTER_LON", "--radius", "$RADIUS_M",
            "--detail-radius", "$RADIUS_M", "--min-zoom", "$MIN_ZOOM", "--max-zoom", "$MAX_ZOOM",
            "--detail-zoom", "$MIN_ZOOM", "--quiet")
        return out
    }

    /** A .pdem of the same area and a walk simulated on it by the host CLI (session log). */
    @Synchronized
    fun simulatedWalk(): Pair<File, File> {
        val dir = File(System.getProperty("pdnav.scratch"), "basemap-fixture")
        dir.mkdirs()
        val dem = File(dir, "engolasters.pdem")
        val log = File(dir, "walk.log")
        if (!dem.isFile) {
            val srtm = "/vsizip/" + TestPaths.sharedData("terrain-andorra/N42E001.hgt.zip").path + "/N42E001.hgt"
            run("/usr/bin/python3", File(root(), "dem-tools/pdnav_dem.py").path, "tile", srtm, "-o", dem.path,
                "--center", "$CENTER_LAT", "$CENTER_LON", "--radius", "900", "--cell", "30", "--fill-voids")
        }
        if (!log.isFile) {
            run(TestPaths.cli().path, "simulate", "--dem", dem.path, "-o", log.path, "--seed", "7",
                "--min-length", "300", "--max-length", "500")
        }
        return dem to log
    }

    /** Where the screen pictures go (under the build folder). */
    fun screensDir(): File {
        val v = System.getProperty("pdnav.screens")
        check(!v.isNullOrEmpty()) { "system property pdnav.screens not set (tools/android-host/pom.xml)" }
        return File(v).apply { mkdirs() }
    }

    fun snapshot(view: View): Bitmap {
        check(view.width > 0 && view.height > 0) { "view not laid out: ${view.width}x${view.height}" }
        val bmp = Bitmap.createBitmap(view.width, view.height, Bitmap.Config.ARGB_8888)
        view.draw(Canvas(bmp))
        return bmp
    }

    fun save(bmp: Bitmap, name: String): File {
        val f = File(screensDir(), "$name.png")
        f.outputStream().use { check(bmp.compress(Bitmap.CompressFormat.PNG, 100, it)) { "PNG encode failed" } }
        println("screen: $f (${bmp.width}x${bmp.height})")
        return f
    }

    fun close(c: Int, ref: Int, tol: Int): Boolean =
        abs(Color.red(c) - Color.red(ref)) <= tol && abs(Color.green(c) - Color.green(ref)) <= tol &&
            abs(Color.blue(c) - Color.blue(ref)) <= tol

    /** Every visible TextView (buttons too) inside [root]: not ellipsized, its text laid out
     *  within its padded box, the box within the picture, and glyph pixels actually drawn. */
    fun assertTextNotClipped(root: View, bmp: Bitmap, screen: String) {
        var checked = 0
        val loc = IntArray(2)
        val rootLoc = IntArray(2)
        root.getLocationInWindow(rootLoc)
        fun visit(v: View) {
            if (v.visibility != View.VISIBLE) return
            if (v is TextView && v.text.isNotEmpty()) {
                val name = "$screen: \"${v.text.toString().take(40)}\""
                val layout = v.layout
                assertTrue(layout != null, "$name has no layout")
                for (i in 0 until layout.lineCount) assertEquals(0, layout.getEllipsisCount(i), "$name ellipsized")
                // a line break inside a word ("NAVIGAT" / "E") is text that did not fit its box
                val t = v.text
                for (i in 0 until layout.lineCount - 1) {
                    val end = layout.getLineEnd(i)
                    if (end <= 0 || end >= t.length) continue
                    val before = t[end - 1]
                    val after = t[end]
                    assertTrue(!before.isLetterOrDigit() || !after.isLetterOrDigit(),
                        "$name: word broken across lines at \"${t.substring(maxOf(0, end - 8), end)}|" +
                            "${t.substring(end, minOf(t.length, end + 8))}\" (${v.width} px wide)")
                }
                val innerH = v.height - v.compoundPaddingTop - v.compoundPaddingBottom
                assertTrue(layout.height <= innerH + 1, "$name: text ${layout.height} px high in a ${innerH} px box")
                for (i in 0 until layout.lineCount) {
                    val w = layout.getLineMax(i)  // the drawn extent; getLineWidth adds trailing whitespace
                    val innerW = v.width - v.compoundPaddingLeft - v.compoundPaddingRight
                    assertTrue(w <= innerW + 1, "$name: line $i is $w px wide in a $innerW px box")
                }
                // glyph pixels: only for boxes wholly on screen (a scrolled-away row is not clipped)
                val vis = android.graphics.Rect()
                if (!v.getGlobalVisibleRect(vis) || vis.width() != v.width || vis.height() != v.height) return
                v.getLocationInWindow(loc)
                val x0 = loc[0] - rootLoc[0]
                val y0 = loc[1] - rootLoc[1]
                assertTrue(x0 >= 0 && y0 >= 0 && x0 + v.width <= bmp.width && y0 + v.height <= bmp.height,
                    "$name: box ($x0,$y0 ${v.width}x${v.height}) outside the ${bmp.width}x${bmp.height} picture")
                // ink = pixels far from the box's most frequent colour (its background); text
                // colours are often translucent (theme secondary text), so not compared directly
                val tx0 = x0 + v.compoundPaddingLeft
                val ty0 = y0 + v.compoundPaddingTop
                val px = ArrayList<Int>()
                for (y in ty0 until minOf(bmp.height, ty0 + layout.height)) {
                    for (x in tx0 until minOf(bmp.width, tx0 + layout.width)) px += bmp.getPixel(x, y)
                }
                val bg = px.groupingBy { it }.eachCount().maxByOrNull { it.value }?.key ?: 0
                val ink = px.count { !close(it, bg, 48) }
                assertTrue(ink >= 5 * v.text.count { !it.isWhitespace() }.coerceAtMost(40),
                    "$name: only $ink text-coloured pixels drawn")
                checked++
            }
            if (v is ViewGroup) for (i in 0 until v.childCount) visit(v.getChildAt(i))
        }
        visit(root)
        assertTrue(checked > 0, "$screen: no text at all")
    }
}

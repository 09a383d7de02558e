package org.pdnav.app.robo

import android.Manifest
import android.content.Context
import android.content.pm.PackageManager
import android.graphics.Bitmap
import android.graphics.Point
import android.graphics.Rect
import android.location.GnssStatus
import android.location.LocationManager
import android.os.Looper
import android.view.View
import org.junit.Test
import org.junit.runner.RunWith
import org.osmdroid.util.GeoPoint
import org.osmdroid.views.MapView
import org.osmdroid.views.overlay.Marker
import org.osmdroid.views.overlay.Overlay
import org.osmdroid.views.overlay.Polygon
import org.osmdroid.views.overlay.Polyline
import org.pdnav.app.R
import org.pdnav.app.map.MapController
import org.pdnav.app.nav.NavOutput
import org.pdnav.app.recording.ReplayTask
import org.pdnav.app.recording.SessionStore
import org.pdnav.app.ui.AppSettings
import org.pdnav.app.nav.SampleBatch
import org.pdnav.app.nav.SampleKind
import org.pdnav.app.nav.SampleSink
import org.pdnav.app.sensors.GnssSource
import org.pdnav.app.sensors.SampleMerger
import org.pdnav.app.sensors.SessionStats
import org.pdnav.app.ui.MainActivity
import org.pdnav.app.ui.SkyPlotView
import org.pdnav.app.ui.SessionsActivity
import org.pdnav.app.ui.SettingsActivity
import org.robolectric.Robolectric
import org.robolectric.RobolectricTestRunner
import org.robolectric.RuntimeEnvironment
import org.robolectric.Shadows.shadowOf
import org.robolectric.annotation.Config
import org.robolectric.annotation.GraphicsMode
import org.robolectric.annotation.LooperMode
import kotlin.math.abs
import kotlin.math.hypot
import kotlin.test.assertEquals
import kotlin.test.assertFalse
import kotlin.test.assertNotNull
import kotlin.test.assertNull
import kotlin.test.assertTrue

/**
 * Pictures of every screen the app has, drawn by Robolectric's native graphics (real Skia,
 * real fonts) into PNGs under the build folder (system property pdnav.screens), each with
 * checks on the picture itself: where the estimate projects the marker's pixels are, the error
 * ellipse and the track are drawn where their points project, the basemap tiles (dem-tools,
 * Mapnik) are drawn under them, and no text is ellipsized, cut off or missing its glyphs.
 * The satellite view is fed a synthetic GnssStatus through the app's own GnssStatus callback
 * (the one that writes the `Status` lines), and its dots and C/N0 bars are checked pixel by pixel.
 */
@RunWith(RobolectricTestRunner::class)
@LooperMode(LooperMode.Mode.PAUSED)
@GraphicsMode(GraphicsMode.Mode.NATIVE)
@Config(qualifiers = "w360dp-h640dp-xhdpi")
class ScreensRoboTest {
    private val app = RuntimeEnvironment.getApplication()

    private fun idle() = shadowOf(Looper.getMainLooper()).idle()

    private fun grantAll() = shadowOf(app).grantPermissions(Manifest.permission.ACCESS_FINE_LOCATION,
        Manifest.permission.ACCESS_COARSE_LOCATION, Manifest.permission.ACTIVITY_RECOGNITION)

    /** Pixels of [a] and [b] (same size) that differ, inside [r]. */
    private fun diff(a: Bitmap, b: Bitmap, r: Rect): List<Point> {
        val out = ArrayList<Point>()
        for (y in r.top until r.bottom) for (x in r.left until r.right) {
            if (a.getPixel(x, y) != b.getPixel(x, y)) out += Point(x, y)
        }
        return out
    }

    private fun bbox(ps: List<Point>): Rect {
        val r = Rect(Int.MAX_VALUE, Int.MAX_VALUE, Int.MIN_VALUE, Int.MIN_VALUE)
        for (p in ps) r.union(p.x, p.y)
        return r
    }

    /** The picture with the overlays of one kind hidden (then shown again). */
    private fun without(decor: View, map: MapView, kind: (Overlay) -> Boolean): Bitmap {
        val hidden = map.overlays.filter { kind(it) && it.isEnabled }
        hidden.forEach { it.isEnabled = false }
        val bmp = BasemapFixture.snapshot(decor)
        hidden.forEach { it.isEnabled = true }
        return bmp
    }

    @Test
    fun mainMapWithAReplayedSession() {
        grantAll()
        val (dem, log) = BasemapFixture.simulatedWalk()
        val basemap = BasemapFixture.mbtiles()
        val settings = AppSettings(app.getSharedPreferences(AppSettings.PREFS, Context.MODE_PRIVATE))
        settings.basemapPath = basemap.path
        settings.demPath = dem.path
        settings.engine = "terrain"
        // replay the simulated session through the native navigator, as the in-app replay does
        val outs = ArrayList<NavOutput>()
        var failure: Exception? = null
        ReplayTask(log.path, settings.navigatorConfig(), 1L, onProgress = { o, _ -> outs += o },
            onDone = { o, e -> if (o != null) outs += o; failure = e },
            chunk = 32).run()  // small batches: this sparse log has ~10 rows/s, the track needs points
        assertNull(failure, "replay failed")
        val valid = outs.filter { it.estimate.valid && !it.estimate.latDeg.isNaN() }
        assertTrue(valid.size > 20, "replay gave ${valid.size} valid estimates")
        val track = valid.map { doubleArrayOf(it.estimate.latDeg, it.estimate.lonDeg) }
        val last = valid.last()

        val activity = Robolectric.buildActivity(MainActivity::class.java).setup().get()
        activity.showOutput(last, track)
        val mapView = activity.findViewById<MapView>(R.id.map_view)
        val decor = activity.window.decorView
        // let osmdroid's tile threads read the MBTiles and the main looper hand the tiles over
        var pic = BasemapFixture.snapshot(decor)
        val mapLoc = IntArray(2).also { mapView.getLocationInWindow(it) }
        val mapRect = Rect(mapLoc[0], mapLoc[1], mapLoc[0] + mapView.width, mapLoc[1] + mapView.height)
        fun basemapPixels(b: Bitmap): Int {
            var n = 0
            for (y in mapRect.top until mapRect.bottom step 4) for (x in mapRect.left until mapRect.right step 4) {
                val c = b.getPixel(x, y)
                // osmdroid's "loading" grid is neutral grey; the basemap is tinted (land cover,
                // hillshade, water, paths)
                val r = android.graphics.Color.red(c)
                val g = android.graphics.Color.green(c)
                val bl = android.graphics.Color.blue(c)
                if (maxOf(abs(r - g), abs(g - bl), abs(r - bl)) >= 8) n++
            }
            return n
        }
        val end = System.currentTimeMillis() + 30_000
        while (System.currentTimeMillis() < end) {
            idle()
            Thread.sleep(100)
            pic = BasemapFixture.snapshot(decor)
            if (basemapPixels(pic) > (mapRect.width() / 4) * (mapRect.height() / 4) * 3 / 4) break
        }
        BasemapFixture.save(pic, "main-map")

        // basemap tiles under the overlays (osmdroid's tile pipeline on the host)
        val cells = (mapRect.width() / 4) * (mapRect.height() / 4)
        assertTrue(basemapPixels(pic) > cells * 3 / 4, "basemap drawn on ${basemapPixels(pic)} of $cells sampled pixels")

        val proj = mapView.projection
        fun px(lat: Double, lon: Double): Point {
            val p = proj.toPixels(GeoPoint(lat, lon), null)
            return Point(p.x + mapLoc[0], p.y + mapLoc[1])
        }
        val e = last.estimate
        val here = px(e.latDeg, e.lonDeg)
        assertTrue(mapRect.contains(here.x, here.y), "estimate projects off the map at $here")

        // marker: a heading arrow whose icon is centred on the estimate. A rotated arrow is not
        // symmetric, so its drawn pixels need not be centred on the anchor; the projected
        // estimate must lie well inside them (an icon anchored at its bottom edge, say, puts
        // the estimate half an icon outside)
        val markerDiff = diff(pic, without(decor, mapView) { it is Marker }, mapRect)
        assertTrue(markerDiff.size >= 100, "marker: ${markerDiff.size} pixels")
        val mb = bbox(markerDiff)
        assertTrue(here.x >= mb.left + 2 && here.x <= mb.right - 2 && here.y >= mb.top + 2 && here.y <= mb.bottom - 2,
            "marker drawn over $mb (centre ${mb.centerX()},${mb.centerY()}), estimate projects to $here")

        // 95 % ellipse: its drawn extent is the projected extent of its own points
        val ellipseDiff = diff(pic, without(decor, mapView) { it is Polygon }, mapRect)
        val expected = bbox(MapController.ellipsePoints(e).map { px(it.latitude, it.longitude) })
        assertTrue(expected.width() >= 6, "ellipse too small to see: $expected")
        expected.intersect(mapRect)
        val eb = bbox(ellipseDiff)
        for ((got, want) in listOf(eb.left to expected.left, eb.right to expected.right, eb.top to expected.top,
                                   eb.bottom to expected.bottom)) {
            assertTrue(abs(got - want) <= 4, "ellipse drawn over $eb, its points project over $expected")
        }

        // track: drawn along its projected vertices
        val trackDiff = diff(pic, without(decor, mapView) { it is Polyline }, mapRect)
        assertTrue(trackDiff.isNotEmpty(), "track not drawn")
        val onScreen = track.map { px(it[0], it[1]) }.filter { mapRect.contains(it.x, it.y) }
        assertTrue(onScreen.size >= 5, "track hardly on screen (${onScreen.size} points)")
        val near = onScreen.count { v -> trackDiff.any { hypot((it.x - v.x).toDouble(), (it.y - v.y).toDouble()) <= 4.0 } }
        // vertices under the marker or the ellipse outline are hidden by them
        assertTrue(near >= onScreen.size * 6 / 10, "track drawn near $near of ${onScreen.size} vertices")

        // status line: engine and reason, not clipped
        // the tester's engine line is behind one tap; the walker reads words (issue 29)
        val details = activity.findViewById<android.widget.TextView>(R.id.details_text)
        assertTrue(details.text.contains("terrain"), "details: ${details.text}")
        val source = activity.findViewById<android.widget.TextView>(R.id.walker_source).text.toString()
        assertTrue(source.startsWith("No satellites: terrain"), "source in words: $source")
        val shown = visibleText(decor)
        for (jargon in listOf("PF", "particles", "engine", "σ")) assertFalse(shown.contains(jargon), "\"$jargon\" on the walker's screen: $shown")
        BasemapFixture.assertTextNotClipped(decor, pic, "main map")
    }

    /** All text of the visible TextViews under [v]. */
    private fun visibleText(v: View): String {
        if (v.visibility != View.VISIBLE) return ""
        if (v is android.widget.TextView) return v.text.toString() + "\n"
        if (v is android.view.ViewGroup) return (0 until v.childCount).joinToString("") { visibleText(v.getChildAt(it)) }
        return ""
    }

    @Test
    fun permissionExplanation() {
        val activity = Robolectric.buildActivity(MainActivity::class.java).setup().get()
        val request = assertNotNull(shadowOf(activity).lastRequestedPermission)
        activity.onRequestPermissionsResult(request.requestCode, request.requestedPermissions,
            IntArray(request.requestedPermissions.size) { PackageManager.PERMISSION_DENIED })
        idle()
        val decor = activity.window.decorView
        val pic = BasemapFixture.snapshot(decor)
        BasemapFixture.save(pic, "permission-explanation")
        val panel = activity.findViewById<View>(R.id.permission_panel)
        assertEquals(View.VISIBLE, panel.visibility)
        BasemapFixture.assertTextNotClipped(panel, pic.let {
            val loc = IntArray(2).also { panel.getLocationInWindow(it) }
            Bitmap.createBitmap(it, loc[0], loc[1], panel.width, panel.height)
        }, "permission explanation")
    }

    @Test
    fun sessionsList() {
        val store = SessionStore(app)
        store.newSessionFile(1_780_300_000_000L).writeText("# walk 1\n")
        store.newSessionFile(1_780_310_000_000L).writeText("# walk 2\n")
        store.newSessionFile(1_780_320_000_000L).writeText("# walk 3\n")
        val activity = Robolectric.buildActivity(SessionsActivity::class.java).setup().get()
        idle()
        val decor = activity.window.decorView
        val pic = BasemapFixture.snapshot(decor)
        BasemapFixture.save(pic, "sessions")
        val list = activity.findViewById<android.widget.ListView>(R.id.sessions_list)
        assertEquals(3, list.childCount, "rows drawn")
        BasemapFixture.assertTextNotClipped(decor, pic, "sessions")
    }

    @Test
    fun settings() {
        val activity = Robolectric.buildActivity(SettingsActivity::class.java).setup().get()
        idle()
        val decor = activity.window.decorView
        val pic = BasemapFixture.snapshot(decor)
        BasemapFixture.save(pic, "settings")
        BasemapFixture.assertTextNotClipped(decor, pic, "settings")
    }

    /** One satellite of the synthetic status: constellation, svid, C/N0, elevation, azimuth, used. */
    private data class Sv(val c: Int, val svid: Int, val cn0: Float, val el: Float, val az: Float, val used: Boolean)

    @Test
    fun satelliteView() {
        grantAll()
        // GnssStatus -> the app's callback -> Status rows (merger) and the satellite list
        val sv = listOf(
            Sv(GnssStatus.CONSTELLATION_GPS, 5, 45f, 60f, 45f, true),
            Sv(GnssStatus.CONSTELLATION_GALILEO, 11, 38f, 30f, 200f, true),
            Sv(GnssStatus.CONSTELLATION_GLONASS, 7, 25f, 15f, 290f, false),
            Sv(GnssStatus.CONSTELLATION_BEIDOU, 23, 30f, 75f, 120f, false),
            Sv(GnssStatus.CONSTELLATION_GPS, 17, 41f, 40f, 330f, true),
        )
        val builder = GnssStatus.Builder()
        for (s in sv) builder.addSatellite(s.c, s.svid, s.cn0, s.el, s.az, true, true, s.used, true, 1.57542e9f, false, 0f)
        val rows = SampleBatch()
        val merger = SampleMerger(0L, listOf(object : SampleSink {
            override fun write(batch: SampleBatch) { for (i in 0 until batch.size) rows.addCopy(batch, i) }
        }))
        val gnss = GnssSource(app.getSystemService(LocationManager::class.java), merger,
            elapsedNs = { 7_000_000_000L }, wallMs = { 1_780_000_000_000L })
        gnss.statusCallback.onSatelliteStatusChanged(builder.build())
        merger.flush(Long.MAX_VALUE, all = true)
        assertEquals(sv.size, rows.size, "one Status row per satellite")
        for ((i, s) in sv.withIndex()) {
            assertEquals(SampleKind.GNSS_STATUS, rows.kind(i))
            assertEquals(s.svid.toLong(), rows.long(i, 4)); assertEquals(if (s.used) 1L else 0L, rows.long(i, 5))
            assertEquals(s.az.toDouble(), rows.double(i, 2), 1e-4); assertEquals(s.el.toDouble(), rows.double(i, 3), 1e-4)
        }

        val activity = Robolectric.buildActivity(MainActivity::class.java).setup().get()
        activity.findViewById<View>(R.id.button_satellites).performClick()
        activity.showStats(SessionStats(durationNs = 95_000_000_000L, recordingNs = 0L, navigating = true, recording = false,
            fileName = "", fileBytes = 0L, rowsByKind = LongArray(SampleKind.COUNT), sensorRows = mapOf("accel" to 9500L),
            gnssEpochs = 95L, fixes = 90L, lateRows = 0L, lastLate = null, magAccuracy = 0, satellites = gnss.satellites,
            lastFix = null, locationEnabled = true, checkpoints = emptyList()))
        idle()
        val sky = activity.findViewById<SkyPlotView>(R.id.sky_plot)
        assertEquals(View.VISIBLE, sky.visibility, "satellites button shows the sky plot")
        val decor = activity.window.decorView
        val pic = BasemapFixture.snapshot(decor)
        BasemapFixture.save(pic, "satellites")
        val loc = IntArray(2).also { sky.getLocationInWindow(it) }
        val g = sky.plotGeometry()
        assertTrue(g[2] > 50, "sky plot radius ${g[2]} px")
        fun at(x: Float, y: Float) = pic.getPixel(loc[0] + x.toInt(), loc[1] + y.toInt())
        // the projection, written out here (not the view's own function): north up, east right,
        // zenith at the centre, horizon at radius r
        fun project(azDeg: Double, elDeg: Double): FloatArray {
            val rho = g[2] * (90.0 - elDeg) / 90.0
            val a = Math.toRadians(azDeg)
            return floatArrayOf((g[0] + rho * kotlin.math.sin(a)).toFloat(), (g[1] - rho * kotlin.math.cos(a)).toFloat())
        }
        for (s in sv) {
            val col = SkyPlotView.constellationColor(s.c)
            val p = project(s.az.toDouble(), s.el.toDouble())
            val r = sky.dotRadius(s.cn0.toDouble())
            val what = "svid ${s.svid} (az ${s.az}, el ${s.el}) at ${p[0]},${p[1]}"
            if (s.used) {
                assertTrue(BasemapFixture.close(at(p[0], p[1]), col, 24), "$what: used-in-fix dot is filled with its constellation colour")
            } else {
                assertTrue(!BasemapFixture.close(at(p[0], p[1]), col, 60), "$what: unused dot is a ring, not filled")
                assertTrue(BasemapFixture.close(at(p[0] - r, p[1]), col, 40), "$what: ring drawn at radius $r px")
            }
            // the mirrored direction (azimuth + 180) stays empty: the dot is not drawn at -east/-north
            val m = project(s.az + 180.0, s.el.toDouble())
            assertTrue(!BasemapFixture.close(at(m[0], m[1]), col, 60), "$what: colour also at the mirrored ${m[0]},${m[1]}")
        }
        // C/N0 bars: one per satellite, height by C/N0, pale when not used; svid labels inside the view
        val bars = sky.barOrder()
        assertEquals(listOf(5, 17, 7, 23, 11), bars.map { it.svid }, "bars by constellation then svid")
        val heights = ArrayList<Int>()
        for ((k, s) in bars.withIndex()) {
            val col = SkyPlotView.constellationColor(s.constellation)
            val rect = sky.barRect(k, bars.size, s.cn0DbHz)
            val what = "bar of svid ${s.svid} over $rect"
            // the drawn bar, measured on the picture: from the bar's foot up while the colour holds
            val foot = at(rect.centerX(), rect.bottom - 1)
            var h = 0
            while (h < sky.barStripPx && BasemapFixture.close(at(rect.centerX(), rect.bottom - 1 - h), foot, 6)) h++
            heights += h
            val inside = at(rect.centerX(), rect.bottom - 1 - h / 2)
            val above = at(rect.centerX(), rect.bottom - 1 - h - 2)
            assertTrue(h >= 10, "$what: $h px high")
            assertTrue(!BasemapFixture.close(above, col, 40), "$what: colour continues above the bar")
            if (s.usedInFix) {
                assertTrue(BasemapFixture.close(inside, col, 24), "$what: used satellite bar in its colour")
            } else {
                val a = 110 / 255.0
                val blend = android.graphics.Color.rgb(
                    (android.graphics.Color.red(col) * a + android.graphics.Color.red(above) * (1 - a)).toInt(),
                    (android.graphics.Color.green(col) * a + android.graphics.Color.green(above) * (1 - a)).toInt(),
                    (android.graphics.Color.blue(col) * a + android.graphics.Color.blue(above) * (1 - a)).toInt())
                assertTrue(BasemapFixture.close(inside, blend, 24), "$what: unused satellite bar pale")
            }
            val label = sky.labelBounds(k, bars.size, s.svid.toString())
            assertTrue(label.left >= 0 && label.top >= 0 && label.right <= sky.width && label.bottom <= sky.height,
                "label ${s.svid} at $label outside the ${sky.width}x${sky.height} view")
            var ink = 0
            for (y in label.top until label.bottom) for (x in label.left until label.right) {
                val c = at(x.toFloat(), y.toFloat())
                if (android.graphics.Color.red(c) < 128 && android.graphics.Color.green(c) < 128) ink++
            }
            assertTrue(ink >= 4, "label ${s.svid}: $ink dark pixels in $label")
        }
        // heights in proportion to C/N0 (the strongest signal is the tallest bar)
        val hMax = heights.maxOrNull() ?: 0
        val cMax = bars.maxOf { it.cn0DbHz }
        for ((k, s) in bars.withIndex()) {
            assertEquals(s.cn0DbHz / cMax, heights[k].toDouble() / hMax, 0.05, "bar height of svid ${s.svid}: $heights px for C/N0 ${bars.map { it.cn0DbHz }}")
        }
        val counters = activity.findViewById<android.widget.TextView>(R.id.counters_text)
        assertTrue(counters.text.contains("3/5 satellites used"), "counters: ${counters.text}")
        assertTrue(counters.text.contains("wave the phone"), "magnetometer unreliable is shown: ${counters.text}")
        // the legend names each constellation in its colour (issue 29)
        val legend = activity.findViewById<android.widget.TextView>(R.id.sky_legend)
        assertEquals(View.VISIBLE, legend.visibility, "legend shown with the plot")
        val spanned = legend.text as android.text.Spanned
        for (c in listOf(1, 3, 5, 6)) {
            val name = SkyPlotView.constellationName(c)
            val at = legend.text.indexOf("●\u00A0$name")
            assertTrue(at >= 0, "legend names $name: ${legend.text}")
            val spans = spanned.getSpans(at, at + 1, android.text.style.ForegroundColorSpan::class.java)
            assertEquals(SkyPlotView.constellationColor(c), spans.single().foregroundColor, "legend dot of $name in its colour")
        }
        BasemapFixture.assertTextNotClipped(decor, pic, "satellite view")
    }
}

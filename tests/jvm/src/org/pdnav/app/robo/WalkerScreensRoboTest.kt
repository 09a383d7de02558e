package org.pdnav.app.robo

import android.Manifest
import android.content.Context
import android.graphics.Bitmap
import android.graphics.Point
import android.graphics.Rect
import android.os.Looper
import android.view.View
import android.widget.TextView
import org.junit.Test
import org.junit.runner.RunWith
import org.osmdroid.util.GeoPoint
import org.osmdroid.views.MapView
import org.pdnav.app.R
import org.pdnav.app.map.MapData
import org.pdnav.app.nav.NativeBridge
import org.pdnav.app.nav.NavOutput
import org.pdnav.app.recording.ReplayTask
import org.pdnav.app.region.Place
import org.pdnav.app.region.PlaceStore
import org.pdnav.app.region.RegionInfo
import org.pdnav.app.region.RegionStore
import org.pdnav.app.ui.AppSettings
import org.pdnav.app.ui.GoToArrowView
import org.pdnav.app.ui.MainActivity
import org.pdnav.app.ui.PlacesActivity
import org.pdnav.app.ui.RegionsActivity
import org.pdnav.app.walk.WalkState
import org.pdnav.app.walk.WalkTracker
import org.pdnav.app.walk.remainingM
import org.robolectric.Robolectric
import org.robolectric.RobolectricTestRunner
import org.robolectric.RuntimeEnvironment
import org.robolectric.Shadows.shadowOf
import org.robolectric.annotation.Config
import org.robolectric.annotation.GraphicsMode
import org.robolectric.annotation.LooperMode
import java.io.File
import kotlin.math.abs
import kotlin.math.cos
import kotlin.math.hypot
import kotlin.test.assertEquals
import kotlin.test.assertFalse
import kotlin.test.assertNotNull
import kotlin.test.assertNull
import kotlin.test.assertTrue

/**
 * The walker's screens (issue 29), drawn by Robolectric's native graphics into PNGs beside
 * ScreensRoboTest's, each with checks on what it shows: a region pack made by
 * dem-tools/pdnav_region.py from the shared Andorra data is installed, a simulated walk
 * replayed through the core picks it by itself, the map shows its basemap with the
 * attribution; the status speaks words; Go-to draws the core's walkway route along the
 * graph's edges and updates bearing and distance per step, or warns when the position is
 * too uncertain; a walk leaving its region says so and goes on. Same sandbox configuration
 * as ScreensRoboTest (one JVM, one class loader for libpdnav_jni).
 */
@RunWith(RobolectricTestRunner::class)
@LooperMode(LooperMode.Mode.PAUSED)
@GraphicsMode(GraphicsMode.Mode.NATIVE)
@Config(qualifiers = "w360dp-h640dp-xhdpi")
class WalkerScreensRoboTest {
    private val app = RuntimeEnvironment.getApplication()
    private val settings = AppSettings(app.getSharedPreferences(AppSettings.PREFS, Context.MODE_PRIVATE))

    private fun idle() = shadowOf(Looper.getMainLooper()).idle()

    private fun grantAll() = shadowOf(app).grantPermissions(Manifest.permission.ACCESS_FINE_LOCATION,
        Manifest.permission.ACCESS_COARSE_LOCATION, Manifest.permission.ACTIVITY_RECOGNITION)

    /** The region pack the real tool makes over 1 km around the Lac d'Engolasters, installed. */
    private fun installRegion(): RegionInfo {
        val pack = RegionFixture.build("Engolasters", "--center", "${BasemapFixture.CENTER_LAT},${BasemapFixture.CENTER_LON}",
            "--radius", "${BasemapFixture.RADIUS_M}")
        return pack.inputStream().use { RegionStore(app.filesDir).install(it, pack.name) }
    }

    private class Replay(val task: ReplayTask, val outs: List<NavOutput>, val walks: List<WalkState>, val pairs: List<Pair<NavOutput, WalkState?>>)

    private fun replay(log: File, target: Place?): Replay {
        val outs = ArrayList<NavOutput>()
        val walks = ArrayList<WalkState>()
        val pairs = ArrayList<Pair<NavOutput, WalkState?>>()
        var failure: Exception? = null
        val task = ReplayTask(log.path, settings.navigatorConfig(), 1L,
            onProgress = { o, _ -> outs += o; pairs += o to walks.lastOrNull() },
            onDone = { o, e -> if (o != null) outs += o; failure = e },
            chunk = 32, regions = RegionStore(app.filesDir), target = target, onWalk = { walks += it })
        task.run()
        assertNull(failure, "replay failed: $failure")
        return Replay(task, outs, walks, pairs)
    }

    /** The screen once osmdroid's tile threads have drawn the basemap (up to 30 s). */
    private fun pictureWithTiles(decor: View, map: MapView): Pair<Bitmap, Rect> {
        val loc = IntArray(2).also { map.getLocationInWindow(it) }
        val r = Rect(loc[0], loc[1], loc[0] + map.width, loc[1] + map.height)
        fun tinted(b: Bitmap): Int {
            var n = 0
            for (y in r.top until r.bottom step 4) for (x in r.left until r.right step 4) {
                val c = b.getPixel(x, y)
                val red = android.graphics.Color.red(c); val g = android.graphics.Color.green(c); val bl = android.graphics.Color.blue(c)
                // osmdroid's "loading" grid is a near-neutral grey; the basemap is tinted
                if (maxOf(abs(red - g), abs(g - bl), abs(red - bl)) >= 12) n++
            }
            return n
        }
        idle()  // layout of the texts just set
        var pic = BasemapFixture.snapshot(decor)
        val end = System.currentTimeMillis() + 30_000
        // the map view is full-screen: about half of it lies under the top panel and the buttons
        while (System.currentTimeMillis() < end && tinted(pic) < (r.width() / 4) * (r.height() / 4) / 3) {
            idle()
            Thread.sleep(100)
            pic = BasemapFixture.snapshot(decor)
        }
        val cells = (r.width() / 4) * (r.height() / 4)
        if (tinted(pic) < cells / 3) BasemapFixture.save(pic, "failed-basemap")
        assertTrue(tinted(pic) >= cells / 3, "the region's basemap is drawn on ${tinted(pic)} of $cells sampled pixels (zoom ${map.zoomLevelDouble})")
        return pic to r
    }

    private fun visibleText(v: View): String {
        if (v.visibility != View.VISIBLE) return ""
        if (v is TextView) return v.text.toString() + "\n"
        if (v is android.view.ViewGroup) return (0 until v.childCount).joinToString("") { visibleText(v.getChildAt(it)) }
        return ""
    }

    private fun text(a: android.app.Activity, id: Int) = a.findViewById<TextView>(id).text.toString()

    /** Local east/north metres of (lat, lon) from (lat0, lon0): test geometry only. */
    private fun en(lat0: Double, lon0: Double, lat: Double, lon: Double) = doubleArrayOf(
        Math.toRadians(lon - lon0) * 6_371_000.0 * cos(Math.toRadians(lat0)), Math.toRadians(lat - lat0) * 6_371_000.0)

    /** Difference of two bearings, degrees in [0, 180]. */
    private fun angleDiff(a: Double, b: Double) = abs(((a - b) % 360.0 + 540.0) % 360.0 - 180.0)

    /**
     * The heading the screen says ("Facing south (158°)") against the arrow on the map: the
     * marker's rotation (1° for the text's rounding) and the arrow as drawn (its pixels, the
     * screen with and without the marker, matched against the app's arrow icon turned by each
     * whole degree: the best match within 6°, the icon's outline being a few pixels wide).
     */
    private fun assertArrowAgreesWithHeading(activity: MainActivity, stepHeadingRad: Double, what: String) {
        val headingText = text(activity, R.id.walker_heading)
        val shownDeg = assertNotNull(Regex("\\((\\d+)°\\)").find(headingText), "$what: heading shown ($headingText)").groupValues[1].toDouble()
        assertTrue(angleDiff(Math.toDegrees(stepHeadingRad), shownDeg) <= 0.5 + 1e-9, "$what: the text is the step's heading")
        val markerDeg = activity.map.markerHeadingDeg
        assertTrue(angleDiff(markerDeg, shownDeg) <= 1.0, "$what: the arrow is turned to $markerDeg°, the screen says \"$headingText\"")
        val drawn = drawnArrowDeg(activity)
        assertTrue(angleDiff(drawn, shownDeg) <= 6.0, "$what: the arrow is drawn pointing at $drawn°, the screen says \"$headingText\"")
    }

    private fun drawnArrowDeg(activity: MainActivity): Double {
        idle()
        val decor = activity.window.decorView
        val mapView = activity.findViewById<MapView>(R.id.map_view)
        val marker = activity.map.estimateMarker
        assertTrue(marker.isEnabled, "the position's arrow is shown")
        val with = BasemapFixture.snapshot(decor)
        marker.isEnabled = false
        val without = BasemapFixture.snapshot(decor)
        marker.isEnabled = true
        val loc = IntArray(2).also { mapView.getLocationInWindow(it) }
        val c = mapView.projection.toPixels(marker.position, null)
        val cx = c.x + loc[0]; val cy = c.y + loc[1]
        val icon = org.pdnav.app.map.MapController.arrowBitmap(android.graphics.Color.BLACK, activity.resources.displayMetrics.density)
        val drawnSize = marker.icon.intrinsicWidth.toDouble()  // the drawable's size on screen
        val scale = icon.width / drawnSize
        val reach = drawnSize.toInt()
        val changed = ArrayList<DoubleArray>()
        for (y in cy - reach..cy + reach) for (x in cx - reach..cx + reach) {
            if (x !in 0 until with.width || y !in 0 until with.height) continue
            if (with.getPixel(x, y) != without.getPixel(x, y)) changed += doubleArrayOf(x - cx + 0.5, y - cy + 0.5)
        }
        assertTrue(changed.size >= 100, "the arrow's pixels: ${changed.size}")
        var best = -1
        var bestHits = -1
        for (deg in 0 until 360) {
            val t = Math.toRadians(deg.toDouble())
            val cs = cos(t); val sn = kotlin.math.sin(t)
            var hits = 0
            for (p in changed) {
                // back into the upright icon: undo a clockwise turn by deg (screen y points down)
                val ux = p[0] * cs + p[1] * sn
                val uy = -p[0] * sn + p[1] * cs
                val ix = (ux * scale + icon.width / 2.0).toInt(); val iy = (uy * scale + icon.height / 2.0).toInt()
                if (ix in 0 until icon.width && iy in 0 until icon.height && android.graphics.Color.alpha(icon.getPixel(ix, iy)) > 0) hits++
            }
            if (hits > bestHits) { bestHits = hits; best = deg }
        }
        return best.toDouble()
    }

    /** Distance (m) from a point to the nearest graph edge segment. */
    private fun toGraphM(edges: List<List<DoubleArray>>, lat: Double, lon: Double): Double {
        var best = Double.MAX_VALUE
        for (e in edges) for (k in 0 until e.size - 1) {
            val a = en(lat, lon, e[k][0], e[k][1])
            val b = en(lat, lon, e[k + 1][0], e[k + 1][1])
            val dx = b[0] - a[0]; val dy = b[1] - a[1]
            val l2 = dx * dx + dy * dy
            val t = if (l2 == 0.0) 0.0 else (-(a[0] * dx + a[1] * dy) / l2).coerceIn(0.0, 1.0)
            best = minOf(best, hypot(a[0] + t * dx, a[1] + t * dy))
        }
        return best
    }

    @Test
    fun aReplayPicksItsRegionAndTheWalkerReadsWords() {
        grantAll()
        // the walker opens the region file with the app ("open with": a VIEW intent)
        val pack = RegionFixture.build("Engolasters", "--center", "${BasemapFixture.CENTER_LAT},${BasemapFixture.CENTER_LON}",
            "--radius", "${BasemapFixture.RADIUS_M}")
        val regions = Robolectric.buildActivity(RegionsActivity::class.java,
            android.content.Intent(android.content.Intent.ACTION_VIEW, android.net.Uri.fromFile(pack))).setup().get()
        regions.importThread?.join(60_000)
        idle()
        assertTrue(text(regions, R.id.regions_status).startsWith("Installed Engolasters ("), text(regions, R.id.regions_status))
        val region = assertNotNull(RegionStore(app.filesDir).find("Engolasters"), "installed")
        assertTrue(region.attribution.contains("© OpenStreetMap contributors"), "manifest attribution: ${region.attribution}")
        val (_, log) = BasemapFixture.simulatedWalk()
        settings.engine = "auto"
        val r = replay(log, null)
        assertEquals(region.name, r.task.region?.name, "the replay picked the region containing its start by itself")
        val w = r.walks.last()
        val truth = File(log.path + ".truth.csv").readLines().drop(1)
        assertEquals(truth.size.toLong(), w.steps, "one per-step estimate per simulated step")
        // distance walked: the core's sum of step lengths; the simulated phone's steps measure
        // 530 m (its stride error model) for a 451 m truth track: the screen shows the former
        val measured = truth.sumOf { it.split(',')[7].toDouble() }
        assertTrue(abs(w.distanceM - measured) <= 0.05 * measured, "walked ${w.distanceM} m, the simulated steps $measured m")
        assertFalse(w.outsideRegion)

        settings.lastRegion = region.name
        val activity = Robolectric.buildActivity(MainActivity::class.java).setup().get()
        assertEquals(region.name, activity.shownRegion?.name, "the map opens on the region")
        val last = r.outs.last { it.estimate.valid }
        val track = r.outs.filter { it.estimate.valid && it.estimate.latDeg.isFinite() }.map { doubleArrayOf(it.estimate.latDeg, it.estimate.lonDeg) }
        activity.mapDataThread?.join(20_000)
        idle()
        // nothing runs and nothing is shown yet: the idle hint
        assertEquals(activity.getString(R.string.status_idle), text(activity, R.id.status_text))
        activity.showOutput(last, track)
        activity.showWalk(w)
        val decor = activity.window.decorView
        val map = activity.findViewById<MapView>(R.id.map_view)
        val (pic, _) = pictureWithTiles(decor, map)
        BasemapFixture.save(pic, "main-walker")
        // a walk is shown (no session runs): no idle hint under it
        assertFalse(visibleText(decor).contains(activity.getString(R.string.status_idle)), "idle hint under a shown walk:\n${visibleText(decor)}")
        assertEquals("", text(activity, R.id.status_text), "no session, a finished walk shown: no state line")
        assertArrowAgreesWithHeading(activity, w.step!!.headingRad, "main screen")
        val attribution = activity.findViewById<TextView>(R.id.map_attribution)
        assertEquals(View.VISIBLE, attribution.visibility, "attribution shown")
        assertTrue(attribution.text.startsWith("© OpenStreetMap contributors"), "attribution: ${attribution.text}")
        assertTrue(activity.map.graphEdgeCount > 10, "the region's walkway graph is drawn (${activity.map.graphEdgeCount} edges)")
        assertTrue(Regex("±\\d+ m, (very good|good|fair|poor|very poor)").matches(text(activity, R.id.walker_position)), text(activity, R.id.walker_position))
        assertTrue(text(activity, R.id.walker_source) in listOf("No satellites: terrain and paths", "No satellites: paths", "Dead reckoning only"),
            text(activity, R.id.walker_source))
        assertTrue(Regex("Facing (north|north-east|east|south-east|south|south-west|west|north-west) \\(\\d+°\\)").matches(text(activity, R.id.walker_heading)),
            text(activity, R.id.walker_heading))
        // the simulated walk took 436 s (first to last step: 7 min 15 s)
        assertTrue(Regex("Walked \\d+ m in 0:07:1[45]").matches(text(activity, R.id.walker_walked)), text(activity, R.id.walker_walked))
        assertEquals("Map: ${region.name}", text(activity, R.id.region_text))
        val shown = visibleText(decor)
        for (jargon in listOf("PF", "particles", "engine", "σ", "ok:", "degraded")) assertFalse(shown.contains(jargon), "\"$jargon\" on the walker's screen:\n$shown")
        BasemapFixture.assertTextNotClipped(decor, pic, "walker's main screen")

        // one tap: the tester's details
        activity.findViewById<View>(R.id.walker_panel).performClick()
        idle()
        val details = BasemapFixture.snapshot(decor)
        BasemapFixture.save(details, "main-details")
        assertTrue(text(activity, R.id.details_text).contains(" steps"), text(activity, R.id.details_text))
        assertTrue(visibleText(decor).contains(last.estimate.statusText()), "the engine line is one tap away")
        BasemapFixture.assertTextNotClipped(decor, details, "details")

        // the regions screen lists it with its area and size
        val rp = BasemapFixture.snapshot(regions.window.decorView)
        BasemapFixture.save(rp, "regions")
        val listed = visibleText(regions.window.decorView)
        assertTrue(listed.contains(region.name) && listed.contains("° N") && listed.contains(" MB"), listed)
        BasemapFixture.assertTextNotClipped(regions.window.decorView, rp, "regions")
    }

    @Test
    fun goToDrawsTheWalkwayRouteUpdatesPerStepAndWarnsWhenUncertain() {
        grantAll()
        val region = installRegion()
        val (_, log) = BasemapFixture.simulatedWalk()
        settings.engine = "auto"
        settings.lastRegion = region.name
        val edges = MapData.split(NativeBridge.graphPolylines(region.graphPath))
        // the place: the graph vertex nearest to 400 m from the walk's start
        val startLat = 42.5217866432; val startLon = 1.5716283767
        val target = edges.flatten().minByOrNull { v -> val d = en(startLat, startLon, v[0], v[1]); abs(hypot(d[0], d[1]) - 400.0) }!!
        val hut = Place("Hut", target[0], target[1], Place.SAVED, 1L)
        val r = replay(log, hut)
        val goTos = r.walks.mapNotNull { it.goTo }
        assertTrue(goTos.size >= 100, "Go-to at every report (${goTos.size})")
        assertTrue(goTos.zipWithNext().all { (a, b) -> b.tNs >= a.tNs }, "per-step updates in time order")
        assertTrue(goTos.map { it.tNs }.distinct().size >= 100, "a new step at (nearly) every report: ${goTos.map { it.tNs }.distinct().size}")
        assertTrue(goTos.map { Math.round(it.straightM) }.distinct().size >= 20, "the distance follows the walker")
        assertTrue(goTos.map { Math.round(it.bearingDeg) }.distinct().size >= 10, "the bearing follows the walker")
        for (g in goTos) {
            val s = r.walks.first { it.goTo === g }.step!!
            // straight distance: the core's geodesic vs a local plane over < 1 km (0.5 %)
            val d = en(s.latDeg, s.lonDeg, hut.latDeg, hut.lonDeg)
            assertEquals(hypot(d[0], d[1]), g.straightM, 0.005 * g.straightM + 0.05, "straight distance")
            assertEquals(g.uncertain, g.sigmaM >= WalkTracker.UNCERTAIN_RATIO * g.straightM, "uncertainty rule")
            val route = assertNotNull(g.route, "a walkway route at ${g.tNs}")
            // along the graph: every vertex on a known edge, the length that of the polyline
            for (p in route.points) assertTrue(toGraphM(edges, p.first, p.second) < 1.0, "route vertex $p is ${toGraphM(edges, p.first, p.second)} m off the graph")
            var len = 0.0
            for (k in 1 until route.points.size) {
                val e = en(route.points[k - 1].first, route.points[k - 1].second, route.points[k].first, route.points[k].second)
                len += hypot(e[0], e[1])
            }
            assertEquals(len, route.lengthM, 0.01 * route.lengthM + 0.5, "route length = its polyline")
            assertTrue(route.remainingM >= g.straightM - 1.0, "along the paths is never shorter than straight")
        }
        val w = r.walks.last()
        val g = w.goTo!!
        assertFalse(g.uncertain, "400 m away with a ${g.sigmaM} m sigma: a direction")

        val activity = Robolectric.buildActivity(MainActivity::class.java).setup().get()
        activity.mapDataThread?.join(20_000)
        idle()
        val last = r.outs.last { it.estimate.valid }
        activity.map.follow = false
        activity.showOutput(last, emptyList())
        activity.showWalk(w)
        // frame the walker and the place
        activity.map.map.zoomToBoundingBox(org.osmdroid.util.BoundingBox.fromGeoPoints(
            (g.route!!.points + listOf(hut.latDeg to hut.lonDeg, w.step!!.latDeg to w.step!!.lonDeg))
                .map { GeoPoint(it.first, it.second) }), false, 60)
        idle()
        val decor = activity.window.decorView
        val mapView = activity.findViewById<MapView>(R.id.map_view)
        val (pic, mapRect) = pictureWithTiles(decor, mapView)
        BasemapFixture.save(pic, "goto")
        assertArrowAgreesWithHeading(activity, w.step!!.headingRad, "go to")
        assertFalse(visibleText(decor).contains(activity.getString(R.string.status_idle)), "idle hint under Go-to")
        assertEquals(View.VISIBLE, activity.findViewById<View>(R.id.goto_panel).visibility)
        val gt = text(activity, R.id.goto_text)
        assertTrue(gt.startsWith("Go to Hut: ") && gt.contains(" straight, bearing ") && gt.contains(" along paths"), gt)
        assertTrue(activity.findViewById<GoToArrowView>(R.id.goto_arrow).arrowShown, "a confident arrow")
        // the route is drawn along its projected vertices
        val routeLine = activity.map.routeLine
        routeLine.isEnabled = false
        val without = BasemapFixture.snapshot(decor)
        routeLine.isEnabled = true
        val drawn = ArrayList<Point>()
        for (y in mapRect.top until mapRect.bottom) for (x in mapRect.left until mapRect.right) if (pic.getPixel(x, y) != without.getPixel(x, y)) drawn += Point(x, y)
        assertTrue(drawn.size > 200, "route pixels: ${drawn.size}")
        val loc = IntArray(2).also { mapView.getLocationInWindow(it) }
        val verts = g.route!!.points.map { mapView.projection.toPixels(GeoPoint(it.first, it.second), null) }.map { Point(it.x + loc[0], it.y + loc[1]) }
            .filter { mapRect.contains(it.x, it.y) }
        assertTrue(verts.size >= 3, "route on screen: ${verts.size} vertices")
        val near = verts.count { v -> drawn.any { hypot((it.x - v.x).toDouble(), (it.y - v.y).toDouble()) <= 4.0 } }
        // the two end vertices may lie under the walker's arrow and the place's dot
        assertTrue(near >= minOf(verts.size - 2, verts.size * 8 / 10), "route drawn at $near of ${verts.size} vertices")
        val far = drawn.count { p -> verts.zipWithNext().none { (a, b) ->
            val dx = (b.x - a.x).toDouble(); val dy = (b.y - a.y).toDouble(); val l2 = dx * dx + dy * dy
            val t = if (l2 == 0.0) 0.0 else (((p.x - a.x) * dx + (p.y - a.y) * dy) / l2).coerceIn(0.0, 1.0)
            hypot(p.x - a.x - t * dx, p.y - a.y - t * dy) <= 8.0 } }
        assertTrue(far <= drawn.size / 20, "$far of ${drawn.size} route pixels away from the route's segments")
        BasemapFixture.assertTextNotClipped(decor, pic, "go to")

        // a place a few metres from the final position: sigma > distance, no confident arrow
        val s = w.step!!
        val near3 = Place("Car park", s.latDeg + 3.0 / 111_195.0, s.lonDeg, Place.SAVED, 2L)
        val u = replay(log, near3).walks.last().goTo!!
        assertTrue(u.sigmaM > u.straightM, "sigma ${u.sigmaM} m > distance ${u.straightM} m")
        assertTrue(u.uncertain, "sigma ${u.sigmaM} m >= half of ${u.straightM} m: flagged uncertain")
        activity.showWalk(r.walks.last().copy(goTo = u))
        idle()
        val up = BasemapFixture.snapshot(decor)
        BasemapFixture.save(up, "goto-uncertain")
        val ut = text(activity, R.id.goto_text)
        assertTrue(ut.startsWith("Go to Car park: position too uncertain for a direction"), ut)
        assertFalse(activity.findViewById<GoToArrowView>(R.id.goto_arrow).arrowShown, "no arrow")
        BasemapFixture.assertTextNotClipped(decor, up, "go to, uncertain")

        // places: kept per region; the screen's Go to returns to the map with the place
        val store = PlaceStore(app.filesDir, region.name)
        val t0 = 1_796_290_860_000L  // 2026-12-03 09:41 UTC
        store.add(Place("Start 09:41", startLat, startLon, Place.START, t0))
        store.add(hut.copy(createdMs = t0 + 240_000L))
        store.add(Place("Checkpoint 09:50", 42.5230, 1.5720, Place.CHECKPOINT, t0 + 540_000L))
        val places = Robolectric.buildActivity(PlacesActivity::class.java,
            android.content.Intent(app, PlacesActivity::class.java).putExtra(PlacesActivity.EXTRA_REGION, region.name)).setup().get()
        idle()
        val pp = BasemapFixture.snapshot(places.window.decorView)
        BasemapFixture.save(pp, "places")
        val listed = visibleText(places.window.decorView)
        for (n in listOf("Start 09:41", "Hut", "Checkpoint 09:50", "walk start", "checkpoint", "saved place")) assertTrue(listed.contains(n), "$n in $listed")
        BasemapFixture.assertTextNotClipped(places.window.decorView, pp, "places")
        places.goTo(places.shown().first { it.name == "Hut" })
        val next = assertNotNull(shadowOf(places).nextStartedActivity)
        assertEquals(hut.latDeg, next.getDoubleExtra(MainActivity.EXTRA_GOTO_LAT, Double.NaN))
    }

    @Test
    fun aWalkLeavingItsRegionIsToldAndNavigationGoesOn() {
        grantAll()
        // the real tool's pack for the southern part only: its DEM, walkways and basemap end at
        // 42.5226 N, so north of it the core has neither terrain nor paths (the walk goes north,
        // then back)
        val pack = RegionFixture.build("Engolasters south", "--bbox", "42.5150,1.5600,42.5226,1.5850")
        val south = RegionStore(app.filesDir).let { store -> pack.inputStream().use { store.install(it, pack.name) } }
        assertTrue(south.bounds.northDeg < 42.5227, "south region bounds ${south.bounds}")
        val demNorth = NativeBridge.demBounds(south.demPath)[2]
        assertTrue(demNorth < 42.5226 + 0.0009, "the DEM ends within 100 m of the region's edge (at $demNorth)")
        val (_, log) = BasemapFixture.simulatedWalk()
        settings.engine = "auto"
        val r = replay(log, null)
        assertEquals("Engolasters south", r.task.region?.name)
        val k = r.pairs.indexOfFirst { it.second?.outsideRegion == true }
        assertTrue(k >= 0, "the walk left the region (north of 42.5226)")
        val leftAt = r.pairs[k].second!!.steps
        // The core's source after leaving is its own: off the DEM the terrain engine stops being a
        // measurement once most of its weight is off the DEM (TerrainEngine: > 50 % -> degraded),
        // which may take a while after the fused position crosses the edge. The screen must say
        // what the core uses, never contradict it: checked at the first output outside.
        val j = k
        val (outAt, walkAt) = r.pairs[j]
        val later = r.walks.last()
        assertTrue(later.steps > walkAt!!.steps + 100, "navigation went on: ${walkAt.steps} -> ${later.steps} steps")
        assertTrue(r.outs.last().estimate.valid, "a valid estimate at the end")
        assertTrue(walkAt.step!!.latDeg > 42.5226 - 0.0003, "left at ${walkAt.step!!.latDeg}")

        settings.lastRegion = "Engolasters south"
        val activity = Robolectric.buildActivity(MainActivity::class.java).setup().get()
        activity.mapDataThread?.join(20_000)
        idle()
        activity.showOutput(outAt, emptyList())
        activity.showWalk(walkAt)
        val decor = activity.window.decorView
        // north of the region's map there are no tiles: a third of the map's picture at least
        val (pic, _) = pictureWithTiles(decor, activity.findViewById(R.id.map_view))
        BasemapFixture.save(pic, "out-of-region")
        // the fact, and the source the core uses: one story
        assertEquals("You have left the map area of Engolasters south", text(activity, R.id.region_text))
        val source = text(activity, R.id.walker_source)
        assertTrue(source == org.pdnav.app.walk.WalkerWords.source(outAt, graphLoaded = true) ||
            source == org.pdnav.app.walk.WalkerWords.source(outAt, graphLoaded = false), "source \"$source\" is not the core's ${outAt.estimate.engine}")
        val shown = visibleText(decor)
        assertFalse(shown.contains(activity.getString(R.string.status_idle)), "idle hint out of the region:\n$shown")
        assertArrowAgreesWithHeading(activity, walkAt.step!!.headingRad, "out of region")
        BasemapFixture.assertTextNotClipped(decor, pic, "out of region")
    }
}

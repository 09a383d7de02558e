package org.pdnav.app.robo

import android.Manifest
import android.content.ComponentName
import android.content.Intent
import android.os.Looper
import android.content.pm.PackageManager
import android.view.View
import android.widget.Button
import android.widget.TextView
import org.junit.Test
import org.junit.runner.RunWith
import org.pdnav.app.R
import org.pdnav.app.map.MapController
import org.pdnav.app.nav.NavEstimate
import org.pdnav.app.nav.NavOutput
import org.pdnav.app.nav.TestPaths
import org.pdnav.app.sensors.NavigationService
import org.pdnav.app.ui.AppSettings
import org.pdnav.app.ui.MainActivity
import org.robolectric.Robolectric
import org.robolectric.RobolectricTestRunner
import org.robolectric.RuntimeEnvironment
import org.robolectric.Shadows.shadowOf
import org.robolectric.annotation.LooperMode
import kotlin.math.abs
import kotlin.test.assertEquals
import kotlin.test.assertFalse
import kotlin.test.assertNotNull
import kotlin.test.assertNull
import kotlin.test.assertTrue

/** The map screen under Robolectric (osmdroid views on the aapt2-linked resources). */
@RunWith(RobolectricTestRunner::class)
@LooperMode(LooperMode.Mode.PAUSED)
class MainActivityRoboTest {
    private val app = RuntimeEnvironment.getApplication()

    @Test
    fun refusedPermissionsShowTheExplanation() {
        val activity = Robolectric.buildActivity(MainActivity::class.java).setup().get()
        val request = assertNotNull(shadowOf(activity).lastRequestedPermission, "permissions requested at start")
        assertTrue(Manifest.permission.ACCESS_FINE_LOCATION in request.requestedPermissions)
        assertTrue(Manifest.permission.ACTIVITY_RECOGNITION in request.requestedPermissions)
        assertTrue(Manifest.permission.POST_NOTIFICATIONS in request.requestedPermissions)
        val panel = activity.findViewById<View>(R.id.permission_panel)
        assertEquals(View.GONE, panel.visibility, "no explanation before the answer")

        activity.onRequestPermissionsResult(request.requestCode, request.requestedPermissions,
            IntArray(request.requestedPermissions.size) { PackageManager.PERMISSION_DENIED })

        assertEquals(View.VISIBLE, panel.visibility)
        assertEquals(activity.getString(R.string.permission_explanation), activity.findViewById<TextView>(R.id.permission_text).text.toString())
        assertFalse(activity.findViewById<Button>(R.id.button_navigate).isEnabled, "cannot navigate without permissions")
    }

    @Test
    fun grantedPermissionsShowTheMapWithoutExplanation() {
        shadowOf(app).grantPermissions(Manifest.permission.ACCESS_FINE_LOCATION, Manifest.permission.ACCESS_COARSE_LOCATION,
            Manifest.permission.ACTIVITY_RECOGNITION)
        val activity = Robolectric.buildActivity(MainActivity::class.java).setup().get()
        assertEquals(View.GONE, activity.findViewById<View>(R.id.permission_panel).visibility)
        assertTrue(activity.findViewById<Button>(R.id.button_navigate).isEnabled)
        // no basemap imported yet: the status says so (offline tiles only, never the network)
        assertEquals(activity.getString(R.string.status_no_basemap), activity.findViewById<TextView>(R.id.status_text).text.toString())
        assertFalse(activity.map.map.useDataConnection(), "no network tile source")
    }

    @Test
    fun activityRecognitionIsOptionalAndNotificationsAreAskedWhenLocationIsGranted() {
        shadowOf(app).grantPermissions(Manifest.permission.ACCESS_FINE_LOCATION, Manifest.permission.ACCESS_COARSE_LOCATION)
        val activity = Robolectric.buildActivity(MainActivity::class.java).setup().get()
        val request = assertNotNull(shadowOf(activity).lastRequestedPermission, "optional permissions asked too")
        assertTrue(Manifest.permission.POST_NOTIFICATIONS in request.requestedPermissions, "notifications asked although location is granted")
        activity.onRequestPermissionsResult(request.requestCode, request.requestedPermissions,
            IntArray(request.requestedPermissions.size) { PackageManager.PERMISSION_DENIED })
        assertEquals(View.GONE, activity.findViewById<View>(R.id.permission_panel).visibility, "activity recognition refused: GNSS-only is fine")
        assertTrue(activity.findViewById<Button>(R.id.button_record).isEnabled, "recording possible without activity recognition")
        assertTrue(activity.findViewById<TextView>(R.id.info_text).text.contains("step detector"), "the cost of the refusal is said")
    }

    @Test
    fun theExplanationIsRecheckedAfterAGrantInSystemSettings() {
        val controller = Robolectric.buildActivity(MainActivity::class.java).setup()
        val activity = controller.get()
        val request = assertNotNull(shadowOf(activity).lastRequestedPermission)
        activity.onRequestPermissionsResult(request.requestCode, request.requestedPermissions,
            IntArray(request.requestedPermissions.size) { PackageManager.PERMISSION_DENIED })
        assertEquals(View.VISIBLE, activity.findViewById<View>(R.id.permission_panel).visibility)
        // the user grants in the system settings and comes back
        shadowOf(app).grantPermissions(Manifest.permission.ACCESS_FINE_LOCATION, Manifest.permission.ACCESS_COARSE_LOCATION)
        controller.pause().resume()
        assertEquals(View.GONE, activity.findViewById<View>(R.id.permission_panel).visibility, "explanation gone after the grant")
        assertTrue(activity.findViewById<Button>(R.id.button_navigate).isEnabled)
    }

    @Test
    fun theMapOpensOnTheBasemapAreaAndFollowCanBeSwitchedOff() {
        shadowOf(app).grantPermissions(Manifest.permission.ACCESS_FINE_LOCATION, Manifest.permission.ACCESS_COARSE_LOCATION)
        val f = java.io.File(app.filesDir, "data/basemap/test.mbtiles").apply { parentFile?.mkdirs(); delete() }
        android.database.sqlite.SQLiteDatabase.openOrCreateDatabase(f, null).use { db ->
            db.execSQL("CREATE TABLE metadata (name TEXT, value TEXT)")
            db.execSQL("CREATE TABLE tiles (zoom_level INTEGER, tile_column INTEGER, tile_row INTEGER, tile_data BLOB)")
            db.execSQL("INSERT INTO metadata VALUES ('name', 'test'), ('format', 'png'), ('bounds', '1.50,42.50,1.52,42.52')")
        }
        AppSettings(app.getSharedPreferences(AppSettings.PREFS, android.content.Context.MODE_PRIVATE)).basemapPath = f.path
        val activity = Robolectric.buildActivity(MainActivity::class.java).setup().get()
        val map = activity.map
        assertEquals(42.51, map.centerLatDeg, 1e-4, "centred on the basemap, not on 0, 0")
        assertEquals(1.51, map.centerLonDeg, 1e-4)
        // Follow off: an output does not move the map
        activity.findViewById<Button>(R.id.button_follow).performClick()
        assertFalse(map.follow)
        val e = NavEstimate(5_000_000_000L, 2, 1, "", 42.6, 1.6, 1500.0, 0.0, 0.0, 4.0, 0.0, 4.0, 3.0)
        activity.showOutput(NavOutput(e, arrayOf(e), 1, DoubleArray(0)), listOf(doubleArrayOf(42.6, 1.6)))
        assertEquals(42.51, map.centerLatDeg, 1e-4, "free map stays where it was")
        activity.findViewById<Button>(R.id.button_follow).performClick()
        activity.showOutput(NavOutput(e, arrayOf(e), 1, DoubleArray(0)), listOf(doubleArrayOf(42.6, 1.6)))
        assertEquals(42.6, map.centerLatDeg, 1e-4, "following again")
    }

    /** The next ACTION_SET service start (the binding's plain intent is skipped). */
    private fun nextSet(): android.content.Intent? {
        while (true) {
            val i = shadowOf(app).nextStartedService ?: return null
            if (i.action == NavigationService.ACTION_SET) return i
        }
    }

    @Test
    fun locationSwitchedOffShowsAPromptThatOpensTheLocationSettings() {
        shadowOf(app).grantPermissions(Manifest.permission.ACCESS_FINE_LOCATION, Manifest.permission.ACCESS_COARSE_LOCATION)
        val lm = app.getSystemService(android.location.LocationManager::class.java)
        shadowOf(lm).setLocationEnabled(false)
        val activity = Robolectric.buildActivity(MainActivity::class.java).setup().get()
        assertEquals(View.VISIBLE, activity.findViewById<View>(R.id.location_panel).visibility, "prompt shown")
        activity.findViewById<Button>(R.id.location_settings).performClick()
        assertEquals(android.provider.Settings.ACTION_LOCATION_SOURCE_SETTINGS, shadowOf(activity).nextStartedActivity?.action)
        shadowOf(lm).setLocationEnabled(true)
        val again = Robolectric.buildActivity(MainActivity::class.java).setup().get()
        assertEquals(View.GONE, again.findViewById<View>(R.id.location_panel).visibility, "no prompt when location is on")
    }

    @Test
    fun withoutABasemapTheMapOpensOnTheDemAndDrawsTheWalkwayGraph() {
        shadowOf(app).grantPermissions(Manifest.permission.ACCESS_FINE_LOCATION, Manifest.permission.ACCESS_COARSE_LOCATION)
        val root = java.io.File(System.getProperty("pdnav.root") ?: error("pdnav.root not set"))
        val s = AppSettings(app.getSharedPreferences(AppSettings.PREFS, android.content.Context.MODE_PRIVATE))
        s.graphPath = java.io.File(root, "tests/fuzz-corpus/graph_reader/small_l.graph").path
        s.demPath = java.io.File(root, "tests/fuzz-corpus/dem_reader/andorra_4x4.pdem").path
        val activity = Robolectric.buildActivity(MainActivity::class.java).setup().get()
        assertNotNull(activity.mapDataThread).join(10_000)
        shadowOf(android.os.Looper.getMainLooper()).idle()
        assertEquals(2, activity.map.graphEdgeCount, "both edges of the graph drawn")
        assertEquals(42.55, activity.map.centerLatDeg, 1e-4, "centred on the DEM tile")
        assertEquals(1.55, activity.map.centerLonDeg, 1e-4)
    }

    @Test
    fun aLongPressStartGoesToTheNextSessionOnlyAndNothingIsSaved() {
        shadowOf(app).grantPermissions(Manifest.permission.ACCESS_FINE_LOCATION, Manifest.permission.ACCESS_COARSE_LOCATION)
        val activity = Robolectric.buildActivity(MainActivity::class.java).setup().get()
        activity.declareStart(42.5, 1.5)
        activity.findViewById<Button>(R.id.button_navigate).performClick()
        val first = assertNotNull(nextSet(), "Navigate started the service")
        assertEquals(NavigationService.ACTION_SET, first.action)
        assertEquals(42.5, first.getDoubleExtra(NavigationService.EXTRA_START_LAT, Double.NaN), 1e-12)
        assertNull(activity.pendingStart, "consumed by that session")
        activity.findViewById<Button>(R.id.button_navigate).performClick()  // (service not bound in the test: starts again)
        val second = assertNotNull(nextSet(), "Navigate started the service again")
        assertFalse(second.hasExtra(NavigationService.EXTRA_START_LAT), "a later session does not inherit the start")
        val prefs = app.getSharedPreferences(AppSettings.PREFS, android.content.Context.MODE_PRIVATE)
        assertFalse(prefs.all.keys.any { it.contains("lat") }, "no start in preferences: ${prefs.all.keys}")
        // an old version's saved start is dropped
        prefs.edit().putLong(AppSettings.OLD_KEY_LAT, 1L).commit()
        assertTrue(AppSettings(prefs).navigatorConfig().startLatDeg.isNaN())
        assertFalse(prefs.contains(AppSettings.OLD_KEY_LAT))
    }

    @Test
    fun anOutputDrawsMarkerEllipseTrackAndStatus() {
        shadowOf(app).grantPermissions(Manifest.permission.ACCESS_FINE_LOCATION, Manifest.permission.ACCESS_COARSE_LOCATION,
            Manifest.permission.ACTIVITY_RECOGNITION)
        val activity = Robolectric.buildActivity(MainActivity::class.java).setup().get()
        // 4 m x 2 m (1 sigma) ellipse, major axis east-west
        val e = NavEstimate(5_000_000_000L, 2, 2, "GNSS lost, terrain engine", 42.5, 1.5, 1500.0,
            10.0, 20.0, 16.0, 0.0, 4.0, 3.0)
        val out = NavOutput(e, arrayOf(e), 12, doubleArrayOf(10.0, 20.0, 12.0, 18.0))
        activity.showOutput(out, listOf(doubleArrayOf(42.49990, 1.49990), doubleArrayOf(42.5, 1.5)))
        // the walker's words on the screen; the engine line and numbers one tap away (issue 29)
        val details = activity.findViewById<TextView>(R.id.details_text).text.toString()
        assertTrue(details.contains("terrain") && details.contains("GNSS lost, terrain engine") && details.contains("12 steps"), details)
        assertEquals(android.view.View.GONE, activity.findViewById<android.view.View>(R.id.details_panel).visibility, "details hidden")
        activity.findViewById<android.view.View>(R.id.walker_panel).performClick()
        assertEquals(android.view.View.VISIBLE, activity.findViewById<android.view.View>(R.id.details_panel).visibility, "one tap shows them")
        assertEquals("±4 m, very good", activity.findViewById<TextView>(R.id.walker_position).text.toString())
        assertEquals("No satellites: terrain", activity.findViewById<TextView>(R.id.walker_source).text.toString())
        val map = activity.map
        assertTrue(map.markerShown)
        assertEquals(1, map.engineCount, "each engine drawn")
        assertTrue(details.contains("42.500000") && details.contains("1.500000") && details.contains("±") && details.contains("terrain"), details)
        assertEquals(36, map.ellipsePointCount)
        assertEquals(2, map.trackPointCount)
        // the 95 % ellipse reaches 2.4477 * 4 m east of the estimate
        val pts = MapController.ellipsePoints(e)
        val eastMost = pts.maxOf { it.longitude }
        val eastM = (eastMost - 1.5) * Math.PI / 180 * 6_371_000.0 * Math.cos(Math.toRadians(42.5))
        assertTrue(abs(eastM - MapController.K95 * 4.0) < 0.05, "east extent $eastM m")
    }

    @Test
    fun aRotationDuringAReplayKeepsTheReplayRunningInTheService() {
        shadowOf(app).grantPermissions(Manifest.permission.ACCESS_FINE_LOCATION, Manifest.permission.ACCESS_COARSE_LOCATION,
            Manifest.permission.ACTIVITY_RECOGNITION)
        val service = Robolectric.buildService(NavigationService::class.java).create().get()
        shadowOf(app).setComponentNameAndServiceForBindService(ComponentName(app, NavigationService::class.java),
            service.onBind(Intent(app, NavigationService::class.java)))
        val log = TestPaths.sharedData("gnss-mountainview/pseudoranges_log_2016_08_22_14_45_50.txt")
        // the replay reads a named pipe: it waits in open() until the test writes the log, so it
        // is certainly still running when the screen rotates (a file this small replays in ms)
        val fifo = java.io.File(TestPaths.scratch("rotation"), log.name)
        val mk = ProcessBuilder("mkfifo", fifo.path).redirectErrorStream(true).start()
        assertTrue(mk.waitFor(30, java.util.concurrent.TimeUnit.SECONDS) && mk.exitValue() == 0, "mkfifo $fifo")
        val intent = Intent(app, MainActivity::class.java).putExtra(MainActivity.EXTRA_REPLAY, fifo.path)
        val controller = Robolectric.buildActivity(MainActivity::class.java, intent).setup()
        shadowOf(Looper.getMainLooper()).idle()
        val task = assertNotNull(service.replay, "the replay runs in the service")
        // the rotation: the Activity is destroyed and re-created with its saved state
        controller.recreate()
        shadowOf(Looper.getMainLooper()).idle()
        assertFalse(task.isCancelled, "the rotation cancelled the replay")
        assertTrue(service.replay === task, "the rotation started a second replay")
        val writer = Thread {
            java.io.FileOutputStream(fifo).use { out -> log.inputStream().use { it.copyTo(out) } }
        }.apply { isDaemon = true; start() }
        writer.join(60_000)
        assertFalse(writer.isAlive, "nobody reads the replay's pipe")
        task.join(120_000)
        shadowOf(Looper.getMainLooper()).idle()
        assertNull(service.replay, "the replay ended (and no other one was started)")
        val status = controller.get().findViewById<TextView>(R.id.status_text).text.toString()
        assertTrue(status.startsWith(app.getString(R.string.status_replay_done, fifo.name)),
            "the re-created screen shows the replay's end: $status")
        controller.destroy()
    }
}

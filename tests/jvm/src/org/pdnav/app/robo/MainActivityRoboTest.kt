package org.pdnav.app.robo

import android.Manifest
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
    fun anOutputDrawsMarkerEllipseTrackAndStatus() {
        shadowOf(app).grantPermissions(Manifest.permission.ACCESS_FINE_LOCATION, Manifest.permission.ACCESS_COARSE_LOCATION,
            Manifest.permission.ACTIVITY_RECOGNITION)
        val activity = Robolectric.buildActivity(MainActivity::class.java).setup().get()
        // 4 m x 2 m (1 sigma) ellipse, major axis east-west
        val e = NavEstimate(5_000_000_000L, 2, 2, "GNSS lost, terrain engine", 42.5, 1.5, 1500.0,
            10.0, 20.0, 16.0, 0.0, 4.0, 3.0)
        val out = NavOutput(e, arrayOf(e), 12, doubleArrayOf(10.0, 20.0, 12.0, 18.0))
        activity.showOutput(out, listOf(doubleArrayOf(42.49990, 1.49990), doubleArrayOf(42.5, 1.5)))
        val status = activity.findViewById<TextView>(R.id.status_text).text.toString()
        assertTrue(status.contains("terrain") && status.contains("GNSS lost, terrain engine") && status.contains("12 steps"), status)
        val map = activity.map
        assertTrue(map.markerShown)
        assertEquals(36, map.ellipsePointCount)
        assertEquals(2, map.trackPointCount)
        // the 95 % ellipse reaches 2.4477 * 4 m east of the estimate
        val pts = MapController.ellipsePoints(e)
        val eastMost = pts.maxOf { it.longitude }
        val eastM = (eastMost - 1.5) * Math.PI / 180 * 6_371_000.0 * Math.cos(Math.toRadians(42.5))
        assertTrue(abs(eastM - MapController.K95 * 4.0) < 0.05, "east extent $eastM m")
    }
}

package org.pdnav.app.ui

import android.Manifest
import android.app.Activity
import android.content.ComponentName
import android.content.Context
import android.content.Intent
import android.content.ServiceConnection
import android.content.pm.PackageManager
import android.graphics.Color
import android.net.Uri
import android.os.Build
import android.os.Bundle
import android.os.Handler
import android.os.IBinder
import android.os.Looper
import android.provider.Settings
import android.view.Gravity
import android.view.View
import android.widget.Button
import android.widget.FrameLayout
import android.widget.LinearLayout
import android.widget.TextView
import org.osmdroid.views.MapView
import org.pdnav.app.R
import org.pdnav.app.map.MapController
import org.pdnav.app.nav.NavOutput
import org.pdnav.app.recording.ReplayTask
import org.pdnav.app.sensors.NavigationService
import java.io.File

/**
 * The map screen: offline basemap with the estimate, its error ellipse, the track and the
 * particle cloud; the engine and its status as text; Navigate / Record / Settings / Sessions.
 * Asks for fine location and activity recognition first and explains why when refused.
 */
class MainActivity : Activity() {
    private lateinit var settings: AppSettings
    private lateinit var mapController: MapController
    private lateinit var status: TextView
    private lateinit var permissionPanel: LinearLayout
    private lateinit var navigateButton: Button
    private lateinit var recordButton: Button
    private var service: NavigationService? = null
    private var replay: ReplayTask? = null
    private val main = Handler(Looper.getMainLooper())

    private val listener = object : NavigationService.Listener {
        override fun onOutput(output: NavOutput, track: List<DoubleArray>) = showOutput(output, track)
        override fun onError(message: String) {
            status.text = message
            updateButtons()
        }
    }

    private val connection = object : ServiceConnection {
        override fun onServiceConnected(name: ComponentName?, binder: IBinder?) {
            val s = (binder as? NavigationService.LocalBinder)?.service ?: return
            service = s
            s.addListener(listener)
            s.lastOutput?.let { showOutput(it, s.track) }
            updateButtons()
        }

        override fun onServiceDisconnected(name: ComponentName?) {
            service = null
            updateButtons()
        }
    }

    override fun onCreate(savedInstanceState: Bundle?) {
        super.onCreate(savedInstanceState)
        settings = AppSettings(getSharedPreferences(AppSettings.PREFS, Context.MODE_PRIVATE))
        setContentView(buildLayout())
        mapController.setOnLongPress { p ->
            settings.startLatDeg = p.latitude
            settings.startLonDeg = p.longitude
            mapController.showStart(p)
            service?.session?.setStart(p.latitude, p.longitude, settings.startSigmaM)
            status.text = getString(R.string.status_start_set, p.latitude, p.longitude, settings.startSigmaM)
        }
        status.text = getString(R.string.status_idle)
        ensurePermissions()
        handleReplayIntent(intent)
    }

    override fun onStart() {
        super.onStart()
        if (!mapController.loadBasemap(this, settings.basemapPath.takeIf { it.isNotEmpty() }?.let(::File))) {
            status.text = getString(R.string.status_no_basemap)
        }
        bindService(Intent(this, NavigationService::class.java), connection, Context.BIND_AUTO_CREATE)
    }

    override fun onStop() {
        service?.removeListener(listener)
        unbindService(connection)
        service = null
        super.onStop()
    }

    override fun onResume() {
        super.onResume()
        mapController.map.onResume()
    }

    override fun onPause() {
        mapController.map.onPause()
        super.onPause()
    }

    override fun onDestroy() {
        replay?.cancel()
        super.onDestroy()
    }

    override fun onNewIntent(intent: Intent) {
        super.onNewIntent(intent)
        handleReplayIntent(intent)
    }

    // ---- permissions ------------------------------------------------------------------------

    /** Permissions without which the app can neither navigate nor record. */
    fun requiredPermissions(): List<String> {
        val p = mutableListOf(Manifest.permission.ACCESS_FINE_LOCATION, Manifest.permission.ACCESS_COARSE_LOCATION)
        if (Build.VERSION.SDK_INT >= 29) p += Manifest.permission.ACTIVITY_RECOGNITION
        return p
    }

    private fun missingPermissions() = requiredPermissions().filter { checkSelfPermission(it) != PackageManager.PERMISSION_GRANTED }

    private fun ensurePermissions() {
        val missing = missingPermissions().toMutableList()
        if (missing.isEmpty()) {
            showExplanation(false)
            return
        }
        if (Build.VERSION.SDK_INT >= 33) missing += Manifest.permission.POST_NOTIFICATIONS
        requestPermissions(missing.toTypedArray(), REQUEST_PERMISSIONS)
    }

    override fun onRequestPermissionsResult(requestCode: Int, permissions: Array<out String>, grantResults: IntArray) {
        super.onRequestPermissionsResult(requestCode, permissions, grantResults)
        if (requestCode != REQUEST_PERMISSIONS) return
        val required = requiredPermissions().toSet()
        val refused = permissions.indices.any { i ->
            permissions[i] in required && grantResults.getOrElse(i) { PackageManager.PERMISSION_DENIED } != PackageManager.PERMISSION_GRANTED
        }
        showExplanation(refused || missingPermissions().isNotEmpty())
    }

    private fun showExplanation(show: Boolean) {
        permissionPanel.visibility = if (show) View.VISIBLE else View.GONE
        updateButtons()
    }

    // ---- navigation / recording / replay ----------------------------------------------------

    private fun toggleNavigation(record: Boolean) {
        val s = service
        if (s?.session != null) {
            NavigationService.stop(this)
            main.postDelayed({ updateButtons() }, 100)
            return
        }
        if (missingPermissions().isNotEmpty()) {
            ensurePermissions()
            return
        }
        NavigationService.start(this, navigate = true, record = record)
        main.postDelayed({ updateButtons() }, 100)
    }

    private fun handleReplayIntent(intent: Intent?) {
        val path = intent?.getStringExtra(EXTRA_REPLAY) ?: return
        replay?.cancel()
        val name = File(path).name
        val task = ReplayTask(path, settings.navigatorConfig(), REPLAY_SEED,
            onProgress = { out, frac ->
                main.post {
                    showOutput(out, emptyList())
                    status.text = getString(R.string.status_replaying, name, (frac * 100).toInt())
                }
            },
            onDone = { out, err ->
                main.post {
                    if (out != null) showOutput(out, emptyList())
                    if (err != null) status.text = err.message ?: err.toString()
                }
            })
        replay = task
        task.start()
    }

    /** Shows one output: map layers and the status line (engine, status, reason). */
    fun showOutput(out: NavOutput, track: List<DoubleArray>) {
        mapController.show(out, track)
        val e = out.estimate
        status.text = "${e.statusText()} · ${out.steps} steps"
    }

    private fun updateButtons() {
        val running = service?.session != null
        val allowed = missingPermissions().isEmpty()
        navigateButton.text = getString(if (running) R.string.action_stop else R.string.action_navigate)
        navigateButton.isEnabled = allowed
        recordButton.isEnabled = allowed && !running
    }

    // ---- layout -------------------------------------------------------------------------------

    private fun buildLayout(): View {
        val root = FrameLayout(this)
        val map = MapView(this).apply { id = R.id.map_view }
        mapController = MapController(this, map)
        root.addView(map, FrameLayout.LayoutParams(-1, -1))

        status = TextView(this).apply {
            id = R.id.status_text
            setBackgroundColor(Color.argb(200, 255, 255, 255))
            setPadding(24, 16, 24, 16)
        }
        root.addView(status, FrameLayout.LayoutParams(-1, -2, Gravity.TOP))

        navigateButton = Views.button(this, R.id.button_navigate, getString(R.string.action_navigate)) { toggleNavigation(record = false) }
        recordButton = Views.button(this, R.id.button_record, getString(R.string.action_record)) { toggleNavigation(record = true) }
        val settingsButton = Views.button(this, R.id.button_settings, getString(R.string.action_settings)) {
            startActivity(Intent(this, SettingsActivity::class.java))
        }
        val sessionsButton = Views.button(this, R.id.button_sessions, getString(R.string.action_sessions)) {
            startActivity(Intent(this, SessionsActivity::class.java))
        }
        root.addView(Views.row(this, navigateButton, recordButton, settingsButton, sessionsButton),
            FrameLayout.LayoutParams(-1, -2, Gravity.BOTTOM))

        permissionPanel = LinearLayout(this).apply {
            id = R.id.permission_panel
            orientation = LinearLayout.VERTICAL
            setBackgroundColor(Color.WHITE)
            setPadding(48, 48, 48, 48)
            visibility = View.GONE
            addView(TextView(this@MainActivity).apply {
                id = R.id.permission_text
                text = getString(R.string.permission_explanation)
            })
            addView(Views.button(this@MainActivity, R.id.permission_retry, getString(R.string.permission_retry)) { ensurePermissions() })
            addView(Views.button(this@MainActivity, View.NO_ID, getString(R.string.permission_open_settings)) {
                startActivity(Intent(Settings.ACTION_APPLICATION_DETAILS_SETTINGS, Uri.fromParts("package", packageName, null)))
            })
        }
        root.addView(permissionPanel, FrameLayout.LayoutParams(-1, -2, Gravity.CENTER))
        return root
    }

    val map: MapController get() = mapController

    companion object {
        const val REQUEST_PERMISSIONS = 1
        const val EXTRA_REPLAY = "org.pdnav.app.extra.REPLAY"
        private const val REPLAY_SEED = 1L
    }
}

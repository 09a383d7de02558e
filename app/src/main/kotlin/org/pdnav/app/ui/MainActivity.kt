package org.pdnav.app.ui

import android.Manifest
import android.app.Activity
import android.app.AlertDialog
import android.content.ComponentName
import android.content.Context
import android.content.Intent
import android.content.ServiceConnection
import android.content.pm.PackageManager
import android.graphics.Color
import android.location.LocationManager
import android.net.Uri
import android.os.Build
import android.os.Bundle
import android.os.IBinder
import android.provider.Settings
import android.text.InputType
import android.view.Gravity
import android.view.View
import android.widget.Button
import android.widget.EditText
import android.widget.FrameLayout
import android.widget.LinearLayout
import android.widget.TextView
import org.osmdroid.views.MapView
import org.pdnav.app.R
import org.pdnav.app.map.MapController
import org.pdnav.app.map.MapData
import org.pdnav.app.nav.NavOutput
import org.pdnav.app.sensors.NavigationService
import org.pdnav.app.sensors.SessionStats
import org.pdnav.app.map.MbtilesBounds
import org.pdnav.app.region.Place
import org.pdnav.app.region.PlaceStore
import org.pdnav.app.region.RegionInfo
import org.pdnav.app.region.RegionStore
import org.pdnav.app.walk.GoTo
import org.pdnav.app.walk.WalkState
import org.pdnav.app.walk.WalkerWords
import org.pdnav.app.walk.remainingM
import org.pdnav.app.walk.sigmaM
import java.io.File
import java.util.Locale

/**
 * The walker's map screen: offline basemap (of the region the walk is in) with its
 * attribution, the estimate (arrow), its error ellipse and the track; what a walker needs in
 * words (how sure the position is, where it comes from, heading, distance and time walked,
 * leaving the region's map); Go-to (bearing, straight distance, the walkway route drawn,
 * or a warning when the position is too uncertain); places (save, long-press, list). The
 * tester's details (engine line, numbers, each engine, the particle cloud, the session's
 * live counters) are one tap away. Navigate and Record are independent switches. Asks for
 * location (required), physical activity and notifications (optional) and explains what a
 * refusal costs.
 */
class MainActivity : Activity() {
    private lateinit var settings: AppSettings
    private lateinit var mapController: MapController
    private lateinit var status: TextView
    private lateinit var info: TextView
    private lateinit var counters: TextView
    private lateinit var permissionPanel: LinearLayout
    private lateinit var permissionText: TextView
    private lateinit var locationPanel: LinearLayout
    private lateinit var interruptedPanel: LinearLayout
    private lateinit var interruptedText: TextView
    private lateinit var navigateButton: Button
    private lateinit var recordButton: Button
    private lateinit var checkpointButton: Button
    private lateinit var followButton: Button
    private lateinit var skyPlot: SkyPlotView
    private lateinit var skyLegend: TextView
    private lateinit var walkerPanel: LinearLayout
    private lateinit var walkerPosition: TextView
    private lateinit var walkerSource: TextView
    private lateinit var walkerHeading: TextView
    private lateinit var walkerWalked: TextView
    private lateinit var regionText: TextView
    private lateinit var detailsPanel: LinearLayout
    private lateinit var detailsText: TextView
    private lateinit var gotoPanel: LinearLayout
    private lateinit var gotoText: TextView
    private lateinit var gotoArrow: GoToArrowView
    private lateinit var attribution: TextView
    private var lastOut: NavOutput? = null
    private var lastWalk: WalkState? = null
    private var graphShown = false
    private var pendingGoTo: Place? = null

    /** The region whose map is shown (null: the settings' single files, or nothing). */
    var shownRegion: RegionInfo? = null
        private set
    private var service: NavigationService? = null
    private var bound = false
    private var asked = false
    private var pendingReplay: String? = null
    private var mapDataKey: String? = null

    /** The background load of the graph / DEM bounds (tests join it). */
    @Volatile var mapDataThread: Thread? = null
        private set

    /** The start declared by a long-press before Navigate: used by the next session only. */
    var pendingStart: DoubleArray? = null
        private set

    private val listener = object : NavigationService.Listener {
        override fun onOutput(output: NavOutput, track: List<DoubleArray>) = showOutput(output, track)
        override fun onError(message: String) {
            errorShown = getString(R.string.status_error, message)
            updateButtons()
        }
        override fun onState() = updateButtons()
        override fun onStats(stats: SessionStats) = showStats(stats)
        override fun onWalk(state: WalkState) = showWalk(state)
        override fun onRegion(region: RegionInfo?) {
            if (region != null) {
                settings.lastRegion = region.name
                if (region.name != shownRegion?.name) showRegionMap(region)
            }
            updateRegionMessage()
        }
        override fun onReplay(output: NavOutput?, fraction: Double, done: Boolean, error: String?) {
            if (output != null) showOutput(output, emptyList())
            updateStateLine()
            if (done) updateButtons()
        }
    }

    private val connection = object : ServiceConnection {
        override fun onServiceConnected(name: ComponentName?, binder: IBinder?) {
            val s = (binder as? NavigationService.LocalBinder)?.service ?: return
            service = s
            s.addListener(listener)
            s.lastOutput?.let { showOutput(it, s.track) }
            s.lastStats?.let { showStats(it) }
            s.lastError?.let { errorShown = getString(R.string.status_error, it) }
            s.region?.let { listener.onRegion(it) }
            s.lastWalk?.let { showWalk(it) }
            pendingGoTo?.let {
                pendingGoTo = null
                s.setGoTo(it)
            }
            s.replayState?.let { listener.onReplay(it.output, it.fraction, it.done, it.error) }  // e.g. after a rotation
            pendingReplay?.let {
                pendingReplay = null
                startReplay(it)
            }
            showInterrupted(s.interrupted)
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
        pendingStart = savedInstanceState?.getDoubleArray(STATE_START)
        asked = savedInstanceState?.getBoolean(STATE_ASKED) ?: false
        mapController.setOnLongPress { p -> onMapLongPress(p.latitude, p.longitude) }
        mapController.onFollowChanged = { updateFollow() }
        updateStateLine()
        if (savedInstanceState?.getBoolean(STATE_ASKED) != true) ensurePermissions()
        pendingReplay = intent?.getStringExtra(EXTRA_REPLAY)
        goToFromIntent(intent)
        if (savedInstanceState != null) pendingReplay = null  // a rotation: the service already replays it
    }

    override fun onSaveInstanceState(outState: Bundle) {
        super.onSaveInstanceState(outState)
        pendingStart?.let { outState.putDoubleArray(STATE_START, it) }
        outState.putBoolean(STATE_ASKED, asked)
    }

    override fun onStart() {
        super.onStart()
        val region = settings.lastRegion.takeIf { it.isNotEmpty() }?.let { RegionStore(filesDir).find(it) }
        if (region != null) {
            if (region.name != shownRegion?.name) showRegionMap(region)
        } else {
            shownRegion = null
            val basemap = settings.basemapPath.takeIf { it.isNotEmpty() }?.let(::File)
            val hasBasemap = mapController.loadBasemap(this, basemap)
            noBasemap = !hasBasemap
            updateStateLine()
            if (!hasBasemap) centerOnLastFix()
            loadMapData(settings.graphPath, settings.demPath, centerOnDem = !hasBasemap)
            // the tester's single files: the basemap's own attribution, OSM's for its graph too
            showAttribution(if (hasBasemap) basemap?.let { MbtilesBounds.attribution(it) } else null,
                osmShown = hasBasemap || settings.graphPath.isNotEmpty())
        }
        bound = bindService(Intent(this, NavigationService::class.java), connection, Context.BIND_AUTO_CREATE)
    }

    override fun onStop() {
        service?.removeListener(listener)
        if (bound) unbindService(connection)
        bound = false
        service = null
        super.onStop()
    }

    override fun onResume() {
        super.onResume()
        mapController.map.onResume()
        // the user may have granted in the system settings meanwhile: check again
        if (asked) showExplanation(missingPermissions().isNotEmpty())
        updateLocationPrompt(null)
        updateButtons()
    }

    override fun onPause() {
        mapController.map.onPause()
        super.onPause()
    }

    override fun onNewIntent(intent: Intent) {
        super.onNewIntent(intent)
        intent.getStringExtra(EXTRA_REPLAY)?.let { startReplay(it) }
        goToFromIntent(intent)
    }

    // ---- regions, places, Go-to ---------------------------------------------------------------

    /** Shows region [r]'s basemap, walkway graph and attribution. */
    fun showRegionMap(r: RegionInfo) {
        shownRegion = r
        val has = mapController.loadBasemap(this, File(r.basemapPath))
        noBasemap = !has
        updateStateLine()
        loadMapData(r.graphPath, r.demPath, centerOnDem = !has)
        showAttribution(r.attribution, osmShown = true)
        updateRegionMessage()
    }

    /**
     * The map's attribution: the data's own text; ODbL requires "© OpenStreetMap
     * contributors" wherever OSM-derived tiles or the walkway graph are shown.
     */
    private fun showAttribution(declared: String?, osmShown: Boolean) {
        var t = declared?.trim().orEmpty()
        if (osmShown && !t.contains("OpenStreetMap")) t = if (t.isEmpty()) RegionStore.OSM_ATTRIBUTION else RegionStore.OSM_ATTRIBUTION + "; " + t
        attribution.text = t
        attribution.visibility = if (t.isEmpty()) View.GONE else View.VISIBLE
    }

    /** The region the walker is in (or whose map is shown): its places are listed and saved. */
    fun currentRegionName(): String? = lastWalk?.region?.name ?: service?.region?.name ?: shownRegion?.name

    fun places(): PlaceStore = PlaceStore(filesDir, currentRegionName())

    /** Saves a place (button, long-press, checkpoint) in the current region's list. */
    fun savePlace(name: String, latDeg: Double, lonDeg: Double, kind: String = Place.SAVED): Place {
        val p = places().add(Place(name, latDeg, lonDeg, kind, System.currentTimeMillis()))
        status.text = getString(R.string.place_saved, p.name)
        return p
    }

    /** Go-to [place] (null: stop): the session computes bearing, distance and route per step. */
    fun goTo(place: Place?) {
        val s = service
        if (s != null) s.setGoTo(place) else pendingGoTo = place
        if (place == null) {
            showGoTo(null)
        } else {
            mapController.showGoTo(place.latDeg, place.lonDeg, null)
            gotoPanel.visibility = View.VISIBLE
            gotoArrow.bearingDeg = Double.NaN
            gotoText.text = getString(R.string.goto_waiting, place.name)
        }
    }

    private fun goToFromIntent(i: Intent?) {
        if (i == null || !i.hasExtra(EXTRA_GOTO_LAT)) return
        val p = Place(i.getStringExtra(EXTRA_GOTO_NAME) ?: "?", i.getDoubleExtra(EXTRA_GOTO_LAT, Double.NaN),
            i.getDoubleExtra(EXTRA_GOTO_LON, Double.NaN), Place.SAVED, 0L)
        i.removeExtra(EXTRA_GOTO_LAT)
        if (p.latDeg.isFinite() && p.lonDeg.isFinite()) goTo(p)
    }

    private fun askSavePlace(latDeg: Double, lonDeg: Double) {
        val n = places().list().count { it.kind == Place.SAVED } + 1
        val name = EditText(this).apply { setText(getString(R.string.place_default_name, n)) }
        AlertDialog.Builder(this).setTitle(R.string.action_save_place).setView(name)
            .setPositiveButton(R.string.settings_save) { _, _ -> savePlace(name.text.toString().ifBlank { "Place $n" }, latDeg, lonDeg) }
            .setNegativeButton(android.R.string.cancel, null)
            .show()
    }

    /** Long-press on the map: start here, save as a place, or go there. */
    fun onMapLongPress(latDeg: Double, lonDeg: Double) {
        val items = arrayOf(getString(R.string.longpress_start), getString(R.string.longpress_save), getString(R.string.longpress_goto))
        AlertDialog.Builder(this).setItems(items) { _, which ->
            when (which) {
                0 -> declareStart(latDeg, lonDeg)
                1 -> askSavePlace(latDeg, lonDeg)
                2 -> goTo(Place(String.format(Locale.US, "%.5f, %.5f", latDeg, lonDeg), latDeg, lonDeg, Place.SAVED, 0L))
            }
        }.show()
    }

    /** The walker's state after the latest steps: heading, distance and time, region, Go-to. */
    fun showWalk(w: WalkState) {
        lastWalk = w
        walkerHeading.text = w.step?.let { WalkerWords.heading(it.headingRad) } ?: ""
        mapController.showHeading(w.step?.let { org.pdnav.app.walk.bearingDeg(it.headingRad) } ?: Double.NaN)  // the arrow says what the text says
        walkerWalked.text = if (w.steps > 0) WalkerWords.walked(w.distanceM, w.walkedNs) else ""
        w.step?.let { walkerPosition.text = WalkerWords.position(it.sigmaM) }
        updateRegionMessage()
        showGoTo(w.goTo)
        updateStateLine()
    }

    private fun showGoTo(g: GoTo?) {
        if (g == null) {
            gotoPanel.visibility = View.GONE
            mapController.showGoTo(Double.NaN, Double.NaN, null)
            return
        }
        gotoPanel.visibility = View.VISIBLE
        gotoArrow.bearingDeg = g.bearingDeg
        gotoArrow.uncertain = g.uncertain
        val along = g.route?.let { getString(R.string.goto_along, WalkerWords.metres(it.remainingM)) } ?: getString(R.string.goto_no_route)
        gotoText.text = if (g.uncertain) {
            getString(R.string.goto_uncertain, g.place.name, WalkerWords.metres(g.sigmaM), WalkerWords.metres(g.straightM), along)
        } else {
            getString(R.string.goto_text, g.place.name, WalkerWords.metres(g.straightM), Math.round(g.bearingDeg).toInt() % 360,
                WalkerWords.compass(g.bearingDeg), along)
        }
        mapController.showGoTo(g.place.latDeg, g.place.lonDeg, g.route?.points?.map { doubleArrayOf(it.first, it.second) })
    }

    /** Which map the walk is on, or that it has left it (navigation goes on). */
    private fun updateRegionMessage() {
        val w = lastWalk
        val r = w?.region ?: service?.region
        val outside = w != null && w.outsideRegion && r != null
        regionText.text = when {
            outside -> getString(R.string.region_left, r!!.name)  // what the position comes from: the source line, from the core
            r != null -> getString(R.string.region_in, r.name)
            shownRegion != null -> getString(R.string.region_shown, shownRegion!!.name)
            else -> ""
        }
        regionText.setTextColor(if (outside) Color.rgb(176, 0, 32) else Color.DKGRAY)
    }

    // ---- permissions ------------------------------------------------------------------------

    /** Permissions without which the app can neither navigate nor record (GNSS + fixes). */
    fun requiredPermissions(): List<String> =
        listOf(Manifest.permission.ACCESS_FINE_LOCATION, Manifest.permission.ACCESS_COARSE_LOCATION)

    /** Asked too, but optional: step detector (29+) and the notification (33+). */
    fun optionalPermissions(): List<String> {
        val p = mutableListOf<String>()
        if (Build.VERSION.SDK_INT >= 29) p += Manifest.permission.ACTIVITY_RECOGNITION
        if (Build.VERSION.SDK_INT >= 33) p += Manifest.permission.POST_NOTIFICATIONS
        return p
    }

    private fun granted(p: String) = checkSelfPermission(p) == PackageManager.PERMISSION_GRANTED
    private fun missingPermissions() = requiredPermissions().filter { !granted(it) }

    private fun ensurePermissions() {
        val ask = (requiredPermissions() + optionalPermissions()).filter { !granted(it) }
        if (ask.isEmpty()) {
            showExplanation(false)
            return
        }
        requestPermissions(ask.toTypedArray(), REQUEST_PERMISSIONS)
    }

    override fun onRequestPermissionsResult(requestCode: Int, permissions: Array<out String>, grantResults: IntArray) {
        super.onRequestPermissionsResult(requestCode, permissions, grantResults)
        if (requestCode != REQUEST_PERMISSIONS) return
        asked = true
        val required = requiredPermissions().toSet()
        val refused = permissions.indices.any { i ->
            permissions[i] in required && grantResults.getOrElse(i) { PackageManager.PERMISSION_DENIED } != PackageManager.PERMISSION_GRANTED
        }
        showExplanation(refused || missingPermissions().isNotEmpty())
    }

    private fun showExplanation(show: Boolean) {
        permissionPanel.visibility = if (show) View.VISIBLE else View.GONE
        val notes = mutableListOf<String>()
        if (Build.VERSION.SDK_INT >= 29 && !granted(Manifest.permission.ACTIVITY_RECOGNITION)) notes += getString(R.string.note_no_activity)
        if (Build.VERSION.SDK_INT >= 33 && !granted(Manifest.permission.POST_NOTIFICATIONS)) notes += getString(R.string.note_no_notifications)
        permissionText.text = if (show) getString(R.string.permission_explanation) else ""
        if (notes.isNotEmpty() && !show) info.text = notes.joinToString("\n")
        updateButtons()
    }

    private fun updateLocationPrompt(stats: SessionStats?) {
        val lm = getSystemService(Context.LOCATION_SERVICE) as LocationManager
        val on = stats?.locationEnabled ?: try {
            if (Build.VERSION.SDK_INT >= 28) lm.isLocationEnabled else lm.isProviderEnabled(LocationManager.GPS_PROVIDER)
        } catch (e: RuntimeException) {
            true
        }
        locationPanel.visibility = if (on || missingPermissions().isNotEmpty()) View.GONE else View.VISIBLE
    }

    // ---- navigation / recording / replay ----------------------------------------------------

    /** Long-press: the start of this session (now, if navigating) or of the next one only. */
    fun declareStart(latDeg: Double, lonDeg: Double) {
        val sigma = settings.startSigmaM
        val s = service
        if (s != null && s.navigating) {
            s.declareStart(latDeg, lonDeg, sigma)
        } else {
            pendingStart = doubleArrayOf(latDeg, lonDeg, sigma)
        }
        mapController.showStart(org.osmdroid.util.GeoPoint(latDeg, lonDeg))
        status.text = getString(R.string.status_start_set, latDeg, lonDeg, sigma)
    }

    private fun toggleNavigation() {
        if (missingPermissions().isNotEmpty()) {
            ensurePermissions()
            return
        }
        val s = service
        val nav = s?.navigating == true
        val rec = s?.recording == true
        NavigationService.set(this, navigate = !nav, record = rec, declaredStart = if (!nav) pendingStart else null)
        if (!nav) pendingStart = null  // consumed by this session
    }

    private fun toggleRecording() {
        if (missingPermissions().isNotEmpty()) {
            ensurePermissions()
            return
        }
        val s = service
        NavigationService.set(this, navigate = s?.navigating == true, record = s?.recording != true)
    }

    private fun startReplay(path: String) {
        val s = service
        if (s == null) {
            pendingReplay = path
            return
        }
        startService(Intent(this, NavigationService::class.java))  // outlives this Activity's binding
        if (s.startReplay(path)) {
            mapController.follow = true
            updateFollow()
        }
        showInterrupted(null)
    }

    /** Checkpoint: the tester is at a known point; picked on the map (centre) or typed. */
    private fun askCheckpoint() {
        val lat = EditText(this).apply {
            inputType = InputType.TYPE_CLASS_NUMBER or InputType.TYPE_NUMBER_FLAG_DECIMAL or InputType.TYPE_NUMBER_FLAG_SIGNED
            setText(String.format(Locale.US, "%.7f", mapController.centerLatDeg))
        }
        val lon = EditText(this).apply {
            inputType = lat.inputType
            setText(String.format(Locale.US, "%.7f", mapController.centerLonDeg))
        }
        val form = LinearLayout(this).apply {
            orientation = LinearLayout.VERTICAL
            val p = Views.dp(context, 16)
            setPadding(p, p, p, p)
            addView(Views.label(context, getString(R.string.checkpoint_hint)))
            addView(lat)
            addView(lon)
        }
        AlertDialog.Builder(this).setTitle(R.string.action_checkpoint).setView(form)
            .setPositiveButton(R.string.checkpoint_write) { _, _ ->
                val a = lat.text.toString().toDoubleOrNull()
                val b = lon.text.toString().toDoubleOrNull()
                if (a == null || b == null || a !in -90.0..90.0 || b !in -180.0..180.0) {
                    status.text = getString(R.string.checkpoint_invalid)
                } else {
                    writeCheckpoint(a, b)
                }
            }
            .setNegativeButton(android.R.string.cancel, null)
            .show()
    }

    /** Writes a Truth line at [latDeg], [lonDeg] now; false when no session runs. */
    fun writeCheckpoint(latDeg: Double, lonDeg: Double): Boolean {
        val ok = service?.checkpoint(latDeg, lonDeg) == true
        if (ok) {
            // a checkpoint is a place too
            places().add(Place(getString(R.string.place_checkpoint_name, java.text.SimpleDateFormat("HH:mm", Locale.US).format(java.util.Date())),
                latDeg, lonDeg, Place.CHECKPOINT, System.currentTimeMillis()))
        }
        status.text = if (ok) getString(R.string.checkpoint_written, latDeg, lonDeg) else getString(R.string.checkpoint_no_session)
        return ok
    }

    /** Walkway graph and DEM bounds, read on a thread (once per pair of files). */
    private fun loadMapData(graph: String, dem: String, centerOnDem: Boolean) {
        graphShown = graph.isNotEmpty()
        val key = "$graph|$dem"
        if (key == mapDataKey || (graph.isEmpty() && dem.isEmpty())) return
        mapDataKey = key
        mapDataThread = Thread({
            val data = MapData.load(graph, dem)
            runOnUiThread {
                mapController.showGraph(data.graphLines)
                val b = data.demBounds
                if (centerOnDem && b != null) mapController.centerOn(b)
                data.error?.let { status.text = getString(R.string.status_error, it) }
            }
        }, "pdnav-mapdata").apply { start() }
    }

    private fun centerOnLastFix() {
        if (missingPermissions().isNotEmpty()) return
        val lm = getSystemService(Context.LOCATION_SERVICE) as LocationManager
        val l = try {
            lm.getLastKnownLocation(LocationManager.GPS_PROVIDER) ?: lm.getLastKnownLocation(LocationManager.NETWORK_PROVIDER)
        } catch (e: SecurityException) {
            null
        } catch (e: IllegalArgumentException) {
            null
        }
        if (l != null) mapController.centerOn(l.latitude, l.longitude)
    }

    private fun showInterrupted(f: File?) {
        if (f == null) {
            interruptedPanel.visibility = View.GONE
            return
        }
        interruptedText.text = getString(R.string.interrupted_text, f.name)
        interruptedPanel.tag = f.path
        interruptedPanel.visibility = View.VISIBLE
    }

    /** Shows one output: map layers, the status line and the numbers (position, sigma, engine). */
    fun showOutput(out: NavOutput, track: List<DoubleArray>) {
        mapController.show(out, track)
        lastOut = out
        val e = out.estimate
        val has = e.valid && e.latDeg.isFinite()
        val sigma = if (has) e.drmsM else Double.NaN
        // the walker's words
        walkerPosition.text = WalkerWords.position(e)
        walkerSource.text = WalkerWords.source(out, graphShown)
        updateRegionMessage()
        // the tester's line and numbers, one tap away
        val numbers = if (has) {
            String.format(Locale.US, "%.6f, %.6f  ±%.1f m (1σ)  %s", e.latDeg, e.lonDeg, sigma, e.engine.label)
        } else {
            getString(R.string.info_no_position)
        }
        detailsText.text = "${e.statusText()} · ${out.steps} steps\n$numbers"
        updateStateLine()
    }

    /** Shows or hides the tester's details (one tap on the walker's panel). */
    fun toggleDetails() {
        val show = detailsPanel.visibility != View.VISIBLE
        detailsPanel.visibility = if (show) View.VISIBLE else View.GONE
        mapController.testerLayers = show  // each engine's ring and the particle cloud
    }

    /** Live state: duration, size, rows per line type, GNSS epochs, magnetometer accuracy, satellites. */
    fun showStats(s: SessionStats) {
        val lines = mutableListOf<String>()
        lines += if (s.recording) s.recordingLine() else getString(R.string.state_not_recording, SessionStats.hms(s.durationNs))
        lines += getString(R.string.counters_gnss, s.gnssEpochs, s.fixes, s.satellites.count { it.usedInFix }, s.satellites.size)
        lines += s.sensorRows.entries.sortedBy { it.key }.joinToString(" · ") { "${it.key} ${it.value}" }
        lines += getString(R.string.counters_mag, magAccuracyText(s.magAccuracy))
        if (s.recording) lines += s.countsLine()
        if (s.lateRows > 0) lines += getString(R.string.counters_late, s.lateRows, s.lastLate ?: "")
        s.checkpoints.lastOrNull()?.let { c ->
            lines += String.format(Locale.US, "checkpoint: %.1f m off (±%.1f m, %s)", c.errorM, c.sigmaM, c.engine)
        }
        counters.text = lines.joinToString("\n")
        skyPlot.satellites = s.satellites
        s.lastFix?.let { mapController.showFix(it.latDeg, it.lonDeg, it.accuracyM) }
        updateLocationPrompt(s)
    }

    private fun magAccuracyText(a: Int): String = when (a) {
        3 -> getString(R.string.mag_high)
        2 -> getString(R.string.mag_medium)
        1, 0 -> getString(R.string.mag_low)
        else -> getString(R.string.mag_unknown)
    }

    /** Buttons from the service's state (called on every state change, never on a timer). */
    private fun updateButtons() {
        val s = service
        val allowed = missingPermissions().isEmpty()
        val nav = s?.navigating == true
        val rec = s?.recording == true
        val replaying = s?.replay != null
        navigateButton.text = getString(if (nav) R.string.action_stop_navigate else R.string.action_navigate)
        recordButton.text = getString(if (rec) R.string.action_stop_record else R.string.action_record)
        navigateButton.isEnabled = allowed && !replaying
        recordButton.isEnabled = allowed && !replaying
        checkpointButton.isEnabled = s?.session != null
        updateStateLine()
    }

    /** A session's error, shown until the next session or replay starts. */
    private var errorShown: String? = null
    private var noBasemap = false
    private var stateShown: String? = null

    /**
     * The state line under the walker's words: what the app is doing now (a session's error,
     * a replay and its progress, navigating / recording), nothing while a finished walk is
     * shown without a session, and the idle hint only when there is no session, no replay
     * and no walk on the screen.
     */
    fun stateLine(): String {
        val s = service
        val rs = s?.replayState
        val replayName = s?.replayPath?.let { File(it).name } ?: ""
        val live = s?.session != null
        return when {
            errorShown != null -> errorShown!!
            s?.replay != null -> getString(R.string.status_replaying, replayName, ((rs?.fraction ?: 0.0) * 100).toInt())
            live && s!!.navigating && s.recording -> getString(R.string.state_navigating_recording)
            live && s!!.navigating -> getString(R.string.state_navigating)
            live && s!!.recording -> getString(R.string.state_recording_only)
            live -> getString(R.string.state_starting)
            rs != null && rs.done && rs.error != null -> getString(R.string.status_error, rs.error)
            rs != null && rs.done -> getString(R.string.status_replay_done, replayName)
            lastWalk?.step != null || lastOut?.estimate?.valid == true -> ""  // a walk is on the screen
            noBasemap -> getString(R.string.status_no_basemap)
            else -> getString(R.string.status_idle)
        }
    }

    /**
     * Shows [stateLine] when the state changed (a notice such as "place saved" stays until
     * then).
     */
    private fun updateStateLine() {
        val s = service
        if (s?.session != null || s?.replay != null) errorShown = null  // a new session or replay
        val line = stateLine()
        if (line == stateShown) return
        stateShown = line
        status.text = line
    }

    private fun updateFollow() {
        followButton.text = getString(if (mapController.follow) R.string.action_follow_on else R.string.action_follow_off)
    }

    // ---- layout -------------------------------------------------------------------------------

    /** An empty line of the top panel takes no room (an empty TextView is still a line high). */
    private fun hideWhenEmpty(v: TextView) {
        v.visibility = View.GONE
        v.addTextChangedListener(object : android.text.TextWatcher {
            override fun beforeTextChanged(s: CharSequence?, start: Int, count: Int, after: Int) = Unit
            override fun onTextChanged(s: CharSequence?, start: Int, before: Int, count: Int) = Unit
            override fun afterTextChanged(s: android.text.Editable?) {
                v.visibility = if (s.isNullOrEmpty()) View.GONE else View.VISIBLE
            }
        })
    }

    private fun buildLayout(): View {
        val root = FrameLayout(this)
        val map = MapView(this).apply { id = R.id.map_view }
        mapController = MapController(this, map)
        root.addView(map, FrameLayout.LayoutParams(-1, -1))

        val pad = Views.dp(this, 8)
        status = TextView(this).apply { id = R.id.status_text; hideWhenEmpty(this) }
        info = TextView(this).apply { id = R.id.info_text; hideWhenEmpty(this) }
        counters = TextView(this).apply { id = R.id.counters_text; textSize = 11f; hideWhenEmpty(this) }
        skyPlot = SkyPlotView(this).apply { id = R.id.sky_plot; visibility = View.GONE }
        skyLegend = TextView(this).apply { id = R.id.sky_legend; text = SkyPlotView.legend(); visibility = View.GONE; textSize = 12f }
        walkerPosition = TextView(this).apply { id = R.id.walker_position; textSize = 20f; setTypeface(typeface, android.graphics.Typeface.BOLD)
            setTextColor(Color.BLACK); text = WalkerWords.position(Double.NaN) }
        walkerSource = TextView(this).apply { id = R.id.walker_source; textSize = 15f; setTextColor(Color.BLACK); hideWhenEmpty(this) }
        walkerHeading = TextView(this).apply { id = R.id.walker_heading; textSize = 15f; setTextColor(Color.BLACK); hideWhenEmpty(this) }
        walkerWalked = TextView(this).apply { id = R.id.walker_walked; textSize = 15f; setTextColor(Color.BLACK); hideWhenEmpty(this) }
        regionText = TextView(this).apply { id = R.id.region_text; textSize = 13f; hideWhenEmpty(this) }
        val detailsHint = TextView(this).apply { id = R.id.details_hint; text = getString(R.string.details_hint); textSize = 12f; setTextColor(Color.GRAY) }
        walkerPanel = LinearLayout(this).apply {
            id = R.id.walker_panel
            orientation = LinearLayout.VERTICAL
            isClickable = true
            setOnClickListener { toggleDetails() }
            addView(LinearLayout(context).apply {
                orientation = LinearLayout.HORIZONTAL
                gravity = Gravity.CENTER_VERTICAL
                addView(walkerPosition, LinearLayout.LayoutParams(0, -2, 1f))
                addView(detailsHint)
            })
            addView(walkerSource)
            addView(walkerHeading)
            addView(walkerWalked)
        }
        detailsText = TextView(this).apply { id = R.id.details_text; textSize = 12f }
        detailsPanel = LinearLayout(this).apply {
            id = R.id.details_panel
            orientation = LinearLayout.VERTICAL
            visibility = View.GONE
            addView(detailsText)
            addView(counters)
        }
        gotoArrow = GoToArrowView(this).apply { id = R.id.goto_arrow }
        gotoText = TextView(this).apply { id = R.id.goto_text; textSize = 14f; setTextColor(Color.BLACK) }
        gotoPanel = LinearLayout(this).apply {
            id = R.id.goto_panel
            orientation = LinearLayout.HORIZONTAL
            gravity = Gravity.CENTER_VERTICAL
            visibility = View.GONE
            addView(gotoArrow, LinearLayout.LayoutParams(Views.dp(context, 56), Views.dp(context, 56)))
            addView(gotoText, LinearLayout.LayoutParams(0, -2, 1f).apply { leftMargin = Views.dp(context, 8) })
            addView(Views.button(context, R.id.goto_stop, getString(R.string.goto_stop)) { goTo(null) },
                LinearLayout.LayoutParams(-2, -2))
        }
        attribution = TextView(this).apply {
            id = R.id.map_attribution
            textSize = 10f
            setTextColor(Color.DKGRAY)
            setBackgroundColor(Color.argb(200, 255, 255, 255))
            setPadding(pad / 2, 0, pad / 2, 0)
            visibility = View.GONE
        }
        locationPanel = LinearLayout(this).apply {
            id = R.id.location_panel
            orientation = LinearLayout.HORIZONTAL
            visibility = View.GONE
            addView(TextView(context).apply { text = getString(R.string.location_off) }, LinearLayout.LayoutParams(0, -2, 1f))
            addView(Views.button(context, R.id.location_settings, getString(R.string.location_open)) {
                startActivity(Intent(Settings.ACTION_LOCATION_SOURCE_SETTINGS))
            })
        }
        interruptedPanel = LinearLayout(this).apply {
            id = R.id.interrupted_panel
            orientation = LinearLayout.HORIZONTAL
            visibility = View.GONE
        }
        interruptedText = TextView(this)
        interruptedPanel.addView(interruptedText, LinearLayout.LayoutParams(0, -2, 1f))
        interruptedPanel.addView(Views.button(this, R.id.interrupted_replay, getString(R.string.action_replay)) {
            (interruptedPanel.tag as? String)?.let { startReplay(it) }
        })
        val top = LinearLayout(this).apply {
            orientation = LinearLayout.VERTICAL
            setBackgroundColor(Color.argb(210, 255, 255, 255))
            setPadding(pad * 2, pad, pad * 2, pad)
            addView(walkerPanel)
            addView(regionText)
            addView(gotoPanel)
            addView(status)
            addView(info)
            addView(detailsPanel)
            addView(locationPanel)
            addView(interruptedPanel)
            addView(skyPlot, LinearLayout.LayoutParams(-1, Views.dp(context, 264)))
            addView(skyLegend)
        }
        root.addView(top, FrameLayout.LayoutParams(-1, -2, Gravity.TOP))

        navigateButton = Views.button(this, R.id.button_navigate, getString(R.string.action_navigate)) { toggleNavigation() }
        recordButton = Views.button(this, R.id.button_record, getString(R.string.action_record)) { toggleRecording() }
        checkpointButton = Views.button(this, R.id.button_checkpoint, getString(R.string.action_checkpoint)) { askCheckpoint() }
        detailsPanel.addView(checkpointButton, LinearLayout.LayoutParams(-2, -2))  // a tester's tool: with the details
        followButton = Views.button(this, R.id.button_follow, getString(R.string.action_follow_on)) {
            mapController.follow = !mapController.follow
            updateFollow()
        }
        val satButton = Views.button(this, R.id.button_satellites, getString(R.string.action_satellites)) {
            skyPlot.visibility = if (skyPlot.visibility == View.VISIBLE) View.GONE else View.VISIBLE
            skyLegend.visibility = skyPlot.visibility
        }
        val savePlaceButton = Views.button(this, R.id.button_save_place, getString(R.string.action_save_place)) {
            val here = service?.currentPosition()
            if (here != null) askSavePlace(here[0], here[1]) else askSavePlace(mapController.centerLatDeg, mapController.centerLonDeg)
        }
        val placesButton = Views.button(this, R.id.button_places, getString(R.string.action_places)) {
            startActivity(Intent(this, PlacesActivity::class.java).putExtra(PlacesActivity.EXTRA_REGION, currentRegionName() ?: ""))
        }
        val settingsButton = Views.button(this, R.id.button_settings, getString(R.string.action_settings)) {
            startActivity(Intent(this, SettingsActivity::class.java))
        }
        val sessionsButton = Views.button(this, R.id.button_sessions, getString(R.string.action_sessions)) {
            startActivity(Intent(this, SessionsActivity::class.java))
        }
        val bottom = LinearLayout(this).apply {
            orientation = LinearLayout.VERTICAL
            addView(attribution, LinearLayout.LayoutParams(-2, -2))
            addView(Views.row(context, navigateButton, recordButton, savePlaceButton, placesButton))
            addView(Views.row(context, followButton, satButton, settingsButton, sessionsButton))
        }
        root.addView(bottom, FrameLayout.LayoutParams(-1, -2, Gravity.BOTTOM))

        permissionText = TextView(this).apply { id = R.id.permission_text }
        permissionPanel = LinearLayout(this).apply {
            id = R.id.permission_panel
            orientation = LinearLayout.VERTICAL
            setBackgroundColor(Color.WHITE)
            val p = Views.dp(context, 24)
            setPadding(p, p, p, p)
            visibility = View.GONE
            addView(permissionText)
            addView(Views.button(this@MainActivity, R.id.permission_retry, getString(R.string.permission_retry)) { ensurePermissions() })
            addView(Views.button(this@MainActivity, R.id.permission_settings, getString(R.string.permission_open_settings)) {
                startActivity(Intent(Settings.ACTION_APPLICATION_DETAILS_SETTINGS, Uri.fromParts("package", packageName, null)))
            })
        }
        root.addView(permissionPanel, FrameLayout.LayoutParams(-1, -2, Gravity.CENTER))
        Views.applySystemBarInsets(root, top, bottom)
        updateFollow()
        return root
    }

    val map: MapController get() = mapController

    companion object {
        const val REQUEST_PERMISSIONS = 1
        const val EXTRA_REPLAY = "org.pdnav.app.extra.REPLAY"
        const val EXTRA_GOTO_NAME = "org.pdnav.app.extra.GOTO_NAME"
        const val EXTRA_GOTO_LAT = "org.pdnav.app.extra.GOTO_LAT"
        const val EXTRA_GOTO_LON = "org.pdnav.app.extra.GOTO_LON"
        private const val STATE_START = "pending_start"
        private const val STATE_ASKED = "permissions_asked"
    }
}

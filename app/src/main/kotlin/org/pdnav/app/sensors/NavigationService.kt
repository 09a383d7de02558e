package org.pdnav.app.sensors

import android.app.Notification
import android.app.NotificationChannel
import android.app.NotificationManager
import android.app.PendingIntent
import android.app.Service
import android.content.Context
import android.content.Intent
import android.content.pm.ServiceInfo
import android.hardware.SensorManager
import android.location.LocationManager
import android.os.Binder
import android.os.Build
import android.os.Handler
import android.os.HandlerThread
import android.os.IBinder
import android.os.Looper
import android.os.PowerManager
import android.os.SystemClock
import org.pdnav.app.R
import org.pdnav.app.nav.NavOutput
import org.pdnav.app.nav.SampleSink
import org.pdnav.app.recording.ReplayTask
import org.pdnav.app.region.Place
import org.pdnav.app.region.RegionInfo
import org.pdnav.app.region.RegionStore
import org.pdnav.app.walk.WalkState
import org.pdnav.app.recording.SessionStore
import org.pdnav.app.ui.AppSettings
import org.pdnav.app.ui.MainActivity
import java.io.File

/**
 * Foreground service (type location) that owns the sensors while navigating and/or
 * recording (two independent switches), and the in-app replay (so a rotation does not
 * cancel it). A partial wake lock is held for the whole session: a chest-mounted phone has
 * its screen off, and without it the CPU sleeps and the sensor FIFOs overflow. Activities
 * bind to it for the estimate and the live state ([Listener]); everything heavy (DEM,
 * graph, RINEX loads, recorder open) runs on the session's worker thread.
 */
class NavigationService : Service() {

    /** Receives outputs, state and errors on the main thread. */
    interface Listener {
        fun onOutput(output: NavOutput, track: List<DoubleArray>)
        fun onError(message: String) = Unit
        /** Navigating / recording / replaying changed. */
        fun onState() = Unit
        fun onStats(stats: SessionStats) = Unit
        /** Replay progress (fraction 0..1), and its end ([done], with the error if it failed). */
        fun onReplay(output: NavOutput?, fraction: Double, done: Boolean, error: String?) = Unit
        /** The walker's state (distance, time, region, Go-to) after the latest steps. */
        fun onWalk(state: WalkState) = Unit
        /** The session (or replay) opened on [region] (null: the settings' files). */
        fun onRegion(region: RegionInfo?) = Unit
    }

    inner class LocalBinder : Binder() {
        val service: NavigationService get() = this@NavigationService
    }

    private val binder = LocalBinder()
    private val listeners = mutableListOf<Listener>()
    private val mainHandler by lazy { Handler(Looper.getMainLooper()) }
    private var worker: HandlerThread? = null
    private var workerHandler: Handler? = null
    private var wakeLock: PowerManager.WakeLock? = null
    private var lastNotificationNs = 0L

    /** The running session, if any. */
    var session: NavigationSession? = null
        private set

    /** The in-app replay, if one runs. */
    var replay: ReplayTask? = null
        private set
    var replayPath: String? = null
        private set

    /** The latest replay report, so a screen re-created by a rotation shows it at once. */
    data class ReplayState(val output: NavOutput?, val fraction: Double, val done: Boolean, val error: String?)
    var replayState: ReplayState? = null
        private set

    /** Test seam: extra sinks every new session feeds (e.g. one that throws, like a full disk). */
    var testSinks: List<SampleSink> = emptyList()

    /** Estimated positions so far (lat, lon), for the track polyline; at most [TRACK_MAX] points. */
    val track = ArrayList<DoubleArray>()
    var lastOutput: NavOutput? = null
        private set
    var lastStats: SessionStats? = null
        private set

    /** The walker's latest state (live or replay), for a screen that binds later. */
    var lastWalk: WalkState? = null
        private set

    /** The region the current (or last) session or replay navigates on. */
    var region: RegionInfo? = null
        private set

    /** The Go-to target (kept across the session's start and a replay). */
    var goToTarget: Place? = null
        private set

    /** Why the last session ended on an error (e.g. an unreadable DEM file, a full disk), or null. */
    var lastError: String? = null
        private set

    /** A recording a killed process left behind, marked as interrupted (offered for replay). */
    var interrupted: File? = null
        private set

    /** The worker looper (sensor callbacks, merging, JNI calls); tests idle it. */
    val workLooper: Looper? get() = worker?.looper

    val navigating: Boolean get() = session?.navigating == true
    val recording: Boolean get() = session?.recording == true

    override fun onCreate() {
        super.onCreate()
        if (session == null) interrupted = SessionStore(this).recoverInterrupted()
    }

    override fun onBind(intent: Intent?): IBinder = binder

    override fun onStartCommand(intent: Intent?, flags: Int, startId: Int): Int {
        when (intent?.action) {
            ACTION_SET -> {
                val start = if (intent.hasExtra(EXTRA_START_LAT)) {
                    doubleArrayOf(intent.getDoubleExtra(EXTRA_START_LAT, Double.NaN),
                        intent.getDoubleExtra(EXTRA_START_LON, Double.NaN), intent.getDoubleExtra(EXTRA_START_SIGMA, 5.0))
                } else {
                    null
                }
                setSwitches(intent.getBooleanExtra(EXTRA_NAVIGATE, false), intent.getBooleanExtra(EXTRA_RECORD, false), start)
            }
            ACTION_STOP -> stopSession()
            null -> {
                // Restarted by the system after the process was killed (START_STICKY): the
                // interrupted recording was marked in onCreate; nothing runs until the user says.
                if (session == null) stopSelf()
            }
        }
        return START_STICKY
    }

    fun addListener(l: Listener) { listeners += l }
    fun removeListener(l: Listener) { listeners -= l }
    val hasListeners: Boolean get() = listeners.isNotEmpty()

    /**
     * Sets the two switches. Starting either one starts a session (foreground, wake lock,
     * sensors); turning both off ends it. [declaredStart] (lat, lon, sigma) belongs to the
     * navigation started here and to no later one.
     */
    fun setSwitches(navigate: Boolean, record: Boolean, declaredStart: DoubleArray? = null) {
        if (!navigate && !record) {
            stopSession()
            return
        }
        if (replay != null) {
            reportError(getString(R.string.error_replay_running))
            if (session == null) stopSelf()
            return
        }
        val s = session ?: startSession(navigate = false, record = false) ?: return
        val h = workerHandler ?: return
        h.post {
            if (navigate && !s.navigating) {
                s.startNavigation(declaredStart)
                s.setGoTo(goToTarget)
            }
            if (!navigate && s.navigating) s.stopNavigation()
            if (record && !s.recording) startRecordingOn(s)
            if (!record && s.recording) {
                s.stopRecording()
                SessionStore(this).clearActive()
            }
            mainHandler.post { stateChanged() }
        }
    }

    private fun startRecordingOn(s: NavigationSession) {
        val store = SessionStore(this)
        val file = store.newSessionFile()
        val settings = AppSettings(getSharedPreferences(AppSettings.PREFS, Context.MODE_PRIVATE))
        store.markActive(file)
        if (!s.startRecording(file, sessionMeta(settings))) store.clearActive()
    }

    /**
     * Starts sensors + GNSS (and, on the worker thread, the navigator and/or a recording).
     * Returns the session at once; failures arrive through [Listener.onError] and end it.
     */
    fun startSession(navigate: Boolean, record: Boolean, declaredStart: DoubleArray? = null): NavigationSession? {
        session?.let { return it }
        lastError = null
        replayState = null
        return try {
            goForeground()
            acquireWakeLock()
            val settings = AppSettings(getSharedPreferences(AppSettings.PREFS, Context.MODE_PRIVATE))
            val thread = HandlerThread("pdnav-sensors").apply { start() }
            worker = thread
            val h = Handler(thread.looper)
            workerHandler = h
            track.clear()
            lastOutput = null
            lastWalk = null
            val s = NavigationSession(
                handler = h,
                sensorManager = getSystemService(Context.SENSOR_SERVICE) as SensorManager,
                locationManager = getSystemService(Context.LOCATION_SERVICE) as LocationManager,
                config = settings.navigatorConfig(),
                clockNs = { SystemClock.elapsedRealtimeNanos() },
                events = sessionEvents(),
                extraSinks = testSinks,
                fullTracking = settings.fullTracking,
                wantOutput = { listeners.isNotEmpty() },
                regions = RegionStore(filesDir),
                filesDir = filesDir,
            )
            session = s
            h.post {
                if (s.open()) {
                    if (navigate) {
                        s.startNavigation(declaredStart)
                        s.setGoTo(goToTarget)
                    }
                    if (record && s.error == null) startRecordingOn(s)
                }
                mainHandler.post { stateChanged() }
            }
            s
        } catch (e: Exception) {
            endAfter(e.message ?: e.toString())
            null
        }
    }

    private fun sessionEvents() = object : NavigationSession.Events {
        override fun onOutput(out: NavOutput) { mainHandler.post { publish(out) } }
        override fun onStats(stats: SessionStats) { mainHandler.post { publishStats(stats) } }
        override fun onWalk(state: WalkState) { mainHandler.post { publishWalk(state) } }
        override fun onRegion(region: RegionInfo?) { mainHandler.post { publishRegion(region) } }
        override fun onError(message: String, error: Throwable) {
            mainHandler.post { endAfter(message) }
        }
    }

    /** The session failed (it has already closed itself on the worker): tell the user, end. */
    private fun endAfter(message: String) {
        lastError = message
        SessionStore(this).clearActive()
        val s = session
        if (s != null) stopSession() else {
            releaseWakeLock()
            stopForegroundCompat()
        }
        notifyError(message)
        listeners.toList().forEach { it.onError(message) }
        stopSelf()
    }

    private fun reportError(message: String) {
        lastError = message
        listeners.toList().forEach { it.onError(message) }
    }

    /** Stops the session on the worker thread (after anything queued there) and ends it. */
    fun stopSession() {
        val s = session
        val thread = worker
        session = null
        worker = null
        workerHandler = null
        if (s != null) {
            if (thread == null) {
                s.stop()
            } else {
                Handler(thread.looper).post {
                    s.stop()
                    SessionStore(this).clearActive()
                    thread.quitSafely()
                }
            }
        }
        releaseWakeLock()
        stopForegroundCompat()
        stateChanged()
        if (replay == null) stopSelf()
    }

    /** A checkpoint at a known point (map pick or typed): a Truth line in the stream. */
    fun checkpoint(latDeg: Double, lonDeg: Double): Boolean {
        val s = session ?: return false
        workerHandler?.post { s.checkpoint(latDeg, lonDeg) } ?: return false
        return true
    }

    /** Go-to [place] (null: stop): the running session or replay uses it from its next step. */
    fun setGoTo(place: Place?) {
        goToTarget = place
        val s = session ?: return
        workerHandler?.post { s.setGoTo(place) }
    }

    /** The walker's current position (latest step, else the latest estimate), or null. */
    fun currentPosition(): DoubleArray? {
        lastWalk?.step?.let { return doubleArrayOf(it.latDeg, it.lonDeg) }
        val e = lastOutput?.estimate ?: return null
        return if (e.valid && e.latDeg.isFinite()) doubleArrayOf(e.latDeg, e.lonDeg) else null
    }

    /** A long-press start during a session: applied now and recorded in the stream. */
    fun declareStart(latDeg: Double, lonDeg: Double, sigmaM: Double): Boolean {
        val s = session ?: return false
        workerHandler?.post { s.declareStart(latDeg, lonDeg, sigmaM) } ?: return false
        return true
    }

    // ---- replay (owned here, not by the Activity: a rotation does not cancel it) --------------

    /** Replays [path] through a fresh navigator; refused while a live session drives the map. */
    fun startReplay(path: String): Boolean {
        if (session != null) {
            reportError(getString(R.string.error_session_running))
            return false
        }
        replay?.cancel()
        val settings = AppSettings(getSharedPreferences(AppSettings.PREFS, Context.MODE_PRIVATE))
        lastWalk = null
        val task = ReplayTask(path, settings.navigatorConfig(), REPLAY_SEED,
            onProgress = { out, frac ->
                mainHandler.post {
                    replayState = ReplayState(out, frac, false, null)
                    listeners.toList().forEach { it.onReplay(out, frac, false, null) }
                }
            },
            onDone = { out, err ->
                mainHandler.post {
                    replay = null
                    val why = err?.let { e -> NavigationSession.describe(e) }
                    replayState = ReplayState(out, 1.0, true, why)
                    listeners.toList().forEach { it.onReplay(out, 1.0, true, why) }
                    stateChanged()
                    if (session == null) stopSelf()
                }
            },
            regions = RegionStore(this.filesDir), target = goToTarget,
            onWalk = { w -> mainHandler.post { if (w.region?.name != region?.name) publishRegion(w.region); publishWalk(w) } })
        replay = task
        replayPath = path
        replayState = ReplayState(null, 0.0, false, null)
        interrupted = null
        task.start()
        stateChanged()
        return true
    }

    fun cancelReplay() {
        replay?.cancel()
    }

    override fun onDestroy() {
        replay?.cancel()
        stopSession()
        releaseWakeLock()
        super.onDestroy()
    }

    // ---- outputs -------------------------------------------------------------------------------

    /** Internal (not private) so the host test can drive the track past [TRACK_MAX]. */
    internal fun publish(out: NavOutput) {
        lastOutput = out
        val e = out.estimate
        if (e.valid && !e.latDeg.isNaN()) {
            val last = track.lastOrNull()
            if (last == null || last[0] != e.latDeg || last[1] != e.lonDeg) {
                track += doubleArrayOf(e.latDeg, e.lonDeg)
                if (track.size > TRACK_MAX) thinTrack()
            }
        }
        listeners.toList().forEach { it.onOutput(out, track) }
    }

    /** Bounded memory: drop every second point of the older half (the recent track stays dense). */
    private fun thinTrack() {
        val half = track.size / 2
        val kept = ArrayList<DoubleArray>(TRACK_MAX)
        for (i in 0 until half) if (i % 2 == 0) kept += track[i]
        for (i in half until track.size) kept += track[i]
        track.clear()
        track.addAll(kept)
    }

    private fun publishWalk(w: WalkState) {
        lastWalk = w
        listeners.toList().forEach { it.onWalk(w) }
    }

    private fun publishRegion(r: RegionInfo?) {
        region = r
        listeners.toList().forEach { it.onRegion(r) }
    }

    private fun publishStats(stats: SessionStats) {
        lastStats = stats
        listeners.toList().forEach { it.onStats(stats) }
        val now = SystemClock.elapsedRealtimeNanos()
        if (session != null && now - lastNotificationNs >= NOTIFICATION_PERIOD_NS) {
            lastNotificationNs = now
            val nm = getSystemService(Context.NOTIFICATION_SERVICE) as NotificationManager
            nm.notify(NOTIFICATION_ID, buildNotification(stateText(stats)))
        }
    }

    private fun stateChanged() {
        listeners.toList().forEach { it.onState() }
    }

    /** The notification's live line: what runs, duration, file size, lines. */
    fun stateText(stats: SessionStats?): String {
        val parts = mutableListOf<String>()
        if (stats == null) return getString(R.string.notification_text)
        if (stats.navigating) parts += getString(R.string.state_navigating)
        parts += if (stats.recording) stats.recordingLine() else SessionStats.hms(stats.durationNs)
        val head = parts.joinToString(" · ")
        // the counts per line type on a second line (the expanded notification shows it)
        return if (stats.recording && stats.rowsByKind.any { it > 0 }) head + "\n" + stats.countsLine() else head
    }

    private fun sessionMeta(s: AppSettings): List<Pair<String, String>> {
        // keys of docs/log-format.md ("Meta keys"); GNSS hardware keys as GnssLogger records them
        val lm = getSystemService(Context.LOCATION_SERVICE) as LocationManager
        val meta = mutableListOf(
            "FormatVersion" to "1",
            "AppVersion" to "pdnav-android ${appVersion()}",
            "UserHeightMeters" to s.heightM.toString(),
            "UserSex" to if (s.female) "female" else "male",
        )
        meta += GnssSource.capabilities(lm, s.fullTracking)
        if (s.demPath.isNotEmpty()) meta += "DemFile" to File(s.demPath).name
        if (s.graphPath.isNotEmpty()) meta += "GraphFile" to File(s.graphPath).name
        return meta
    }

    private fun appVersion(): String = try {
        @Suppress("DEPRECATION") packageManager.getPackageInfo(packageName, 0).versionName ?: "?"
    } catch (e: Exception) {
        "?"
    }

    // ---- wake lock, foreground, notifications ------------------------------------------------

    private fun acquireWakeLock() {
        if (wakeLock?.isHeld == true) return
        val pm = getSystemService(Context.POWER_SERVICE) as PowerManager
        val wl = pm.newWakeLock(PowerManager.PARTIAL_WAKE_LOCK, WAKE_LOCK_TAG).apply { setReferenceCounted(false) }
        wl.acquire(WAKE_LOCK_MAX_MS)  // a bound, should a stop never come: 12 h
        wakeLock = wl
    }

    private fun releaseWakeLock() {
        val wl = wakeLock ?: return
        wakeLock = null
        if (wl.isHeld) wl.release()
    }

    private fun channel(nm: NotificationManager) {
        if (Build.VERSION.SDK_INT >= 26) {
            nm.createNotificationChannel(NotificationChannel(CHANNEL, getString(R.string.notification_channel), NotificationManager.IMPORTANCE_LOW))
            nm.createNotificationChannel(NotificationChannel(CHANNEL_ERRORS, getString(R.string.notification_channel_errors), NotificationManager.IMPORTANCE_HIGH))
        }
    }

    private fun builder(channel: String): Notification.Builder {
        val nm = getSystemService(Context.NOTIFICATION_SERVICE) as NotificationManager
        channel(nm)
        return if (Build.VERSION.SDK_INT >= 26) Notification.Builder(this, channel) else @Suppress("DEPRECATION") Notification.Builder(this)
    }

    /** The ongoing notification: live state and a Stop action. */
    fun buildNotification(text: String): Notification {
        val open = PendingIntent.getActivity(this, 0, Intent(this, MainActivity::class.java), PendingIntent.FLAG_IMMUTABLE)
        val stop = PendingIntent.getService(this, 1, Intent(this, NavigationService::class.java).setAction(ACTION_STOP),
            PendingIntent.FLAG_IMMUTABLE)
        val action = if (Build.VERSION.SDK_INT >= 23) {
            Notification.Action.Builder(android.graphics.drawable.Icon.createWithResource(this, R.drawable.ic_launcher),
                getString(R.string.action_stop), stop).build()
        } else {
            @Suppress("DEPRECATION") Notification.Action(R.drawable.ic_launcher, getString(R.string.action_stop), stop)
        }
        return builder(CHANNEL).setContentTitle(getString(R.string.app_name))
            .setContentText(text)
            .setStyle(Notification.BigTextStyle().bigText(text))
            .setSmallIcon(R.drawable.ic_launcher)
            .setContentIntent(open)
            .setOngoing(true)
            .setOnlyAlertOnce(true)
            .addAction(action)
            .build()
    }

    private fun notifyError(message: String) {
        val nm = getSystemService(Context.NOTIFICATION_SERVICE) as NotificationManager
        val open = PendingIntent.getActivity(this, 2, Intent(this, MainActivity::class.java), PendingIntent.FLAG_IMMUTABLE)
        val n = builder(CHANNEL_ERRORS).setContentTitle(getString(R.string.notification_error_title))
            .setContentText(message)
            .setStyle(Notification.BigTextStyle().bigText(message))
            .setSmallIcon(R.drawable.ic_launcher)
            .setContentIntent(open)
            .setAutoCancel(true)
            .build()
        nm.notify(ERROR_NOTIFICATION_ID, n)
    }

    private fun goForeground() {
        val n = buildNotification(getString(R.string.notification_text))
        if (Build.VERSION.SDK_INT >= 29) {
            startForeground(NOTIFICATION_ID, n, ServiceInfo.FOREGROUND_SERVICE_TYPE_LOCATION)
        } else {
            startForeground(NOTIFICATION_ID, n)
        }
    }

    private fun stopForegroundCompat() {
        if (Build.VERSION.SDK_INT >= 24) stopForeground(Service.STOP_FOREGROUND_REMOVE) else @Suppress("DEPRECATION") stopForeground(true)
    }

    companion object {
        const val ACTION_SET = "org.pdnav.app.action.SET"
        const val ACTION_STOP = "org.pdnav.app.action.STOP"
        const val EXTRA_NAVIGATE = "navigate"
        const val EXTRA_RECORD = "record"
        const val EXTRA_START_LAT = "start_lat_deg"
        const val EXTRA_START_LON = "start_lon_deg"
        const val EXTRA_START_SIGMA = "start_sigma_m"
        const val WAKE_LOCK_TAG = "pdnav:session"
        const val NOTIFICATION_ID = 1
        const val ERROR_NOTIFICATION_ID = 2
        const val TRACK_MAX = 5000
        private const val WAKE_LOCK_MAX_MS = 12L * 3600 * 1000
        private const val NOTIFICATION_PERIOD_NS = 1_000_000_000L
        private const val CHANNEL = "navigation"
        private const val CHANNEL_ERRORS = "errors"
        private const val REPLAY_SEED = 1L

        /** Sets the switches (starts the foreground service when one is on). */
        fun set(context: Context, navigate: Boolean, record: Boolean, declaredStart: DoubleArray? = null) {
            val i = Intent(context, NavigationService::class.java)
                .setAction(ACTION_SET).putExtra(EXTRA_NAVIGATE, navigate).putExtra(EXTRA_RECORD, record)
            if (declaredStart != null) {
                i.putExtra(EXTRA_START_LAT, declaredStart[0]).putExtra(EXTRA_START_LON, declaredStart[1])
                    .putExtra(EXTRA_START_SIGMA, declaredStart[2])
            }
            if ((navigate || record) && Build.VERSION.SDK_INT >= 26) context.startForegroundService(i) else context.startService(i)
        }

        fun stop(context: Context) {
            context.startService(Intent(context, NavigationService::class.java).setAction(ACTION_STOP))
        }
    }
}

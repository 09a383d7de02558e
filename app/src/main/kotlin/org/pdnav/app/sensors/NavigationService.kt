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
import android.os.SystemClock
import org.pdnav.app.R
import org.pdnav.app.nav.NavOutput
import org.pdnav.app.recording.SessionStore
import org.pdnav.app.ui.AppSettings
import org.pdnav.app.ui.MainActivity
import java.io.File

/**
 * Foreground service (type location) that owns the sensors while navigating or recording,
 * so a locked screen does not stop them. Started with [start]/[stop]; activities bind to
 * it for the estimate ([Listener]).
 */
class NavigationService : Service() {

    /** Receives every navigator output (and start errors) on the main thread. */
    interface Listener {
        fun onOutput(output: NavOutput, track: List<DoubleArray>)
        fun onError(message: String) = Unit
    }

    inner class LocalBinder : Binder() {
        val service: NavigationService get() = this@NavigationService
    }

    private val binder = LocalBinder()
    private val listeners = mutableListOf<Listener>()
    private val mainHandler by lazy { Handler(Looper.getMainLooper()) }
    private var worker: HandlerThread? = null

    /** The running session, if any. */
    var session: NavigationSession? = null
        private set

    /** Estimated positions so far (lat, lon), for the track polyline. */
    val track = mutableListOf<DoubleArray>()
    var lastOutput: NavOutput? = null
        private set

    /** The worker looper (sensor callbacks, merging, JNI calls); tests idle it. */
    val workLooper: Looper? get() = worker?.looper

    override fun onBind(intent: Intent?): IBinder = binder

    override fun onStartCommand(intent: Intent?, flags: Int, startId: Int): Int {
        when (intent?.action) {
            ACTION_START -> startSession(
                navigate = intent.getBooleanExtra(EXTRA_NAVIGATE, true),
                record = intent.getBooleanExtra(EXTRA_RECORD, false),
            )
            ACTION_STOP -> {
                stopSession()
                stopSelf()
            }
        }
        return START_NOT_STICKY
    }

    fun addListener(l: Listener) { listeners += l }
    fun removeListener(l: Listener) { listeners -= l }

    /** Why the last start failed (e.g. an unreadable DEM file), or null. */
    var lastError: String? = null
        private set

    /** Starts sensors + GNSS, the navigator and (optionally) a recording; null on failure. */
    fun startSession(navigate: Boolean, record: Boolean): NavigationSession? {
        session?.let { return it }
        return try {
            lastError = null
            createSession(navigate, record)
        } catch (e: Exception) {
            // e.g. IOException / RuntimeException from the core for a bad DEM or graph file
            lastError = e.message ?: e.toString()
            worker?.quitSafely()
            worker = null
            stopForegroundCompat()
            listeners.toList().forEach { it.onError(lastError ?: "") }
            null
        }
    }

    private fun createSession(navigate: Boolean, record: Boolean): NavigationSession {
        goForeground()
        val settings = AppSettings(getSharedPreferences(AppSettings.PREFS, Context.MODE_PRIVATE))
        val thread = HandlerThread("pdnav-sensors").apply { start() }
        worker = thread
        val file: File? = if (record) SessionStore(this).newSessionFile() else null
        track.clear()
        val s = NavigationSession(
            handler = Handler(thread.looper),
            sensorManager = getSystemService(Context.SENSOR_SERVICE) as SensorManager,
            locationManager = getSystemService(Context.LOCATION_SERVICE) as LocationManager,
            config = settings.navigatorConfig(),
            navigate = navigate,
            recordFile = file,
            clockNs = { SystemClock.elapsedRealtimeNanos() },
            onOutput = { out -> mainHandler.post { publish(out) } },
            meta = sessionMeta(settings),
        )
        session = s
        s.start()
        return s
    }

    /** Stops the session on the worker thread (after anything queued there) and ends it. */
    fun stopSession() {
        val s = session ?: return
        val thread = worker
        session = null
        worker = null
        if (thread == null) {
            s.stop()
        } else {
            Handler(thread.looper).post {
                s.stop()
                thread.quitSafely()
            }
        }
        stopForegroundCompat()
    }

    override fun onDestroy() {
        stopSession()
        super.onDestroy()
    }

    private fun publish(out: NavOutput) {
        lastOutput = out
        val e = out.estimate
        if (e.valid && !e.latDeg.isNaN()) {
            val last = track.lastOrNull()
            if (last == null || last[0] != e.latDeg || last[1] != e.lonDeg) track += doubleArrayOf(e.latDeg, e.lonDeg)
        }
        listeners.toList().forEach { it.onOutput(out, track) }
    }

    private fun sessionMeta(s: AppSettings): List<Pair<String, String>> {
        // keys of docs/log-format.md ("Meta keys"); the navigator reads the start on replay
        val meta = mutableListOf(
            "FormatVersion" to "1",
            "AppVersion" to "pdnav-android 0.1.0",
            "Device" to "${Build.MANUFACTURER} ${Build.MODEL}",
            "UserHeightMeters" to s.heightM.toString(),
            "UserSex" to if (s.female) "female" else "male",
        )
        if (!s.startLatDeg.isNaN()) {
            meta += "StartLatitudeDegrees" to s.startLatDeg.toString()
            meta += "StartLongitudeDegrees" to s.startLonDeg.toString()
            meta += "StartSigmaMeters" to s.startSigmaM.toString()
        }
        if (s.demPath.isNotEmpty()) meta += "DemFile" to java.io.File(s.demPath).name
        if (s.graphPath.isNotEmpty()) meta += "GraphFile" to java.io.File(s.graphPath).name
        return meta
    }

    private fun goForeground() {
        val nm = getSystemService(Context.NOTIFICATION_SERVICE) as NotificationManager
        val builder = if (Build.VERSION.SDK_INT >= 26) {
            nm.createNotificationChannel(NotificationChannel(CHANNEL, getString(R.string.notification_channel), NotificationManager.IMPORTANCE_LOW))
            Notification.Builder(this, CHANNEL)
        } else {
            @Suppress("DEPRECATION") Notification.Builder(this)
        }
        val open = PendingIntent.getActivity(this, 0, Intent(this, MainActivity::class.java), PendingIntent.FLAG_IMMUTABLE)
        val n = builder.setContentTitle(getString(R.string.app_name))
            .setContentText(getString(R.string.notification_text))
            .setSmallIcon(R.drawable.ic_launcher)
            .setContentIntent(open)
            .setOngoing(true)
            .build()
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
        const val ACTION_START = "org.pdnav.app.action.START"
        const val ACTION_STOP = "org.pdnav.app.action.STOP"
        const val EXTRA_NAVIGATE = "navigate"
        const val EXTRA_RECORD = "record"
        private const val CHANNEL = "navigation"
        private const val NOTIFICATION_ID = 1

        fun start(context: Context, navigate: Boolean, record: Boolean) {
            val i = Intent(context, NavigationService::class.java)
                .setAction(ACTION_START).putExtra(EXTRA_NAVIGATE, navigate).putExtra(EXTRA_RECORD, record)
            if (Build.VERSION.SDK_INT >= 26) context.startForegroundService(i) else context.startService(i)
        }

        fun stop(context: Context) {
            context.startService(Intent(context, NavigationService::class.java).setAction(ACTION_STOP))
        }
    }
}

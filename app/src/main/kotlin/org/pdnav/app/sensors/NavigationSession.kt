package org.pdnav.app.sensors

import android.hardware.SensorManager
import android.location.LocationManager
import android.os.Handler
import android.util.Log
import org.pdnav.app.nav.FixRow
import org.pdnav.app.nav.NativeNavigator
import org.pdnav.app.nav.NativeRecorder
import org.pdnav.app.nav.NavOutput
import org.pdnav.app.nav.NavigatorConfig
import org.pdnav.app.nav.SampleBatch
import org.pdnav.app.nav.SampleKind
import org.pdnav.app.nav.SampleSink
import org.pdnav.app.nav.SessionFeeder
import org.pdnav.app.region.RegionInfo
import org.pdnav.app.region.RegionStore
import org.pdnav.app.walk.RegionalNavigator
import org.pdnav.app.walk.WalkState
import java.io.File
import java.io.FileInputStream

/**
 * One run of the sensors with two independent switches: navigating (a [NativeNavigator]
 * behind a [SessionFeeder]) and recording (a [NativeRecorder]). Sensors + GNSS ->
 * [SampleMerger] -> the sinks that are on. Every method except the read-only state runs on
 * the worker [handler]'s thread (the service posts them there), so flush, output and
 * shutdown are serialised and no sink is called after it is closed.
 *
 * The pump runs from the sensor and GNSS callbacks (at most every [TICK_NS]) and from a
 * fallback tick on the worker, never from the main looper. Any failure of a sink (a full
 * disk, a native error, a missing native library) ends the session through [fail]: sensors
 * unregistered, the recording closed and kept, the reason reported to [events].
 */
class NavigationSession(
    private val handler: Handler,
    sensorManager: SensorManager,
    locationManager: LocationManager,
    private val config: NavigatorConfig,
    private val clockNs: () -> Long,
    private val events: Events,
    private val seed: Long = 1L,
    private val extraSinks: List<SampleSink> = emptyList(),
    private val fullTracking: Boolean = false,
    private val syncFile: (File) -> Unit = ::fsync,
    private val wantOutput: () -> Boolean = { true },
    private val device: String = android.os.Build.MODEL ?: "",
    /** Installed regions (the navigator opens on the one the walk is in); null: settings' files only. */
    private val regions: RegionStore? = null,
    /** App storage for the places (the session start is saved there); null: not saved. */
    private val filesDir: File? = null,
) {
    /** What the session reports (called on the worker thread). */
    interface Events {
        fun onOutput(out: NavOutput) = Unit
        fun onStats(stats: SessionStats) = Unit
        /** The session ended on [error]; the recording (if any) is closed and kept. */
        fun onError(message: String, error: Throwable) = Unit
        /** The walker's state after the latest per-step estimates (issue 29). */
        fun onWalk(state: WalkState) = Unit
        /** The navigator opened on [region] (null: the settings' files). */
        fun onRegion(region: RegionInfo?) = Unit
    }

    /** The navigator, on the region the walk is in (opened once the stream shows where). */
    @Volatile var regional: RegionalNavigator? = null
        private set
    val navigator: NativeNavigator? get() = regional?.navigator
    val feeder: SessionFeeder? get() = regional?.feeder
    @Volatile var recorder: NativeRecorder? = null
        private set
    @Volatile var recordFile: File? = null
        private set
    val merger = SampleMerger(HOLD_NS, emptyList(), ::late)
    val sensors = SensorSource(sensorManager, merger) { maybePump() }
    val gnss = GnssSource(locationManager, merger, clockNs, onEvent = { maybePump() })
    var sensorTypes: List<Int> = emptyList()
        private set
    var gnssRegistered: GnssSource.Registered? = null
        private set
    @Volatile var running = false
        private set
    @Volatile var error: String? = null
        private set
    @Volatile var lastLate: String? = null
        private set
    private var closed = false
    private var lastPumpNs = Long.MIN_VALUE
    private var lastRecorderFlushNs = 0L
    private var lastSyncNs = 0L
    private var recordStartNs = 0L
    private val startNs = clockNs()

    val navigating: Boolean get() = regional != null
    val recording: Boolean get() = recorder != null

    private val tick = object : Runnable {
        override fun run() {
            if (!running) return
            pump()
            if (running) handler.postDelayed(this, TICK_MS)
        }
    }

    /** Registers sensors and GNSS and starts the pump. False (and [events] told) on failure. */
    fun open(): Boolean = guarded("start") {
        running = true
        sensorTypes = sensors.start(handler)
        gnssRegistered = gnss.start(handler, fullTracking)
        handler.postDelayed(tick, TICK_MS)
    }

    /**
     * Switches navigation on: loads the DEM / graph / ephemeris (this thread, not the main
     * one) and feeds the navigator from now on. [declaredStart] (lat, lon, sigma) is this
     * session's start: written into the stream (and so the recording) as Meta lines.
     */
    fun startNavigation(declaredStart: DoubleArray? = null): Boolean = guarded("navigation") {
        if (regional != null) return@guarded
        regional = RegionalNavigator(config, seed, regions, filesDir, saveStart = true) { events.onRegion(it.region) }
        updateSinks()
        if (declaredStart != null) declareStart(declaredStart[0], declaredStart[1], declaredStart[2])
    }

    fun stopNavigation() = guarded("stop navigation") {
        val nav = regional ?: return@guarded
        merger.flush(clockNs(), all = true)
        regional = null
        updateSinks()
        nav.close()
    }

    /**
     * Switches recording on into [file]: header Meta lines ([meta]) first, then every row
     * from now on; the navigator keeps running (its converged state is not lost). When the
     * navigator already has a position, it is written as the recording's declared start so
     * a replay begins where the field run was.
     */
    fun startRecording(file: File, meta: List<Pair<String, String>>): Boolean = guarded("recording") {
        if (recorder != null) return@guarded
        val rec = NativeRecorder(file.path, device)
        try {
            val t = clockNs()
            val b = SampleBatch(meta.size + 3)
            meta.forEach { (k, v) -> b.addMeta(t, k, v) }
            val e = navigator?.estimate()
            if (e != null && e.valid && e.latDeg.isFinite()) {
                val sigma = Math.sqrt((e.covEastEastM2 + e.covNorthNorthM2).coerceAtLeast(1.0))
                SessionFeeder.addDeclaredStart(b, t, e.latDeg, e.lonDeg, sigma)
            }
            rec.write(b)
            rec.flush()
        } catch (e: Exception) {
            rec.close()
            throw e
        }
        recorder = rec
        recordFile = file
        recordStartNs = clockNs()
        lastRecorderFlushNs = recordStartNs
        lastSyncNs = recordStartNs
        updateSinks()
    }

    /** Ends the recording: pending rows, an end marker, close, fsync. */
    fun stopRecording(reason: String = "stopped") = guarded("stop recording") {
        val rec = recorder ?: return@guarded
        merger.flush(clockNs(), all = true)
        endRecording(rec, reason)
    }

    private fun endRecording(rec: NativeRecorder, reason: String) {
        recorder = null
        updateSinks()
        try {
            val b = SampleBatch(1)
            b.addMeta(clockNs(), KEY_END, reason)
            rec.write(b)
        } finally {
            rec.close()
            recordFile?.let(syncFile)
        }
    }

    private fun updateSinks() {
        merger.setSinks(listOfNotNull<SampleSink>(recorder, regional) + extraSinks)
    }

    /** Pumps when the last pump is [TICK_NS] old (called from every callback). */
    private fun maybePump() {
        val now = clockNs()
        if (lastPumpNs == Long.MIN_VALUE || now - lastPumpNs >= TICK_NS) pump()
    }

    /** One flush: merged samples to the sinks, recorder to the OS (1 Hz) and disk (0.1 Hz), output. */
    fun pump() {
        if (closed) return
        guarded("pump") {
            val now = clockNs()
            lastPumpNs = now
            merger.flush(now)
            val rec = recorder
            if (rec != null && now - lastRecorderFlushNs >= RECORDER_FLUSH_NS) {
                rec.flush()
                lastRecorderFlushNs = now
                if (now - lastSyncNs >= SYNC_NS) {
                    recordFile?.let(syncFile)
                    lastSyncNs = now
                }
            }
            val nav = navigator
            if (nav != null && wantOutput()) {
                events.onOutput(nav.output(MAX_PARTICLES))
                regional?.tracker?.let { events.onWalk(it.state) }
            }
            events.onStats(stats())
        }
    }

    /** Declares the start (long-press) now: Meta lines in the stream; the feeder applies them. */
    fun declareStart(latDeg: Double, lonDeg: Double, sigmaM: Double) {
        val t = clockNs()
        merger.add { b -> SessionFeeder.addDeclaredStart(b, t, latDeg, lonDeg, sigmaM) }
    }

    /** Go-to [place] (null: stop); applied from the next step on. */
    fun setGoTo(place: org.pdnav.app.region.Place?) {
        regional?.setTarget(place)
    }

    /** A checkpoint: the tester is at this known point now (a `Truth` line). */
    fun checkpoint(latDeg: Double, lonDeg: Double) {
        val t = clockNs()
        merger.add { b -> b.addTruth(t, latDeg, lonDeg) }
    }

    fun stats(): SessionStats {
        val now = clockNs()
        val file = recordFile
        return SessionStats(
            durationNs = now - startNs,
            recordingNs = if (recorder != null) now - recordStartNs else 0L,
            navigating = navigating,
            recording = recording,
            fileName = file?.name ?: "",
            fileBytes = if (recorder != null) file?.length() ?: 0L else 0L,
            rowsByKind = merger.emittedByKind(),
            sensorRows = sensors.rowsByType().mapKeys { SensorSource.typeName(it.key) },
            gnssEpochs = gnss.epochs,
            fixes = gnss.fixes,
            lateRows = merger.lateRows,
            lastLate = lastLate,
            magAccuracy = sensors.magAccuracy,
            satellites = gnss.satellites,
            lastFix = gnss.lastFix,
            locationEnabled = gnss.providerEnabled,
            checkpoints = feeder?.checkpoints ?: emptyList(),
        )
    }

    private fun late(kind: Int, tNs: Long, behindNs: Long) {
        val msg = "late ${kindName(kind)} row at $tNs ns, ${behindNs / 1_000_000} ms behind the stream (emitted anyway)"
        lastLate = msg
        try {
            Log.w(TAG, msg)
        } catch (e: RuntimeException) {
            // android.util.Log is a stub on a plain JVM
        }
    }

    /** Ends the session (idempotent): unregisters, emits what is pending, closes the sinks. */
    fun stop(reason: String = "stopped") {
        if (closed) return
        closed = true
        running = false
        handler.removeCallbacks(tick)
        var first: Throwable? = null
        fun step(f: () -> Unit) {
            try {
                f()
            } catch (e: Exception) {
                if (first == null) first = e
            } catch (e: LinkageError) {
                if (first == null) first = e
            }
        }
        step { sensors.stop() }
        step { gnss.stop() }
        step { merger.flush(clockNs(), all = true) }
        step { regional?.finish() }  // end of input: the core releases a short last walk
        step { navigator?.let { if (wantOutput()) events.onOutput(it.output(MAX_PARTICLES)) } }
        step { regional?.tracker?.let { if (wantOutput()) events.onWalk(it.state) } }
        step { events.onStats(stats()) }
        step { recorder?.let { endRecording(it, reason) } }
        step { regional?.close() }
        regional = null
        first?.let { e -> if (error == null) report(e, "stop") }
    }

    /** Runs [f]; a failure ends the session cleanly and reports why. True when [f] succeeded. */
    private fun guarded(what: String, f: () -> Unit): Boolean {
        return try {
            f()
            true
        } catch (e: Exception) {
            fail(what, e)
            false
        } catch (e: LinkageError) {  // UnsatisfiedLinkError: an APK without its .so
            fail(what, e)
            false
        }
    }

    private fun fail(what: String, e: Throwable) {
        if (error != null || closed) return
        report(e, what)
        stop("error: ${error ?: ""}")
    }

    private fun report(e: Throwable, what: String) {
        val msg = describe(e)
        error = "$what failed: $msg"
        try {
            Log.e(TAG, "session $what failed", e)
        } catch (ignored: RuntimeException) {
        }
        events.onError(error ?: msg, e)
    }

    companion object {
        /** Hold time of the merger: covers 100 ms sensor batching and ~1 s GNSS callback delay. */
        const val HOLD_NS = 1_500_000_000L
        const val TICK_MS = 200L
        const val TICK_NS = 200_000_000L
        const val RECORDER_FLUSH_NS = 1_000_000_000L
        /** fsync period: a cold-battery shutdown loses at most this much (plus the OS's own write-back). */
        const val SYNC_NS = 10_000_000_000L
        const val MAX_PARTICLES = 200
        const val KEY_END = "SessionEnd"
        private const val TAG = "pdnav"

        /** What the user reads: the exception's message, or a plain reason for the common ones. */
        fun describe(e: Throwable): String = when (e) {
            is UnsatisfiedLinkError -> "the native library is missing from this build (${e.message})"
            is java.io.IOException -> e.message ?: "I/O error"
            else -> e.message ?: e.javaClass.simpleName
        }

        /** fsync through a second descriptor: Linux syncs the file's data whatever fd asks. */
        fun fsync(file: File) {
            if (!file.isFile) return
            FileInputStream(file).use { it.fd.sync() }
        }

        fun kindName(kind: Int): String = when (kind) {
            SampleKind.ACCEL -> "Accel"; SampleKind.GYRO -> "Gyro"; SampleKind.MAG -> "Mag"
            SampleKind.UNCAL_ACCEL -> "UncalAccel"; SampleKind.UNCAL_GYRO -> "UncalGyro"; SampleKind.UNCAL_MAG -> "UncalMag"
            SampleKind.ORIENTATION -> "OrientationDeg"; SampleKind.PRESSURE -> "Pressure"
            SampleKind.ROTATION_VECTOR -> "RotationVector"; SampleKind.STEP_DETECTOR -> "StepDetector"
            SampleKind.STEP_COUNTER -> "StepCounter"; SampleKind.GNSS_RAW -> "Raw"; SampleKind.FIX -> "Fix"
            SampleKind.NAV_MESSAGE -> "Nav"; SampleKind.GNSS_STATUS -> "Status"; SampleKind.AGC -> "Agc"
            SampleKind.TRUTH -> "Truth"; SampleKind.META -> "Meta"
            SampleKind.GAME_ROTATION_VECTOR -> "GameRotationVector"; SampleKind.SENSOR_ACCURACY -> "SensorAccuracy"
            else -> "kind $kind"
        }
    }
}

/** A snapshot of a session for the screen and the notification. */
data class SessionStats(
    val durationNs: Long,
    val recordingNs: Long,
    val navigating: Boolean,
    val recording: Boolean,
    val fileName: String,
    val fileBytes: Long,
    val rowsByKind: LongArray,
    val sensorRows: Map<String, Long>,
    val gnssEpochs: Long,
    val fixes: Long,
    val lateRows: Long,
    val lastLate: String?,
    val magAccuracy: Int,
    val satellites: List<GnssSource.Satellite>,
    val lastFix: FixRow?,
    val locationEnabled: Boolean,
    val checkpoints: List<SessionFeeder.Checkpoint>,
) {
    /** e.g. "REC 00:12:34 · 1.2 MB · 123456 lines". */
    fun recordingLine(): String {
        val lines = rowsByKind.sum()
        return "REC ${hms(recordingNs)} · ${mb(fileBytes)} · $lines lines"
    }

    /** Counts per line type, e.g. "Accel 1200 · Gyro 1200 · Raw 340 · Status 90". */
    fun countsLine(): String = rowsByKind.indices.filter { rowsByKind[it] > 0 }
        .joinToString(" · ") { "${NavigationSession.kindName(it)} ${rowsByKind[it]}" }

    companion object {
        fun hms(ns: Long): String {
            val s = ns / 1_000_000_000L
            return String.format(java.util.Locale.US, "%02d:%02d:%02d", s / 3600, (s / 60) % 60, s % 60)
        }
        fun mb(bytes: Long): String = String.format(java.util.Locale.US, "%.1f MB", bytes / 1e6)
    }
}

package org.pdnav.app.sensors

import android.hardware.SensorManager
import android.location.LocationManager
import android.os.Handler
import org.pdnav.app.nav.NavOutput
import org.pdnav.app.nav.NativeNavigator
import org.pdnav.app.nav.NativeRecorder
import org.pdnav.app.nav.NavigatorConfig
import org.pdnav.app.nav.SampleBatch
import org.pdnav.app.nav.SampleSink
import java.io.File

/**
 * One navigation and/or recording run: sensors + GNSS -> [SampleMerger] -> navigator and
 * recorder, all on the worker [handler]'s thread (flush, output and shutdown are serialised
 * there, so no sink is ever called after it is closed).
 */
class NavigationSession(
    private val handler: Handler,
    sensorManager: SensorManager,
    locationManager: LocationManager,
    config: NavigatorConfig,
    navigate: Boolean,
    val recordFile: File?,
    private val clockNs: () -> Long,
    private val onOutput: (NavOutput) -> Unit,
    seed: Long = 1L,
    meta: List<Pair<String, String>> = emptyList(),
) {
    val navigator: NativeNavigator? = if (navigate) NativeNavigator(config, seed) else null
    val recorder: NativeRecorder? = recordFile?.let { NativeRecorder(it.path, android.os.Build.MODEL ?: "") }
    val merger = SampleMerger(HOLD_NS, listOfNotNull<SampleSink>(recorder, navigator))
    val sensors = SensorSource(sensorManager, merger)
    val gnss = GnssSource(locationManager, merger, clockNs)
    var sensorTypes: List<Int> = emptyList()
        private set
    var gnssRegistered: GnssSource.Registered? = null
        private set
    @Volatile var running = false
        private set
    private var stopped = false
    private var lastRecorderFlushNs = 0L

    private val tick = object : Runnable {
        override fun run() {
            if (!running) return
            pump()
            handler.postDelayed(this, TICK_MS)
        }
    }

    init {
        val t = clockNs()
        if (meta.isNotEmpty()) {
            val b = SampleBatch(meta.size)
            meta.forEach { (k, v) -> b.addMeta(t, k, v) }
            recorder?.write(b)
            navigator?.feed(b)
        }
    }

    /** Registers the sensors and GNSS callbacks and starts the periodic flush. */
    fun start() {
        running = true
        sensorTypes = sensors.start(handler)
        gnssRegistered = gnss.start(handler)
        lastRecorderFlushNs = clockNs()
        handler.postDelayed(tick, TICK_MS)
    }

    /** One flush: merged samples to the sinks, recorder to the OS (>= 1 Hz), output to the UI. */
    fun pump() {
        val now = clockNs()
        merger.flush(now)
        val rec = recorder
        if (rec != null && now - lastRecorderFlushNs >= RECORDER_FLUSH_NS) {
            rec.flush()
            lastRecorderFlushNs = now
        }
        navigator?.let { onOutput(it.output(200)) }
    }

    /** Declares the start (long-press) at the current time. */
    fun setStart(latDeg: Double, lonDeg: Double, sigmaM: Double) {
        handler.post { if (!stopped) navigator?.setStart(latDeg, lonDeg, sigmaM, clockNs()) }
    }

    /** Unregisters everything, emits what is pending and closes the sinks (idempotent). */
    fun stop() {
        if (stopped) return
        stopped = true
        running = false
        handler.removeCallbacks(tick)
        sensors.stop()
        gnss.stop()
        merger.flush(clockNs(), all = true)
        navigator?.let { onOutput(it.output(200)) }
        recorder?.close()
        navigator?.close()
    }

    companion object {
        /** Hold time of the merger: covers 100 ms sensor batching and ~1 s GNSS callback delay. */
        const val HOLD_NS = 1_500_000_000L
        const val TICK_MS = 200L
        const val RECORDER_FLUSH_NS = 1_000_000_000L
    }
}

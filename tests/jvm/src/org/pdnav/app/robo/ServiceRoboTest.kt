package org.pdnav.app.robo

import android.Manifest
import android.hardware.Sensor
import android.hardware.SensorManager
import android.location.GnssClock
import android.location.GnssMeasurement
import android.location.GnssMeasurementsEvent
import android.location.Location
import android.location.LocationManager
import android.os.SystemClock
import org.junit.Test
import org.junit.runner.RunWith
import org.pdnav.app.nav.NativeLogReader
import org.pdnav.app.nav.NavOutput
import org.pdnav.app.nav.NavigatorConfig
import org.pdnav.app.nav.SampleBatch
import org.pdnav.app.nav.SampleKind
import org.pdnav.app.recording.ReplayTask
import org.pdnav.app.sensors.NavigationService
import org.robolectric.Robolectric
import org.robolectric.RobolectricTestRunner
import org.robolectric.RuntimeEnvironment
import org.robolectric.Shadows.shadowOf
import org.robolectric.annotation.LooperMode
import org.robolectric.shadows.SensorEventBuilder
import org.robolectric.shadows.ShadowSensor
import org.robolectric.shadows.ShadowSystemClock
import java.time.Duration
import kotlin.test.assertEquals
import kotlin.test.assertNotNull
import kotlin.test.assertNull
import kotlin.test.assertTrue

/**
 * The foreground service with injected SensorEvents (ShadowSensorManager) and
 * GnssMeasurementsEvents / fixes (ShadowLocationManager): the bridge receives one stream in
 * time order, the recording is written through NativeRecorder and replays in the app.
 */
@RunWith(RobolectricTestRunner::class)
@LooperMode(LooperMode.Mode.PAUSED)
class ServiceRoboTest {
    private val app = RuntimeEnvironment.getApplication()
    private val types = listOf(Sensor.TYPE_ACCELEROMETER, Sensor.TYPE_GYROSCOPE, Sensor.TYPE_MAGNETIC_FIELD,
        Sensor.TYPE_ROTATION_VECTOR, Sensor.TYPE_PRESSURE, Sensor.TYPE_STEP_DETECTOR)

    private fun gnssEvent(tNs: Long, svids: List<Int>): GnssMeasurementsEvent {
        val clock = GnssClock().apply {
            timeNanos = 1_000_000_000_000L + tNs
            fullBiasNanos = -1_300_000_000_000_000_000L
            elapsedRealtimeNanos = tNs
        }
        val ms = svids.map { sv ->
            GnssMeasurement().apply {
                svid = sv
                constellationType = 1
                state = 16431
                receivedSvTimeNanos = 123_456_789L + sv
                cn0DbHz = 30.0 + sv
                pseudorangeRateMetersPerSecond = -100.0 * sv
                codeType = "C"
            }
        }
        return GnssMeasurementsEvent.Builder().setClock(clock).setMeasurements(ms).build()
    }

    @Test
    fun sensorAndGnssEventsReachTheBridgeInTimeOrderAndTheRecordingReplays() {
        shadowOf(app).grantPermissions(Manifest.permission.ACCESS_FINE_LOCATION, Manifest.permission.ACTIVITY_RECOGNITION)
        val sm = app.getSystemService(SensorManager::class.java)
        val sensors = types.associateWith { ShadowSensor.newInstance(it).also { s -> shadowOf(sm).addSensor(s) } }
        val lm = app.getSystemService(LocationManager::class.java)
        shadowOf(lm).setProviderEnabled(LocationManager.GPS_PROVIDER, true)

        val service = Robolectric.buildService(NavigationService::class.java).create().get()
        val session = assertNotNull(service.startSession(navigate = true, record = true), service.lastError)
        assertEquals(types.toSet(), session.sensorTypes.toSet(), "every sensor registered")
        assertNotNull(shadowOf(service).lastForegroundNotification, "runs as a foreground service")
        val registered = assertNotNull(session.gnssRegistered)
        assertTrue(registered.measurements && registered.fixes, "GNSS callbacks registered: $registered")
        val looper = assertNotNull(service.workLooper)

        val t0 = SystemClock.elapsedRealtimeNanos()
        val n = 100  // 1 s at 100 Hz
        fun send(type: Int, k: Int, values: FloatArray) = shadowOf(sm).sendSensorEventToListeners(
            SensorEventBuilder.newBuilder().setSensor(sensors.getValue(type)).setTimestamp(t0 + k * 10_000_000L).setValues(values).build())
        // Accelerometer first, then the gyroscope's whole batch: the two streams overlap in time.
        for (k in 0 until n) send(Sensor.TYPE_ACCELEROMETER, k, floatArrayOf(0.1f * (k % 10), 0f, 9.81f))
        for (k in 0 until n) send(Sensor.TYPE_GYROSCOPE, k, floatArrayOf(0f, 0.01f * k, 0f))
        for (k in 0 until n step 2) send(Sensor.TYPE_MAGNETIC_FIELD, k, floatArrayOf(20f, -5f, -40f))
        for (k in 0 until n step 2) send(Sensor.TYPE_ROTATION_VECTOR, k, floatArrayOf(0f, 0f, 0.3826834f, 0.9238795f, 0.1f))
        for (k in 0 until n step 10) send(Sensor.TYPE_PRESSURE, k, floatArrayOf(1013.25f))
        send(Sensor.TYPE_STEP_DETECTOR, 55, floatArrayOf(1f))
        // GNSS epochs at 0.25 s and 0.75 s arrive after all the sensor data (as on a phone).
        shadowOf(lm).simulateGnssMeasurementsEvent(gnssEvent(t0 + 250_000_000L, listOf(3, 7, 12)))
        shadowOf(lm).simulateGnssMeasurementsEvent(gnssEvent(t0 + 750_000_000L, listOf(3, 7)))
        shadowOf(lm).simulateLocation(Location(LocationManager.GPS_PROVIDER).apply {
            latitude = 37.4; longitude = -122.08; accuracy = 4f; time = 1_700_000_000_000L
            elapsedRealtimeNanos = t0 + 500_000_000L
        })
        shadowOf(looper).idle()

        ShadowSystemClock.advanceBy(Duration.ofSeconds(3))
        session.pump()
        val nav = assertNotNull(session.navigator)
        val ignored = nav.ignored()
        assertTrue(ignored.keys.none { it.contains("order") || it.contains("backward") }, "navigator saw out-of-order samples: $ignored")
        assertEquals(0L, session.merger.lateRows, "rows emitted out of time order")
        val file = assertNotNull(session.recordFile)

        service.stopSession()  // runs on the worker thread, which then quits
        looper.thread.join(10_000)
        assertTrue(!looper.thread.isAlive, "worker thread ended")
        assertNull(service.session)

        // The recording: every injected sample, one time-ordered stream.
        val counts = mutableMapOf<Int, Int>()
        var lastT = Long.MIN_VALUE
        val svids = mutableListOf<Long>()
        NativeLogReader(file.path).use { r ->
            val b = SampleBatch()
            while (r.read(b, 1000)) {
                for (i in 0 until b.size) {
                    assertTrue(b.tNs(i) >= lastT, "row time ${b.tNs(i)} < previous $lastT")
                    lastT = b.tNs(i)
                    counts.merge(b.kind(i), 1, Int::plus)
                    if (b.kind(i) == SampleKind.GNSS_RAW) {
                        svids += b.long(i, 5)
                        assertEquals(30.0 + b.long(i, 5), b.double(i, 6), "Cn0 of svid ${b.long(i, 5)}")
                    }
                }
            }
            assertEquals(0L, r.stats.skipped)
        }
        assertEquals(n, counts[SampleKind.ACCEL]); assertEquals(n, counts[SampleKind.GYRO])
        assertEquals(n / 2, counts[SampleKind.MAG]); assertEquals(n / 2, counts[SampleKind.ROTATION_VECTOR])
        assertEquals(n / 10, counts[SampleKind.PRESSURE]); assertEquals(1, counts[SampleKind.STEP_DETECTOR])
        assertEquals(listOf(3L, 7L, 12L, 3L, 7L), svids)
        assertEquals(1, counts[SampleKind.FIX])
        assertTrue((counts[SampleKind.META] ?: 0) >= 2, "session metadata written")

        // ... and it replays in the app's replay task.
        var done: NavOutput? = null
        var error: Exception? = null
        ReplayTask(file.path, NavigatorConfig(), 1L, onProgress = { _, _ -> }, onDone = { o, e -> done = o; error = e }).run()
        assertNull(error)
        assertNotNull(done)
    }
}

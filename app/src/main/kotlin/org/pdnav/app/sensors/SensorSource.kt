package org.pdnav.app.sensors

import android.hardware.Sensor
import android.hardware.SensorEvent
import android.hardware.SensorEventListener
import android.hardware.SensorManager
import android.os.Build
import android.os.Handler
import android.os.SystemClock
import org.pdnav.app.nav.SampleBatch
import org.pdnav.app.nav.SampleKind
import kotlin.math.sqrt

/**
 * The phone's motion and pressure sensors, registered with explicit rates and hardware
 * batching, converted into [SampleBatch] rows on the merger. SensorEvent.timestamp is on the
 * elapsedRealtimeNanos clock on Android 7+ phones (the project's common timeline).
 *
 * Screen off: the session holds a partial wake lock, so the CPU keeps draining the sensor
 * FIFOs; where the phone has a wake-up variant of a sensor it is preferred (its FIFO wakes
 * the CPU before it overflows, so batching survives even a suspend the wake lock did not
 * prevent). [onEvent] runs after every delivery: the session pumps from there.
 */
class SensorSource(
    private val sensors: SensorManager,
    private val merger: SampleMerger,
    /** Clock of onAccuracyChanged rows (the callback has no timestamp): elapsedRealtimeNanos, UTC ms. */
    private val clock: () -> Pair<Long, Long> = { SystemClock.elapsedRealtimeNanos() to System.currentTimeMillis() },
    private val onEvent: () -> Unit = {},
) : SensorEventListener {

    /** One sensor subscription: type, sampling period and allowed report latency, minimum API. */
    data class Rate(val type: Int, val periodUs: Int, val maxLatencyUs: Int, val minSdk: Int = 24)

    private val registered = mutableListOf<Sensor>()
    private val rows = java.util.concurrent.ConcurrentHashMap<Int, Long>()

    /** Magnetometer accuracy (SensorManager.SENSOR_STATUS_*), -1 before the first report. */
    @Volatile var magAccuracy = -1
        private set

    /** Sensors registered as wake-up sensors. */
    var wakeUpTypes: List<Int> = emptyList()
        private set

    /** Rows delivered so far per sensor type. */
    fun rowsByType(): Map<Int, Long> = HashMap(rows)

    /** Registers every available sensor of [RATES]; returns the types registered. */
    fun start(handler: Handler?): List<Int> {
        val types = mutableListOf<Int>()
        val wake = mutableListOf<Int>()
        for (r in RATES) {
            if (Build.VERSION.SDK_INT < r.minSdk) continue
            val s = defaultSensor(r.type) ?: continue
            if (sensors.registerListener(this, s, r.periodUs, r.maxLatencyUs, handler)) {
                registered += s
                types += r.type
                if (s.isWakeUpSensor) wake += r.type
            }
        }
        wakeUpTypes = wake
        return types
    }

    /** The wake-up variant when the phone has one, else the default sensor of [type]. */
    private fun defaultSensor(type: Int): Sensor? {
        val wakeUp = try {
            sensors.getDefaultSensor(type, true)
        } catch (e: RuntimeException) {
            null  // some vendor/emulator images do not list wake-up sensors
        }
        return wakeUp ?: sensors.getDefaultSensor(type)
    }

    fun stop() {
        sensors.unregisterListener(this)
        registered.clear()
    }

    override fun onSensorChanged(event: SensorEvent) {
        val t = event.timestamp
        val v = event.values
        val type = event.sensor.type
        if (type == Sensor.TYPE_MAGNETIC_FIELD) magAccuracy = event.accuracy
        merger.add { b -> addEvent(b, type, t, v) }
        rows.merge(type, 1L, Long::plus)
        onEvent()
    }

    /**
     * Records a `SensorAccuracy` line (docs/log-format.md) for every accuracy report of a
     * subscribed sensor: the magnetometer's says when the heading can be trusted (a user waves
     * the phone at "unreliable"), and replay can tell which stretches had a calibrated compass.
     */
    override fun onAccuracyChanged(sensor: Sensor, accuracy: Int) {
        val type = sensor.type
        if (type == Sensor.TYPE_MAGNETIC_FIELD) magAccuracy = accuracy
        if (type <= 0 || accuracy !in -1..3) return  // not a SENSOR_STATUS: nothing the log can hold
        val (t, utc) = clock()
        merger.add { b -> b.addSensorAccuracy(t, type, accuracy, utc) }
        accuracyReports.merge(type, 1L, Long::plus)
        onEvent()
    }

    private val accuracyReports = java.util.concurrent.ConcurrentHashMap<Int, Long>()

    /** onAccuracyChanged reports recorded so far per sensor type. */
    fun accuracyReportsByType(): Map<Int, Long> = HashMap(accuracyReports)

    companion object {
        /** Batching: up to 100 ms of samples per delivery (saves power, keeps latency low). */
        private const val LATENCY_US = 100_000

        /** 100 Hz inertial (step detection needs >= 50 Hz), 50 Hz mag/rotation, 10 Hz baro. */
        val RATES = listOf(
            Rate(Sensor.TYPE_ACCELEROMETER, 10_000, LATENCY_US),
            Rate(Sensor.TYPE_GYROSCOPE, 10_000, LATENCY_US),
            Rate(Sensor.TYPE_MAGNETIC_FIELD, 20_000, LATENCY_US),
            Rate(Sensor.TYPE_ROTATION_VECTOR, 20_000, LATENCY_US),
            // gyro + accelerometer only: an attitude that magnetic disturbances do not bend
            Rate(Sensor.TYPE_GAME_ROTATION_VECTOR, 20_000, LATENCY_US),
            Rate(Sensor.TYPE_PRESSURE, 100_000, LATENCY_US),
            Rate(Sensor.TYPE_STEP_DETECTOR, 0, 0),
            // GnssLogger's UncalAccel / UncalGyro / UncalMag (bias estimates kept beside the values)
            Rate(Sensor.TYPE_ACCELEROMETER_UNCALIBRATED, 10_000, LATENCY_US, minSdk = 26),
            Rate(Sensor.TYPE_GYROSCOPE_UNCALIBRATED, 10_000, LATENCY_US),
            Rate(Sensor.TYPE_MAGNETIC_FIELD_UNCALIBRATED, 20_000, LATENCY_US),
        )

        /** Human name of a sensor type, for the counters on screen. */
        fun typeName(type: Int): String = when (type) {
            Sensor.TYPE_ACCELEROMETER -> "accel"
            Sensor.TYPE_GYROSCOPE -> "gyro"
            Sensor.TYPE_MAGNETIC_FIELD -> "mag"
            Sensor.TYPE_ROTATION_VECTOR -> "rotation"
            Sensor.TYPE_GAME_ROTATION_VECTOR -> "game rotation"
            Sensor.TYPE_PRESSURE -> "baro"
            Sensor.TYPE_STEP_DETECTOR -> "steps"
            Sensor.TYPE_ACCELEROMETER_UNCALIBRATED -> "uncal accel"
            Sensor.TYPE_GYROSCOPE_UNCALIBRATED -> "uncal gyro"
            Sensor.TYPE_MAGNETIC_FIELD_UNCALIBRATED -> "uncal mag"
            else -> "type $type"
        }

        /** Appends one SensorEvent (type, timestamp, values) as a row; other types are ignored. */
        fun addEvent(b: SampleBatch, type: Int, t: Long, v: FloatArray) {
            when (type) {
                Sensor.TYPE_ACCELEROMETER -> if (v.size >= 3) b.addVector(SampleKind.ACCEL, t, v[0].toDouble(), v[1].toDouble(), v[2].toDouble())
                Sensor.TYPE_GYROSCOPE -> if (v.size >= 3) b.addVector(SampleKind.GYRO, t, v[0].toDouble(), v[1].toDouble(), v[2].toDouble())
                Sensor.TYPE_MAGNETIC_FIELD -> if (v.size >= 3) b.addVector(SampleKind.MAG, t, v[0].toDouble(), v[1].toDouble(), v[2].toDouble())
                Sensor.TYPE_PRESSURE -> if (v.isNotEmpty()) b.addPressure(t, v[0] * 100.0)  // hPa -> Pa
                Sensor.TYPE_ROTATION_VECTOR -> if (v.size >= 3) addRotation(b, t, v)
                Sensor.TYPE_GAME_ROTATION_VECTOR -> if (v.size >= 3) {
                    val q = quaternion(v)
                    b.addGameRotationVector(t, q[0], q[1], q[2], q[3])
                }
                Sensor.TYPE_STEP_DETECTOR -> b.addStep(t)
                Sensor.TYPE_ACCELEROMETER_UNCALIBRATED -> addUncal(b, SampleKind.UNCAL_ACCEL, t, v)
                Sensor.TYPE_GYROSCOPE_UNCALIBRATED -> addUncal(b, SampleKind.UNCAL_GYRO, t, v)
                Sensor.TYPE_MAGNETIC_FIELD_UNCALIBRATED -> addUncal(b, SampleKind.UNCAL_MAG, t, v)
            }
        }

        /** values[0..2] uncalibrated, values[3..5] the bias (drift for the gyroscope). */
        private fun addUncal(b: SampleBatch, kind: Int, t: Long, v: FloatArray) {
            if (v.size < 3) return
            val value = DoubleArray(3) { v[it].toDouble() }
            val bias = DoubleArray(3) { if (v.size >= 6) v[3 + it].toDouble() else Double.NaN }
            b.addUncalibrated(kind, t, value, bias)
        }

        /** x, y, z, w of a rotation-vector event; values[3] (w) is optional on old devices: from the unit norm. */
        private fun quaternion(v: FloatArray): DoubleArray {
            val x = v[0].toDouble()
            val y = v[1].toDouble()
            val z = v[2].toDouble()
            val w = if (v.size >= 4) v[3].toDouble() else sqrt((1.0 - x * x - y * y - z * z).coerceAtLeast(0.0))
            return doubleArrayOf(x, y, z, w)
        }

        private fun addRotation(b: SampleBatch, t: Long, v: FloatArray) {
            val q = quaternion(v)
            // values[4]: estimated heading accuracy (rad), -1 when unavailable.
            val acc = if (v.size >= 5 && v[4] >= 0f) v[4].toDouble() else Double.NaN
            b.addRotationVector(t, q[0], q[1], q[2], q[3], acc)
        }
    }
}
